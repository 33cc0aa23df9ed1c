"""Workspace-wide pytest set-up: every test process gets its own ROS 2 domain.

Processes on one machine see each other on the same ROS_DOMAIN_ID even with
localhost discovery (shared docs, platform.md), so each pytest process (xdist
worker, or a second pytest run beside this one) claims a free domain by holding
an exclusive lock file for its lifetime. Subprocesses inherit the domain.
"""
import fcntl
import os
import tempfile

_LOCK_DIR = os.path.join(tempfile.gettempdir(), 'dukw-ros-domains')
_held = None


def _claim_domain() -> int:
    global _held
    os.makedirs(_LOCK_DIR, exist_ok=True)
    for domain in range(101, 232):  # clear of the default 0 and of a developer's low ids
        handle = open(os.path.join(_LOCK_DIR, f'{domain}.lock'), 'w')
        try:
            fcntl.flock(handle, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except OSError:
            handle.close()
            continue
        _held = handle
        return domain
    raise RuntimeError('no free ROS_DOMAIN_ID for this test process')


os.environ['ROS_DOMAIN_ID'] = str(_claim_domain())
os.environ['ROS_AUTOMATIC_DISCOVERY_RANGE'] = 'LOCALHOST'
os.environ.setdefault('PYTHONUNBUFFERED', '1')

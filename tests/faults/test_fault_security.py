"""Fault matrix, access control set-up (README "Security").

Row: a stranger on another machine of the network. Must: the stacks keep the ROS graph
on the vehicle (localhost discovery) -- tests in src/dukw_bringup/test/test_bringup.py.
Row: SROS2 on a ROS 2 install with DDS-Security. Checked as far as the PyPI build
allows: the policy's structure, one enclave per node of the boat stack, exactly one
publishing enclave per safety topic and one server and one client per state-changing
service; `bringup` puts each node in its enclave; and a secured start on the PyPI Fast
DDS (no DDS-Security) is refused with exit 2 and a message, never run unsecured.
"""
import os
import subprocess
import xml.etree.ElementTree as ET
from pathlib import Path
from xml.etree import ElementInclude

import pytest

from dukw_bringup.bringup import load_stack, node_command, stack_path
from dukw_common.testing import executable

ROOT = Path(__file__).resolve().parents[2]
POLICY = ROOT / 'config' / 'sros2' / 'dukw_policy.xml'
SAFETY_TOPICS = ('tracks/cmd', 'props/cmd', 'drive_mode', 'authority', 'cmd_vel')
SAFETY_SERVICES = ('set_mode', 'set_pose')
QUALIFIERS = {'topics': ('publish', 'subscribe'), 'services': ('reply', 'request')}


def _policy():
    tree = ET.parse(POLICY)
    root = tree.getroot()

    def loader(href, parse, encoding=None):
        return ElementInclude.default_loader(str(POLICY.parent / href), parse, encoding)
    ElementInclude.include(root, loader=loader)
    return root


def _grants(root):
    """{(enclave, kind, qualifier): set of names} with every qualifier ALLOW."""
    grants = {}
    for enclave in root.iter('enclave'):
        for profile in enclave.iter('profile'):
            for group in profile:
                assert group.tag in QUALIFIERS, group.tag
                for qualifier in QUALIFIERS[group.tag]:
                    value = group.get(qualifier)
                    if value is None:
                        continue
                    assert value in ('ALLOW', 'DENY')
                    names = {e.text.strip() for e in group}
                    grants.setdefault((enclave.get('path'), group.tag, qualifier),
                                      set()).update(names)
    return grants


def test_policy_has_one_enclave_per_boat_node_in_the_sros2_format():
    root = _policy()
    assert root.tag == 'policy' and root.get('version') == '0.2.0'
    enclaves = {e.get('path'): e for e in root.find('enclaves')}
    for spec in load_stack(stack_path('boat')).nodes:
        enclave = enclaves[f'/dukw/{spec.name}']
        (profile,) = enclave.iter('profile')
        assert profile.get('ns') == '/' and profile.get('node') == spec.name


@pytest.mark.parametrize('topic', SAFETY_TOPICS)
def test_each_safety_topic_has_exactly_one_publishing_enclave(topic):
    publishers = [enclave for (enclave, kind, qualifier), names in _grants(_policy()).items()
                  if kind == 'topics' and qualifier == 'publish' and topic in names]
    assert len(publishers) == 1, publishers


@pytest.mark.parametrize('service', SAFETY_SERVICES)
def test_each_state_changing_service_has_one_server_and_one_client(service):
    grants = _grants(_policy())
    for qualifier, expected in (('reply', 1), ('request', 1)):
        holders = [enclave for (enclave, kind, q), names in grants.items()
                   if kind == 'services' and q == qualifier and service in names]
        assert len(holders) == expected, (qualifier, holders)


def test_bringup_runs_each_node_in_its_enclave_when_security_is_on():
    spec = load_stack(stack_path('boat')).node('ekf_node')
    command = node_command(spec, [], secure=True)
    assert command[command.index('--enclave') + 1] == '/dukw/ekf_node'
    assert '--enclave' not in node_command(spec, [])


def test_secured_start_on_the_pypi_dds_is_refused_not_run_unsecured(tmp_path):
    enclave = tmp_path / 'keystore' / 'enclaves' / 'dukw' / 'mode_manager_node'
    enclave.mkdir(parents=True)
    for name in ('identity_ca.cert.pem', 'cert.pem', 'key.pem', 'permissions_ca.cert.pem',
                 'governance.p7s', 'permissions.p7s'):
        (enclave / name).write_text('placeholder: the PyPI Fast DDS never reads it\n')
    env = {'ROS_SECURITY_ENABLE': 'true', 'ROS_SECURITY_STRATEGY': 'Enforce',
           'ROS_SECURITY_KEYSTORE': str(tmp_path / 'keystore')}
    proc = subprocess.run([str(executable('dukw_control', 'mode_manager_node')), '--ros-args',
                           '--enclave', '/dukw/mode_manager_node'], capture_output=True,
                          text=True, timeout=60, env={**os.environ, **env})
    assert proc.returncode == 2, proc.stderr
    assert 'security' in proc.stderr.lower() and 'Traceback' not in proc.stderr, proc.stderr

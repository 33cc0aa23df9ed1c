"""Runs for sysid from files: the simulator's ``maneuver --csv`` and rosbag2 folders.

ROS-free: bags are read with ``rosbags`` and the dukw_msgs ``.msg`` text. Inputs are
``tracks/cmd`` (land) or ``props/cmd`` (water); outputs u, v, r from the twist of
``odometry/filtered`` (body axes, base_link) or, with ``truth``, from ``sim/truth``.
The medium of a bag comes from ``sim/truth`` or else ``drive_mode``: a bag that also
holds other media (a whole mission) gives its longest stretch in the asked medium.
"""
from __future__ import annotations

import csv
from pathlib import Path

import numpy as np

from dukw_model.state_space import Run, SysIdError

#: Command topic per medium.
COMMAND_TOPIC = {'land': 'tracks/cmd', 'water': 'props/cmd'}
ODOMETRY_TOPIC = 'odometry/filtered'
TRUTH_TOPIC = 'sim/truth'
MODE_TOPIC = 'drive_mode'
#: maneuver CSV columns of the commands per medium.
CSV_COMMANDS = {'land': ('port_cmd', 'stbd_cmd'), 'water': ('port_prop_cmd', 'stbd_prop_cmd')}
CSV_OUTPUTS = ('u', 'v', 'r')
#: SimTruth.medium / DriveMode.mode values (dukw_msgs) -> medium name.
MEDIUM_CODES = {0: 'land', 1: 'transition', 2: 'water', 3: 'safe stop'}
MEDIUM_NAMES = {name: code for code, name in MEDIUM_CODES.items()}


def majority_medium(codes: np.ndarray) -> str:
    """The medium of most samples (e.g. 'land'), 'unknown' when there are none."""
    if codes.size == 0:
        return 'unknown'
    values, counts = np.unique(codes.astype(int), return_counts=True)
    return MEDIUM_CODES.get(int(values[np.argmax(counts)]), 'unknown')


def read_csv(path: str | Path, medium: str) -> Run:
    """A ``maneuver --csv`` file as a Run (its own 0.01 s steps)."""
    path = Path(path)
    try:
        with open(path, newline='') as handle:
            rows = list(csv.DictReader(handle))
    except OSError as exc:
        raise SysIdError(f'{path}: {exc.strerror or exc}') from exc
    need = ('t', 'medium') + CSV_COMMANDS[medium] + CSV_OUTPUTS
    if not rows or any(name not in rows[0] for name in need):
        raise SysIdError(f'{path}: not a maneuver CSV (needs columns {", ".join(need)})')
    try:
        col = {name: np.array([float(r[name]) for r in rows]) for name in need}
    except (TypeError, ValueError) as exc:
        raise SysIdError(f'{path}: unreadable number: {exc}') from exc
    return Run(path.name, majority_medium(col['medium']), col['t'],
               np.column_stack([col[c] for c in CSV_COMMANDS[medium]]),
               np.column_stack([col[c] for c in CSV_OUTPUTS]))


def _typestore():
    from rosbags.typesys import Stores, get_types_from_msg, get_typestore

    from dukw_estimation.fit_terrain import msg_dir
    store = get_typestore(Stores.ROS2_JAZZY)
    types: dict = {}
    for msg in sorted(msg_dir().glob('*.msg')):
        types.update(get_types_from_msg(msg.read_text(), f'dukw_msgs/msg/{msg.stem}'))
    store.register(types)
    return store


def _read_topics(path: Path, topics: tuple[str, ...]) -> dict[str, list]:
    """(receive time s, message) lists per wanted topic (names without leading slash)."""
    from rosbags.rosbag2 import Reader
    store = _typestore()
    out: dict[str, list] = {t: [] for t in topics}
    with Reader(path) as reader:
        conns = [c for c in reader.connections if c.topic.lstrip('/') in out]
        for conn, stamp_ns, raw in reader.messages(connections=conns):
            out[conn.topic.lstrip('/')].append(
                (stamp_ns * 1e-9, store.deserialize_cdr(raw, conn.msgtype)))
    return out


def read_bag(path: str | Path, medium: str, truth: bool = False) -> Run:
    """A rosbag2 folder recorded by the project as a Run (message times, not resampled)."""
    path = Path(path)
    if not (path / 'metadata.yaml').is_file():
        raise SysIdError(f'{path}: not a rosbag2 folder (no metadata.yaml)')
    out_topic = TRUTH_TOPIC if truth else ODOMETRY_TOPIC
    cmd_topic = COMMAND_TOPIC[medium]
    data = _read_topics(path, (cmd_topic, out_topic, TRUTH_TOPIC, MODE_TOPIC))
    missing = [t for t in (cmd_topic, out_topic) if len(data[t]) < 2]
    if missing:
        raise SysIdError(f'{path}: the bag lacks the needed topics: {", ".join(missing)} '
                         f'(record them, e.g. record --out BAG {cmd_topic} {out_topic} '
                         f'{MODE_TOPIC})')
    t_y = np.array([t for t, _ in data[out_topic]])
    if truth:
        y = np.array([(m.surge_mps, m.sway_mps, m.yaw_rate_rps) for _, m in data[out_topic]])
    else:
        y = np.array([(m.twist.twist.linear.x, m.twist.twist.linear.y,
                       m.twist.twist.angular.z) for _, m in data[out_topic]])
    t_u = np.array([t for t, _ in data[cmd_topic]])
    u = np.array([(m.port_pct, m.stbd_pct) for _, m in data[cmd_topic]])
    source = data[TRUTH_TOPIC] or data[MODE_TOPIC]   # empty: nothing says; trust the user
    t_m = [t for t, _ in source]
    codes = [m.medium if hasattr(m, 'medium') else m.mode for _, m in source]
    keep = t_y >= t_u[0]
    t_y, y = t_y[keep], y[keep]
    if codes:
        media = _held(np.array(t_m), np.array(codes), t_y) if t_y.size else np.array(codes)
        found = majority_medium(np.array(codes))
        lo, hi = _longest_stretch(media, MEDIUM_NAMES[medium])
        if hi - lo >= 2:          # the bag's longest stretch in the asked medium
            found, t_y, y = medium, t_y[lo:hi], y[lo:hi]
    else:
        found = medium
    return Run(path.name, found, t_y, _held(t_u, u, t_y), y)


def _longest_stretch(codes: np.ndarray, wanted: int) -> tuple[int, int]:
    """[start, end) of the longest run of ``wanted`` in ``codes`` ((0, 0) if none)."""
    best, start = (0, 0), None
    for k, code in enumerate(list(codes) + [None]):
        if code == wanted and start is None:
            start = k
        elif code != wanted and start is not None:
            best = max(best, (start, k), key=lambda s: s[1] - s[0])
            start = None
    return best


def _held(t_u: np.ndarray, u: np.ndarray, t: np.ndarray) -> np.ndarray:
    idx = np.clip(np.searchsorted(t_u, t, side='right') - 1, 0, t_u.size - 1)
    return u[idx]


def read_run(path: str | Path, medium: str, truth: bool = False) -> Run:
    """A bag folder or a maneuver CSV, by what ``path`` is."""
    path = Path(path)
    if path.is_dir():
        return read_bag(path, medium, truth)
    if path.suffix.lower() == '.csv':
        return read_csv(path, medium)
    raise SysIdError(f'{path}: neither a rosbag2 folder nor a maneuver .csv')

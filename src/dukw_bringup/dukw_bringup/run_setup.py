"""The main job's run folder and what it writes before the stack starts, without ROS.

A run folder holds everything of one run:

    dukw.yaml            the parameter file the nodes read (a copy)
    params_overlay.yaml  the run's overrides: sim start and sea, real-time factor,
                         use_sim_time for every node but the simulator, mission file
    mission.yaml         the mission as flown (cut to --waypoints when asked)
    logs/<node>.log      each node's output
    bag/                 rosbag2 (MCAP) of every topic
    summary.json, *.png  written at the end (plot_run rewrites them from bag/)

Time: the simulator publishes /clock; every other node (and the recorder and the
main job's monitor) runs with use_sim_time, so mission times and bag timestamps
are simulator seconds, and ``real_time_factor`` > 1 runs the whole mission faster
than real time as long as the nodes keep up.
"""
from __future__ import annotations

import datetime as dt
import math
import shutil
import tempfile
from dataclasses import asdict, replace
from pathlib import Path
from typing import Any

import yaml

from dukw_bringup.bringup import NodeSpec, StackSpec
from dukw_bringup.mission import MissionSpec, Progress
from dukw_common.config import ConfigError

SIM_NODE = 'sim_node'
SHORE_NODE = 'shore_link_node'
#: Where the main job's shore link sends: a ground station's default port on this machine.
SHORE_URL = 'udpout:127.0.0.1:14550'
ShoreSetup = tuple[Path, str]      # the shore link's signing key file and url
RECORDER = 'recorder'
MONITOR = 'main_job'
LIVE_VIEW = 'live_view_node'


def default_run_dir(root: Path, now: dt.datetime | None = None) -> Path:
    """``<root>/runs/<UTC timestamp>`` (e.g. runs/20261122T010203Z)."""
    now = now or dt.datetime.now(dt.timezone.utc)
    return root / 'runs' / now.strftime('%Y%m%dT%H%M%SZ')


def make_run_dir(path: Path) -> Path:
    """Create the run folder; refuse one that already holds a run (a bag or a summary)."""
    if (path / 'bag').exists() or (path / 'summary.json').exists():
        raise ConfigError(f'{path} already holds a run; give a new folder')
    path.mkdir(parents=True, exist_ok=True)
    return path


def mission_document(spec: MissionSpec) -> dict[str, Any]:
    """The mission as a mission-file document (round-trips through parse_mission)."""
    tree = asdict(spec)
    tree['waypoints'] = [asdict(w) for w in spec.waypoints]
    return {'mission': tree}


def sim_overrides(spec: MissionSpec, real_time_factor: float) -> dict[str, Any]:
    """sim_node parameters that set up the mission's world (see config/dukw.yaml sim_node)."""
    start_at = 'sand' if spec.start.x_m < 0.0 else 'afloat'
    return {
        'real_time_factor': real_time_factor,
        'start_at': start_at,
        'start': {f'{start_at}_x_m': spec.start.x_m},
        'start_yaw_rad': spec.start.yaw_rad,
        'seed': spec.sea.seed,
        'waves': {'model': 'irregular' if spec.sea.significant_height_m > 0.0 else 'none',
                  'significant_height_m': spec.sea.significant_height_m,
                  'peak_period_s': spec.sea.peak_period_s},
    }


def write_overlay(path: Path, stack: StackSpec, spec: MissionSpec, mission_file: Path,
                  real_time_factor: float, shore: ShoreSetup | None = None) -> Path:
    """Write the run's parameter overlay (a ROS 2 parameter file given after dukw.yaml)."""
    doc: dict[str, Any] = {}
    for name in stack.node_names() + [MONITOR]:
        if name == SIM_NODE:
            doc[name] = {'ros__parameters': sim_overrides(spec, real_time_factor)}
        else:
            doc[name] = {'ros__parameters': {'use_sim_time': True}}
    if LIVE_VIEW in doc:                # draws the same sea as the simulator
        sea = sim_overrides(spec, real_time_factor)
        doc[LIVE_VIEW]['ros__parameters'].update(seed=sea['seed'], waves=sea['waves'])
    if 'mission_node' in doc:
        doc['mission_node']['ros__parameters']['mission_file'] = str(mission_file)
    if SHORE_NODE in doc:
        if shore is None:
            raise ConfigError(f'{SHORE_NODE} in the stack needs a signing key file and a url')
        doc[SHORE_NODE]['ros__parameters'].update(signing_key_file=str(shore[0]), url=shore[1])
    path.write_text("# The run's overrides of dukw.yaml (written by main_job).\n"
                    + yaml.safe_dump(doc, sort_keys=False))
    return path


def prepare_run(run_dir: Path, config: Path, stack: StackSpec, spec: MissionSpec,
                real_time_factor: float, shore: ShoreSetup | None = None) -> tuple[Path, Path]:
    """Copy the config, write mission.yaml and the overlay; return (config copy, overlay)."""
    if not (real_time_factor >= 0.0 and math.isfinite(real_time_factor)):
        raise ConfigError(f'real-time factor must be >= 0 (0 = as fast as possible), '
                          f'got {real_time_factor}')
    config_copy = run_dir / 'dukw.yaml'
    shutil.copyfile(config, config_copy)
    mission_file = run_dir / 'mission.yaml'
    mission_file.write_text('# The mission as flown (written by main_job).\n'
                            + yaml.safe_dump(mission_document(spec), sort_keys=False))
    overlay = write_overlay(run_dir / 'params_overlay.yaml', stack, spec, mission_file,
                            real_time_factor, shore)
    return config_copy, overlay


def shore_key_path(run_dir: Path) -> Path:
    """A per-run signing key outside the repository: <tmp>/dukw-shore-keys/<run>.key."""
    return Path(tempfile.gettempdir()) / 'dukw-shore-keys' / f'{run_dir.name}.key'


def make_shore_key(path: Path) -> str:
    """Write a new signing key (and its passphrase) for the run's shore link; return the
    passphrase a ground station is given."""
    from dukw_driver.mavlink_signing import generate_key_file
    return generate_key_file(path)[1]


def with_shore_link(stack: StackSpec) -> StackSpec:
    """The stack with the shore link last (it needs a per-run key, so the stack files, which
    ``bringup`` and the launch file also start, do not list it)."""
    return replace(stack, nodes=(*stack.nodes, NodeSpec(SHORE_NODE, 'dukw_driver', SHORE_NODE)))


def with_recorder(stack: StackSpec, bag_dir: Path) -> StackSpec:
    """The stack with the recorder first: it starts before and stops after every node."""
    recorder = NodeSpec(RECORDER, 'dukw_bringup', 'record',
                        cli_args=('--out', str(bag_dir), '--all'))
    return replace(stack, nodes=(recorder, *stack.nodes))


def format_progress(t_s: float, mode: str, progress: Progress | None, speed_mps: float,
                    track_a: tuple[float, float], prop_a: tuple[float, float]) -> str:
    """One progress line: time, mode, next waypoint and distance, speed, currents."""
    if progress is None:
        where = 'mission: no status yet'
    elif progress.state.finished:
        where = f'mission {progress.state.value}'
    else:
        total = progress.waypoints_total
        distance = ('?' if not math.isfinite(progress.distance_m)
                    else f'{progress.distance_m:5.1f} m')
        where = (f'{progress.state.value} wp {min(progress.waypoint_index + 1, total)}/{total} '
                 f'{progress.waypoint_name} {distance}')

    def amps(pair: tuple[float, float]) -> str:
        return '/'.join('--' if not math.isfinite(a) else f'{a:4.1f}' for a in pair)
    speed = '--' if not math.isfinite(speed_mps) else f'{speed_mps:4.2f}'
    return (f't={t_s:6.1f}s  {mode:<10} {where}  speed {speed} m/s  '
            f'tracks {amps(track_a)} A  props {amps(prop_a)} A')

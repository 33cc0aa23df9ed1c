"""plot_run: (re)write a run folder's summary.json and plots from its bag.

    plot_run runs/20261122T010203Z

Reads ``RUN_DIR/bag`` (rosbag2, MCAP) with rosbags, the mission and parameter
file the run used (``RUN_DIR/mission.yaml``, ``RUN_DIR/dukw.yaml``; the
workspace's when absent), writes ``RUN_DIR/summary.json`` and the PNGs, and
prints the summary and, last, the folder.
"""
from __future__ import annotations

import argparse
import json
import math
import sys
from pathlib import Path
from typing import Any

from dukw_bringup.bag_io import BagError, summarize
from dukw_bringup.mission import MissionSpec, load_mission
from dukw_bringup.plots import PlotContext, write_plots
from dukw_bringup.summary import load_run, summarize_run, summary_lines, write_summary
from dukw_common.config import ConfigError, default_config_path, node_params
from dukw_common.vehicle import Vehicle

BAG_DIR = 'bag'
SUMMARY_FILE = 'summary.json'
#: what main_job adds to the summary and a later plot_run keeps
RUN_KEYS = ('ending', 'exit_code', 'real_time_factor', 'wall_time_s')
MISSION_COPY = 'mission.yaml'
CONFIG_COPY = 'dukw.yaml'


def run_files(run_dir: Path) -> tuple[Path, Path]:
    """The parameter file and mission file of a run (its copies, else the workspace's)."""
    config = run_dir / CONFIG_COPY
    mission = run_dir / MISSION_COPY
    config = config if config.is_file() else default_config_path()
    mission = mission if mission.is_file() else config.parent / MISSION_COPY
    return config, mission


def previous_run_keys(path: Path) -> dict[str, Any]:
    """RUN_KEYS of an earlier summary.json ({} if there is none or it is unreadable)."""
    try:
        previous = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    return {k: previous[k] for k in RUN_KEYS if isinstance(previous, dict) and k in previous}


def render_run(run_dir: str | Path, wall_time_s: float | None = None,
               extra: dict[str, Any] | None = None) -> dict[str, Any]:
    """Read the run's bag, write summary.json and the plots; return the summary.

    Without ``extra``, the main job's own keys (RUN_KEYS) of an existing summary stay.
    """
    run_dir = Path(run_dir)
    if extra is None:
        extra = previous_run_keys(run_dir / SUMMARY_FILE)
    config_path, mission_path = run_files(run_dir)
    vehicle = Vehicle.load(str(config_path))
    sim = node_params('sim_node', config_path)
    mission: MissionSpec = load_mission(mission_path)
    run = load_run(run_dir / BAG_DIR)
    limit_a = vehicle.drivetrain.continuous_current_limit_a
    summary = summarize_run(run, limit_a, mission.name, wall_time_s)
    summary.update(extra)
    info = summarize(run_dir / BAG_DIR)
    summary['bag'] = BAG_DIR
    summary['bag_messages'] = info.message_count
    summary['bag_topics'] = {t.topic: t.count for t in info.topics}
    context = PlotContext(
        beach_slope_rad=vehicle.site.beach_slope_rad,
        sea_floor_depth_m=vehicle.site.sea_floor_depth_m,
        current_limit_a=limit_a, displacement_n=vehicle.body.displacement_n,
        displaced_volume_m3=vehicle.body.displaced_volume_m3,
        flat_start_x_m=float(sim.get('world.flat_start_x_m', -math.inf)),
        waypoints=mission.waypoints, title=f'{mission.name}: {run_dir.name}')
    summary['plots'] = [p.name for p in write_plots(run, context, run_dir)]
    write_summary(summary, run_dir / SUMMARY_FILE)
    return summary


def main(argv: list[str] | None = None) -> int:
    """Console-script entry point."""
    parser = argparse.ArgumentParser(prog='plot_run', description=__doc__.split('\n')[0])
    parser.add_argument('run_dir', type=Path, help='a run folder holding bag/')
    parser.add_argument('--json', action='store_true', help='print summary.json, not lines')
    args = parser.parse_args(argv)
    try:
        summary = render_run(args.run_dir)
    except (BagError, ConfigError) as exc:
        print(f'[FATAL] plot_run: {exc}', file=sys.stderr)
        return 2
    if args.json:
        print(json.dumps(summary, indent=2))
    else:
        print('\n'.join(summary_lines(summary)))
    print(args.run_dir)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())

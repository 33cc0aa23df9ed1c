"""main_job: the whole stack on the simulator through the land -> sea -> land mission.

    main_job [--out DIR] [--rtf 2] [--waypoints N] [--time-limit S] [--no-shore-link]

Creates the run folder (default runs/<UTC timestamp>/; see dukw_bringup.run_setup),
starts the recorder (every topic to bag/, MCAP), the simulator stack
(config/stack_sim_composed.yaml, the control chain in one process; ``--stack sim``: one
process per node) and the shore link (MAVLink 2 to a ground station on
udpout:127.0.0.1:14550, signed with a key made for the run, outside the repository,
whose file and passphrase are printed) through the bring-up runner, prints the mode changes and
one progress line a second, and stops when the mission ends, the time limit
passes, a node dies or on Ctrl-C. The stack stops in reverse order, the
recorder last (the bag is closed cleanly, also on Ctrl-C); then summary.json and
the plots are written from the bag, the summary is printed and, as the last
line, the run folder. Exit code: 0 mission done, 3 not done (timeout, time
limit), 1 a node failed, 2 bad configuration, 130 interrupted.
"""
from __future__ import annotations

import argparse
import math
import sys
import threading
import time
from pathlib import Path

from dukw_bringup.bag_io import BagError
from dukw_bringup.bringup import Runner, install_stop_signals, load_stack, stack_path
from dukw_bringup.mission import MissionState, Progress, load_mission
from dukw_bringup.plot_run import BAG_DIR, render_run
from dukw_bringup.run_setup import (MONITOR, SHORE_URL, default_run_dir, format_progress,
                                    make_run_dir, make_shore_key, prepare_run, shore_key_path,
                                    with_recorder, with_shore_link)
from dukw_bringup.summary import MODE_NAMES, summary_lines, write_summary
from dukw_common.config import ConfigError, default_config_path

#: The Foxglove layout for the live view and the run's bag.
LAYOUT = 'config/foxglove/dukw_layout.json'
EXIT_DONE, EXIT_FAILED, EXIT_CONFIG, EXIT_NOT_DONE, EXIT_INTERRUPTED = 0, 1, 2, 3, 130


class Monitor:
    """A small rclpy node in its own context: what the progress lines show."""

    def __init__(self, overlay: Path) -> None:
        import rclpy
        from rclpy.context import Context
        from rclpy.executors import SingleThreadedExecutor
        self._rclpy = rclpy
        self.context = Context()
        rclpy.init(args=['--ros-args', '--params-file', str(overlay)], context=self.context)
        self.node = rclpy.create_node(MONITOR, context=self.context)
        self.executor = SingleThreadedExecutor(context=self.context)
        self.executor.add_node(self.node)
        self.progress: Progress | None = None
        self.mode = 'no mode'
        self.mode_changes: list[tuple[float, str, str]] = []
        self.speed_mps = math.nan
        self.track_a = (math.nan, math.nan)
        self.prop_a = (math.nan, math.nan)
        self.live_view_url = ''
        self._subscribe()

    def _subscribe(self) -> None:
        from dukw_msgs.msg import DriveMode, DrivetrainStatus
        from nav_msgs.msg import Odometry
        from std_msgs.msg import String

        from dukw_common.node_tools import SENSOR_QOS, STATE_QOS
        node = self.node
        node.create_subscription(String, 'mission/status', self._on_status, STATE_QOS)
        node.create_subscription(String, 'live_view/url', self._on_live_view, STATE_QOS)
        node.create_subscription(DriveMode, 'drive_mode', self._on_mode, STATE_QOS)
        node.create_subscription(Odometry, 'odometry/filtered', self._on_odom, SENSOR_QOS)
        node.create_subscription(DrivetrainStatus, 'tracks/status',
                                 lambda m: setattr(self, 'track_a', self._amps(m)), SENSOR_QOS)
        node.create_subscription(DrivetrainStatus, 'props/status',
                                 lambda m: setattr(self, 'prop_a', self._amps(m)), SENSOR_QOS)

    @staticmethod
    def _amps(msg) -> tuple[float, float]:
        return (msg.port.current_a, msg.stbd.current_a)

    def _on_status(self, msg) -> None:
        try:
            self.progress = Progress.from_json(msg.data)
        except ValueError as exc:
            self.node.get_logger().warn(str(exc), throttle_duration_sec=5.0)

    def _on_live_view(self, msg) -> None:
        if msg.data != self.live_view_url:
            self.live_view_url = msg.data
            print(f'[main_job] live view: {msg.data} (Foxglove: Open connection -> Foxglove '
                  f'WebSocket; layout {LAYOUT})', flush=True)

    def _on_mode(self, msg) -> None:
        mode = MODE_NAMES.get(msg.mode, str(msg.mode))
        if mode != self.mode:
            self.mode = mode
            self.mode_changes.append((self.now_s(), mode, msg.reason))
            print(f'[main_job] mode -> {mode} at t={self.now_s():.1f}s: {msg.reason}',
                  flush=True)

    def _on_odom(self, msg) -> None:
        self.speed_mps = msg.twist.twist.linear.x

    def now_s(self) -> float:
        """Sim time (use_sim_time), s."""
        return self.node.get_clock().now().nanoseconds * 1e-9

    def spin(self, duration_s: float) -> None:
        """Handle messages for about ``duration_s`` of wall time."""
        deadline = time.monotonic() + duration_s
        while time.monotonic() < deadline and self.context.ok():
            self.executor.spin_once(timeout_sec=min(0.05, duration_s))

    def line(self) -> str:
        """The current progress line."""
        return format_progress(self.now_s(), self.mode, self.progress, self.speed_mps,
                               self.track_a, self.prop_a)

    def close(self) -> None:
        """Tear the node and its context down."""
        self.executor.shutdown()
        self.node.destroy_node()
        self._rclpy.try_shutdown(context=self.context)


def parse_args(argv: list[str] | None) -> argparse.Namespace:
    """Command-line options."""
    parser = argparse.ArgumentParser(prog='main_job', description=__doc__.split('\n')[0])
    parser.add_argument('--out', type=Path, help='run folder (default runs/<UTC timestamp>)')
    parser.add_argument('--mission', type=Path, help='mission file (default config/mission.yaml)')
    parser.add_argument('--params-file', type=Path,
                        help='parameter file (default config/dukw.yaml)')
    parser.add_argument('--stack', default='sim_composed',
                        help='stack name or file (default sim_composed: the control chain in '
                             'one process, the faster shape; sim: one process per node)')
    parser.add_argument('--rtf', type=float, default=1.0,
                        help='real-time factor of the simulator (0 = as fast as possible)')
    parser.add_argument('--waypoints', type=int, help='fly only the first N waypoints')
    parser.add_argument('--shore-url', default=SHORE_URL,
                        help=f'where the shore link talks (default {SHORE_URL})')
    parser.add_argument('--no-shore-link', action='store_true',
                        help='do not start the shore link')
    parser.add_argument('--time-limit', type=float,
                        help='stop after this many wall seconds (default: mission timeout / '
                             'rtf + 60 s)')
    return parser.parse_args(argv)


def run(args: argparse.Namespace, stop: threading.Event) -> int:
    """The main job; returns the exit code. Always prints the run folder last."""
    config = args.params_file or default_config_path()
    try:
        mission = load_mission(args.mission)
        if args.waypoints:
            mission = mission.with_waypoints(args.waypoints)
        stack = load_stack(stack_path(args.stack))
        if args.rtf != 1.0:          # real-time priority only at real time (bringup)
            stack = stack.at_normal_priority()
        run_dir = make_run_dir(args.out or default_run_dir(Path.cwd()))
        stack = with_recorder(stack, run_dir / BAG_DIR)
        shore_key = None
        if not args.no_shore_link:
            stack, shore_key = with_shore_link(stack), shore_key_path(run_dir)
            passphrase = make_shore_key(shore_key)
            print(f'[main_job] shore link: MAVLink 2 on {args.shore_url}, signed; key file '
                  f'{shore_key}, passphrase for QGroundControl / MAVProxy: {passphrase}',
                  flush=True)
            if args.shore_url.startswith('udpout:'):    # the ground station listens there
                print('[main_job] ground station: mavproxy.py --master=udpin:'
                      f'{args.shore_url[len("udpout:"):]} '
                      f'--cmd="set param_ftp 0; signing key {passphrase}"', flush=True)
        config_copy, overlay = prepare_run(run_dir, config, stack, mission, args.rtf,
                                           (shore_key, args.shore_url) if shore_key else None)
        runner = Runner(stack, [config_copy, overlay], log_dir=run_dir / 'logs', echo=False)
    except ConfigError as exc:
        print(f'[main_job] FATAL: {exc}', file=sys.stderr)
        return EXIT_CONFIG
    rtf = args.rtf if args.rtf > 0 else 1.0
    wall_limit_s = args.time_limit or mission.timeout_s / rtf + 60.0
    print(f'[main_job] run folder {run_dir}; mission {mission.name!r}, '
          f'{len(mission.waypoints)} waypoints, real-time factor {args.rtf:g}, '
          f'stops after {wall_limit_s:.0f} s at most', flush=True)
    started = time.monotonic()
    code, ending = EXIT_NOT_DONE, 'time limit'
    monitor = None
    try:
        runner.start()
        monitor = Monitor(overlay)
        while not stop.is_set():
            monitor.spin(1.0)
            print(f'[main_job] {monitor.line()}', flush=True)
            dead = runner.poll()
            if dead is not None:
                code, ending = EXIT_FAILED, runner.report_death(dead)
                break
            if monitor.progress is not None and monitor.progress.state.finished:
                done = monitor.progress.state is MissionState.DONE
                code = EXIT_DONE if done else EXIT_NOT_DONE
                ending = f'mission {monitor.progress.state.value}'
                break
            if time.monotonic() - started > wall_limit_s:
                break
        else:
            code, ending = EXIT_INTERRUPTED, 'interrupted'
    except (ConfigError, OSError) as exc:
        code, ending = EXIT_FAILED, f'could not start the stack: {exc}'
        print(f'[main_job] ERROR: {ending}', file=sys.stderr)
    finally:
        print(f'[main_job] stopping the stack ({ending})', flush=True)
        if monitor is not None:
            monitor.close()
        runner.stop()
    wall_s = time.monotonic() - started
    extra = {'ending': ending, 'exit_code': code, 'real_time_factor': args.rtf,
             'wall_time_s': round(wall_s, 2)}
    try:
        summary = render_run(run_dir, wall_s, extra)
        print('\n'.join(f'[main_job] {line}' for line in summary_lines(summary)))
    except (BagError, ConfigError, OSError) as exc:
        print(f'[main_job] ERROR: no summary from the bag: {exc}', file=sys.stderr)
        write_summary({**extra, 'reached': False, 'bag': None, 'error': str(exc)},
                      run_dir / 'summary.json')
    print(run_dir, flush=True)
    return code


def main(argv: list[str] | None = None) -> int:
    """Console-script entry point."""
    args = parse_args(argv)
    stop = threading.Event()
    install_stop_signals(stop)
    return run(args, stop)


if __name__ == '__main__':
    raise SystemExit(main())

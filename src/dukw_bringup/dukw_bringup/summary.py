"""A run's time series out of its bag, and the run's summary (summary.json), without ROS.

``load_run`` reads the topics the summary and the plots need from a rosbag2
(through dukw_bringup.bag_io / rosbags) into numpy arrays on one time axis: the
bag's receive time in seconds from the first message (sim time when the
recorder ran with use_sim_time). ``summarize_run`` turns them into the
figures of the main job's summary: reached or not, time, mode timeline, peak and
average motor currents against the continuous limit, slip and submersion
extremes.
"""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from dukw_bringup.bag_io import deserialize, read_messages, topic_key
from dukw_bringup.mission import MissionState, Progress

#: dukw_msgs/DriveMode mode constants (same values), for people.
MODE_NAMES = {0: 'LAND', 1: 'TRANSITION', 2: 'WATER', 3: 'SAFE_STOP'}

Getter = Callable[[Any], float]


def _sides(prefix: str, field_name: str) -> dict[str, Getter]:
    return {f'port_{prefix}': lambda m: getattr(m.port, field_name),
            f'stbd_{prefix}': lambda m: getattr(m.stbd, field_name)}


def _twist(msg):
    return getattr(msg, 'twist', msg)


#: topic -> column -> how to read it from the deserialized message.
COLUMNS: dict[str, dict[str, Getter]] = {
    'odometry/filtered': {
        'x_m': lambda m: m.pose.pose.position.x, 'y_m': lambda m: m.pose.pose.position.y,
        'z_m': lambda m: m.pose.pose.position.z, 'speed_mps': lambda m: m.twist.twist.linear.x},
    'tracks/status': {**_sides('current_a', 'current_a'), **_sides('force_n', 'force_n'),
                      **_sides('speed_mps', 'speed_mps')},
    'props/status': {**_sides('current_a', 'current_a'), **_sides('force_n', 'force_n')},
    'traction': {name: (lambda m, n=name: getattr(m, n)) for name in (
        'port_slip', 'stbd_slip', 'submerged_volume_m3', 'effective_weight_n',
        'weight_on_tracks_fraction', 'waterline_distance_m', 'port_force_predicted_n',
        'stbd_force_predicted_n', 'port_force_measured_n', 'stbd_force_measured_n')},
    'sim/truth': {name: (lambda m, n=name: getattr(m, n)) for name in (
        'x_m', 'y_m', 'z_m', 'surge_mps', 'port_slip', 'stbd_slip', 'port_force_n',
        'stbd_force_n', 'submerged_volume_m3', 'effective_weight_n',
        'weight_on_tracks_fraction', 'water_depth_m', 'wave_elevation_m', 'medium')},
    'drive_mode': {'mode': lambda m: m.mode},
    'tracks/cmd': {'port_pct': lambda m: m.port_pct, 'stbd_pct': lambda m: m.stbd_pct},
    'props/cmd': {'port_pct': lambda m: m.port_pct, 'stbd_pct': lambda m: m.stbd_pct},
    'cmd_vel': {'speed_mps': lambda m: _twist(m).linear.x,       # Twist or TwistStamped
                'yaw_rate_rps': lambda m: _twist(m).angular.z},
}
#: topics kept as text (time, text)
TEXT_TOPICS = {'mission/status': lambda m: m.data, 'drive_mode': lambda m: m.reason}


@dataclass
class Series:
    """One topic's columns over time."""

    t_s: np.ndarray
    columns: dict[str, np.ndarray]

    def __getitem__(self, name: str) -> np.ndarray:
        return self.columns[name]

    def __len__(self) -> int:
        return len(self.t_s)


@dataclass
class RunData:
    """A run's series by topic (relative names), plus text messages."""

    series: dict[str, Series] = field(default_factory=dict)
    texts: dict[str, list[tuple[float, str]]] = field(default_factory=dict)
    duration_s: float = 0.0      # first to last message of the topics read
    message_count: int = 0       # messages of the topics read

    def get(self, topic: str) -> Series | None:
        """The topic's series, or None when the bag has no message of it."""
        series = self.series.get(topic)
        return series if series is not None and len(series) else None


def load_run(bag_path: str | Path) -> RunData:
    """Read the summary's and plots' topics from the bag at ``bag_path``."""
    rows: dict[str, list[tuple[float, ...]]] = {t: [] for t in COLUMNS}
    times: dict[str, list[float]] = {t: [] for t in COLUMNS}
    texts: dict[str, list[tuple[float, str]]] = {t: [] for t in TEXT_TOPICS}
    t0_ns: int | None = None
    count = 0
    last_ns = 0
    for message in read_messages(bag_path, [*COLUMNS, *TEXT_TOPICS]):
        count += 1
        if t0_ns is None and message.timestamp_ns > 0:
            t0_ns = message.timestamp_ns  # a sim-time recorder stamps 0 before the first /clock
        last_ns = message.timestamp_ns
        key = topic_key(message.topic)
        msg = deserialize(message)
        t_s = max(0.0, (message.timestamp_ns - (t0_ns or message.timestamp_ns)) * 1e-9)
        if key in COLUMNS:
            rows[key].append(tuple(float(get(msg)) for get in COLUMNS[key].values()))
            times[key].append(t_s)
        if key in TEXT_TOPICS:
            texts[key].append((t_s, str(TEXT_TOPICS[key](msg))))
    run = RunData(texts=texts, message_count=count,
                  duration_s=0.0 if t0_ns is None else (last_ns - t0_ns) * 1e-9)
    for topic, names in COLUMNS.items():
        table = np.array(rows[topic], dtype=float).reshape(-1, len(names))
        run.series[topic] = Series(np.array(times[topic], dtype=float),
                                   {name: table[:, i] for i, name in enumerate(names)})
    return run


def mode_timeline(run: RunData) -> list[dict[str, Any]]:
    """Every change of drive mode: time, mode name, the mode manager's reason."""
    reasons = dict(run.texts.get('drive_mode', []))
    series = run.get('drive_mode')
    timeline: list[dict[str, Any]] = []
    if series is None:
        return timeline
    previous = None
    for t_s, mode in zip(series.t_s, series['mode'], strict=True):
        if mode != previous:
            timeline.append({'t_s': round(float(t_s), 3),
                             'mode': MODE_NAMES.get(int(mode), str(int(mode))),
                             'reason': reasons.get(t_s, '')})
            previous = mode
    return timeline


def final_progress(run: RunData) -> Progress | None:
    """The last mission/status the bag holds (None without any)."""
    for _, text in reversed(run.texts.get('mission/status', [])):
        try:
            return Progress.from_json(text)
        except ValueError:
            continue
    return None


def _finite(values: np.ndarray) -> np.ndarray:
    return values[np.isfinite(values)]


def _extreme(values: np.ndarray, how: Callable) -> float | None:
    finite = _finite(values)
    return round(float(how(finite)), 4) if finite.size else None


def time_average(t_s: np.ndarray, values: np.ndarray) -> float:
    """Time-weighted mean of a sampled signal (sample-and-hold), NaN for no samples."""
    if len(values) == 0:
        return math.nan
    if len(values) == 1 or t_s[-1] <= t_s[0]:
        return float(np.mean(values))
    dt = np.diff(t_s)
    return float(np.sum(values[:-1] * dt) / np.sum(dt))


def current_figures(series: Series | None, limit_a: float) -> dict[str, Any]:
    """Peak, time-averaged mean and time above ``limit_a`` of each side's |current|."""
    figures: dict[str, Any] = {}
    for side in ('port', 'stbd'):
        if series is None:
            figures[side] = None
            continue
        amps = np.abs(series[f'{side}_current_a'])
        ok = np.isfinite(amps)
        t_s, amps = series.t_s[ok], amps[ok]
        over = amps > limit_a
        dt = np.diff(t_s, append=t_s[-1]) if len(t_s) else np.array([])
        figures[side] = {
            'peak_a': round(float(amps.max()), 2) if amps.size else None,
            'mean_a': round(time_average(t_s, amps), 2) if amps.size else None,
            'time_over_limit_s': round(float(np.sum(dt[over])), 2),
            'peak_over_limit': bool(amps.size and amps.max() > limit_a)}
    return figures


def summarize_run(run: RunData, current_limit_a: float,
                  mission_name: str = '', wall_time_s: float | None = None) -> dict[str, Any]:
    """The run's summary as a JSON-ready dict (the keys of summary.json)."""
    progress = final_progress(run)
    traction, truth, odom = run.get('traction'), run.get('sim/truth'), run.get('odometry/filtered')
    state = progress.state.value if progress else 'unknown'
    summary: dict[str, Any] = {
        'mission': mission_name,
        'reached': bool(progress and progress.state is MissionState.DONE),
        'state': state,
        'waypoints_reached': len(progress.reached_s) if progress else 0,
        'waypoints_total': progress.waypoints_total if progress else 0,
        'time_s': round(progress.elapsed_s, 2) if progress else None,
        'waypoint_times_s': [round(t, 2) for t in progress.reached_s] if progress else [],
        'recorded_s': round(run.duration_s, 2),
        'wall_time_s': None if wall_time_s is None else round(wall_time_s, 2),
        'mode_timeline': mode_timeline(run),
        'current_limit_a': current_limit_a,
        'track_currents': current_figures(run.get('tracks/status'), current_limit_a),
        'prop_currents': current_figures(run.get('props/status'), current_limit_a),
    }
    summary['slip'] = {
        source: None if series is None else {
            side: {'min': _extreme(series[f'{side}_slip'], np.min),
                   'max': _extreme(series[f'{side}_slip'], np.max)} for side in ('port', 'stbd')}
        for source, series in (('estimated', traction), ('truth', truth))}
    summary['submersion'] = {
        source: None if series is None else {
            'max_submerged_volume_m3': _extreme(series['submerged_volume_m3'], np.max),
            'min_effective_weight_n': _extreme(series['effective_weight_n'], np.min),
            'min_weight_on_tracks_fraction': _extreme(series['weight_on_tracks_fraction'],
                                                      np.min)}
        for source, series in (('estimated', traction), ('truth', truth))}
    path = truth or odom
    if path is not None:
        steps = np.hypot(np.diff(path['x_m']), np.diff(path['y_m']))
        summary['distance_m'] = round(float(np.sum(_finite(steps))), 2)
        summary['x_range_m'] = [_extreme(path['x_m'], np.min), _extreme(path['x_m'], np.max)]
    else:
        summary['distance_m'] = None
        summary['x_range_m'] = None
    return summary


def write_summary(summary: dict[str, Any], path: str | Path) -> None:
    """Write summary.json (NaN/inf become null)."""
    def clean(value: Any) -> Any:
        if isinstance(value, float) and not math.isfinite(value):
            return None
        if isinstance(value, dict):
            return {k: clean(v) for k, v in value.items()}
        if isinstance(value, list):
            return [clean(v) for v in value]
        return value
    Path(path).write_text(json.dumps(clean(summary), indent=2) + '\n')


def summary_lines(summary: dict[str, Any]) -> list[str]:
    """A few lines for people at the end of a run."""
    lines = [f"mission {summary['mission']!r}: {summary['state']}"
             f" ({summary['waypoints_reached']}/{summary['waypoints_total']} waypoints"
             + (f", {summary['time_s']:.1f} s" if summary['time_s'] is not None else '') + ')']
    modes = ' -> '.join(f"{m['mode']}@{m['t_s']:.1f}s" for m in summary['mode_timeline'])
    lines.append(f'modes: {modes or "none recorded"}')
    limit = summary['current_limit_a']
    for label, key in (('tracks', 'track_currents'), ('props', 'prop_currents')):
        sides = summary[key]
        if sides.get('port') is None:
            continue
        lines.append(f'{label} current vs {limit:.0f} A: ' + ', '.join(
            f"{side} peak {fig['peak_a']} A mean {fig['mean_a']} A"
            f" ({fig['time_over_limit_s']} s over)" for side, fig in sides.items()))
    for source in ('estimated', 'truth'):
        slip, sub = summary['slip'][source], summary['submersion'][source]
        if slip is None:
            continue
        lines.append(f'{source}: slip port [{slip["port"]["min"]}, {slip["port"]["max"]}] '
                     f'stbd [{slip["stbd"]["min"]}, {slip["stbd"]["max"]}], '
                     f'max submerged {sub["max_submerged_volume_m3"]} m3, '
                     f'min effective weight {sub["min_effective_weight_n"]} N')
    return lines

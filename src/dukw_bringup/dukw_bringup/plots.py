"""The main job's plots (matplotlib, Agg, PNG), from a RunData: the paper's sections VI-VII.

trajectory.png   plan view with the waypoints, and the vehicle over the beach profile
forces.png       track forces (measured, predicted) and motor currents against the limit
slip.png         slip per track, estimated and true
submersion.png   submerged volume and effective weight, estimated and true
modes.png        drive-mode timeline with speed and command
"""
from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402  (backend first)
import numpy as np  # noqa: E402

from dukw_bringup.mission import Waypoint  # noqa: E402
from dukw_bringup.summary import MODE_NAMES, RunData  # noqa: E402

PLOT_FILES = ('trajectory.png', 'forces.png', 'slip.png', 'submersion.png', 'modes.png')


@dataclass(frozen=True)
class PlotContext:
    """What the plots need besides the data: the site, the vehicle's limits, the mission."""

    beach_slope_rad: float
    sea_floor_depth_m: float
    current_limit_a: float
    displacement_n: float
    displaced_volume_m3: float
    flat_start_x_m: float = -float('inf')   # the simulator's flat sand landward of this
    waypoints: tuple[Waypoint, ...] = ()
    title: str = ''


def beach_profile(x_m: np.ndarray, slope_rad: float, floor_depth_m: float,
                  flat_start_x_m: float = -np.inf) -> np.ndarray:
    """Ground height above the mean water level: flat sand, a plane slope, the sea floor."""
    x = np.maximum(np.asarray(x_m, dtype=float), flat_start_x_m)
    return np.maximum(-x * np.tan(slope_rad), -floor_depth_m)


def _figure(rows: int, title: str):
    fig, axes = plt.subplots(rows, 1, figsize=(10, 3.2 * rows), sharex=rows > 1,
                             squeeze=False)
    if title:
        fig.suptitle(title)
    return fig, axes[:, 0]


def _save(fig, path: Path) -> Path:
    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path


def _legend(ax, loc: str = 'upper right') -> None:
    if ax.get_legend_handles_labels()[0]:
        ax.legend(loc=loc, fontsize='small')


def _no_data(ax, what: str) -> None:
    ax.text(0.5, 0.5, f'no {what} in this run', ha='center', va='center',
            transform=ax.transAxes, color='grey')


def plot_trajectory(run: RunData, ctx: PlotContext, path: Path) -> Path:
    """Plan view and elevation over the beach profile."""
    fig, (plan, side) = plt.subplots(2, 1, figsize=(10, 8))
    fig.suptitle(ctx.title or 'trajectory')
    xs = []
    for topic, label, style in (('sim/truth', 'truth', '-'), ('odometry/filtered', 'EKF', '--')):
        series = run.get(topic)
        if series is None:
            continue
        plan.plot(series['x_m'], series['y_m'], style, label=label)
        side.plot(series['x_m'], series['z_m'], style, label=f'{label} (base_link height)')
        xs.append(series['x_m'])
    if ctx.waypoints:
        plan.plot([w.x_m for w in ctx.waypoints], [w.y_m for w in ctx.waypoints], 'k^',
                  label='waypoints')
        for w in ctx.waypoints:
            plan.annotate(w.name, (w.x_m, w.y_m), textcoords='offset points', xytext=(4, 4))
        xs.append(np.array([w.x_m for w in ctx.waypoints]))
    plan.axvline(0.0, color='tab:blue', lw=0.8, ls=':', label='mean waterline')
    plan.set_xlabel('x seaward (m)')
    plan.set_ylabel('y (m)')
    plan.set_aspect('equal', adjustable='datalim')
    _legend(plan, 'center')
    if xs:
        finite = np.concatenate(xs)
        finite = finite[np.isfinite(finite)]
        lo, hi = (finite.min() - 2.0, finite.max() + 2.0) if finite.size else (-12.0, 22.0)
    else:
        lo, hi = -12.0, 22.0
    grid = np.linspace(lo, hi, 400)
    ground = beach_profile(grid, ctx.beach_slope_rad, ctx.sea_floor_depth_m,
                           ctx.flat_start_x_m)
    side.fill_between(grid, ground, ground.min() - 0.3, color='tan', label='beach (config)')
    side.fill_between(grid, ground, 0.0, where=ground < 0.0, color='lightblue', alpha=0.6,
                      label='mean sea level')
    side.set_xlabel('x seaward (m)')
    side.set_ylabel('height above mean water (m)')
    _legend(side)
    if not xs:
        _no_data(plan, 'trajectory')
    return _save(fig, path)


def plot_forces(run: RunData, ctx: PlotContext, path: Path) -> Path:
    """Track forces and motor currents with the continuous current limit."""
    fig, (force_ax, current_ax, prop_ax) = _figure(3, ctx.title or 'track forces and currents')
    tracks, traction = run.get('tracks/status'), run.get('traction')
    if tracks is not None:
        for side, color in (('port', 'tab:red'), ('stbd', 'tab:green')):
            force_ax.plot(tracks.t_s, tracks[f'{side}_force_n'], color=color, lw=0.8,
                          label=f'{side} measured (current x gain)')
            current_ax.plot(tracks.t_s, tracks[f'{side}_current_a'], color=color, lw=0.8,
                            label=f'{side} track motor')
    else:
        _no_data(force_ax, 'tracks/status')
    if traction is not None:
        for side, color in (('port', 'darkred'), ('stbd', 'darkgreen')):
            force_ax.plot(traction.t_s, traction[f'{side}_force_predicted_n'], color=color,
                          ls='--', lw=0.8, label=f'{side} predicted (Wong)')
    props = run.get('props/status')
    if props is not None:
        for side, color in (('port', 'tab:red'), ('stbd', 'tab:green')):
            prop_ax.plot(props.t_s, props[f'{side}_current_a'], color=color, lw=0.8,
                         label=f'{side} propeller')
    else:
        _no_data(prop_ax, 'props/status')
    for ax in (current_ax, prop_ax):
        ax.axhline(ctx.current_limit_a, color='k', ls='--', lw=1.0,
                   label=f'{ctx.current_limit_a:.0f} A continuous limit')
        ax.set_ylabel('current (A)')
        _legend(ax)
    force_ax.set_ylabel('track force (N)')
    _legend(force_ax)
    prop_ax.set_xlabel('time (s)')
    return _save(fig, path)


def plot_slip(run: RunData, ctx: PlotContext, path: Path) -> Path:
    """Slip per track: estimated (traction) and true (sim/truth)."""
    fig, axes = _figure(2, ctx.title or 'track slip')
    for ax, side in zip(axes, ('port', 'stbd'), strict=True):
        plotted = False
        for topic, label, style in (('traction', 'estimated', '-'), ('sim/truth', 'truth', '--')):
            series = run.get(topic)
            if series is not None:
                ax.plot(series.t_s, series[f'{side}_slip'], style, lw=0.8, label=label)
                plotted = True
        if not plotted:
            _no_data(ax, 'slip')
        ax.set_ylabel(f'{side} slip i')
        ax.set_ylim(-1.2, 1.2)
        ax.axhline(0.0, color='grey', lw=0.5)
        _legend(ax)
    axes[-1].set_xlabel('time (s)')
    return _save(fig, path)


def plot_submersion(run: RunData, ctx: PlotContext, path: Path) -> Path:
    """Submerged volume and effective weight, estimated and true."""
    fig, (vol_ax, weight_ax) = _figure(2, ctx.title or 'submersion')
    plotted = False
    for topic, label, style in (('traction', 'estimated', '-'), ('sim/truth', 'truth', '--')):
        series = run.get(topic)
        if series is None:
            continue
        plotted = True
        vol_ax.plot(series.t_s, series['submerged_volume_m3'], style, lw=0.8, label=label)
        weight_ax.plot(series.t_s, series['effective_weight_n'], style, lw=0.8, label=label)
    if not plotted:
        _no_data(vol_ax, 'submersion')
    vol_ax.axhline(ctx.displaced_volume_m3, color='k', ls=':', lw=1.0,
                   label=f'afloat, {ctx.displaced_volume_m3:.3f} m3')
    weight_ax.axhline(ctx.displacement_n, color='k', ls=':', lw=1.0,
                      label=f'dry, {ctx.displacement_n:.0f} N')
    vol_ax.set_ylabel('submerged volume (m3)')
    weight_ax.set_ylabel('effective weight W_e (N)')
    weight_ax.set_xlabel('time (s)')
    for ax in (vol_ax, weight_ax):
        _legend(ax)
    return _save(fig, path)


def plot_modes(run: RunData, ctx: PlotContext, path: Path) -> Path:
    """Drive mode over time, with speed and the track/propeller commands."""
    fig, (mode_ax, speed_ax, cmd_ax) = _figure(3, ctx.title or 'drive mode')
    modes = run.get('drive_mode')
    if modes is not None:
        mode_ax.step(modes.t_s, modes['mode'], where='post', label='drive_mode')
    else:
        _no_data(mode_ax, 'drive_mode')
    truth = run.get('sim/truth')
    if truth is not None:
        mode_ax.step(truth.t_s, truth['medium'], where='post', ls='--', alpha=0.6,
                     label='true medium (LAND/TRANSITION/WATER)')
    _legend(mode_ax)
    mode_ax.set_yticks(list(MODE_NAMES), list(MODE_NAMES.values()))
    for topic, column, label in (('odometry/filtered', 'speed_mps', 'EKF surge speed'),
                                 ('sim/truth', 'surge_mps', 'true surge speed'),
                                 ('cmd_vel', 'speed_mps', 'cmd_vel')):
        series = run.get(topic)
        if series is not None:
            speed_ax.plot(series.t_s, series[column], lw=0.8, label=label)
    speed_ax.set_ylabel('speed (m/s)')
    _legend(speed_ax)
    for topic, label in (('tracks/cmd', 'tracks'), ('props/cmd', 'props')):
        series = run.get(topic)
        if series is not None:
            for side in ('port', 'stbd'):
                cmd_ax.plot(series.t_s, series[f'{side}_pct'], lw=0.8, label=f'{label} {side}')
    cmd_ax.set_ylabel('command (%)')
    cmd_ax.set_xlabel('time (s)')
    _legend(cmd_ax)
    return _save(fig, path)


def write_plots(run: RunData, ctx: PlotContext, out_dir: str | Path) -> list[Path]:
    """Write every plot into ``out_dir``; return the files."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    makers = (plot_trajectory, plot_forces, plot_slip, plot_submersion, plot_modes)
    return [make(run, ctx, out / name) for make, name in zip(makers, PLOT_FILES, strict=True)]

"""Comparison plots of ``validate``: the simulator against the paper (matplotlib, PNG)."""
from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use('Agg')
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402


def _bars(ax, labels: list, sim: list, paper: list, unit: str, title: str) -> None:
    x = np.arange(len(labels))
    ax.bar(x - 0.2, paper, 0.4, label='paper')
    ax.bar(x + 0.2, sim, 0.4, label='simulator')
    ax.set_xticks(x, labels, rotation=45)
    ax.set_ylabel(unit)
    ax.set_title(title)
    ax.legend()


def _turns(rows: list, title: str, path: Path) -> Path:
    fig, ax = plt.subplots(figsize=(8, 4.5))
    _bars(ax, [r[0] for r in rows], [r[1] for r in rows], [r[2] for r in rows],
          'radius, m', title + ' (port/stbd %)')
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def _inclines(rows: list, path: Path) -> Path:
    labels, sim, paper = [], [], []
    for slope, sp, ss, pp, ps in rows:
        labels += [f'{slope:g} deg port', f'{slope:g} deg stbd']
        sim += [sp, ss]
        paper += [pp, ps]
    fig, ax = plt.subplots(figsize=(7, 4.5))
    _bars(ax, labels, sim, paper, 'mean current, A', 'inclines at equal 100 % commands')
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def _surf(rows: list, path: Path) -> Path:
    fig, ax = plt.subplots(figsize=(7, 4.5))
    for k, direction in enumerate(('land-to-sea', 'sea-to-land')):
        pts = [r for r in rows if r[0] == direction]
        if not pts:
            continue
        cmds = [r[1] for r in pts]
        color = f'C{k}'
        ax.axhspan(pts[0][3], pts[0][4], color=color, alpha=0.15,
                   label=f'paper {direction} range')
        ax.plot(cmds, [r[2] for r in pts], 'o-', color=color, label=f'simulator {direction}')
    ax.set_xlabel('track command, %')
    ax.set_ylabel('mean force per track in the surf, N')
    ax.set_title('surf zone, day 1 (28 cm)')
    ax.legend()
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def _drift(rows: list, path: Path) -> Path:
    fig, ax = plt.subplots(figsize=(7, 4.5))
    _bars(ax, [r[0].replace('rms_', '') for r in rows], [r[1] for r in rows],
          [r[2] for r in rows], 'RMS', 'drift in the surf, day 1')
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def _zigzag(series: tuple, title: str, path: Path) -> Path:
    t, sim, model = series
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for k, name in enumerate(('u, m/s', 'v, m/s', 'r')):
        axes[k].plot(t, sim[:, k], label='simulator')
        axes[k].plot(t, model[:, k], label="paper's identified model")
        axes[k].set_ylabel(name)
    axes[0].set_title(title)
    axes[0].legend()
    axes[-1].set_xlabel('t, s')
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def write_plots(res, folder: Path) -> list[Path]:
    """Write one PNG per group that ran into ``folder``; return the paths."""
    folder.mkdir(parents=True, exist_ok=True)
    s = res.series
    out = []
    if 'land_turns' in s:
        out.append(_turns(s['land_turns'], 'land turns', folder / 'land_turns.png'))
    if 'water_turns' in s:
        out.append(_turns(s['water_turns'], 'water turns', folder / 'water_turns.png'))
    if 'inclines' in s:
        out.append(_inclines(s['inclines'], folder / 'inclines.png'))
    if 'surf_transitions' in s:
        out.append(_surf(s['surf_transitions'], folder / 'surf_forces.png'))
    if 'drift' in s:
        out.append(_drift(s['drift'], folder / 'drift_rms.png'))
    for medium in ('land', 'water'):
        key = f'zigzag_{medium}'
        if key in s:
            out.append(_zigzag(s[key], f'{medium} zigzag', folder / f'{key}.png'))
    return out

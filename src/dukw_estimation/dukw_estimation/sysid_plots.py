"""Plots of sysid comparisons like the paper's Figs. 18-23: each output, data and model."""
from __future__ import annotations

import re
from pathlib import Path
from typing import Sequence

from dukw_model.state_space import OUTPUTS, Comparison

_LABELS = {'u': 'surge u, m/s', 'v': 'sway v, m/s', 'r': 'yaw rate r, rad/s'}


def _safe(name: str) -> str:
    return re.sub(r'[^A-Za-z0-9_.-]+', '_', name).strip('_') or 'run'


def plot_comparisons(comparisons: Sequence[Comparison], out_dir: str | Path, stage: str,
                     medium: str) -> list[Path]:
    """One PNG per run: u, v, r measured and simulated (and one-step when known)."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    paths = []
    for i, comp in enumerate(comparisons):
        t = comp.run.t_s - comp.run.t_s[0]
        fig, axes = plt.subplots(len(OUTPUTS), 1, sharex=True, figsize=(8, 7))
        for j, (ax, name) in enumerate(zip(axes, OUTPUTS, strict=True)):
            ax.plot(t, comp.run.y[:, j], 'k', lw=1.0, label='measured')
            ax.plot(t, comp.y_sim[:, j], 'C0', lw=1.2,
                    label=f'model, simulated: fit {comp.fit_pct[name]:.1f} %')
            if comp.y_one_step is not None:
                ax.plot(t, comp.y_one_step[:, j], 'C1--', lw=0.8, label='one step ahead')
            ax.set_ylabel(_LABELS[name])
            ax.grid(True, alpha=0.3)
            ax.legend(loc='best', fontsize=7)
        axes[-1].set_xlabel('time, s')
        fig.suptitle(f'{medium} model, {stage} data: {comp.run.name}')
        fig.tight_layout()
        path = out / f'{stage}_{medium}_{i}_{_safe(comp.run.name)}.png'
        fig.savefig(path, dpi=90)
        plt.close(fig)
        paths.append(path)
    return paths


def plot_singular_values(values, out_dir: str | Path, order: int) -> Path:
    """The singular values used for the order choice, log scale."""
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    fig, ax = plt.subplots(figsize=(6, 3.5))
    ax.semilogy(range(1, len(values) + 1), values, 'o-')
    ax.axvline(order + 0.5, color='C3', ls='--', label=f'order {order}')
    ax.set_xlabel('index')
    ax.set_ylabel('singular value')
    ax.legend()
    ax.grid(True, alpha=0.3)
    fig.tight_layout()
    path = out / 'singular_values.png'
    fig.savefig(path, dpi=90)
    plt.close(fig)
    return path

"""Real-time factor of the simulator core at 100 Hz (target >= 50x on a 2-core machine).

Prints one line per scenario: simulated seconds per wall-clock second, and the mean
wall time of one step. Figures only; nothing here passes or fails.
"""
from __future__ import annotations

import argparse
import time

from dukw_sim.core import Actuation, SimCore

SCENARIOS = [
    ('flat sand, calm', {}, {'x_m': -30.0}, Actuation(100, 96)),
    ('surf, irregular 28 cm sea', {'waves.model': 'irregular',
                                   'waves.significant_height_m': 0.28}, {'start': 'sand'},
     Actuation(64, 64)),
    ('afloat, irregular 28 cm sea', {'waves.model': 'irregular',
                                     'waves.significant_height_m': 0.28},
     {'start': 'afloat'}, Actuation(0, 0, 100, -100)),
]


def main() -> None:
    """Run every scenario for --seconds of simulated time and print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=60.0, help='simulated time per case')
    args = parser.parse_args()
    for name, overrides, reset, act in SCENARIOS:
        sim = SimCore.from_config(overrides=overrides, seed=1)
        sim.reset(**reset)
        steps = int(args.seconds / sim.dt_s)
        start = time.perf_counter()
        for _ in range(steps):
            sim.step(act)
        wall = time.perf_counter() - start
        print(f'sim core, {name}: real-time factor {args.seconds / wall:6.1f}x at '
              f'{1.0 / sim.dt_s:.0f} Hz ({wall / steps * 1e6:6.1f} us/step)')


if __name__ == '__main__':
    main()

"""Real-time factor of the simulator core at 100 Hz (target >= 50x on a 2-core machine).

Prints one line per scenario: simulated seconds per wall-clock second, the same per
second of this process's CPU time (what the core costs when the machine is shared),
and the mean wall time of one step; then the load average. Figures only.
"""
from __future__ import annotations

import argparse
import os
import time

from dukw_sim.core import Actuation, SimCore
from figures import report

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
    parser.add_argument('--only', default='', help='run the scenarios whose name has this')
    args = parser.parse_args()
    for name, overrides, reset, act in SCENARIOS:
        if args.only not in name:
            continue
        sim = SimCore.from_config(overrides=overrides, seed=1)
        sim.reset(**reset)
        steps = int(args.seconds / sim.dt_s)
        start, cpu_start = time.perf_counter(), time.process_time()
        for _ in range(steps):
            sim.step(act)
        wall = time.perf_counter() - start
        cpu = time.process_time() - cpu_start
        print(f'sim core, {name}: real-time factor {args.seconds / wall:6.1f}x wall, '
              f'{args.seconds / cpu:6.1f}x CPU at {1.0 / sim.dt_s:.0f} Hz '
              f'({wall / steps * 1e6:6.1f} us/step)')
        irregular = 'irregular 28 cm sea' in name
        report(f'sim core real-time factor, {name}', args.seconds / wall, 'x',
               target=100.0 if irregular else None, better='higher')
    print(f'load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores')


if __name__ == '__main__':
    main()

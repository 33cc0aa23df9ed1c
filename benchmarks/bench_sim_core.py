"""Real-time factor of the simulator core at 100 Hz, alone and with every sensor model.

Per scenario, two runs over the same seeded sea: the physics core alone (``SimCore.step``),
then the core with the sensor models (``SensorModel.sample`` on every step's truth, at
their configured rates: what sim_node and the in-process stack harness run per step).
Prints simulated seconds per wall-clock second, the same per second of this process's CPU
time (what the core costs when the machine is shared) and the mean wall time of one step;
then the load average. Target (issue 16): >= 100x in the irregular 28 cm sea with all
sensors. Figures only.
"""
from __future__ import annotations

import argparse
import os
import time

from dukw_sim.core import Actuation, SimCore
from dukw_sim.sensors import SensorModel
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


def run(overrides: dict, reset: dict, act: Actuation, seconds: float,
        with_sensors: bool) -> tuple[float, float, int]:
    """Wall and CPU seconds of ``seconds`` of simulated time, and the steps taken."""
    sim = SimCore.from_config(overrides=overrides, seed=1)
    sensors = SensorModel.from_config(seed=1) if with_sensors else None
    truth = sim.reset(**reset)
    steps = int(seconds / sim.dt_s)
    start, cpu_start = time.perf_counter(), time.process_time()
    if sensors is None:
        for _ in range(steps):
            sim.step(act)
    else:
        sensors.sample(truth)
        for _ in range(steps):
            sensors.sample(sim.step(act))
    return time.perf_counter() - start, time.process_time() - cpu_start, steps


def main() -> None:
    """Run every scenario for --seconds of simulated time and print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--seconds', type=float, default=60.0, help='simulated time per case')
    parser.add_argument('--only', default='', help='run the scenarios whose name has this')
    parser.add_argument('--no-sensors', action='store_true', help='the core alone only')
    parser.add_argument('--sensors-only', action='store_true', help='core + sensors only')
    args = parser.parse_args()
    kinds = [k for k, skip in ((False, args.sensors_only), (True, args.no_sensors)) if not skip]
    for name, overrides, reset, act in SCENARIOS:
        if args.only not in name:
            continue
        for with_sensors in kinds:
            wall, cpu, steps = run(overrides, reset, act, args.seconds, with_sensors)
            label = f'{name}, with sensors' if with_sensors else name
            print(f'sim core, {label}: real-time factor {args.seconds / wall:6.1f}x wall, '
                  f'{args.seconds / cpu:6.1f}x CPU at {steps / args.seconds:.0f} Hz '
                  f'({wall / steps * 1e6:6.1f} us/step)', flush=True)
            target = 100.0 if with_sensors and 'irregular 28 cm sea' in name else None
            report(f'sim core real-time factor, {label}', args.seconds / wall, 'x',
                   target=target, better='higher')
    print(f'load average {os.getloadavg()[0]:.1f} on {os.cpu_count()} cores')


if __name__ == '__main__':
    main()

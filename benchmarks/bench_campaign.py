"""Campaign throughput: seconds per run and runs per hour with 1 and 2 local Dask workers.

Runs the same N runs of a campaign spec (default config/campaigns/transitions.yaml) on a
LocalCluster of 1, then 2 worker processes, and prints wall time, runs/hour and the mean
per-run wall time the workers measured; then what 10 000 runs would take on M machines of
the same kind. Figures only (a shared machine gives lower figures).
"""
from __future__ import annotations

import argparse
import os
import time

from dukw_bringup import campaign, campaign_cli


def measure(spec: campaign.Spec, runs: int, workers: int) -> tuple[float, float]:
    """Wall seconds for ``runs`` on ``workers`` local processes; mean per-run wall seconds."""
    client, cluster = campaign_cli.open_client(workers, None)
    try:
        client.wait_for_workers(workers)
        start = time.perf_counter()
        rows = campaign_cli.run_on_dask(spec, runs, client, progress=False)
        wall = time.perf_counter() - start
    finally:
        campaign_cli.close_client(client, cluster)
    per_run = sum(r['wall_s'] for r in rows) / len(rows)
    return wall, per_run


def main() -> None:
    """Measure with 1 and 2 workers and print the figures."""
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--spec', default='config/campaigns/transitions.yaml')
    parser.add_argument('--runs', type=int, default=12)
    args = parser.parse_args()
    spec = campaign.load_spec(args.spec)
    print(f'{args.runs} runs of {spec.name}, {spec.duration_s:.0f} s simulated each')
    rate = {}
    for workers in (1, 2):
        wall, per_run = measure(spec, args.runs, workers)
        rate[workers] = 3600.0 * args.runs / wall
        print(f'{workers} worker(s): {wall:6.1f} s wall, {wall / args.runs:5.2f} s/run, '
              f'{rate[workers]:6.0f} runs/h (a run itself: {per_run:.2f} s wall)')
    per_core = rate[1]
    for machines, cores in ((1, 2), (10, 8), (50, 8)):
        minutes = 60.0 * 10_000 / (per_core * machines * cores)
        print(f'10 000 runs on {machines} machine(s) x {cores} cores: ~{minutes:.0f} min '
              '(one worker per core, scaling as 1 worker)')
    print(f'load average: {os.getloadavg()[0]:.2f}')


if __name__ == '__main__':
    main()

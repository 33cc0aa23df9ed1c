"""campaign: randomized runs of the in-process stack on Dask distributed.

    campaign SPEC.yaml [--runs N] [--workers W] [--scheduler ADDRESS] [--out DIR]
    campaign SPEC.yaml --rerun INDEX [--out DIR]

By default a LocalCluster of W worker processes (one thread each) on this machine; with
--scheduler, an existing cluster (`dask scheduler` + `dask worker ADDRESS` on machines with
this workspace installed). Writes runs.csv, runs.parquet, summary.json and plots into DIR
(last line of the output). --rerun reproduces one run here, with its series.csv and
series.png.
Exit 0 when the campaign finished (whatever the share), 2 on a bad spec or option.
"""
from __future__ import annotations

import argparse
import json
import os
import sys
import time
import traceback
from datetime import datetime, timezone
from pathlib import Path
from typing import Sequence

from dukw_bringup import campaign, campaign_report


def run_on_dask(spec: campaign.Spec, runs: int, client, progress: bool = True,
                run=campaign.run_one) -> list[dict]:
    """Submit runs 0..runs-1 to the cluster; collect rows as they finish (a run whose task
    itself fails, e.g. a worker that died, becomes a row with its traceback)."""
    from distributed import as_completed
    from tqdm import tqdm
    futures = [client.submit(run, spec, index, pure=False) for index in range(runs)]
    index_of = {f.key: i for i, f in enumerate(futures)}
    rows = []
    for future in tqdm(as_completed(futures), total=runs, disable=not progress,
                       desc=spec.name, unit='run', file=sys.stderr):
        try:
            rows.append(future.result())
        except Exception as exc:  # noqa: BLE001 (recorded, never fatal to the campaign)
            rows.append({'index': index_of[future.key], 'targets_met': False,
                         'error': ''.join(traceback.format_exception(exc))})
        future.release()
    return sorted(rows, key=lambda r: r['index'])


def open_client(workers: int, scheduler: str | None):
    """(Client, its own LocalCluster or None): on the given scheduler, else a new cluster."""
    from distributed import Client, LocalCluster
    if scheduler:
        return Client(scheduler), None
    cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                           dashboard_address=':0')
    return Client(cluster), cluster


def close_client(client, cluster) -> None:
    """Close the client, and the LocalCluster if it was ours (never a given scheduler)."""
    client.close()
    if cluster is not None:
        cluster.close()


def write_campaign(spec: campaign.Spec, rows: list[dict], out: Path) -> dict:
    """runs.csv, summary.json and the plots into ``out``; the summary."""
    out.mkdir(parents=True, exist_ok=True)
    campaign_report.write_runs_csv(rows, out / 'runs.csv')
    campaign_report.write_runs_parquet(rows, out / 'runs.parquet')
    summary = campaign_report.summarize(spec, rows)
    campaign_report.write_summary(summary, out / 'summary.json')
    campaign_report.plot_campaign(rows, out)
    return summary


def rerun(spec: campaign.Spec, index: int, out: Path) -> dict:
    """Run ``index`` here; its row (run.json), series.csv and series.png into ``out``."""
    out.mkdir(parents=True, exist_ok=True)
    row = campaign.run_one(spec, index, keep_series=True)
    series = row.pop('_series', None)
    if series is not None:
        campaign_report.write_series(series, out / 'series.csv')
        campaign_report.plot_series(series, out / 'series.png')
    (out / 'run.json').write_text(json.dumps(row, indent=2) + '\n', encoding='utf-8')
    return row


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog='campaign', description=__doc__.split('\n\n')[0])
    p.add_argument('spec', help='campaign spec (YAML; e.g. config/campaigns/transitions.yaml)')
    p.add_argument('--runs', type=int, help="number of runs (default: the spec's)")
    p.add_argument('--workers', type=int, default=os.cpu_count() or 1,
                   help='LocalCluster worker processes (default: CPU count)')
    p.add_argument('--scheduler', help='address of a running dask scheduler, tcp://HOST:8786')
    p.add_argument('--out', type=Path, help='output folder (default: runs/campaign-NAME-UTC)')
    p.add_argument('--rerun', type=int, metavar='INDEX', help='reproduce one run locally')
    p.add_argument('--no-progress', action='store_true', help='no progress bar')
    return p


def main(argv: Sequence[str] | None = None) -> int:
    """Console-script entry point."""
    parser = _parser()
    args = parser.parse_args(argv)
    try:
        spec = campaign.load_spec(args.spec)
    except campaign.SpecError as exc:
        print(f'campaign: {exc}', file=sys.stderr)
        return 2
    runs = spec.runs if args.runs is None else args.runs
    if runs < 1 or args.workers < 1 or (args.rerun is not None and args.rerun < 0):
        parser.error('--runs, --workers must be >= 1 and --rerun >= 0')
    stamp = datetime.now(timezone.utc).strftime('%Y%m%dT%H%M%SZ')
    if args.rerun is not None:
        out = args.out or Path('runs') / f'campaign-{spec.name}-run{args.rerun}-{stamp}'
        row = rerun(spec, args.rerun, out)
        print(json.dumps({k: v for k, v in row.items() if k != 'error'}), flush=True)
        if row['error']:
            print(row['error'], file=sys.stderr)
        print(out)
        return 0
    out = args.out or Path('runs') / f'campaign-{spec.name}-{stamp}'
    start = time.perf_counter()
    client, cluster = open_client(args.workers, args.scheduler)
    try:
        rows = run_on_dask(spec, runs, client, progress=not args.no_progress)
    finally:
        close_client(client, cluster)
    summary = write_campaign(spec, rows, out)
    wall = time.perf_counter() - start
    print(f'{summary["completed"]}/{runs} runs completed, '
          f'{summary["share_meeting_targets"]:.1%} meeting the targets, '
          f'{len(summary["failed_indices"])} raised; {wall:.0f} s wall '
          f'({3600.0 * runs / wall:.0f} runs/h)', flush=True)
    print(out)
    return 0


if __name__ == '__main__':
    raise SystemExit(main())

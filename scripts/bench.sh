#!/usr/bin/env bash
# Benchmarks: each prints its figures (no pass/fail on timing), then one summary table
# of every figure against its target (benchmarks/figures.py, benchmarks/summary.py).
# BENCHES="benchmarks/bench_ekf.py ..." runs only those.
set -uo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
DUKW_BENCH_FIGURES="$(mktemp --suffix=.jsonl)"
export DUKW_BENCH_FIGURES
trap 'rm -f "$DUKW_BENCH_FIGURES"' EXIT
rc=0
for b in ${BENCHES:-benchmarks/bench_*.py}; do
  [ -e "$b" ] || continue
  echo "== $b"
  timeout -k 10 900 python "$b" "$@" || rc=1
done
echo "== summary ($(date -u '+%Y-%m-%d %H:%M UTC'), load average $(cut -d' ' -f1 /proc/loadavg))"
python benchmarks/summary.py "$DUKW_BENCH_FIGURES" || rc=1
exit $rc

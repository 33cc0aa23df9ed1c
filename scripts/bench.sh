#!/usr/bin/env bash
# Benchmarks: each prints its figures (no pass/fail on timing).
set -uo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
rc=0
for b in benchmarks/bench_*.py; do
  [ -e "$b" ] || continue
  echo "== $b"
  timeout -k 10 900 python "$b" "$@" || rc=1
done
exit $rc

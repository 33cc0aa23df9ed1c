#!/usr/bin/env bash
# Run every test of the workspace (package unit tests under src/*/test, workspace
# tests under tests/) in two parallel workers, each on its own ROS_DOMAIN_ID.
set -uo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
python -m pytest -n 2 src tests "$@"
rc=$?
if [ "$rc" -eq 5 ]; then
  echo "[test] error: pytest collected no tests (exit 5); that is a failure here" >&2
  exit 1
fi
exit "$rc"

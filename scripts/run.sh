#!/usr/bin/env bash
# The main job: the whole stack on the simulator through the land-sea-land mission
# (dukw_bringup main_job). Extra arguments go to main_job, e.g.
#   make run ARGS="--rtf 2 --out runs/try1"      bash scripts/run.sh --waypoints 2
# The run folder's path is the last line of the output.
set -uo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
exec install/lib/dukw_bringup/main_job "$@"

#!/usr/bin/env bash
# The main job: the whole stack on the simulator.
set -uo pipefail
cd "$(dirname "$0")/.."
source scripts/env.sh
exec install/lib/dukw_sim/sim_node "$@"

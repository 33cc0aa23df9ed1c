#!/usr/bin/env bash
# Regenerate the golden bags of the replay regression tests (tests/golden/) after a
# deliberate change of behaviour (simulator, sensor models, EKF, mode manager, controller
# or config/dukw.yaml). Offline and deterministic: same code + config = same bytes.
# Then run: python -m pytest -q tests/test_replay_regression.py, look at the mode
# timelines printed here, and commit tests/golden/ with the change that moved them.
set -euo pipefail
cd "$(dirname "$0")/.."
set +u; source scripts/env.sh; set -u
timeout -k 10 900 python -m dukw_bringup.golden --out tests/golden "$@"

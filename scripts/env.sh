# Source me: the environment shell of the DUKW-Ling workspace
# (the venv with ROS 2 Jazzy, then the workspace overlay).
_dukw_root=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
_dukw_u=$-
set +u
# shellcheck disable=SC1091
source "$_dukw_root/.venv/bin/activate"
# shellcheck disable=SC1091
source "$_dukw_root/install/setup.bash"
case $_dukw_u in *u*) set -u ;; esac
export ROS_AUTOMATIC_DISCOVERY_RANGE=${ROS_AUTOMATIC_DISCOVERY_RANGE:-LOCALHOST}
unset _dukw_root _dukw_u

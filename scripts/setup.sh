#!/usr/bin/env bash
# Idempotent set-up of the DUKW-Ling workspace on a plain Debian/Ubuntu machine:
#   system tools (cmake, C/C++ compiler, python3-venv) -> .venv with the pinned
#   ROS 2 Jazzy wheels and Python dependencies -> the wheels' CMake fix ->
#   colcon build --merge-install into install/.
# Each step is skipped when its inputs have not changed since it last ran.
set -euo pipefail
cd "$(dirname "$0")/.."
ROOT=$PWD
VENV=$ROOT/.venv
PYTHON=${PYTHON:-python3}

log() { printf '[setup] %s\n' "$*"; }

# One set-up at a time in this tree (parallel `make test` runs share .venv and build/).
exec 9>"$ROOT/.setup.lock"
flock 9

# 1. System tools.
missing=()
command -v cmake >/dev/null || missing+=(cmake)
command -v g++ >/dev/null || missing+=(g++)
command -v make >/dev/null || missing+=(make)
"$PYTHON" -c 'import venv, ensurepip' 2>/dev/null || missing+=(python3-venv)
if [ ${#missing[@]} -gt 0 ]; then
  if [ "$(id -u)" = 0 ] && command -v apt-get >/dev/null; then
    log "installing system packages: ${missing[*]}"
    apt-get update -qq && DEBIAN_FRONTEND=noninteractive apt-get install -y -qq "${missing[@]}"
  else
    echo "[setup] error: missing system tools: ${missing[*]} (apt-get install them)" >&2
    exit 1
  fi
fi
"$PYTHON" -c 'import sys; sys.exit(0 if sys.version_info >= (3, 11) else 1)' || {
  echo "[setup] error: Python 3.11+ required, found $("$PYTHON" --version)" >&2; exit 1; }

# 2. Virtual environment and pinned packages.
[ -x "$VENV/bin/python" ] || { log "creating .venv"; "$PYTHON" -m venv "$VENV"; }
deps_hash=$(cat requirements.txt requirements-nodeps.txt constraints.txt | sha256sum | cut -d' ' -f1)
stamp=$VENV/.dukw-deps
if [ "$(cat "$stamp" 2>/dev/null)" != "$deps_hash" ]; then
  log "installing pinned Python packages (requirements*.txt, constraints.txt)"
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check \
    -r requirements.txt -c constraints.txt
  "$VENV/bin/python" -m pip install -q --disable-pip-version-check --no-deps \
    -r requirements-nodeps.txt
  # The wheels' CMake exports name the include folders of the machine that built them.
  PYINC=$("$VENV/bin/python" -c "import sysconfig; print(sysconfig.get_paths()['include'])")
  NPINC=$("$VENV/bin/python" -c "import numpy; print(numpy.get_include())")
  { grep -rl '/opt/python/cp311-cp311/' "$VENV/share" --include='*.cmake' || true; } | xargs -r sed -i \
    -e "s#/opt/python/cp311-cp311/lib/python3.11/site-packages/numpy/_core/include#$NPINC#g" \
    -e "s#/opt/python/cp311-cp311/include/python3.11#$PYINC#g"
  # Make `source .venv/bin/activate` enough for the ament index to see the venv.
  grep -q 'AMENT_PREFIX_PATH' "$VENV/bin/activate" || cat >> "$VENV/bin/activate" <<'ACT'
# dukw: the ros-jazzy wheels make the venv an ament prefix but never export it.
export AMENT_PREFIX_PATH="$VIRTUAL_ENV${AMENT_PREFIX_PATH:+:$AMENT_PREFIX_PATH}"
export CMAKE_PREFIX_PATH="$VIRTUAL_ENV${CMAKE_PREFIX_PATH:+:$CMAKE_PREFIX_PATH}"
ACT
  echo "$deps_hash" > "$stamp"
else
  log "Python packages up to date"
fi

# 3. Build the workspace (skipped when nothing under src/, compat/ or config/ changed).
# tf2_msgs (TFMessage for /tf, /tf_static): the wheels have none, a ROS install has it.
# compat/tf2_msgs is built only when Python cannot import one without this workspace
# (compat/COLCON_IGNORE keeps a plain `colcon build` on a ROS install from shadowing it).
base_paths=(src)
outside_pythonpath=$(printf '%s' "${PYTHONPATH:-}" | tr ':' '\n' | grep -v "^$ROOT/install" \
  | paste -sd: - || true)
if ! PYTHONPATH=$outside_pythonpath "$VENV/bin/python" -c 'import tf2_msgs.msg' 2>/dev/null
then
  base_paths+=(compat/tf2_msgs)
fi
build_stamp=$ROOT/install/.dukw-build
if [ -f "$build_stamp" ] && [ -z "$(find src compat config -newer "$build_stamp" -print -quit)" ]
then
  log "workspace build up to date"
else
  log "colcon build --merge-install (${base_paths[*]})"
  set +u
  # shellcheck disable=SC1091
  source "$VENV/bin/activate"
  set -u
  export AMENT_PREFIX_PATH=$VENV CMAKE_PREFIX_PATH=$VENV
  colcon --log-base log build --merge-install --symlink-install \
    --base-paths "${base_paths[@]}" --build-base build --install-base install --event-handlers console_start_end- \
    --cmake-args -DBUILD_TESTING=OFF -DPython3_EXECUTABLE="$VENV/bin/python" \
    > "$ROOT/.colcon-build.txt" 2>&1 || { tail -50 "$ROOT/.colcon-build.txt" >&2; exit 1; } 
  # The EKF's numba kernels compiled into their cache beside the built module (a node's
  # first sample, or a test's, would otherwise wait seconds for the compiler).
  log "compiling the EKF, stance and hull-volume kernels (numba cache)"
  "$VENV/bin/python" -c "import sys; sys.path[:0] = ['$ROOT/build/dukw_estimation', '$ROOT/build/dukw_common', \
'$ROOT/build/dukw_model']; import dukw_estimation.ekf_kernels as k, dukw_estimation.stance as s, \
dukw_model.buoyancy as b; k.warm(); s.warm(); b.warm()"
  touch "$build_stamp"
fi
log "ready: source scripts/env.sh"

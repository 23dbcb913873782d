#!/usr/bin/env bash
# builds the pybind11 module _penumbra_rollout without the rest of penumbra, for a training
# machine that has a C++20 compiler, a Python with headers and pybind11 (or PyTorch, whose
# wheel ships pybind11's headers) but not Debian's packages (e.g. a GPU machine's PyTorch
# image). on Debian, CMake builds the module (build/python) and this script is not needed.
#
#   bash train/build_standalone.sh OUT_DIR [PYTHON]
#
# MuJoCo comes from PYTHON's `mujoco` package (pip install mujoco==4.0.0, the pin of
# scripts/requirements.txt): its folder holds include/mujoco/*.h and libmujoco.so.4.0.0; set
# MUJOCO_DIR to use another such folder. run Python with PYTHONPATH=OUT_DIR:python (the module
# finds libmujoco through its rpath).
set -euo pipefail
out=${1:?usage: MUJOCO_DIR=DIR build_standalone.sh OUT_DIR [PYTHON]}
py=${2:-python3}
if [ -z "${MUJOCO_DIR:-}" ]; then
  MUJOCO_DIR=$("$py" -c 'import importlib.util as u; s = u.find_spec("mujoco"); print(s.submodule_search_locations[0] if s else "")')
fi
lib=$(ls "$MUJOCO_DIR"/libmujoco.so.* 2>/dev/null | head -1 || true)
if [ ! -f "$MUJOCO_DIR/include/mujoco/mujoco.h" ] || [ -z "$lib" ]; then
  echo "build_standalone: no MuJoCo at '$MUJOCO_DIR' (expected include/mujoco/mujoco.h and libmujoco.so.*): pip install mujoco==4.0.0 into $py, or set MUJOCO_DIR" >&2
  exit 2
fi
root=$(cd "$(dirname "$0")/.." && pwd)
pyinc=$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
pbinc=$("$py" -c 'import pybind11; print(pybind11.get_include())' 2>/dev/null ||
        "$py" -c 'import os, torch; print(os.path.join(os.path.dirname(torch.__file__), "include"))')
suffix=$("$py" -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))')
mkdir -p "$out"
c++ -O3 -std=c++20 -shared -fPIC -fvisibility=hidden -DNDEBUG \
  -I"$root/src" -I"$MUJOCO_DIR/include" -I"$pyinc" -I"$pbinc" \
  "$root/python/penumbra_rollout/binding.cc" "$root"/src/penumbra/rollout/*.cc \
  "$root/src/penumbra/core/thread_pool.cc" "$root/src/penumbra/core/error.cc" \
  "$root/src/penumbra/core/input_file.cc" "$root/src/penumbra/core/output_path_policy.cc" \
  "$lib" -Wl,-rpath,"$MUJOCO_DIR" -pthread \
  -o "$out/_penumbra_rollout$suffix"
echo "built $out/_penumbra_rollout$suffix"

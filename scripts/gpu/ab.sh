#!/usr/bin/env bash
# on a GPU machine: a realtime A/B in one call
# (docs/journal/2026-11-26-gpu-speed.md, "Realtime kernels: warp-shared
# penumbra rays, one surface evaluation"): unpacks scripts/gpu/pack.sh's tarball, runs a baseline
# render_cuda_bench (xz-compressed, another commit's, run with this pack's libraries) and this
# pack's, interleaved (--realtime, default and house at 640x480), the realtime `gpu` tests, and
# Nsight Compute on one frame's realtime kernels of each if ncu is there; the logs go to RESULTS
# (default $OUT or /tmp/ab-out), a summary to stdout. steps stop starting after AB_BUDGET_S
# (default 380) seconds; AB_TESTS=0 skips the tests, AB_NCU="new" profiles this pack's alone.
#
#   scripts/gpu/ab.sh PACK.tar.xz BASELINE_render_cuda_bench.xz [repeats]
set -u
pack=${1:?usage: ab.sh PACK.tar.xz BASELINE.xz [repeats]}
baseline=${2:?usage: ab.sh PACK.tar.xz BASELINE.xz [repeats]}
repeats=${3:-2}
R=${OUT:-/tmp/ab-out}
mkdir -p "$R"
. "$(dirname "$0")/use-pack.sh"
unpack_pack "$pack" "$baseline"
nvidia-smi --query-gpu=name,driver_version,memory.total,compute_cap,clocks.sm,clocks.max.sm,temperature.gpu --format=csv | tee "$R/card.txt"
STEP_T0=$(date +%s)
STEP_BUDGET_S=${AB_BUDGET_S:-380}
STEP_MIN_LEFT_S=15
STEP_LOGS=$R
for k in $(seq 1 "$repeats"); do
  step base_$k 70 "$B/base_bench" --realtime --frames 30 "$W/default.yaml" "$W/house.yaml"
  step new_$k 70 "$B/render_cuda_bench" --realtime --frames 30 "$W/default.yaml" "$W/house.yaml"
done
[ "${AB_TESTS:-1}" = 1 ] && step tests 150 "$B/render_cuda_gpu_tests" --gtest_filter='*RealtimeRgbGpu*:*RealtimeExposure*'
NCU=$(command -v ncu || ls /usr/local/cuda/bin/ncu 2>/dev/null | head -1)
if [ -n "$NCU" ]; then
  for who in ${AB_NCU:-new base}; do
    bin=$B/render_cuda_bench; [ $who = base ] && bin=$B/base_bench
    step ncu_$who 60 "$NCU" --kernel-name regex:'Kernel' --launch-count 12 \
      --section SpeedOfLight --section Occupancy --section LaunchStats \
      "$bin" --realtime --frames 1 "$W/house.yaml"
  done
else
  echo "no ncu"
fi
echo; echo "== realtime rows (Render default and kernels)"
for f in "$R"/base_*.txt "$R"/new_*.txt; do
  echo "-- $(basename "$f")"
  grep -E '^\| (default|house)' "$f" | grep -E 'device sky|kernels|bit-identical' | grep -v 'host sky'
done
[ -f "$R/tests.txt" ] && echo && echo "== tests" && grep -E '^\[ +(OK|FAILED) +\]|radiance|PSNR|psnr|dB' "$R/tests.txt" | head -40
for who in new base; do
  [ -f "$R/ncu_$who.txt" ] || continue
  echo; echo "== ncu $who"
  grep -E '^  [A-Za-z].*Kernel|Duration|Registers Per|Achieved Occupancy|Theoretical Occupancy|Compute \(SM\) Throughput|Memory Throughput|Local Memory' "$R/ncu_$who.txt" | head -80
done

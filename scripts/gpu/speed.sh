#!/usr/bin/env bash
# on a GPU machine: the realtime tier's speed table in one go
# (docs/journal/2026-11-26-gpu-speed.md, "Realtime speed on
# an H100"): unpacks scripts/gpu/pack.sh's tarball, names the card, and runs
# render_cuda_bench --realtime (Render() stages, the kernels, CPU backend; 3 repeats at
# 640x480, one at 128x128), the single-camera table of this build and, if given, of a baseline
# render_cuda_bench (xz-compressed, e.g. another commit's, for the same machine), the batches
# of 1, 64 and 1024 cameras in the house, the `gpu` tests, and Nsight Compute on the shading
# kernel if ncu is there; prints a summary and writes it, with every log (logs.tgz), to
# RESULTS (default $OUT or /tmp/speed-out). each step has a time limit and the whole stops
# starting steps after 500 s.
#
#   scripts/gpu/speed.sh PACK.tar.xz [BASELINE_render_cuda_bench.xz]
set -u
pack=${1:?usage: speed.sh PACK.tar.xz [BASELINE_render_cuda_bench.xz]}
baseline=${2:-}
RESULTS=${OUT:-/tmp/speed-out}
mkdir -p "$RESULTS"
. "$(dirname "$0")/use-pack.sh"
unpack_pack "$pack" "$baseline"
OUT=$work/logs  # the step logs, packed into one file of $RESULTS at the end (8 files come back)
mkdir -p "$OUT"
nvidia-smi --query-gpu=name,driver_version,memory.total,compute_cap,clocks.sm,clocks.max.sm,temperature.gpu,utilization.gpu --format=csv > "$OUT/card.txt" 2>&1
echo "CPU: $(nproc) cores,$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)" >> "$OUT/card.txt"
cat "$OUT/card.txt"
STEP_T0=$(date +%s)
STEP_BUDGET_S=500
STEP_MIN_LEFT_S=20
STEP_LOGS=$OUT
# the realtime tier in detail (Render stages, kernels, cpu), 640x480
step realtime_1 120 "$B/render_cuda_bench" --realtime --frames 50 "$W/default.yaml" "$W/house.yaml"
# the standard single-camera table: the baseline (if given) and this build
[ -n "$baseline" ] && step bench_base 120 "$B/base_bench" --frames 30 "$W/default.yaml" "$W/house.yaml"
step bench_new 120 "$B/render_cuda_bench" --frames 30 "$W/default.yaml" "$W/house.yaml"
# the gpu tests
step gpu_tests 180 "$B/render_cuda_gpu_tests"
# batches in the house, 128x128
step batch 90 "$B/render_cuda_bench" --frames 20 --batch 1,64,1024 --size 128x128 "$W/house.yaml"
# repeats and 128x128
step realtime_2 90 "$B/render_cuda_bench" --realtime --frames 50 "$W/default.yaml" "$W/house.yaml"
step realtime_3 90 "$B/render_cuda_bench" --realtime --frames 50 "$W/default.yaml" "$W/house.yaml"
step realtime_128 60 "$B/render_cuda_bench" --realtime --frames 50 --size 128x128 "$W/default.yaml" "$W/house.yaml"
# one kernel profile, if ncu is there
NCU=$(command -v ncu || ls /usr/local/cuda/bin/ncu 2>/dev/null | head -1)
if [ -n "$NCU" ]; then
  step ncu 90 "$NCU" --kernel-name 'regex:Shade(Stored|Queued)Kernel' --launch-count 1 --section SpeedOfLight \
    --section Occupancy --section LaunchStats --section WarpStateStats \
    "$B/render_cuda_bench" --realtime --frames 3 "$W/house.yaml"
fi
summary() {
echo; echo "== failures"; grep -h -E 'FAILED|Failure|DIFFERENT| NO ' "$OUT"/gpu_*tests.txt "$OUT"/realtime_*.txt | head -30
echo; echo "== realtime (rep 1 full, reps 2-3 rows)"; grep '^|' "$OUT/realtime_1.txt"
for rep in 2 3; do grep -E 'Render\(\)|\| kernels \|' "$OUT/realtime_$rep.txt" 2>/dev/null; done
echo; echo "== realtime 128x128"; grep '^|' "$OUT/realtime_128.txt"
echo; echo "== baseline single camera"; grep -E '^\| (default|house)' "$OUT/bench_base.txt" 2>/dev/null | grep -E 'cuda|realtime'
echo; echo "== this branch single camera"; grep -E '^\| (default|house)' "$OUT/bench_new.txt" | grep -E 'cuda|realtime'
echo; echo "== batch"; grep '^|' "$OUT/batch.txt"
echo; echo "== gpu tests"; grep -E '^\[ +(OK|FAILED|SKIPPED) +\]|PASSED|FAILED  \]' "$OUT/gpu_tests.txt" | tail -25
[ -f "$OUT/ncu.txt" ] && { echo; echo "== ncu"; grep -E 'Duration|Registers|Occupancy|Throughput|Local|Stack|No Eligible|Warp Cycles|Active Warps' "$OUT/ncu.txt" | head -30; }
}
summary 2>&1 | tee "$RESULTS/summary.txt"
tar -C "$work" -czf "$RESULTS/logs.tgz" logs

#!/usr/bin/env bash
# on a GPU machine: what Render() spends outside its kernels, old against new in one call
# (docs/journal/2026-11-26-gpu-speed.md, "`Render()`'s host overhead"): unpacks pack.sh's
# tarball, names the card, runs a baseline render_cuda_bench (xz-compressed, another commit's,
# run with this pack's libraries) and this pack's, interleaved base, new, base, new, ...: the
# single-camera table (`--frames 100`, default and house, 640x480 and 128x128) REPEATS times and
# `--realtime` (640x480; Render()'s variants and, in this pack's, where its time goes) twice,
# this pack's `--realtime --size 128x128` once, then the `gpu` tests. steps stop starting after
# OVERHEAD_BUDGET_S (default 280) seconds. the logs go to one tarball in RESULTS (default $OUT
# or /tmp/overhead-out), a summary to stdout and RESULTS/summary.txt.
#
#   scripts/gpu/overhead.sh PACK.tar.xz BASELINE_render_cuda_bench.xz [repeats]
set -u
pack=${1:?usage: overhead.sh PACK.tar.xz BASELINE.xz [repeats]}
baseline=${2:?usage: overhead.sh PACK.tar.xz BASELINE.xz [repeats]}
repeats=${3:-3}
R=${OUT:-/tmp/overhead-out}
mkdir -p "$R"
. "$(dirname "$0")/use-pack.sh"
unpack_pack "$pack" "$baseline"
L=$work/logs
mkdir -p "$L"
nvidia-smi --query-gpu=name,driver_version,memory.total,compute_cap,clocks.sm,clocks.max.sm,temperature.gpu --format=csv > "$L/card.txt" 2>&1
echo "CPU: $(nproc) cores,$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)" >> "$L/card.txt"
STEP_T0=$(date +%s)
STEP_BUDGET_S=${OVERHEAD_BUDGET_S:-280}
STEP_MIN_LEFT_S=10
STEP_LOGS=$L
two="$W/default.yaml $W/house.yaml"
for k in $(seq 1 "$repeats"); do
  step std_base_$k 45 "$B/base_bench" --frames 100 $two
  step std_new_$k 45 "$B/render_cuda_bench" --frames 100 $two
  if [ "$k" -le 2 ]; then
    step rt_base_$k 45 "$B/base_bench" --realtime --frames 50 $two
    step rt_new_$k 45 "$B/render_cuda_bench" --realtime --frames 50 $two
  fi
  [ "$k" = 1 ] && step tests 110 "$B/render_cuda_gpu_tests"
done
step rt128_new 40 "$B/render_cuda_bench" --realtime --frames 50 --size 128x128 $two
summary() {
  cat "$L/card.txt"
  echo; echo "== single camera, cuda rows (frames/s): base / new per repeat"
  for k in $(seq 1 "$repeats"); do
    for who in base new; do
      [ -f "$L/std_${who}_$k.txt" ] || continue
      echo "-- $who $k"
      grep -E '^\| (default|house)' "$L/std_${who}_$k.txt" | grep '| cuda |' | awk -F'|' '{printf "%s %s %s %s %s\n", $2, $3, $4, $6, $7}'
    done
  done
  echo; echo "== --realtime, Render() default rows and hashes"
  for f in "$L"/rt_base_*.txt "$L"/rt_new_*.txt; do
    [ -f "$f" ] || continue
    echo "-- $(basename "$f")"
    grep -E '^\| (default|house)' "$f" | grep -E 'cuda Render\(\) \||radiance in 2 bands copies \||FNV|bit-identical|\| kernels \||kernels, all speed-ups|developed again' | cut -c1-160
  done
  echo; echo "== where Render()'s time goes (this pack)"
  for f in "$L"/rt_new_1.txt "$L"/rt128_new.txt; do
    [ -f "$f" ] && sed -n '/^Where Render/,$p' "$f" | grep '^|'
  done
  echo; echo "== gpu tests"
  grep -E '^\[  (PASSED|FAILED) |^\[  FAILED  \]|tests ran' "$L/tests.txt" | head -20
}
summary > "$R/summary.txt" 2>&1
tar -C "$work" -czf "$R/logs.tgz" logs
cat "$R/summary.txt"

#!/usr/bin/env bash
# on a GPU machine: unpacks scripts/gpu/pack.sh's tarball, names the card, runs the CUDA
# backend's tests (the `gpu` tests and the host tests) and its benchmarks beside the CPU
# backend (single camera, and the flashlight, rain, fog and smoke_plume worlds' effects frames on
# the GPU and the CPU;
# batches of 1, 64 and 1024 cameras at 128x128 in the house, depth+seg
# and realtime rgb+depth with its stages' GPU times; copy rates), the pathtraced tier's frame
# time beside the CPU backend's (default, house, fog, rain and snow, 320x240, 64 samples per
# pixel), the smoke_plume and fire grids' media frames as in a run (--media: a new grid every
# frame), the parity table (parity.sh), and prints one summary table, then the measurements
# (docs/gpu.md).
#
#   scripts/gpu/check.sh [tarball|unpacked-folder] [benchmark frames]
#                                           (default .gpu/penumbra-gpu.tar.xz, 50)
#   CHECK_LOG_DIR=DIR CHECK_LIMIT_S=60 scripts/gpu/check.sh ...  (logs kept in DIR; the steps'
#   limits are multiples of CHECK_LIMIT_S: gpu tests 3x, batch 1.5x, parity 2x, bench 1.5x,
#   sessions 0.75x, pathtraced bench 1x, media bench 0.75x, host tests 1x)
set -uo pipefail
tarball=${1:-.gpu/penumbra-gpu.tar.xz}
frames=${2:-50}
work=$(mktemp -d)
if [ -d "$tarball" ]; then
  pkg=$(cd "$tarball" && pwd)  # an unpacked pack
else
  tar -C "$work" -xJf "$tarball"
  pkg=$work/penumbra-gpu
fi
# the carried libraries: the executables find them through their run path, the libraries
# they load (e.g. MuJoCo its libccd) through this
export LD_LIBRARY_PATH=$pkg/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
# the binaries find the worlds in the source folder they were built in (PENUMBRA_SOURCE_DIR)
src=$(cat "$pkg/source-dir.txt" 2>/dev/null || echo /work/wt-cuda)
if [ ! -e "$src/worlds" ]; then
  mkdir -p "$src" && ln -sfn "$pkg/src/worlds" "$src/worlds"
fi
# the logs of each step (CHECK_LOG_DIR to keep them, e.g. in a folder that is copied back);
# each step has its own time limit (CHECK_LIMIT_S seconds times its share), so one slow step
# cannot take the others' results with it
log=${CHECK_LOG_DIR:-$work/log}
mkdir -p "$log"
limit=${CHECK_LIMIT_S:-60}
card=$(nvidia-smi --query-gpu=name,driver_version,memory.total,compute_cap --format=csv,noheader 2>/dev/null || echo "none")
cpu="$(nproc) cores,$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
echo "card: $card; CPU: $cpu" > "$log/card.txt"
count() { grep -c -E "$1" "$2" || true; }
timeout $((limit * 3)) "$pkg/bin/render_cuda_gpu_tests" > "$log/gpu.txt" 2>&1
gpu_rc=$?
timeout $((limit * 3 / 2)) "$pkg/bin/render_cuda_bench" --frames "$frames" --batch 1,64,1024 \
  --size 128x128 "$pkg/src/worlds/house.yaml" > "$log/batch.txt" 2>&1
batch_rc=$?
timeout $((limit * 2)) "$pkg/parity.sh" "$pkg/bin/render_cuda_bench" "$pkg/src/worlds" \
  > "$log/parity.txt" 2>&1
parity_rc=$?
timeout $((limit * 3 / 2)) "$pkg/bin/render_cuda_bench" --frames "$frames" \
  "$pkg/src/worlds/default.yaml" "$pkg/src/worlds/house.yaml" \
  "$pkg/src/worlds/effects/flashlight.yaml" "$pkg/src/worlds/effects/rain.yaml" \
  "$pkg/src/worlds/effects/fog.yaml" "$pkg/src/worlds/effects/smoke_plume.yaml" \
  > "$log/bench.txt" 2>&1
bench_rc=$?
timeout $((limit * 3 / 4)) "$pkg/bin/render_cuda_bench" --frames "$frames" --batch 64 \
  --size 128x128 --sessions 4 "$pkg/src/worlds/house.yaml" > "$log/sessions.txt" 2>&1
sessions_rc=$?
timeout "$limit" "$pkg/bin/render_cuda_bench" --pathtraced --spp 64 --size 320x240 --frames 3 \
  "$pkg/src/worlds/default.yaml" "$pkg/src/worlds/house.yaml" \
  "$pkg/src/worlds/effects/fog.yaml" "$pkg/src/worlds/effects/rain.yaml" \
  "$pkg/src/worlds/effects/snow.yaml" > "$log/pathtraced.txt" 2>&1
path_rc=$?
# the grid media as in a run: a new smoke / fire grid every frame, uploaded every frame
timeout $((limit * 3 / 4)) "$pkg/bin/render_cuda_bench" --media --frames 30 \
  "$pkg/src/worlds/effects/smoke_plume.yaml" "$pkg/src/worlds/effects/fire.yaml" \
  > "$log/media.txt" 2>&1
media_rc=$?
# the host tests run where they were built too (CI); a pack may leave them out (PACK_BINS)
if [ -x "$pkg/bin/render_cuda_tests" ]; then
  timeout "$limit" "$pkg/bin/render_cuda_tests" > "$log/host.txt" 2>&1
  host_rc=$?
else
  echo "render_cuda_tests: not in the pack" > "$log/host.txt"
  host_rc=0
fi
verdict() { [ "$1" -eq 0 ] && echo "pass" || echo "FAIL (rc $1)"; }
echo "| check | result |"
echo "|---|---|"
echo "| card | $card |"
echo "| CPU | $cpu |"
if [ -x "$pkg/bin/render_cuda_tests" ]; then
  echo "| host tests (render_cuda_tests) | $(verdict $host_rc): $(count '^\[ +OK ' "$log/host.txt") ok, $(count '^\[ +FAILED +\] [A-Z]' "$log/host.txt") failed |"
else
  echo "| host tests (render_cuda_tests) | not in the pack (PACK_BINS) |"
fi
echo "| gpu tests (render_cuda_gpu_tests, label gpu) | $(verdict $gpu_rc): $(count '^\[ +OK ' "$log/gpu.txt") ok, $(count '^\[ +FAILED +\] [A-Z]' "$log/gpu.txt") failed, $(count '^\[ +SKIPPED ' "$log/gpu.txt") skipped |"
echo "| single-camera bench | $(verdict $bench_rc) |"
echo "| batch bench (house, 128x128) | $(verdict $batch_rc) |"
echo "| batch bench, 4 sessions | $(verdict $sessions_rc) |"
echo "| parity table | $(verdict $parity_rc) |"
echo "| pathtraced bench (320x240, 64 spp) | $(verdict $path_rc) |"
echo "| media bench (grids as in a run) | $(verdict $media_rc) |"
# the benchmark rows, cuda beside cpu: single camera (world, size, outputs, backend, timed,
# frames/s) and batches (world, size, outputs, cameras, backend, timed, frames/s)
awk -F'|' 'NF == 9 && $2 ~ /yaml/ {
             gsub(/^ +| +$/, "", $7);
             printf "| bench:%s%s%s 1 camera,%s,%s | %s frames/s |\n", $2, $3, $4, $5, $6, $7 }
           NF == 10 && $2 ~ /yaml/ {
             gsub(/^ +| +$/, "", $8);
             printf "| bench:%s%s%s%s cameras,%s,%s | %s frames/s |\n", $2, $3, $4, $5, $6, $7, $8 }' \
  "$log/bench.txt" "$log/batch.txt" "$log/sessions.txt"
# the pathtraced rows: world, size, spp, cuda Render() ms, kernel ms, cpu ms, speed-up
awk -F'|' 'NF == 12 && $2 ~ /yaml/ {
             printf "| pathtraced:%s%s, %s spp | cuda%s ms (kernel%s ms), cpu%s ms, speed-up%s |\n",
               $2, $3, $4, $5, $6, $7, $8 }' "$log/pathtraced.txt"
awk -F'|' '$2 ~ /pinned|pageable/ { gsub(/^ +| +$/, "", $4);
             printf "| copy back:%s%s MiB | %s GB/s |\n", $2, $3, $4 }' "$log/batch.txt"
echo
echo "== failures and frame lines of the tests"
grep -h -E 'Failure|FAILED|frame [0-9]+:|camera [0-9]+ \(|skipped' "$log/host.txt" "$log/gpu.txt" | head -60
echo
echo "== single camera"; grep -v '^\[20' "$log/bench.txt"
echo
echo "== batch"; grep -v '^\[20' "$log/batch.txt"
echo
echo "== batch, sessions"; grep -v '^\[20' "$log/sessions.txt"
echo
echo "== pathtraced"; grep -v '^\[20' "$log/pathtraced.txt"
echo
echo "== media (device-built volumes; last row of each world: a new grid every frame)"
grep -v '^\[20' "$log/media.txt"
echo
echo "== parity"; cat "$log/parity.txt"
exit $(( host_rc | gpu_rc | bench_rc | batch_rc | sessions_rc | parity_rc | path_rc | media_rc ))

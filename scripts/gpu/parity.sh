#!/usr/bin/env bash
# on a GPU machine, in an unpacked pack (scripts/gpu/pack.sh) or a build folder: prints the
# parity table of the CUDA backend against the CPU backend (docs/gpu.md
# "Measured") for the default, house, warehouse and outdoor worlds and every worlds/effects/*.yaml:
# the first camera at 320x240 after 1 s, depth within 1 mm %, segmentation equal %, same-depth
# ties, whether the frame with the world's effects is on the GPU (every effect: lighting effects,
# particles, homogeneous and grid media, particles seen through media),
# and the rgb PSNR of that frame (every frame renders on the GPU); then the pathtraced tier's row (target:
# pathtraced at 1024 spp, mean relative difference <= 1 %): the default and house worlds' first
# camera at 128x96 after 1 s, 1024 samples per pixel, the radiance's mean relative difference
# between the GPU's and the CPU backend's (8x8 blocks and the image mean; render_cuda_bench
# --pathtraced, tests/render/cuda/path_parity.h).
#
#   scripts/gpu/parity.sh BENCH_BINARY WORLDS_DIR [WxH]
set -uo pipefail
bench=${1:?render_cuda_bench binary}
worlds=${2:?worlds folder}
size=${3:-320x240}
files=("$worlds/default.yaml" "$worlds/house.yaml" "$worlds/warehouse.yaml" "$worlds/outdoor.yaml")
for f in "$worlds"/effects/*.yaml; do files+=("$f"); done
"$bench" --parity --size "$size" "${files[@]}" 2>&1 | grep -v '^\[20'
rc=${PIPESTATUS[0]}
"$bench" --pathtraced --spp 1024 --size 128x96 --frames 1 "$worlds/default.yaml" \
  "$worlds/house.yaml" 2>&1 | grep -v '^\[20'
exit $(( rc | PIPESTATUS[0] ))

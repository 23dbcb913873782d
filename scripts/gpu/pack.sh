#!/usr/bin/env bash
# packs the CUDA backend's GPU tests and benchmark for a GPU machine without this machine's
# packages (docs/gpu.md, "The lean pack"): render_cuda_gpu_tests, render_cuda_tests and
# render_cuda_bench (render, scene, physics, effects, session; not the `penumbra` binary, whose
# OpenCV codecs, ROS and viewer libraries are too large to carry; linked --as-needed and with
# textures decoded by libpng and TurboJPEG, so OpenCV's imgcodecs and its GDAL, codec and ICU
# libraries are not loaded), every library `ldd` lists for them except the C library's own
# (libc, libm, libdl, libpthread, librt, ld-linux: the target's newer glibc runs them) and the
# CUDA driver (the target's), the bundled worlds, and scripts/gpu/check.sh and parity.sh. the
# binaries find the libraries through their $ORIGIN/../lib run path (CMakeLists.txt) and the
# worlds at the source path they were built from (recorded in source-dir.txt). writes one
# xz-compressed tarball and fails if it is 64 MiB or more.
#
#   scripts/gpu/pack.sh [build-dir] [out.tar.xz]      (default: build, .gpu/penumbra-gpu.tar.xz)
#   PACK_BINS="render_cuda_gpu_tests render_cuda_bench" scripts/gpu/pack.sh ...
#                      (these executables only; check.sh reports the others as not packed)
#   PACK_BASE=other-build/render_cuda_bench scripts/gpu/pack.sh ...
#                      (another commit's benchmark as bin/base_bench, for A/B runs in one call:
#                      it shares most bytes with render_cuda_bench, so xz adds 4-5 MiB, not the
#                      7 of a tarball of its own; the call's working tree and carried files
#                      must stay under 64 MiB together)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
out=${2:-$root/.gpu/penumbra-gpu.tar.xz}
read -r -a bins <<< "${PACK_BINS:-render_cuda_gpu_tests render_cuda_tests render_cuda_bench}"
nice cmake --build "$build" -j2 --target "${bins[@]}"
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/penumbra-gpu/bin" "$stage/penumbra-gpu/lib" "$stage/penumbra-gpu/src"
for b in "${bins[@]}"; do
  cp "$build/$b" "$stage/penumbra-gpu/bin/"
  strip "$stage/penumbra-gpu/bin/$b"
done
if [ -n "${PACK_BASE:-}" ]; then
  case "$PACK_BASE" in
    *.xz) xz -dc "$PACK_BASE" > "$stage/penumbra-gpu/bin/base_bench" ;;
    *) cp "$PACK_BASE" "$stage/penumbra-gpu/bin/base_bench" ;;
  esac
  chmod +x "$stage/penumbra-gpu/bin/base_bench"
  strip "$stage/penumbra-gpu/bin/base_bench"
fi
# libraries: everything ldd resolves, less glibc's and the driver's
for b in "${bins[@]}"; do ldd "$build/$b"; done |
  awk '$2 == "=>" && $3 ~ /^\// {print $3}' | sort -u |
  grep -v -E '/(libc|libm|libdl|libpthread|librt|libresolv|ld-linux-x86-64|libcuda)\.so' |
  while read -r lib; do
    cp -L "$lib" "$stage/penumbra-gpu/lib/"
    strip --strip-unneeded "$stage/penumbra-gpu/lib/$(basename "$lib")" 2>/dev/null || true
  done
if ls "$stage/penumbra-gpu/lib" | grep -q -E 'libopencv_imgcodecs|libgdal'; then
  echo "pack: OpenCV imgcodecs / GDAL are linked again; the pack is no longer lean" >&2
  exit 1
fi
# the worlds and their assets (the tests and the benchmark load worlds/*.yaml by path)
cp -r "$root/worlds" "$stage/penumbra-gpu/src/"
cp "$root/scripts/gpu/check.sh" "$root/scripts/gpu/parity.sh" "$stage/penumbra-gpu/"
# the source folder the binaries were built in (PENUMBRA_SOURCE_DIR): check.sh links the
# worlds there
grep -m1 '^CMAKE_HOME_DIRECTORY:' "$build/CMakeCache.txt" | cut -d= -f2 > "$stage/penumbra-gpu/source-dir.txt"
mkdir -p "$(dirname "$out")"
tar -C "$stage" -cf - penumbra-gpu | xz -T2 -9 > "$out"
size=$(stat -c %s "$out")
echo "pack: $out, $((size / 1024 / 1024)) MiB ($size bytes), $(ls "$stage/penumbra-gpu/lib" | wc -l) libraries"
if [ "$size" -ge $((64 * 1024 * 1024)) ]; then
  echo "pack: $out is 64 MiB or more: too large to carry" >&2
  exit 1
fi

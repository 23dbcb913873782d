#!/usr/bin/env bash
# packs the whole `penumbra` executable for a GPU machine without this machine's packages, to
# measure `penumbra run --backend cuda` there (docs/gpu.md, "A run on the GPU"): the
# executable, every library `ldd` lists for it except the C library's own and the CUDA
# driver (as scripts/gpu/pack.sh), and the bundled worlds. its 190-odd libraries (OpenCV's
# codecs with GDAL, ROS, Open3D, OpenVDB, ...) come to more than the 64 MiB one device call
# can carry, so the xz-compressed tarball is cut into parts of at most PART_MIB (default 60)
# MiB, named OUT.partaa, OUT.partab, ...: carry them in consecutive calls (a warm machine keeps
# the earlier calls' ignored files) and join them there with scripts/gpu/run-breakdown.sh
# (which can also run a newer build's executable with these libraries: PENUMBRA_BIN).
#
#   scripts/gpu/pack-full.sh [build-dir] [out-prefix]   (default: build, .gpu/full/penumbra-full.tar.xz)
set -euo pipefail
root=$(cd "$(dirname "$0")/../.." && pwd)
build=${1:-$root/build}
out=${2:-$root/.gpu/full/penumbra-full.tar.xz}
part_mib=${PART_MIB:-60}
nice cmake --build "$build" -j2 --target penumbra
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage/penumbra-full/bin" "$stage/penumbra-full/lib" "$stage/penumbra-full/src"
cp "$build/penumbra" "$stage/penumbra-full/bin/"
strip "$stage/penumbra-full/bin/penumbra"
ldd "$build/penumbra" | awk '$2 == "=>" && $3 ~ /^\// {print $3}' | sort -u |
  grep -v -E '/(libc|libm|libdl|libpthread|librt|libresolv|ld-linux-x86-64|libcuda)\.so' |
  while read -r lib; do
    cp -L "$lib" "$stage/penumbra-full/lib/"
    strip --strip-unneeded "$stage/penumbra-full/lib/$(basename "$lib")" 2>/dev/null || true
  done
cp -r "$root/worlds" "$stage/penumbra-full/src/"
cp "$root/scripts/gpu/run-breakdown.sh" "$root/scripts/gpu/use-pack.sh" "$stage/penumbra-full/"
grep -m1 '^CMAKE_HOME_DIRECTORY:' "$build/CMakeCache.txt" | cut -d= -f2 > "$stage/penumbra-full/source-dir.txt"
mkdir -p "$(dirname "$out")"
rm -f "$out".part*
tar -C "$stage" -cf - penumbra-full | xz -T2 -9 | split -b "${part_mib}M" - "$out.part"
total=$(cat "$out".part* | wc -c)
echo "pack-full: $((total / 1024 / 1024)) MiB ($total bytes) in $(ls "$out".part* | wc -l) part(s) of <= $part_mib MiB, $(ls "$stage/penumbra-full/lib" | wc -l) libraries:"
ls -l "$out".part*

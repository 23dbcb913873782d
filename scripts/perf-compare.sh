#!/usr/bin/env bash
# a render-speed regression guard (docs/performance.md "Comparing two binaries"): runs
# `penumbra bench render --no-adversity` of two binaries on the bundled worlds, interleaved
# (A B A B ..., so that load drifting on a shared machine hits both alike), and prints per world
# the frames/s of each binary (median and min-max over the rounds) and the ratio NEW/OLD
# (median and min-max of the per-round ratios), then the same for the CPU time of the render
# threads per frame (the bench's cpu-ms/frame; steadier than frames/s on a loaded machine).
#
#   scripts/perf-compare.sh OLD_BIN NEW_BIN [--frames N] [--rounds R] [--size 640x480|800x800]
#                           [--worlds WORLD...]
#
# WORLD is a bundled world's name (default, house, warehouse, outdoor: worlds/NAME.yaml) or a
# path to a world file; default: the four. --frames: timed frames per bench run (default 20);
# --rounds: A/B rounds, >= 3 (default 3); --size: which of the bench's two resolutions the
# table reports (default 640x480). every command is run from an argument array, never a
# string through a shell. timings only: nothing here passes or fails on speed.
set -euo pipefail

usage() {
  echo "usage: $0 OLD_BIN NEW_BIN [--frames N] [--rounds R] [--size 640x480|800x800] [--worlds WORLD...]" >&2
  exit 2
}

[[ $# -ge 2 ]] || usage
old_bin=$1
new_bin=$2
shift 2
for b in "$old_bin" "$new_bin"; do
  [[ -x $b && -f $b ]] || { echo "$0: '$b' is not an executable file; expected a penumbra binary" >&2; exit 2; }
done

frames=20
rounds=3
size=640x480
worlds=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --frames)
      [[ $# -ge 2 && $2 =~ ^[1-9][0-9]{0,5}$ ]] || { echo "$0: --frames expects a positive integer" >&2; exit 2; }
      frames=$2
      shift 2
      ;;
    --rounds)
      [[ $# -ge 2 && $2 =~ ^[0-9]{1,3}$ && $2 -ge 3 ]] || { echo "$0: --rounds expects an integer >= 3" >&2; exit 2; }
      rounds=$2
      shift 2
      ;;
    --size)
      [[ $# -ge 2 && ( $2 == 640x480 || $2 == 800x800 ) ]] || { echo "$0: --size expects 640x480 or 800x800" >&2; exit 2; }
      size=$2
      shift 2
      ;;
    --worlds)
      shift
      while [[ $# -gt 0 && $1 != --* ]]; do
        worlds+=("$1")
        shift
      done
      ;;
    *)
      echo "$0: unknown argument '$1'" >&2
      usage
      ;;
  esac
done

source "$(dirname "${BASH_SOURCE[0]}")/perf-common.sh"
perf_resolve_worlds

# "FPS CPU_MS" of one bench run: the "<size> rgb+depth ...: X frames/s, ..., Y cpu-ms/frame"
# line (640x480 alone is timed when that is the size asked for)
bench_fps() {
  local bin=$1 world=$2 out
  local args=(bench render --world "$world" --frames "$frames" --no-adversity)
  [[ $size == 640x480 ]] && args+=(--only-640x480)
  if ! out=$(nice "$bin" "${args[@]}" 2>&1); then
    echo "$0: '$bin bench render --world $world' failed:" >&2
    echo "$out" >&2
    return 1
  fi
  awk -v size="$size" '$1 == size && /frames\/s/ { f = ""; c = ""; for (i = 1; i <= NF; ++i) { if ($i == "frames/s,") f = $(i - 1); if ($i == "cpu-ms/frame,") c = $(i - 1) } if (f != "" && c != "") print f, c; exit }' <<<"$out"
}


echo "perf-compare: OLD $old_bin"
echo "              NEW $new_bin"
echo "bench render --no-adversity --frames $frames, $size rgb+depth, $rounds interleaved rounds, $(nproc) core(s), load $(cut -d' ' -f1-3 /proc/loadavg)"
rows=()
for i in "${!world_files[@]}"; do
  olds=()
  news=()
  ratios=()
  old_cpu=()
  new_cpu=()
  cpu_ratios=()
  for ((r = 1; r <= rounds; ++r)); do
    read -r a ac <<<"$(bench_fps "$old_bin" "${world_files[$i]}")"
    read -r b bc <<<"$(bench_fps "$new_bin" "${world_files[$i]}")"
    [[ -n $a && -n $b && -n $ac && -n $bc ]] || { echo "$0: no '$size ... frames/s, ... cpu-ms/frame' line from the bench on ${worlds[$i]}" >&2; exit 1; }
    olds+=("$a")
    news+=("$b")
    old_cpu+=("$ac")
    new_cpu+=("$bc")
    ratios+=("$(awk -v a="$a" -v b="$b" 'BEGIN { printf "%.3f", (a > 0 ? b / a : 0) }')")
    cpu_ratios+=("$(awk -v a="$ac" -v b="$bc" 'BEGIN { printf "%.3f", (a > 0 ? b / a : 0) }')")
    echo "  ${worlds[$i]} round $r: old $a, new $b frames/s; old $ac, new $bc cpu-ms/frame" >&2
  done
  read -r om omin omax <<<"$(stats "${olds[@]}")"
  read -r nm nmin nmax <<<"$(stats "${news[@]}")"
  read -r rm rmin rmax <<<"$(stats "${ratios[@]}")"
  read -r ocm ocmin ocmax <<<"$(stats "${old_cpu[@]}")"
  read -r ncm ncmin ncmax <<<"$(stats "${new_cpu[@]}")"
  read -r crm crmin crmax <<<"$(stats "${cpu_ratios[@]}")"
  rows+=("$(printf '| %s | %.1f (%.1f-%.1f) | %.1f (%.1f-%.1f) | %.3f (%.3f-%.3f) | %.1f (%.1f-%.1f) | %.1f (%.1f-%.1f) | %.3f (%.3f-%.3f) |' \
    "${worlds[$i]}" "$om" "$omin" "$omax" "$nm" "$nmin" "$nmax" "$rm" "$rmin" "$rmax" \
    "$ocm" "$ocmin" "$ocmax" "$ncm" "$ncmin" "$ncmax" "$crm" "$crmin" "$crmax")")
done
echo
echo "| world | old frames/s | new frames/s | ratio new/old | old cpu-ms/frame | new cpu-ms/frame | cpu ratio new/old |"
echo "|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"

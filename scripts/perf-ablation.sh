#!/usr/bin/env bash
# what costs what in the CPU renderer (docs/performance.md "What costs what"): runs
# `penumbra bench render --no-adversity --only-640x480` of one binary on the bundled worlds with
# every part of --parts switched off in turn (`--ablate PART`) and with all on, interleaved
# (all variants of a world once per round, so that load drifting on a shared machine hits them
# alike), and prints per world and part the frames/s (wall clock) and the CPU time per frame
# (every render thread; far steadier than the wall clock on a loaded machine) with the part off,
# each as the median and min-max over the rounds, and the part's share of the frame's CPU time,
# 1 - cpu(part off) / cpu(all on), as the median and min-max of the per-round shares (each
# against the same round's all-on run).
#
#   scripts/perf-ablation.sh BIN [--frames N] [--rounds R] [--worlds WORLD...] [--parts PART...]
#
# WORLD: a bundled world's name (default, house, warehouse, outdoor) or a world file; default:
# the four. PART: a name `penumbra bench render --ablate` takes (mirror, mirror-sparse,
# sky-volume, texture-filter, shadows, sun-occluder, film); default: all of them. --frames:
# timed frames per run (default 10); --rounds (>= 3, default 3). every command is run from an
# argument array, never a string through a shell. timings only: nothing here passes or fails.
set -euo pipefail

usage() {
  echo "usage: $0 BIN [--frames N] [--rounds R] [--worlds WORLD...] [--parts PART...]" >&2
  exit 2
}

[[ $# -ge 1 ]] || usage
bin=$1
shift
[[ -x $bin && -f $bin ]] || { echo "$0: '$bin' is not an executable file; expected a penumbra binary" >&2; exit 2; }
frames=10
rounds=3
worlds=()
parts=()
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
    --worlds)
      shift
      while [[ $# -gt 0 && $1 != --* ]]; do worlds+=("$1"); shift; done
      ;;
    --parts)
      shift
      while [[ $# -gt 0 && $1 != --* ]]; do parts+=("$1"); shift; done
      ;;
    *)
      echo "$0: unknown argument '$1'" >&2
      usage
      ;;
  esac
done

source "$(dirname "${BASH_SOURCE[0]}")/perf-common.sh"
perf_resolve_worlds
[[ ${#parts[@]} -gt 0 ]] || parts=(mirror mirror-sparse sky-volume texture-filter shadows sun-occluder film)

# "frames/s cpu-ms/frame" of one bench run ("" = all parts on)
bench_fps() {
  local world=$1 part=$2 out
  local args=(bench render --world "$world" --frames "$frames" --no-adversity --only-640x480 --backend cpu)
  [[ -z $part ]] || args+=(--ablate "$part")
  if ! out=$(nice "$bin" "${args[@]}" 2>&1); then
    echo "$0: '$bin ${args[*]}' failed:" >&2
    echo "$out" >&2
    return 1
  fi
  awk '$1 == "640x480" && /frames\/s/ { f = ""; c = ""; for (i = 1; i <= NF; ++i) { if ($i == "frames/s,") f = $(i - 1); if ($i == "cpu-ms/frame" || $i == "cpu-ms/frame,") c = $(i - 1) } if (f != "" && c != "") print f, c; exit }' <<<"$out"
}


echo "perf-ablation: $bin"
echo "bench render --no-adversity --only-640x480 --frames $frames, rgb+depth, $rounds interleaved rounds, $(nproc) core(s), load $(cut -d' ' -f1-3 /proc/loadavg)"
echo
echo "| world | part switched off | frames/s | CPU ms/frame | share of the frame's CPU time |"
echo "|---|---|---|---|---|"
for i in "${!world_files[@]}"; do
  declare -A fps=() cpu=() share=()
  ons=()
  on_cpus=()
  for ((r = 1; r <= rounds; ++r)); do
    read -r on on_cpu <<<"$(bench_fps "${world_files[$i]}" "")"
    [[ -n $on && -n $on_cpu ]] || { echo "$0: no 640x480 frames/s and cpu-ms/frame line on ${worlds[$i]}" >&2; exit 1; }
    ons+=("$on")
    on_cpus+=("$on_cpu")
    line="  ${worlds[$i]} round $r: all on $on fps $on_cpu cpu-ms"
    for p in "${parts[@]}"; do
      read -r v c <<<"$(bench_fps "${world_files[$i]}" "$p")"
      [[ -n $v && -n $c ]] || { echo "$0: no 640x480 line on ${worlds[$i]} --ablate $p" >&2; exit 1; }
      fps[$p]+="$v "
      cpu[$p]+="$c "
      share[$p]+="$(awk -v a="$on_cpu" -v b="$c" 'BEGIN { printf "%.3f", (a > 0 ? 1 - b / a : 0) }') "
      line+=", -$p $v fps $c cpu-ms"
    done
    echo "$line" >&2
  done
  read -r m lo hi <<<"$(stats "${ons[@]}")"
  read -r cm clo chi <<<"$(stats "${on_cpus[@]}")"
  printf '| %s | (none: all on) | %.1f (%.1f-%.1f) | %.0f (%.0f-%.0f) | |\n' "${worlds[$i]}" "$m" "$lo" "$hi" "$cm" "$clo" "$chi"
  for p in "${parts[@]}"; do
    read -r m lo hi <<<"$(stats ${fps[$p]})"
    read -r cm clo chi <<<"$(stats ${cpu[$p]})"
    read -r sm slo shi <<<"$(stats ${share[$p]})"
    printf '| %s | %s | %.1f (%.1f-%.1f) | %.0f (%.0f-%.0f) | %.2f (%.2f to %.2f) |\n' "${worlds[$i]}" "$p" "$m" "$lo" "$hi" "$cm" "$clo" "$chi" "$sm" "$slo" "$shi"
  done
  unset fps cpu share
done

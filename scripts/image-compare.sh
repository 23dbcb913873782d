#!/usr/bin/env bash
# do two binaries render the same images? (docs/rendering.md "Checking that a change keeps the
# images"): runs `penumbra run` of each binary once per world on the CPU backend for the first
# camera frames (t = 0, the rgb, depth and segmentation of every camera) and prints one markdown
# row per world, camera and image kind: byte-identical or not and, where not, the rgb PSNR (dB,
# lowest over the frames), the largest code difference (rgb: 8-bit channel codes; depth: mm)
# and the pixels that differ (scripts/image_compare.py does the arithmetic).
#
#   scripts/image-compare.sh OLD_BIN NEW_BIN [--tier realtime|pathtraced] [--spp N]
#                            [--worlds WORLD...] [--out DIR]
#
# WORLD is a bundled world's name (default, house, effects/rain: worlds/NAME.yaml) or a path to
# a world file; default: every bundled world (worlds/*.yaml and worlds/*/*.yaml but the
# adversity preset files, as tests/app/bundled_worlds_test.cc lists them). --tier: render tier
# (default realtime); --spp: samples per pixel of the pathtraced tier (default: the world's);
# --out: where the runs are written, DIR/old/WORLD and DIR/new/WORLD (default: a new temporary
# folder, kept). a world a binary fails to run is a row saying so. it reports, it does not
# judge: exit 0 after the table, 2 on bad arguments or a missing tool, 1 when a run writes no
# rgb image for a camera. every command is run from an argument array, never a string through
# a shell.
set -euo pipefail

usage() {
  echo "usage: $0 OLD_BIN NEW_BIN [--tier realtime|pathtraced] [--spp N] [--worlds WORLD...] [--out DIR]" >&2
  exit 2
}

[[ $# -ge 2 ]] || usage
old_bin=$1
new_bin=$2
shift 2
for b in "$old_bin" "$new_bin"; do
  [[ -x $b && -f $b ]] || { echo "$0: '$b' is not an executable file; expected a penumbra binary" >&2; exit 2; }
done

tier=realtime
spp=
out=
worlds=()
while [[ $# -gt 0 ]]; do
  case $1 in
    --tier)
      [[ $# -ge 2 && ( $2 == realtime || $2 == pathtraced ) ]] || { echo "$0: --tier expects realtime or pathtraced" >&2; exit 2; }
      tier=$2
      shift 2
      ;;
    --spp)
      [[ $# -ge 2 && $2 =~ ^[1-9][0-9]{0,4}$ ]] || { echo "$0: --spp expects a positive integer" >&2; exit 2; }
      spp=$2
      shift 2
      ;;
    --out)
      [[ $# -ge 2 && -n $2 && $2 != --* ]] || { echo "$0: --out expects a folder" >&2; exit 2; }
      out=$2
      shift 2
      ;;
    --worlds)
      shift
      while [[ $# -gt 0 && $1 != --* ]]; do
        worlds+=("$1")
        shift
      done
      [[ ${#worlds[@]} -gt 0 ]] || { echo "$0: --worlds expects at least one world" >&2; exit 2; }
      ;;
    *)
      echo "$0: unknown argument '$1'" >&2
      usage
      ;;
  esac
done
[[ -z $spp || $tier == pathtraced ]] || { echo "$0: --spp applies to --tier pathtraced only" >&2; exit 2; }

repo=$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)
helper=$repo/scripts/image_compare.py

# a python with numpy and Pillow: the system's, else the repository's .venv
python=
for p in python3 "$repo/.venv/bin/python3"; do
  if command -v "$p" >/dev/null && "$p" -c 'import numpy, PIL' 2>/dev/null; then
    python=$p
    break
  fi
done
[[ -n $python ]] || { echo "$0: no python3 with numpy and Pillow (python3-numpy, python3-pil, or the .venv of scripts/install-deps.sh)" >&2; exit 2; }

# labels (worlds/ relative, no .yaml) and files of the worlds
labels=()
files=()
if [[ ${#worlds[@]} -eq 0 ]]; then
  shopt -s nullglob
  for f in "$repo"/worlds/*.yaml "$repo"/worlds/*/*.yaml; do
    [[ $f == "$repo"/worlds/adversity/* ]] && continue
    files+=("$f")
  done
  shopt -u nullglob
  mapfile -t files < <(printf '%s\n' "${files[@]}" | sort)
  for f in "${files[@]}"; do
    l=${f#"$repo"/worlds/}
    labels+=("${l%.yaml}")
  done
else
  for w in "${worlds[@]}"; do
    if [[ $w == *.yaml ]]; then f=$w; l=$(basename "$w" .yaml); else f=$repo/worlds/$w.yaml; l=$w; fi
    [[ -f $f ]] || { echo "$0: world '$w': no file $f; expected a bundled world name or a world file" >&2; exit 2; }
    files+=("$f")
    labels+=("$l")
  done
fi

if [[ -z $out ]]; then out=$(mktemp -d -t image-compare.XXXXXX); fi
mkdir -p "$out/old" "$out/new"

run_args=(--force --duration 0.05 --outputs "rgb,depth,segmentation" --threads 2 --backend cpu --tier "$tier" -q)
[[ -n $spp ]] && run_args+=(--spp "$spp")

# run BIN on world file F into DIR; 0 when it ran and every camera wrote an rgb PNG
render() {
  local bin=$1 f=$2 dir=$3 log lacking
  mkdir -p "$(dirname "$dir")"
  if ! log=$(nice "$bin" run "$f" --out "$dir" "${run_args[@]}" 2>&1); then
    echo "$0: '$bin run $f' failed:" >&2
    tail -n 5 <<<"$log" >&2
    return 1
  fi
  [[ -f $dir/camera_info.json ]] || return 0  # a world without cameras
  if ! lacking=$("$python" "$helper" check "$dir"); then
    echo "$0: '$bin run $f' wrote no rgb image for camera(s): ${lacking//$'\n'/ }" >&2
    exit 1
  fi
}

echo "image-compare: OLD $old_bin"
echo "               NEW $new_bin"
echo "run --duration 0.05 --outputs rgb,depth,segmentation --threads 2 --backend cpu --tier $tier${spp:+ --spp $spp}; runs in $out"
rows=()
for i in "${!files[@]}"; do
  l=${labels[$i]}
  old_ok=1
  new_ok=1
  render "$old_bin" "${files[$i]}" "$out/old/$l" || old_ok=0
  render "$new_bin" "${files[$i]}" "$out/new/$l" || new_ok=0
  if [[ $old_ok == 1 && $new_ok == 1 ]]; then
    text=$("$python" "$helper" compare "$out/old/$l" "$out/new/$l" "$l")
    if [[ -n $text ]]; then
      mapfile -t world_rows <<<"$text"
      rows+=("${world_rows[@]}")
    else
      rows+=("| $l | - | - | no cameras | - | - | - | - |")
    fi
  else
    failed=
    [[ $old_ok == 1 ]] || failed=old
    [[ $new_ok == 1 ]] || failed=${failed:+$failed and }new
    rows+=("| $l | - | - | run failed ($failed) | - | - | - | - |")
  fi
  echo "  $l done" >&2
done
echo
echo "| world | camera | kind | identical | PSNR dB | max diff | differing pixels | frames |"
echo "|---|---|---|---|---|---|---|---|"
printf '%s\n' "${rows[@]}"

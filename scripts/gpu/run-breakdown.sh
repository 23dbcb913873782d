#!/usr/bin/env bash
# on a GPU machine: joins and unpacks scripts/gpu/pack-full.sh's parts, names the card and runs
# `penumbra run WORLD --backend B --duration S` for each world with the CPU and the CUDA
# backend (interleaved: cpu, cuda, cpu, cuda for two rounds), then prints where each run's wall
# time went, from run.json's timings_sec (docs/gpu.md, "A run on the GPU").
#
#   scripts/gpu/run-breakdown.sh OUT-FOLDER SIM-SECONDS PART... | UNPACKED-FOLDER
#   WORLDS="house default"   bundled worlds to run (default: house default)
#   PENUMBRA_BIN=FILE[.xz]   an executable to run instead of the packed one (a newer build of
#                            the same libraries: only the executable needs to travel again)
set -uo pipefail
out=$1
seconds=$2
shift 2
read -r -a worlds <<< "${WORLDS:-house default}"
work=$(mktemp -d)
if [ $# -eq 1 ] && [ -d "$1" ]; then
  pkg=$(cd "$1" && pwd)
else
  cat "$@" | tar -C "$work" -xJf - || { echo "run-breakdown: cannot unpack $*" >&2; exit 2; }
  pkg=$work/penumbra-full
fi
if [ -n "${PENUMBRA_BIN:-}" ]; then
  case $PENUMBRA_BIN in
    *.xz) xz -dc "$PENUMBRA_BIN" > "$pkg/bin/penumbra" ;;
    *) cp "$PENUMBRA_BIN" "$pkg/bin/penumbra" ;;
  esac
  chmod +x "$pkg/bin/penumbra"
fi
. "$(dirname "$0")/use-pack.sh"
use_pack "$pkg"
mkdir -p "$out"
card=$(nvidia-smi --query-gpu=name,driver_version --format=csv,noheader 2>/dev/null || echo none)
echo "card: $card; CPU: $(nproc) cores,$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2)"
for round in 1 2; do
  for w in "${worlds[@]}"; do
    for b in cpu cuda; do
      d=$out/$w-$b-$round
      "$pkg/bin/penumbra" run "$pkg/src/worlds/$w.yaml" --backend "$b" --duration "$seconds" \
        --out "$d" > "$d.log" 2>&1 || echo "run-breakdown: $w $b round $round failed (log $d.log)"
    done
  done
done
python3 - "$out" "${worlds[@]}" <<'PY'
import json, os, sys
out, worlds = sys.argv[1], sys.argv[2:]
keys = ["total_sec", "physics_sec", "render_sec", "render_first_frames_sec",
        "render_renderer_sec", "png_encode_sec", "png_write_sec", "scene_build_sec",
        "compose_sec", "load_sec", "sensors_lidar_effects_sec"]
print("| world | backend | round | frames | " + " | ".join(k[:-4] for k in keys) + " |")
print("|---|---|---|---|" + "---|" * len(keys))
for w in worlds:
    for b in ("cpu", "cuda"):
        for r in (1, 2):
            p = os.path.join(out, f"{w}-{b}-{r}", "run.json")
            if not os.path.exists(p):
                print(f"| {w} | {b} | {r} | (no run.json) |")
                continue
            d = json.load(open(p))
            t = d.get("timings_sec", {})
            frames = sum(d.get("frames_per_camera", {}).values())
            print(f"| {w} | {b} | {r} | {frames} | " +
                  " | ".join(f"{t.get(k, float('nan')):.3f}" for k in keys) + " |")
PY

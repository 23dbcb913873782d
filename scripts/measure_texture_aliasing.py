#!/usr/bin/env python3
"""Measures texture aliasing on a far checker floor (docs/rendering.md, "Textures").

Uses Pillow. Writes a world into OUT_DIR: MuJoCo's standard Menagerie ground
plane (a 300 x 300 checker with mark="edge", texrepeat 5 5, texuniform) and one 640 x 480
camera 1.2 m above it, fovy 20 deg, pitched 2 deg down, looking along it; runs

    PENUMBRA run OUT_DIR/world.yaml --out OUT_DIR/run

for one frame, and prints, for the floor pixels whose range is in [15, 60] m:

    far_residual_std   the standard deviation of luminance minus its local mean (9 x 9 box)

and, for the floor pixels nearer than 8 m, near_residual_std (the near checker's contrast,
which filtering must keep), and

    line_contrast      the contrast of the edge-mark line y = 0, which runs away from the camera
                       (the middle columns): per image row whose floor is 10-15 m away, the
                       brightest luminance of the 7 columns around the middle over the median of
                       the 25 around it (the next lines are >= 18 columns away), minus 1,
                       averaged over those rows (0: the line is gone)

Luminance is Rec. 709 luma of the 8-bit sRGB values in [0, 1]
(as stored). Usage, from the repository root:

    python3 scripts/measure_texture_aliasing.py OUT_DIR [--penumbra build/penumbra]
                                                [--tier realtime|pathtraced] [--spp N]
                                                [--max-anisotropy N]
"""

import argparse
import json
import os
import struct
import subprocess
import sys

from PIL import Image

FLOOR_XML = """<mujoco model="floor">
  <asset>
    <texture type="2d" name="groundplane" builtin="checker" mark="edge" rgb1="0.2 0.3 0.4"
             rgb2="0.1 0.2 0.3" markrgb="0.8 0.8 0.8" width="300" height="300"/>
    <material name="groundplane" texture="groundplane" texuniform="true" texrepeat="5 5"
              reflectance="0.2"/>
  </asset>
  <worldbody>
    <geom name="floor" size="0 0 0.05" type="plane" material="groundplane"/>
  </worldbody>
</mujoco>
"""

WORLD_YAML = """seed: 1
duration_sec: 0.05
physics: {timestep_sec: 0.002}
render: {tier: %(tier)s, samples_per_pixel: %(spp)d, max_bounces: 2, denoise: false,
         max_anisotropy: %(aniso)d}
sky: {type: daylight, turbidity: 3, sun_elevation_deg: 45, sun_azimuth_deg: 30}
models:
  - {name: floor, file: floor.xml}
lights:
  - {name: sun, type: sun, direction: [-0.5, -0.3, -0.8], illuminance_lux: 50000}
cameras:
  - name: far
    pose: {xyz: [0, 0, 1.2], rpy_deg: [0, 2, 0]}
    width: 640
    height: 480
    fovy_deg: 20
    rate_hz: 10
    outputs: [rgb, range]
mjcf_cameras: {enabled: false}
"""


def read_png(path):
    """(width, height, channels, rows of samples) of an 8/16-bit grey or RGB PNG (Pillow,
    Debian's python3-pil)."""
    with Image.open(path) as im:
        w, h = im.size
        if im.mode in ("L", "RGB"):
            ch = len(im.mode)
            flat = im.tobytes()
        elif im.mode in ("I;16", "I"):  # 16-bit grey (Pillow >= 10: I;16, older: I)
            ch = 1
            fmt = "<%dH" if im.mode == "I;16" else "=%di"
            flat = struct.unpack(fmt % (w * h), im.tobytes())
        else:
            raise ValueError("%s: unexpected PNG mode %s" % (path, im.mode))
    stride = w * ch
    return w, h, ch, [list(flat[y * stride:(y + 1) * stride]) for y in range(h)]


def residual_std(lum, mask, w, h, r=4):
    """std-dev of lum - (its (2r+1)^2 box mean) over the pixels where mask is set and the whole
    box lies inside the image."""
    integ = [[0.0] * (w + 1) for _ in range(h + 1)]
    for y in range(h):
        acc = 0.0
        for x in range(w):
            acc += lum[y][x]
            integ[y + 1][x + 1] = integ[y][x + 1] + acc
    vals = []
    n = (2 * r + 1) ** 2
    for y in range(r, h - r):
        for x in range(r, w - r):
            if not mask[y][x]:
                continue
            s = (integ[y + r + 1][x + r + 1] - integ[y - r][x + r + 1] - integ[y + r + 1][x - r] +
                 integ[y - r][x - r])
            vals.append(lum[y][x] - s / n)
    if not vals:
        return float("nan"), 0
    m = sum(vals) / len(vals)
    return (sum((v - m) ** 2 for v in vals) / len(vals)) ** 0.5, len(vals)


def line_contrast(lum, rng, w, h):
    """contrast of the line in the middle columns over the rows whose floor is 10-15 m away
    (module docstring)."""
    cu, vals = w // 2, []
    for y in range(h):
        if not 10000 <= rng[y][cu] <= 15000:
            continue
        win = sorted(lum[y][cu - 12:cu + 13])
        peak = max(lum[y][cu - 3:cu + 4])
        vals.append(peak / win[12] - 1 if win[12] > 0 else 0.0)
    return (sum(vals) / len(vals) if vals else float("nan")), len(vals)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("out_dir")
    ap.add_argument("--penumbra", default="build/penumbra")
    ap.add_argument("--tier", default="realtime", choices=["realtime", "pathtraced"])
    ap.add_argument("--spp", type=int, default=4)
    ap.add_argument("--max-anisotropy", type=int, default=16)
    a = ap.parse_args()
    os.makedirs(a.out_dir, exist_ok=True)
    with open(os.path.join(a.out_dir, "floor.xml"), "w") as f:
        f.write(FLOOR_XML)
    with open(os.path.join(a.out_dir, "world.yaml"), "w") as f:
        f.write(WORLD_YAML % {"tier": a.tier, "spp": a.spp, "aniso": a.max_anisotropy})
    run = os.path.join(a.out_dir, "run")
    subprocess.run([a.penumbra, "run", os.path.join(a.out_dir, "world.yaml"), "--out", run],
                   check=True, stdout=subprocess.DEVNULL)
    w, h, _, rgb = read_png(os.path.join(run, "far", "rgb", "000000.png"))
    _, _, _, rng = read_png(os.path.join(run, "far", "range", "000000.png"))
    lum = [[(0.2126 * row[3 * x] + 0.7152 * row[3 * x + 1] + 0.0722 * row[3 * x + 2]) / 255.0
            for x in range(w)] for row in rgb]
    far = [[15000 <= rng[y][x] <= 60000 for x in range(w)] for y in range(h)]
    near = [[0 < rng[y][x] < 8000 for x in range(w)] for y in range(h)]
    far_std, far_n = residual_std(lum, far, w, h)
    near_std, near_n = residual_std(lum, near, w, h)
    contrast, contrast_rows = line_contrast(lum, rng, w, h)
    print(json.dumps({"tier": a.tier, "max_anisotropy": a.max_anisotropy,
                      "far_residual_std": round(far_std, 5), "far_pixels": far_n,
                      "near_residual_std": round(near_std, 5), "near_pixels": near_n,
                      "line_contrast": round(contrast, 4), "line_rows": contrast_rows,
                      "image": os.path.join(run, "far", "rgb", "000000.png")}))


if __name__ == "__main__":
    sys.exit(main())

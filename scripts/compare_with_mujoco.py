#!/usr/bin/python3
"""Side by side with MuJoCo's own renderer.

Renders bare models with Penumbra (`penumbra run MODEL.xml`: the auto-framed `default` camera,
the bare-model daylight) and with MuJoCo 4's OpenGL renderer (tools/mujoco_offscreen.cc,
under Xvfb) from the same camera (the pose of frame 0 in <out>/default/frames.csv, the vertical
field of view of camera_info.json), at the model's initial state, and reports per model:

- silhouette IoU: the pixels of the model's moving bodies (geoms whose body is not the world;
  all non-plane geoms when nothing moves) in Penumbra's segmentation image against MuJoCo's
  segmentation render (geom ids);
- hue (deg) and saturation (HSV, of the 8-bit sRGB pixels as displayed) of the labelled parts:
  the median over each geom's pixels that both renderers see, for the largest parts;
- shadow contrast of the floor (plane geoms): 1 - (2nd percentile) / (median) of the floor
  pixels' luminance (Rec. 709 of the decoded sRGB values) near the model (inside its silhouette's
  bounding box grown by its size on every side): the darkest floor, where the shadow lies, against the
  typical floor. a proxy: a checker floor's dark squares count too, in both renderers alike;
- the background (skybox) colour: the mean of the pixels that no geom covers.

Writes <out>/<model>/{penumbra,mujoco}.png, a side-by-side pair <pairs>/<model>.png (MuJoCo
left, Penumbra right) when --pairs is given, <out>/results.json and a Markdown table (stdout and
<out>/table.md). With --min-iou, --max-background-hue-diff and --min-shadow-contrast-ratio it exits
1 when a model falls outside them (the ctest check `compare_with_mujoco`).

    xvfb-run -a /usr/bin/python3 scripts/compare_with_mujoco.py --binary build/penumbra \\
        --tool build/mujoco_offscreen --out /tmp/cmp --pairs docs/compare_mujoco

Needs numpy and PIL (Debian: python3-numpy, python3-pil), a display for GLFW (xvfb-run) and the
tool (built by CMake as `mujoco_offscreen` where GLFW is installed: libglfw3-dev).
"""

import argparse
import colorsys
import csv
import json
import math
import os
import shutil
import subprocess
import sys

import numpy as np
from PIL import Image

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.dirname(HERE)

GYM_ASSETS = os.path.join(ROOT, ".venv/lib/python3.11/site-packages/gymnasium/envs/mujoco/assets")
DEFAULT_MODELS = [
    os.path.join(GYM_ASSETS, "humanoid.xml"),  # MuJoCo's classic humanoid, gymnasium's copy
    os.path.join(ROOT, "worlds/models/quadruped.xml"),
    os.path.join(ROOT, "worlds/models/arm.xml"),
]

MJ_PLANE = 0  # mjGEOM_PLANE


def run(cmd, timeout):
    """runs cmd (an argv list, never through a shell); raises with its stderr on failure."""
    p = subprocess.run(cmd, stdout=subprocess.PIPE, stderr=subprocess.PIPE, timeout=timeout,
                       check=False)
    if p.returncode != 0:
        raise RuntimeError("%s failed (%d): %s" % (cmd[0], p.returncode,
                                                   p.stderr.decode(errors="replace")[-2000:]))
    return p


def quat_to_matrix(qw, qx, qy, qz):
    n = math.sqrt(qw * qw + qx * qx + qy * qy + qz * qz)
    qw, qx, qy, qz = qw / n, qx / n, qy / n, qz / n
    return np.array([
        [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
        [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
        [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)],
    ])


def srgb_to_linear(c):
    c = np.asarray(c, dtype=np.float64) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055) ** 2.4)


def luminance(rgb8):
    lin = srgb_to_linear(rgb8)
    return 0.2126 * lin[..., 0] + 0.7152 * lin[..., 1] + 0.0722 * lin[..., 2]


def hue_sat(pixels):
    """median saturation and circular-mean hue (deg) of (N x 3) 8-bit sRGB pixels."""
    hs = np.array([colorsys.rgb_to_hsv(*(p / 255.0))[:2] for p in pixels])
    sat = float(np.median(hs[:, 1]))
    ang = hs[:, 0] * 2 * math.pi
    hue = math.degrees(math.atan2(np.mean(np.sin(ang)), np.mean(np.cos(ang)))) % 360.0
    return hue, sat


def hue_distance(a, b):
    d = abs(a - b) % 360.0
    return min(d, 360.0 - d)


def shadow_contrast(lum, floor_mask, model_mask):
    if floor_mask.sum() < 50 or model_mask.sum() == 0:
        return None
    vs, us = np.nonzero(model_mask)
    v0, v1, u0, u1 = vs.min(), vs.max(), us.min(), us.max()
    dv, du = (v1 - v0) + 1, (u1 - u0) + 1
    near = np.zeros_like(floor_mask)
    near[max(0, v0 - dv):v1 + dv + 1, max(0, u0 - du):u1 + du + 1] = True
    values = lum[floor_mask & near]
    if values.size < 50:
        return None
    median = float(np.median(values))
    return 1.0 - float(np.percentile(values, 2)) / median if median > 0 else None


def compare_model(model, args):
    name = os.path.splitext(os.path.basename(model))[0]
    work = os.path.join(args.out, name)
    os.makedirs(work, exist_ok=True)
    run_dir = os.path.join(work, "run")
    run([args.binary, "run", model, "--out", run_dir, "--duration", "0.01", "--outputs",
         "rgb,segmentation", "--force", "--quiet"], timeout=args.timeout)
    with open(os.path.join(run_dir, "default", "frames.csv"), newline="") as f:
        rows = list(csv.DictReader(f))
    r0 = rows[0]
    pos = [float(r0["x"]), float(r0["y"]), float(r0["z"])]
    R = quat_to_matrix(float(r0["qw"]), float(r0["qx"]), float(r0["qy"]), float(r0["qz"]))
    with open(os.path.join(run_dir, "camera_info.json")) as f:
        info = json.load(f)["default"]
    width, height = int(info["width"]), int(info["height"])
    fy = float(info["K"][4])
    fovy = math.degrees(2 * math.atan(0.5 * height / fy))
    forward, up = R[:, 2], -R[:, 1]
    prefix = os.path.join(work, "mujoco")
    run([args.tool, model, prefix, str(width), str(height)] +
        ["%.9g" % v for v in list(pos) + list(forward) + list(up)] + ["%.9g" % fovy],
        timeout=args.timeout)

    pb_rgb = np.asarray(Image.open(os.path.join(run_dir, "default", "rgb", "000000.png"))
                        .convert("RGB"))
    pb_seg = np.asarray(Image.open(os.path.join(run_dir, "default", "segmentation",
                                                "000000.png"))).astype(np.int64) - 1
    mj_rgb = np.asarray(Image.open(prefix + ".ppm").convert("RGB"))
    mj_seg = np.fromfile(prefix + ".seg", dtype="<i4").reshape(height, width).astype(np.int64)
    with open(prefix + ".json") as f:
        geoms = json.load(f)["geoms"]
    Image.fromarray(pb_rgb).save(os.path.join(work, "penumbra.png"))
    Image.fromarray(mj_rgb).save(os.path.join(work, "mujoco.png"))

    moving = [g["id"] for g in geoms if g["body"] != 0]
    if not moving:
        moving = [g["id"] for g in geoms if g["type"] != MJ_PLANE]
    planes = [g["id"] for g in geoms if g["type"] == MJ_PLANE]
    pb_model, mj_model = np.isin(pb_seg, moving), np.isin(mj_seg, moving)
    union = (pb_model | mj_model).sum()
    iou = float((pb_model & mj_model).sum() / union) if union > 0 else 0.0

    parts = []
    for g in geoms:
        if g["type"] == MJ_PLANE:
            continue
        both = (pb_seg == g["id"]) & (mj_seg == g["id"])
        if both.sum() < args.min_part_pixels:
            continue
        h_mj, s_mj = hue_sat(mj_rgb[both][:: max(1, both.sum() // 2000)])
        h_pb, s_pb = hue_sat(pb_rgb[both][:: max(1, both.sum() // 2000)])
        parts.append({"geom": g["name"] or "#%d" % g["id"], "pixels": int(both.sum()),
                      "rgba": g["rgba"], "mujoco_hue": h_mj, "mujoco_sat": s_mj,
                      "penumbra_hue": h_pb, "penumbra_sat": s_pb,
                      "hue_diff": hue_distance(h_mj, h_pb) if min(s_mj, s_pb) > 0.1 else None})
    parts.sort(key=lambda p: -p["pixels"])
    parts = parts[:args.max_parts]

    contrast = {}
    for label, rgb, seg, model_mask in (("mujoco", mj_rgb, mj_seg, mj_model),
                                        ("penumbra", pb_rgb, pb_seg, pb_model)):
        contrast[label] = shadow_contrast(luminance(rgb), np.isin(seg, planes), model_mask)
    background = {}
    for label, rgb, seg in (("mujoco", mj_rgb, mj_seg), ("penumbra", pb_rgb, pb_seg)):
        bg = seg < 0
        background[label] = ([round(float(c), 1) for c in rgb[bg].mean(axis=0)]
                             if bg.sum() > 0 else None)

    if args.pairs:
        os.makedirs(args.pairs, exist_ok=True)
        w = min(width, 320)
        h = int(round(height * w / width))
        pair = Image.new("RGB", (2 * w, h))
        pair.paste(Image.fromarray(mj_rgb).resize((w, h), Image.BILINEAR), (0, 0))
        pair.paste(Image.fromarray(pb_rgb).resize((w, h), Image.BILINEAR), (w, 0))
        pair.save(os.path.join(args.pairs, name + ".png"))
    return {"model": model, "name": name, "iou": iou, "parts": parts,
            "shadow_contrast": contrast, "background_rgb": background,
            "camera": {"position": pos, "forward": forward.tolist(), "up": up.tolist(),
                       "fovy_deg": fovy, "width": width, "height": height}}


def fmt(v, spec):
    return "-" if v is None else format(v, spec)


def table(results):
    lines = ["| model | silhouette IoU | shadow contrast MuJoCo / Penumbra | background (sRGB) "
             "MuJoCo / Penumbra |", "|---|---|---|---|"]
    for r in results:
        c, b = r["shadow_contrast"], r["background_rgb"]
        lines.append("| %s | %.3f | %s / %s | %s / %s |" % (
            r["name"], r["iou"], fmt(c["mujoco"], ".2f"), fmt(c["penumbra"], ".2f"),
            b["mujoco"], b["penumbra"]))
    lines += ["", "| model | part | pixels | hue MuJoCo / Penumbra (deg) | saturation MuJoCo / "
              "Penumbra |", "|---|---|---|---|---|"]
    for r in results:
        for p in r["parts"]:
            lines.append("| %s | %s | %d | %.0f / %.0f | %.2f / %.2f |" % (
                r["name"], p["geom"], p["pixels"], p["mujoco_hue"], p["penumbra_hue"],
                p["mujoco_sat"], p["penumbra_sat"]))
    return "\n".join(lines) + "\n"


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--binary", default=os.path.join(ROOT, "build", "penumbra"))
    ap.add_argument("--tool", default=os.path.join(ROOT, "build", "mujoco_offscreen"))
    ap.add_argument("--models", nargs="+", default=DEFAULT_MODELS)
    ap.add_argument("--out", required=True, help="work folder (replaced)")
    ap.add_argument("--pairs", help="folder for the side-by-side PNGs (e.g. docs/compare_mujoco)")
    ap.add_argument("--min-iou", type=float, help="exit 1 if a model's silhouette IoU is lower")
    ap.add_argument("--max-background-hue-diff", type=float,
                    help="exit 1 if the hues of a model's mean background colours (its skybox) "
                         "differ by more than this many degrees (both renderers show one)")
    ap.add_argument("--min-shadow-contrast-ratio", type=float,
                    help="exit 1 if Penumbra's floor shadow contrast is below this fraction of "
                         "MuJoCo's (models with a floor)")
    ap.add_argument("--min-part-pixels", type=int, default=60)
    ap.add_argument("--max-parts", type=int, default=4)
    ap.add_argument("--timeout", type=float, default=300)
    args = ap.parse_args()
    for exe in (args.binary, args.tool):
        if not os.access(exe, os.X_OK):
            sys.exit("compare_with_mujoco: %s is not an executable" % exe)
    if os.path.isdir(args.out):
        shutil.rmtree(args.out)
    os.makedirs(args.out)
    results = [compare_model(m, args) for m in args.models]
    with open(os.path.join(args.out, "results.json"), "w") as f:
        json.dump(results, f, indent=1)
    text = table(results)
    with open(os.path.join(args.out, "table.md"), "w") as f:
        f.write(text)
    sys.stdout.write(text)
    problems = []
    for r in results:
        if args.min_iou is not None and r["iou"] < args.min_iou:
            problems.append("%s: silhouette IoU %.3f < %.3f" % (r["name"], r["iou"], args.min_iou))
        b = r["background_rgb"]
        if args.max_background_hue_diff is not None and b["mujoco"] and b["penumbra"]:
            h_mj, _ = hue_sat(np.array([b["mujoco"]]))
            h_pb, _ = hue_sat(np.array([b["penumbra"]]))
            diff = hue_distance(h_mj, h_pb)
            if diff > args.max_background_hue_diff:
                problems.append("%s: background %s (MuJoCo, hue %.0f deg) vs %s (Penumbra, hue "
                                "%.0f deg): %.0f > %.0f deg" %
                                (r["name"], b["mujoco"], h_mj, b["penumbra"], h_pb, diff,
                                 args.max_background_hue_diff))
        c = r["shadow_contrast"]
        if (args.min_shadow_contrast_ratio is not None and c["mujoco"] is not None and
                c["penumbra"] is not None and
                c["penumbra"] < args.min_shadow_contrast_ratio * c["mujoco"]):
            problems.append("%s: shadow contrast %.2f < %.2f x MuJoCo's %.2f" %
                            (r["name"], c["penumbra"], args.min_shadow_contrast_ratio,
                             c["mujoco"]))
    for p in problems:
        sys.stderr.write("compare_with_mujoco: %s\n" % p)
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())

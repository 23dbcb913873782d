#!/usr/bin/env python3
"""The image arithmetic of scripts/image-compare.sh: compares the camera images of one world as
two `penumbra run` folders hold them and prints one markdown table row per camera and image kind.

usage: image_compare.py compare OLD_RUN_DIR NEW_RUN_DIR WORLD_LABEL
       image_compare.py check RUN_DIR

A run folder holds CAMERA/KIND/NNNNNN.png (KIND: rgb, depth, segmentation). Per (camera, kind)
every frame file of either folder is paired by name; the row says whether all pairs are
byte-identical and, where not, for rgb (8-bit RGB) the lowest PSNR over the frames (dB, peak 255,
over all channels), the largest per-channel code difference and the pixels with any channel
different; for depth (16-bit z-depth, mm) the largest absolute difference in mm and the
differing pixels; for segmentation (16-bit ids) the differing pixels. A frame present in one
folder only is reported as missing. Exit status 0 after printing the rows; 2 on bad arguments
or an unreadable image.

`check` lists the cameras of a run folder (the keys of its camera_info.json) that wrote no rgb
PNG, one a line; exit status 0 when every camera wrote one, 1 when some did not, 2 when the
folder has no camera_info.json.

Needs numpy and Pillow (the repository's .venv has both).
"""

import json
import math
import os
import sys

import numpy as np
from PIL import Image

KINDS = ("rgb", "depth", "segmentation")


def frames(run_dir, camera, kind):
    folder = os.path.join(run_dir, camera, kind)
    if not os.path.isdir(folder):
        return set()
    return {n for n in os.listdir(folder) if n.endswith(".png")}


def cameras(run_dir):
    if not os.path.isdir(run_dir):
        return set()
    return {c for c in os.listdir(run_dir)
            if any(os.path.isdir(os.path.join(run_dir, c, k)) for k in KINDS)}


def load(path):
    with Image.open(path) as im:
        return np.asarray(im).astype(np.int64)


def compare_kind(old_dir, new_dir, camera, kind):
    """the table cells (identical, psnr, max diff, differing pixels, frames) of one camera's kind"""
    old_f, new_f = frames(old_dir, camera, kind), frames(new_dir, camera, kind)
    names = sorted(old_f | new_f)
    if not names:
        return None
    missing = [n for n in names if n not in old_f or n not in new_f]
    identical = not missing
    psnr = math.inf
    max_diff = 0
    diff_pixels = 0
    compared = 0
    for n in names:
        if n in missing:
            continue
        a_path = os.path.join(old_dir, camera, kind, n)
        b_path = os.path.join(new_dir, camera, kind, n)
        with open(a_path, "rb") as fa, open(b_path, "rb") as fb:
            if fa.read() == fb.read():
                compared += 1
                continue
        identical = False
        a, b = load(a_path), load(b_path)
        compared += 1
        if a.shape != b.shape:
            raise ValueError(f"{a_path} is {a.shape}, {b_path} is {b.shape}")
        d = np.abs(a - b)
        max_diff = max(max_diff, int(d.max()) if d.size else 0)
        per_pixel = d if d.ndim == 2 else d.max(axis=2)
        diff_pixels += int(np.count_nonzero(per_pixel))
        if kind == "rgb":
            mse = float(np.mean(d.astype(np.float64) ** 2))
            if mse > 0:
                psnr = min(psnr, 10.0 * math.log10(255.0 * 255.0 / mse))
    if identical:
        return ("yes", "-", "-", "-", str(compared))
    verdict = "no" if not missing else f"no ({len(missing)} frame(s) in one run only)"
    if kind == "rgb":
        psnr_cell = "inf" if math.isinf(psnr) else f"{psnr:.2f}"
    else:
        psnr_cell = "-"
    max_cell = "-" if kind == "segmentation" else (f"{max_diff} mm" if kind == "depth" else str(max_diff))
    return (verdict, psnr_cell, max_cell, str(diff_pixels), str(compared))


USAGE = "usage: image_compare.py compare OLD_RUN_DIR NEW_RUN_DIR WORLD_LABEL | check RUN_DIR"


def check(run_dir):
    info = os.path.join(run_dir, "camera_info.json")
    try:
        with open(info) as f:
            names = sorted(json.load(f))
    except (OSError, ValueError) as e:
        print(f"image_compare.py: {info}: {e}", file=sys.stderr)
        return 2
    lacking = [c for c in names if not frames(run_dir, c, "rgb")]
    for c in lacking:
        print(c)
    return 1 if lacking else 0


def main(argv):
    if len(argv) == 3 and argv[1] == "check":
        return check(argv[2])
    if len(argv) != 5 or argv[1] != "compare":
        print(USAGE, file=sys.stderr)
        return 2
    old_dir, new_dir, label = argv[2], argv[3], argv[4]
    for d in (old_dir, new_dir):
        if not os.path.isdir(d):
            print(f"{argv[0]}: '{d}' is not a folder; expected a penumbra run folder", file=sys.stderr)
            return 2
    try:
        for camera in sorted(cameras(old_dir) | cameras(new_dir)):
            for kind in KINDS:
                cells = compare_kind(old_dir, new_dir, camera, kind)
                if cells is not None:
                    print("| " + " | ".join((label, camera, kind) + cells) + " |")
    except (OSError, ValueError) as e:
        print(f"{argv[0]}: {e}", file=sys.stderr)
        return 2
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv))

#!/usr/bin/env python3
"""`penumbra compare` against NVIDIA's own FLIP (the flip-evaluator package, pinned in
scripts/requirements.txt): on generated image pairs (identical, noise, blur, shift, colour change,
two unrelated noise images) the mean LDR-FLIP that `penumbra compare` prints agrees with
flip_evaluator.evaluate's within 1e-3 absolute (measured: <= 2e-5), identical images give 0,
the heatmap is FLIP's magma map of the error; the verb's errors name the file (exit 2).

usage: flip_reference_test.py PENUMBRA_BINARY OUT_DIR
exit 77 (skipped) with the reason when flip_evaluator, numpy or PIL cannot be imported."""

import re
import shutil
import subprocess
import sys
from pathlib import Path

SKIP = 77
MEAN_TOLERANCE = 1e-3

try:
    import numpy as np
    from PIL import Image
except ImportError as e:
    print(f"skipped: numpy and PIL are needed ({e})")
    sys.exit(SKIP)
try:
    import flip_evaluator
except ImportError as e:
    print(f"skipped: flip-evaluator is not installed ({e}); "
          "pip install -r scripts/requirements.txt into the venv")
    sys.exit(SKIP)


def scene(h, w):
    y, x = np.mgrid[0:h, 0:w]
    img = np.stack([x * 255 // w, y * 255 // h, (x + y) * 127 // (w + h) + 60], -1)
    img = img.astype(np.uint8)
    img[h // 4:h // 2, w // 4:w // 2] = [200, 50, 30]
    img[h // 2:h - 8, 2 * w // 3:w - 10] = [20, 180, 220]
    return img


def blur(img):
    k = np.array([1, 4, 6, 4, 1], np.float32) / 16
    out = img.astype(np.float32)
    for axis in (0, 1):
        out = sum(k[i] * np.roll(out, i - 2, axis=axis) for i in range(5))
    return np.clip(np.rint(out), 0, 255).astype(np.uint8)


def pairs():
    rng = np.random.default_rng(7)
    h, w = 120, 160
    a = scene(h, w)
    noisy = np.clip(a.astype(int) + rng.integers(-20, 21, a.shape), 0, 255).astype(np.uint8)
    tinted = np.clip(a.astype(float) * [1.1, 0.9, 1.0] + [0, 0, 15], 0, 255).astype(np.uint8)
    r1 = rng.integers(0, 256, (h, w, 3)).astype(np.uint8)
    r2 = rng.integers(0, 256, (h, w, 3)).astype(np.uint8)
    return {
        "identical": (a, a.copy(), None),
        "noise": (a, noisy, None),
        "blur": (a, blur(a), None),
        "shift": (a, np.roll(a, 2, axis=1), None),
        "colour": (a, tinted, None),
        "unrelated": (r1, r2, None),
        "noise_ppd30": (a, noisy, 30.0),
    }


def run(binary, *args):
    return subprocess.run([binary, *args], capture_output=True, text=True, timeout=120)


def main():
    binary, out = sys.argv[1], Path(sys.argv[2])
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    failures = []
    print(f"{'pair':12s} {'penumbra':>10s} {'flip-eval':>10s} {'|diff|':>9s}")
    for name, (a, b, ppd) in pairs().items():
        pa, pb, heat = out / f"{name}_a.png", out / f"{name}_b.png", out / f"{name}_heat.png"
        Image.fromarray(a).save(pa)
        Image.fromarray(b).save(pb)
        args = [str(pa), str(pb), "--heatmap", str(heat)]
        params = {}
        if ppd is not None:
            args += ["--ppd", str(ppd)]
            params["ppd"] = ppd
        r = run(binary, "compare", *args)
        if r.returncode != 0:
            failures.append(f"{name}: exit {r.returncode}: {r.stderr.strip()}")
            continue
        m = re.search(r"Mean: ([0-9.]+)", r.stdout)
        if not m:
            failures.append(f"{name}: no 'Mean:' line in {r.stdout!r}")
            continue
        ours = float(m.group(1))
        ref_map, ref_mean, _ = flip_evaluator.evaluate(
            a.astype(np.float32) / 255, b.astype(np.float32) / 255, "LDR",
            applyMagma=False, parameters=params)
        diff = abs(ours - ref_mean)
        print(f"{name:12s} {ours:10.6f} {ref_mean:10.6f} {diff:9.2e}")
        if diff > MEAN_TOLERANCE:
            failures.append(f"{name}: mean {ours} vs flip-evaluator {ref_mean} (> {MEAN_TOLERANCE})")
        if name == "identical" and ours != 0.0:
            failures.append(f"identical images: mean {ours}, expected 0")
        if name != "identical" and not ours > 0.01:
            failures.append(f"{name}: mean {ours}, expected a visible difference")
        # the heatmap: FLIP's magma entry of each pixel's error (ours or the reference's error
        # may round to the neighbouring entry)
        ref_magma, _, _ = flip_evaluator.evaluate(
            a.astype(np.float32) / 255, b.astype(np.float32) / 255, "LDR",
            applyMagma=True, parameters=params)
        ref_rgb = np.rint(ref_magma * 255).astype(int)
        got = np.asarray(Image.open(heat).convert("RGB")).astype(int)
        same = np.all(got == ref_rgb, axis=-1).mean()
        worst = np.abs(got - ref_rgb).max()
        if same < 0.99 or worst > 4:
            failures.append(f"{name}: heatmap equals the reference's magma at {same:.4f} of "
                            f"pixels, worst channel difference {worst}")
    # errors name the file and what was expected (exit 2)
    a_png = out / "noise_a.png"
    small = out / "small.png"
    Image.fromarray(np.zeros((10, 12, 3), np.uint8)).save(small)
    text = out / "not_a.png"
    text.write_text("not a png\n")
    rgba = out / "rgba.png"
    Image.fromarray(np.zeros((120, 160, 4), np.uint8)).save(rgba)
    for args, needle in [([str(a_png), str(out / "missing.png")], "missing.png"),
                         ([str(a_png), str(small)], "small.png"),
                         ([str(text), str(a_png)], "not_a.png"),
                         ([str(a_png), str(rgba)], "rgba.png"),
                         ([str(a_png), str(a_png), "--ppd", "0"], "--ppd"),
                         ([str(a_png), str(a_png), "--ppd", "5000"], "--ppd")]:
        r = run(binary, "compare", *args)
        if r.returncode != 2 or needle not in r.stderr:
            failures.append(f"compare {' '.join(args)}: exit {r.returncode}, stderr "
                            f"{r.stderr.strip()!r}; expected exit 2 naming {needle}")
    if failures:
        print("FAILED:\n  " + "\n  ".join(failures))
        return 1
    print(f"ok: means within {MEAN_TOLERANCE} of flip-evaluator's")
    return 0


if __name__ == "__main__":
    sys.exit(main())

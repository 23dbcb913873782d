#!/usr/bin/env python3
"""Penumbra's pathtraced tier against Mitsuba 3 (an independent renderer, pinned in
scripts/requirements.txt) on three scenes both express exactly (tests/eval/mitsuba/: a closed
cornell-style room lit by a point lamp, a sphere and a box on a plane under a directional sun and
a uniform sky, a glossy floor reflecting a spherical lamp beside a metallic sphere). Each scene is
rendered by `penumbra run` (1,024 spp, no denoiser, manual exposure, linear tone map, white
balance none; two seeds) and by Mitsuba from scripts/mitsuba_export.py's export of the run
(2,048 spp, two seeds); Penumbra's 8-bit sRGB is decoded back to cd/m^2 and Mitsuba's radiance
goes through the same exposure, 8-bit sRGB rounding and decoding (pixels clipped at 255 in
Penumbra's images are left out). Asserted per scene, with the tolerances below:

  mean      the image's mean radiance agrees per channel within MEAN_TOL (relative);
  regions   the mean luminance of each block of a 4 x 4 grid agrees within REGION_TOL;
  pixels    the mean absolute pixel difference |P - M| is at most NOISE_RATIO_TOL times the
            difference that the two renderers' own noise explains, mean |(PA - PB) + (MA - MB)| / 2
            (the same variance as P - M when neither is biased).

usage: mitsuba_crosscheck_test.py PENUMBRA_BINARY SOURCE_DIR OUT_DIR [--light-scale S]
       [--scenes a,b] (--light-scale scales every exported light: 1.1 must fail)
exit 77 (skipped) with the reason when mitsuba (or its LLVM backend), mujoco, numpy, PIL or
ruamel.yaml cannot be imported."""

import argparse
import math
import shutil
import subprocess
import sys
import time
from pathlib import Path

SKIP = 77
SCENES = ("cornell", "sun_sphere", "glossy_floor")
PENUMBRA_SPP = 1024
MITSUBA_SPP = 2048
# measured (docs/rendering.md, "Cross-check against Mitsuba 3"): mean <= 0.16 %, regions <= 0.4 %,
# noise ratio 0.97-1.07, where Penumbra's own region means have 0.03-0.2 % noise (rms over the
# 16 regions, two seeds). the tolerances fail every scene with its lights 10 % brighter and the
# room and the sun scene with them 3 % brighter (the glossy floor's image is mostly sky light).
MEAN_TOL = 0.01
REGION_TOL = 0.02
NOISE_RATIO_TOL = 1.2

try:
    import numpy as np
    from PIL import Image
except ImportError as e:
    print(f"skipped: numpy and PIL are needed ({e})")
    sys.exit(SKIP)


def decode(png, ev100):
    """cd/m^2 of Penumbra's 8-bit sRGB under manual exposure ev100 and the linear tone map
    (film_math.h: code = sRGB(L / (1.2 2^ev100))), and the clipped-pixel mask."""
    code = np.asarray(Image.open(png)).astype(np.float64)[..., :3]
    c = code / 255.0
    lin = np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055)**2.4)
    return lin * 1.2 * 2.0**ev100, (code >= 255).any(-1)


def develop(L, ev100):
    """Mitsuba's radiance L through Penumbra's film as decode() reads it back: exposed, clamped,
    rounded to 8-bit sRGB and decoded (the same quantisation as Penumbra's pixels)."""
    s = 1.2 * 2.0**ev100
    x = np.clip(L / s, 0.0, 1.0)
    c = np.where(x <= 0.0031308, 12.92 * x, 1.055 * x**(1 / 2.4) - 0.055)
    c = np.rint(c * 255.0) / 255.0
    return np.where(c <= 0.04045, c / 12.92, ((c + 0.055) / 1.055)**2.4) * s


def luminance(img):
    return img @ np.array([0.2126, 0.7152, 0.0722])


def compare(PA, PB, MA, MB, clipped):
    P, M = (PA + PB) / 2, (MA + MB) / 2
    keep = ~clipped
    mean_rel = np.abs(P[keep].mean(0) - M[keep].mean(0)) / M[keep].mean(0)
    h, w = keep.shape
    regions = []
    for by in range(4):
        for bx in range(4):
            sl = (slice(by * h // 4, (by + 1) * h // 4), slice(bx * w // 4, (bx + 1) * w // 4))
            k = keep[sl]
            yp, ym = luminance(P[sl][k]).mean(), luminance(M[sl][k]).mean()
            regions.append(abs(yp - ym) / ym)
    diff = np.abs(P - M)[keep].mean()
    noise = np.abs((PA - PB) + (MA - MB))[keep].mean() / 2
    peak = M[keep].max()
    mse = ((P - M)[keep]**2).mean()
    return dict(mean=float(mean_rel.max()), region=float(max(regions)),
                noise_ratio=float(diff / noise), psnr=float(10 * math.log10(peak * peak / mse)),
                mrd=float(diff / M[keep].mean()), clipped=float(clipped.mean()))


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("binary")
    ap.add_argument("source_dir")
    ap.add_argument("out_dir")
    ap.add_argument("--light-scale", type=float, default=1.0)
    ap.add_argument("--scenes", default=",".join(SCENES))
    a = ap.parse_args()
    src = Path(a.source_dir)
    sys.path.insert(0, str(src / "scripts"))
    try:
        import mitsuba as mi
        import mujoco  # noqa: F401 (the exporter compiles composed.xml with it)
        import ruamel.yaml  # noqa: F401
    except ImportError as e:
        print(f"skipped: {e}; pip install -r scripts/requirements.txt into the venv")
        return SKIP
    import mitsuba_export as mx
    if "llvm_ad_rgb" not in mi.variants():
        print("skipped: this mitsuba has no llvm_ad_rgb variant")
        return SKIP
    # a tiny render in a child process: with too old an LLVM (Debian 12's 15) Dr.Jit's kernels
    # abort the process ("Cannot select: fminimum"); install-deps.sh installs libllvm19
    probe = ("import mitsuba as mi; mi.set_variant('llvm_ad_rgb'); mi.render(mi.load_dict("
             "{'type': 'scene', 'integrator': {'type': 'path'}, 'sensor': {'type': "
             "'perspective', 'film': {'type': 'hdrfilm', 'width': 4, 'height': 4}}, "
             "'s': {'type': 'sphere', 'center': [0, 0, 3]}, "
             "'l': {'type': 'point', 'position': [0, 1, 0]}}), spp=4)")
    r = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True, timeout=120)
    if r.returncode != 0:
        print("skipped: Mitsuba's LLVM backend does not run here (an LLVM >= 16 shared library, "
              "Debian: libllvm19): " + (r.stderr.strip().splitlines() or [""])[0][:200])
        return SKIP
    mx.set_variant("llvm_ad_rgb")

    out = Path(a.out_dir)
    shutil.rmtree(out, ignore_errors=True)
    out.mkdir(parents=True)
    failures = []
    print(f"{'scene':14s} {'mean':>7s} {'region':>7s} {'noise x':>8s} {'MRD':>7s} {'PSNR':>7s} "
          f"{'clipped':>8s} {'time':>6s}")
    for name in a.scenes.split(","):
        t0 = time.monotonic()
        world = src / "tests" / "eval" / "mitsuba" / f"{name}.yaml"
        ev100 = float(mx.load_world(world)["render"]["exposure"]["ev100"])
        imgs, runs = [], []
        for seed in (1, 2):
            run_dir = out / f"{name}_seed{seed}"
            r = subprocess.run([a.binary, "run", str(world), "--out", str(run_dir), "--force",
                                "--quiet", "--seed", str(seed), "--spp", str(PENUMBRA_SPP),
                                "--threads", "0"], capture_output=True, text=True, timeout=200)
            if r.returncode != 0:
                print(r.stdout + r.stderr)
                failures.append(f"{name}: penumbra run exited {r.returncode}")
                break
            imgs.append(decode(run_dir / "cam" / "rgb" / "000000.png", ev100))
            runs.append(run_dir)
        if len(imgs) < 2:
            continue
        scene = mx.build_scene(runs[0], world, "cam", 0, MITSUBA_SPP, 0,
                               light_scale=a.light_scale)
        MA = mx.render(scene, MITSUBA_SPP, seed=0)
        MB = mx.render(scene, MITSUBA_SPP, seed=1)
        np.save(out / f"{name}_mitsuba.npy", (MA + MB) / 2)
        MA, MB = develop(MA, ev100), develop(MB, ev100)
        (PA, ca), (PB, cb) = imgs
        m = compare(PA, PB, MA, MB, ca | cb)
        print(f"{name:14s} {m['mean'] * 100:6.2f}% {m['region'] * 100:6.2f}% "
              f"{m['noise_ratio']:8.3f} {m['mrd'] * 100:6.2f}% {m['psnr']:6.2f}dB "
              f"{m['clipped'] * 100:7.2f}% {time.monotonic() - t0:5.1f}s", flush=True)
        if not m["mean"] <= MEAN_TOL:
            failures.append(f"{name}: mean radiance differs by {m['mean']:.4f} > {MEAN_TOL}")
        if not m["region"] <= REGION_TOL:
            failures.append(f"{name}: a region's mean differs by {m['region']:.4f} > "
                            f"{REGION_TOL}")
        if not m["noise_ratio"] <= NOISE_RATIO_TOL:
            failures.append(f"{name}: pixel differences are {m['noise_ratio']:.3f} x what the "
                            f"noise explains > {NOISE_RATIO_TOL}")
    for f in failures:
        print("FAIL", f)
    print("ok" if not failures else f"{len(failures)} failure(s)")
    return 1 if failures else 0


if __name__ == "__main__":
    sys.exit(main())

"""scripts/image-compare.sh on two fake `penumbra` binaries (no renders): each writes one camera's
rgb (8-bit), depth and segmentation (16-bit) PNGs as `penumbra run` lays them out; the new one
changes one rgb channel of one pixel by 3 codes, one depth pixel by 7 mm and two segmentation
ids. checks the table (identical rows, the PSNR, largest difference and differing pixels of the
changed ones), a failing run reported as a row, a run without an rgb image refused, and the
argument checks.

usage: image_compare_test.py REPO_ROOT
exit status 77 (skipped) when neither python3 nor the repository's .venv has numpy and Pillow.
"""

import math
import os
import stat
import struct
import subprocess
import sys
import tempfile
import zlib

# the fake binary: `FAKE run WORLD --out DIR ...`; behaviour from the world file's first word
# (same, change, fail, nocamera-rgb) and from its own VARIANT (old or new)
FAKE = r'''#!/usr/bin/env python3
import json, os, struct, sys, zlib
VARIANT = "@VARIANT@"

def png(path, w, h, bit_depth, colour, rows):
    raw = b"".join(b"\x00" + r for r in rows)
    def chunk(t, d):
        return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d) & 0xffffffff)
    os.makedirs(os.path.dirname(path), exist_ok=True)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", w, h, bit_depth, colour, 0, 0, 0))
                + chunk(b"IDAT", zlib.compress(raw)) + chunk(b"IEND", b""))

args = sys.argv[1:]
assert args[0] == "run", args
world, out = args[1], args[args.index("--out") + 1]
mode = open(world).read().split()[0]
if mode == "fail" and VARIANT == "new":
    print("error: this world fails", file=sys.stderr)
    sys.exit(1)
change = mode == "change" and VARIANT == "new"
os.makedirs(out, exist_ok=True)
with open(os.path.join(out, "camera_info.json"), "w") as f:
    json.dump({"eye": {"width": 4, "height": 2}}, f)
W, H = 4, 2
rgb = [[(10 * x, 20 * y, 30) for x in range(W)] for y in range(H)]
depth = [[1000 + 10 * x + 100 * y for x in range(W)] for y in range(H)]
seg = [[x % 3 for x in range(W)] for y in range(H)]
if change:
    r, g, b = rgb[1][2]
    rgb[1][2] = (r, g + 3, b)
    depth[0][1] += 7
    seg[0][0] = 9
    seg[1][3] = 9
if mode != "nocamera-rgb":
    png(os.path.join(out, "eye", "rgb", "000000.png"), W, H, 8, 2,
        [bytes(c for p in row for c in p) for row in rgb])
png(os.path.join(out, "eye", "depth", "000000.png"), W, H, 16, 0,
    [b"".join(struct.pack(">H", v) for v in row) for row in depth])
png(os.path.join(out, "eye", "segmentation", "000000.png"), W, H, 16, 0,
    [b"".join(struct.pack(">H", v) for v in row) for row in seg])
'''

HEADER = ["world", "camera", "kind", "identical", "PSNR dB", "max diff", "differing pixels",
          "frames"]


def table(stdout):
    lines = [l for l in stdout.splitlines() if l.startswith("|")]
    assert len(lines) >= 2, stdout
    assert [c.strip() for c in lines[0].strip("|").split("|")] == HEADER, lines[0]
    return [[c.strip() for c in l.strip("|").split("|")] for l in lines[2:]]


def main():
    repo = sys.argv[1]
    if not any(subprocess.run([p, "-c", "import numpy, PIL"], capture_output=True,
                              check=False).returncode == 0
               for p in ("python3", os.path.join(repo, ".venv", "bin", "python3"))
               if p == "python3" or os.path.exists(p)):
        print("no python3 with numpy and Pillow: skipped")
        sys.exit(77)
    script = os.path.join(repo, "scripts", "image-compare.sh")
    with tempfile.TemporaryDirectory() as tmp:
        bins = {}
        for variant in ("old", "new"):
            path = os.path.join(tmp, f"fake-{variant}")
            with open(path, "w") as f:
                f.write(FAKE.replace("@VARIANT@", variant))
            os.chmod(path, os.stat(path).st_mode | stat.S_IXUSR)
            bins[variant] = path
        worlds = {}
        for mode in ("same", "change", "fail", "nocamera-rgb"):
            worlds[mode] = os.path.join(tmp, f"{mode}.yaml")
            with open(worlds[mode], "w") as f:
                f.write(mode + "\n")

        def run(*args):
            return subprocess.run(["bash", script, *args], capture_output=True, text=True,
                                  timeout=120, check=False)

        r = run(bins["old"], bins["new"], "--out", os.path.join(tmp, "out"), "--worlds",
                worlds["same"], worlds["change"], worlds["fail"])
        assert r.returncode == 0, f"exit {r.returncode}\n{r.stdout}\n{r.stderr}"
        rows = table(r.stdout)
        by_key = {(row[0], row[2]): row for row in rows}
        assert len(rows) == 7, rows  # 3 kinds of 2 worlds, one failed world
        for kind in ("rgb", "depth", "segmentation"):
            assert by_key[("same", kind)][3:] == ["yes", "-", "-", "-", "1"], by_key[("same", kind)]
        psnr = 10 * math.log10(255 * 255 / (9 / (4 * 2 * 3)))
        rgb = by_key[("change", "rgb")]
        assert rgb[3] == "no" and rgb[5:] == ["3", "1", "1"], rgb
        assert abs(float(rgb[4]) - psnr) < 0.01, (rgb, psnr)
        assert by_key[("change", "depth")][3:] == ["no", "-", "7 mm", "1", "1"], by_key[("change", "depth")]
        assert by_key[("change", "segmentation")][3:] == ["no", "-", "-", "2", "1"], by_key[("change", "segmentation")]
        assert by_key[("fail", "-")][3] == "run failed (new)", by_key[("fail", "-")]
        assert "this world fails" in r.stderr, r.stderr
        # a camera without an rgb image: an error, no table
        r = run(bins["old"], bins["new"], "--out", os.path.join(tmp, "out2"), "--worlds",
                worlds["nocamera-rgb"])
        assert r.returncode == 1 and "eye" in r.stderr and "| world |" not in r.stdout, r
        # bad arguments: exit 2 naming the argument, nothing run
        for args, word in (([bins["old"]], "usage"),
                           ([bins["old"], os.path.join(tmp, "none")], "not an executable"),
                           ([bins["old"], bins["new"], "--tier", "fast"], "--tier"),
                           ([bins["old"], bins["new"], "--tier", "pathtraced", "--spp", "0"], "--spp"),
                           ([bins["old"], bins["new"], "--spp", "4"], "--spp"),
                           ([bins["old"], bins["new"], "--worlds"], "--worlds"),
                           ([bins["old"], bins["new"], "--worlds", "no_such_world"], "no_such_world"),
                           ([bins["old"], bins["new"], "--out"], "--out"),
                           ([bins["old"], bins["new"], "--frames", "3"], "unknown argument")):
            bad = run(*args)
            assert bad.returncode == 2 and word in bad.stderr, (args, bad.returncode, bad.stderr)
            assert "| world |" not in bad.stdout, bad.stdout
    print("image-compare table and argument checks: ok")


if __name__ == "__main__":
    main()

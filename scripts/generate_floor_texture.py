#!/usr/bin/env python3
"""Generates worlds/models/textures/wood_floor.png, the plank floor of the default world.

Pure Python (zlib + struct), deterministic: the same script always writes the same bytes.
Run from the repository root:  python3 scripts/generate_floor_texture.py

The texture is 512 x 512 sRGB and tiles seamlessly. It shows 8 planks side by side along
u (columns), each 64 px wide, with grain running along v (rows), staggered end joints, a
per-plank tone and dark seams. With texuniform and texrepeat 1.6 in room.xml (MuJoCo repeats a
texuniform texture texrepeat / 2 times per metre) one tile covers 1.25 m, so a plank is about
0.16 m wide.
"""

import math
import os
import random
import struct
import zlib

SIZE = 512
PLANK_PX = 64
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "worlds", "models",
                   "textures", "wood_floor.png")


def png_bytes(width, height, rows):
    """8-bit RGB PNG from a list of rows of bytes, every row with the "up" filter (type 2):
    the grain runs along the columns, so a row predicts the next one well."""
    filtered = []
    prev = bytes(len(rows[0]))
    for r in rows:
        filtered.append(b"\x02" + bytes((a - b) & 0xFF for a, b in zip(r, prev)))
        prev = r
    raw = b"".join(filtered)

    def chunk(tag, data):
        body = tag + data
        return struct.pack(">I", len(data)) + body + struct.pack(">I", zlib.crc32(body))

    ihdr = struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", ihdr) + chunk(b"sRGB", b"\x00") +
            chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def main():
    rng = random.Random(20240607)
    planks = SIZE // PLANK_PX
    # per plank: tone (oak, honey to light brown), one end joint position, grain phases
    tones = []
    for _ in range(planks):
        k = rng.uniform(-1.0, 1.0)
        tones.append((168 + 22 * k, 118 + 18 * k, 72 + 12 * k))
    joints = [rng.randrange(SIZE) for _ in range(planks)]
    phases = [(rng.uniform(0, 2 * math.pi), rng.uniform(0, 2 * math.pi)) for _ in range(2 * planks)]

    rows = []
    for v in range(SIZE):
        row = bytearray()
        for u in range(SIZE):
            p = u // PLANK_PX
            x = u % PLANK_PX
            # two board pieces per plank column, split at the staggered joint
            piece = 2 * p + (1 if (v - joints[p]) % SIZE < SIZE // 2 else 0)
            ph1, ph2 = phases[piece]
            # grain: fine lines across the plank width that wander slowly along its length
            wander = 3.0 * math.sin(2 * math.pi * v / SIZE * 2 + ph1)
            g = math.sin((x + wander) * 0.9 + ph2) * 0.5 + 0.5
            g2 = math.sin((x * 0.23 + v * 0.011) * 2 * math.pi / 3 + ph1) * 0.5 + 0.5
            shade = 0.86 + 0.10 * g ** 3 + 0.06 * g2 + 0.03 * (((piece * 7) % 5) / 4.0 - 0.5)
            r, gg, b = (t * shade for t in tones[p])
            # dark seams: between planks (columns) and at the end joints (rows)
            at_joint = min((v - joints[p]) % (SIZE // 2), (joints[p] - v) % (SIZE // 2)) < 1
            if x == 0 or x == PLANK_PX - 1 or at_joint:
                r, gg, b = r * 0.45, gg * 0.45, b * 0.45
            row += bytes((max(0, min(255, int(r))), max(0, min(255, int(gg))),
                          max(0, min(255, int(b)))))
        rows.append(row)
    os.makedirs(os.path.dirname(OUT), exist_ok=True)
    data = png_bytes(SIZE, SIZE, rows)
    with open(OUT, "wb") as f:
        f.write(data)
    print(f"wrote {os.path.normpath(OUT)} ({len(data)} bytes)")


if __name__ == "__main__":
    main()

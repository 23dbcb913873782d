#!/usr/bin/python3
"""the contact sheet of docs/npc_walkers.png from a run of worlds/effects/walkers.yaml.

  ./build/penumbra run worlds/effects/walkers.yaml --out /tmp/walkers_run --duration 1.25
  /usr/bin/python3 scripts/walkers_contact_sheet.py /tmp/walkers_run docs/npc_walkers.png

top row: the `side` camera's rgb at t = 0.4, 0.8 and 1.2 s; bottom row at 1.2 s: depth
(colour-mapped 1-8 m), instance segmentation (one random colour per body: every limb is a body
of its own) and semantic segmentation (class 24 person red, 27 vehicle blue). needs Debian's
python3-numpy and python3-pil.
"""
import sys
import numpy as np
from PIL import Image, ImageDraw
run = sys.argv[1]
out = sys.argv[2]
W, H = 640, 480
S = 0.5  # tiles at half size
tw, th = int(W * S), int(H * S)
pad, lab = 6, 20
def tile(img, label):
    img = img.convert('RGB').resize((tw, th), Image.LANCZOS)
    t = Image.new('RGB', (tw, th + lab), (255, 255, 255))
    t.paste(img, (0, lab))
    ImageDraw.Draw(t).text((4, 4), label, fill=(0, 0, 0))
    return t
frames = {0: '0.0', 2: '0.4', 4: '0.8', 6: '1.2'}
row1 = [tile(Image.open(f'{run}/side/rgb/{f:06d}.png'), f'rgb, t = {frames[f]} s') for f in (2, 4, 6)]
d = np.array(Image.open(f'{run}/side/depth/000006.png')).astype(float) / 1000.0
valid = d > 0
v = np.clip((d - 1.0) / 7.0, 0, 1)
rgb = np.zeros(d.shape + (3,), np.uint8)
rgb[..., 0] = (255 * (1 - v)).astype(np.uint8)
rgb[..., 1] = (255 * (1 - np.abs(v - 0.5) * 2)).astype(np.uint8)
rgb[..., 2] = (255 * v).astype(np.uint8)
rgb[~valid] = 0
depth = Image.fromarray(rgb)
inst = np.array(Image.open(f'{run}/side/instance_segmentation/000006.png'))
rng = np.random.default_rng(3)
pal = rng.integers(40, 255, size=(int(inst.max()) + 1, 3)).astype(np.uint8)
pal[0] = 0
instance = Image.fromarray(pal[inst])
sem = np.array(Image.open(f'{run}/side/semantic_segmentation/000006.png'))
s = np.full(sem.shape + (3,), 60, np.uint8)
s[sem == 24] = (220, 40, 60)
s[sem == 27] = (60, 90, 220)
semantic = Image.fromarray(s)
row2 = [tile(depth, 'depth (1-8 m), t = 1.2 s'), tile(instance, 'instance (one colour per body)'),
        tile(semantic, 'semantic: person red, vehicle blue')]
sheet = Image.new('RGB', (3 * tw + 2 * pad, 2 * (th + lab) + pad), (255, 255, 255))
for i, t in enumerate(row1):
    sheet.paste(t, (i * (tw + pad), 0))
for i, t in enumerate(row2):
    sheet.paste(t, (i * (tw + pad), th + lab + pad))
sheet.save(out, optimize=True)
print(out, sheet.size)

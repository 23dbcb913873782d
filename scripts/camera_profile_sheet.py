#!/usr/bin/python3
"""docs/camera_profiles.png: the first frame of each camera profile (columns: ideal,
realsense_d435_rgb, blackfly_s_imx250) in the daylight room (worlds/default.yaml, top) and the
night room lit by flashlights (worlds/effects/flashlight.yaml, bottom).

  /usr/bin/python3 scripts/camera_profile_sheet.py ./build/penumbra docs/camera_profiles.png

for each world and profile it writes a copy of the world file next to the original (so its
relative paths hold) with the first camera's `profile:` replaced and its size set to 320 x 240,
runs `penumbra run --duration 0.05 --outputs rgb` on it into a temporary folder, and removes the
copy. needs python3-pil.
"""
import os
import re
import subprocess
import sys
import tempfile

from PIL import Image, ImageDraw

penumbra, out = sys.argv[1], sys.argv[2]
root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
worlds = [('daylight room', 'worlds/default.yaml'), ('night, flashlights', 'worlds/effects/flashlight.yaml')]
profiles = ['ideal', 'realsense_d435_rgb', 'blackfly_s_imx250']
tw, th, lab = 240, 180, 16


def first_frame(world, profile, tmp):
    src = os.path.join(root, world)
    text = open(src).read()
    # the first camera: its profile and a 320 x 240 image with the same field of view
    text = re.sub(r'profile: \w+', 'profile: ' + profile, text, count=1)
    text = re.sub(r'width: 640', 'width: 320', text, count=1)
    text = re.sub(r'height: 480', 'height: 240', text, count=1)
    copy = os.path.join(os.path.dirname(src), '.camera_profile_sheet.yaml')
    with open(copy, 'w') as f:
        f.write(text)
    run = os.path.join(tmp, os.path.basename(world) + '_' + profile)
    try:
        subprocess.run([penumbra, 'run', copy, '--duration', '0.05', '--outputs', 'rgb', '-q',
                        '--out', run], check=True)
    finally:
        os.remove(copy)
    cams = sorted(d for d in os.listdir(run) if os.path.isdir(os.path.join(run, d, 'rgb')))
    cam = 'front' if 'front' in cams else cams[0]
    return Image.open(os.path.join(run, cam, 'rgb', '000000.png')).convert('RGB')


with tempfile.TemporaryDirectory() as tmp:
    sheet = Image.new('RGB', (len(profiles) * tw, len(worlds) * (th + lab)), (255, 255, 255))
    draw = ImageDraw.Draw(sheet)
    for r, (name, world) in enumerate(worlds):
        for c, profile in enumerate(profiles):
            img = first_frame(world, profile, tmp).resize((tw, th), Image.LANCZOS)
            y = r * (th + lab)
            sheet.paste(img, (c * tw, y + lab))
            draw.text((c * tw + 4, y + 2), f'{profile}, {name}', fill=(0, 0, 0))
    sheet.save(out, optimize=True)

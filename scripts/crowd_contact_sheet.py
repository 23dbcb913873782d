#!/usr/bin/python3
"""the crowd contact sheet of docs/npc_crowd.png (docs/npcs.md): a preset crowd (people and,
in the warehouse, a forklift; nothing else of adversity) in the bundled house and warehouse,
seen by a fixed camera high in a corner, at three instants, with each world's walkable map.

  /usr/bin/python3 scripts/crowd_contact_sheet.py ./build/penumbra docs/npc_crowd.png [WORK_DIR]

runs (the arguments as a list, no shell):
  penumbra run worlds/house.yaml --adversity WORK/crowd.yaml#crowd --override WORK/house_cam.yaml
      --duration 6.1 --out WORK/house
  penumbra run worlds/warehouse.yaml ... (its own camera) --out WORK/warehouse
and tiles each run's camera `overview` at t = 2, 4 and 6 s (rgb) beside its npc_map.png. needs
Debian's python3-pil.
"""
import os
import subprocess
import sys
import tempfile

from PIL import Image, ImageDraw

PRESET = """presets:
  crowd:
    description: the crowd of a preset alone (people and vehicles; no fog, smoke, rain or dimming)
    npcs: {people: 8, vehicles: 1, speed_m_s: 1.3, pause_sec: 0.5}
"""

# cameras in the world frame: x forward, pitch > 0 looks down (worlds/effects/walkers.yaml)
CAMERAS = {
    # the living room's north-west corner under the 2.7 m ceiling, looking east-south-east
    # across the living room and the wide opening into the kitchen
    "house": "{name: overview, pose: {xyz: [-5.7, 4.2, 2.45], rpy_deg: [0, 30, -22]}, "
             "width: 480, height: 300, fovy_deg: 72, rate_hz: 0.5, "
             "outputs: [rgb]}",
    # above the west end of the main aisle, looking east along it
    "warehouse": "{name: overview, pose: {xyz: [-14.7, 1.4, 4.0], rpy_deg: [0, 18, 0]}, "
                 "width: 480, height: 300, fovy_deg: 65, rate_hz: 0.5, "
                 "outputs: [rgb]}",
}
TIMES = [2.0, 4.0, 6.0]


def tile(img, label, w, h, lab=20):
    img = img.convert("RGB")
    img.thumbnail((w, h), Image.LANCZOS)
    t = Image.new("RGB", (w, h + lab), (255, 255, 255))
    t.paste(img, ((w - img.width) // 2, lab + (h - img.height) // 2))
    ImageDraw.Draw(t).text((4, 4), label, fill=(0, 0, 0))
    return t


def main():
    binary, out = sys.argv[1], sys.argv[2]
    work = sys.argv[3] if len(sys.argv) > 3 else tempfile.mkdtemp(prefix="crowd_sheet_")
    os.makedirs(work, exist_ok=True)
    source = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
    preset = os.path.join(work, "crowd.yaml")
    with open(preset, "w") as f:
        f.write(PRESET)
    rows = []
    for world, camera in CAMERAS.items():
        override = os.path.join(work, world + "_cam.yaml")
        with open(override, "w") as f:
            f.write("cameras:\n  - " + camera + "\n")
        run = os.path.join(work, world)
        if not os.path.isdir(os.path.join(run, "overview")):
            subprocess.run([binary, "run", os.path.join(source, "worlds", world + ".yaml"),
                            "--adversity", preset + "#crowd", "--override", override,
                            "--duration", "6.1", "--out", run, "--force"], check=True)
        w, h = 400, 250
        row = [tile(Image.open(os.path.join(run, "npc_map.png")), f"{world}: walkable map", w, h)]
        for t in TIMES:
            frame = int(round(t * 0.5))
            row.append(tile(Image.open(os.path.join(run, "overview", "rgb", f"{frame:06d}.png")),
                            f"{world}, t = {t:.0f} s", w, h))
        rows.append(row)
    pad = 6
    tw, th = rows[0][0].width, rows[0][0].height
    sheet = Image.new("RGB", (len(rows[0]) * (tw + pad) + pad, len(rows) * (th + pad) + pad),
                      (255, 255, 255))
    for r, row in enumerate(rows):
        for c, t in enumerate(row):
            sheet.paste(t, (pad + c * (tw + pad), pad + r * (th + pad)))
    sheet.save(out)
    print(f"{out}: {sheet.width} x {sheet.height} px from {work}")


if __name__ == "__main__":
    main()

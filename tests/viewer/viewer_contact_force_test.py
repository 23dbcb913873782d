#!/usr/bin/env python3
"""the viewer's contact-force signals against an independent computation (a plot
peak of 1.96e5 N in the default world is the `major` preset's forklift, a kinematic NPC,
pinning the robot, not a unit or sum error: docs/viewer.md "Plots").

A world with a 2.5 kg crate as its robot and, in a static model, a 4 kg loose box and the
floor, both resting on the floor (no camera): served by `penumbra view --running`, read by a raw
WebSocket client (python3-websocket). After 1 s of sim time both rest, so
  contacts/normal_force_N       = (2.5 + 4) kg * 9.81 m/s^2 = 63.765 N  (every contact)
  contacts/crate/normal_force_N =  2.5 kg * 9.81 m/s^2      = 24.525 N  (the robot's only)
within 2 % (masses from the MJCF written here, g from MuJoCo's default gravity).

usage: viewer_contact_force_test.py --binary build/penumbra
"""

import argparse
import json
import os
import re
import shutil
import signal
import subprocess
import sys
import tempfile
import threading
import time

import websocket

G = 9.81
CRATE_KG, BOX_KG = 2.5, 4.0

CRATE_XML = f"""<mujoco model="crate">
  <worldbody>
    <body name="crate" pos="0 0 0.1">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.1" mass="{CRATE_KG}" rgba="0.8 0.5 0.2 1"/>
    </body>
  </worldbody>
</mujoco>
"""

STAGE_XML = f"""<mujoco model="stage">
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1" rgba="0.5 0.5 0.5 1"/>
    <body name="box" pos="1 0 0.15">
      <freejoint/>
      <geom type="box" size="0.15 0.15 0.15" mass="{BOX_KG}" rgba="0.2 0.4 0.8 1"/>
    </body>
  </worldbody>
</mujoco>
"""

WORLD_YAML = """seed: 1
duration_sec: 30
mjcf_cameras: {enabled: false}
robots:
  - {name: crate, file: crate.xml}
models:
  - {name: stage, file: stage.xml}
lights:
  - {name: sun, type: sun, direction: [0.3, 0.4, -1], illuminance_lux: 20000}
"""


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="penumbra_viewer_force_")
    for name, text in [("crate.xml", CRATE_XML), ("stage.xml", STAGE_XML),
                       ("world.yaml", WORLD_YAML)]:
        with open(os.path.join(tmp, name), "w") as f:
            f.write(text)
    proc = subprocess.Popen([args.binary, "view", os.path.join(tmp, "world.yaml"), "--viewer",
                             "127.0.0.1:0", "--out", os.path.join(tmp, "out"), "--running"],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines, found = [], {}

    def read():
        for line in proc.stdout:
            lines.append(line.rstrip())
            m = re.search(r"viewer: open (http://\S+/\?token=[0-9a-f]{64}) ", line)
            if m:
                found["url"] = m.group(1)

    threading.Thread(target=read, daemon=True).start()
    ok = False
    try:
        end = time.monotonic() + 60
        while "url" not in found:
            if proc.poll() is not None or time.monotonic() > end:
                sys.exit("penumbra view did not start:\n" + "\n".join(lines))
            time.sleep(0.05)
        base, token = found["url"].split("/?token=")
        c = websocket.create_connection(base.replace("http://", "ws://") + "/ws?token=" + token,
                                        timeout=10)
        signals = None
        end = time.monotonic() + 120
        while time.monotonic() < end:
            op, data = c.recv_data()
            if op != websocket.ABNF.OPCODE_TEXT:
                continue
            m = json.loads(data)
            if m.get("type") == "state" and m["time_sec"] >= 1.0:
                signals = m["signals"]
                t = m["time_sec"]
                break
        c.close()
        assert signals, "no state after 1 s of sim time"
        total, crate = signals["contacts/normal_force_N"], signals.get("contacts/crate/normal_force_N")
        want_total, want_crate = (CRATE_KG + BOX_KG) * G, CRATE_KG * G
        print(f"t = {t:.3f} s: contacts/normal_force_N {total:.4f} N (m g = {want_total:.4f}), "
              f"contacts/crate/normal_force_N {crate} N (m g = {want_crate:.4f}), "
              f"{signals['contacts/count']} contacts")
        assert abs(total - want_total) <= 0.02 * want_total, "the sum of all contacts is not m g"
        assert crate is not None, "no contacts/crate/normal_force_N signal"
        assert abs(crate - want_crate) <= 0.02 * want_crate, "the robot's contacts are not its m g"
        ok = True
    finally:
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(timeout=30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        if not ok:
            print("\n".join(lines[-30:]))
        shutil.rmtree(tmp, ignore_errors=True)
    print("all checks passed")


if __name__ == "__main__":
    main()

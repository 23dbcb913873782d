#!/usr/bin/env python3
"""the crowd's walkable map in the live viewer's scene view,
end to end with the real binary, a raw WebSocket client (python3-websocket) and a headless
Chromium (Debian's chromium, chromium-driver, python3-selenium):

  penumbra npc-map worlds/house.yaml --adversity major --out map.png     (the reference)
  penumbra view worlds/house.yaml --adversity major --viewer 127.0.0.1:0  (paused at the start)

checks: the scene message carries `npc_map` (docs/npcs.md "The walkable map in the viewer")
with the grid npc-map printed (cells, m^2 walkable by people and by vehicles, crowd agents),
the robot's start and every agent on a walkable cell, the run folder's npc_map.json is the
same map; the page draws it on the floor of its scene view (the overview's pixels change when
the "walkable map" box is unticked and come back when it is ticked again, and the page counts
as many map texels as the message has walkable cells). the page's screenshot is kept
(--artefacts: viewer_npc_map.png).

usage: viewer_npc_map_test.py --binary build/penumbra --source . [--artefacts DIR]
"""

import argparse
import base64
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import threading
import time

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from viewer_browser_test import View, check, log, recv_json, wait_for, ws_client  # noqa: E402

# the overview canvas as PNG bytes (base64), read back from its WebGL drawing buffer
OVERVIEW_PNG = """
return window.penumbraViewer.three.renderer.domElement.toDataURL('image/png').split(',')[1];
"""

# mean absolute difference (0..255) between two PNGs (base64) of the same size
DIFF_PNGS = """
const [a64, b64, done] = arguments;
const load = (b) => new Promise((ok, bad) => {
  const i = new Image(); i.onload = () => ok(i); i.onerror = bad; i.src = 'data:image/png;base64,' + b;
});
Promise.all([load(a64), load(b64)]).then(([a, b]) => {
  const px = (img) => {
    const c = document.createElement('canvas'); c.width = img.width; c.height = img.height;
    const x = c.getContext('2d'); x.drawImage(img, 0, 0);
    return x.getImageData(0, 0, c.width, c.height).data;
  };
  const p = px(a), q = px(b);
  if (p.length !== q.length) return done({error: 'sizes differ'});
  let s = 0;
  for (let i = 0; i < p.length; i += 4) s += Math.abs(p[i] - q[i]) + Math.abs(p[i+1] - q[i+1]) + Math.abs(p[i+2] - q[i+2]);
  done({mad: s / (3 * p.length / 4)});
}).catch(() => done({error: 'png did not load'}));
"""


class HouseView(View):
    """`penumbra view` of a world under the `major` preset (its crowd), paused at the start."""

    def __init__(self, binary, world, out):
        self.proc = subprocess.Popen(
            [binary, "view", world, "--adversity", "major", "--viewer", "127.0.0.1:0",
             "--out", out, "--duration", "120"],
            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
        self.lines = []
        self.url = None
        threading.Thread(target=self._read, daemon=True).start()


def cell_of(m, x, y):
    ix = int((x - m["min"][0]) // m["cell_m"])
    iy = int((y - m["min"][1]) // m["cell_m"])
    if not (0 <= ix < m["nx"] and 0 <= iy < m["ny"]):
        return None
    return m["cells"][iy * m["nx"] + ix]


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("--artefacts", default=None)
    args = ap.parse_args()
    tmp = tempfile.mkdtemp(prefix="penumbra_viewer_npc_map_")
    artefacts = args.artefacts or os.path.join(tmp, "artefacts")
    os.makedirs(artefacts, exist_ok=True)
    world = os.path.join(args.source, "worlds", "house.yaml")

    # the reference: npc-map's own numbers
    r = subprocess.run([args.binary, "npc-map", world, "--adversity", "major", "--out",
                        os.path.join(tmp, "map.png")], capture_output=True, text=True, timeout=300)
    check(r.returncode == 0, f"penumbra npc-map runs ({r.stderr[-400:]})")
    text = r.stdout + r.stderr
    g = re.search(r"(\d+) x (\d+) cells of ([0-9.]+) m, walkable by people ([0-9.]+) m\^2, by "
                  r"vehicles ([0-9.]+) m\^2; (\d+) areas, (\d+) lanes, (\d+) crowd agents", text)
    check(g is not None, f"npc-map prints the map's sizes ({text.strip()[-300:]})")
    nx, ny, cell = int(g.group(1)), int(g.group(2)), float(g.group(3))
    person_m2, vehicle_m2 = float(g.group(4)), float(g.group(5))
    areas, lanes, agents = int(g.group(6)), int(g.group(7)), int(g.group(8))

    out = os.path.join(tmp, "out")
    view = HouseView(args.binary, world, out)
    driver = None
    ok = False
    try:
        wait_for("the viewer's URL", lambda: view.url or (view.proc.poll() is not None and
                                                      sys.exit("penumbra view exited:\n" +
                                                               "\n".join(view.lines))), 120)
        url = view.url
        log(f"viewer at {url}")
        c = ws_client(url)
        scene = recv_json(c, "scene", timeout=30)
        c.close()
        m = scene.get("npc_map")
        check(m is not None, "the scene message carries the walkable map (npc_map)")
        check((m["nx"], m["ny"]) == (nx, ny) and abs(m["cell_m"] - cell) < 1e-9,
              f"its grid is npc-map's: {m['nx']} x {m['ny']} cells of {m['cell_m']} m")
        check(len(m["cells"]) == nx * ny and set(m["cells"]) <= set("0123"),
              "one character 0-3 per cell")
        a = m["cell_m"] ** 2
        # npc-map prints the areas to 0.1 m^2
        check(abs(m["person_cells"] * a - person_m2) <= 0.05 + 1e-9 and
              abs(m["vehicle_cells"] * a - vehicle_m2) <= 0.05 + 1e-9,
              f"walkable by people {m['person_cells'] * a:.1f} m^2, by vehicles "
              f"{m['vehicle_cells'] * a:.1f} m^2, as npc-map printed")
        check(m["cells"].count("3") == m["vehicle_cells"] and
              m["cells"].count("2") <= m["person_cells"] <= m["cells"].count("2") +
              m["cells"].count("3"), "the cells' classes count the regions' cells")
        check(len(m["areas"]) == areas and len(m["lanes"]) == lanes and
              len(m["agents"]) == agents, f"{areas} areas, {lanes} lanes, {agents} agents")
        for p in m["robots"] + m["agents"]:
            check(cell_of(m, *p) in ("2", "3"), f"({p[0]:.2f}, {p[1]:.2f}) stands on a walkable cell")
        with open(os.path.join(out, "npc_map.json")) as f:
            saved = json.load(f)
        check(saved == m, "the run folder's npc_map.json is the same map")

        from selenium import webdriver
        from selenium.webdriver.chrome.service import Service
        o = webdriver.ChromeOptions()
        o.binary_location = "/usr/bin/chromium"
        for arg in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
                    "--window-size=1600,1000", "--use-angle=swiftshader",
                    "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"]:
            o.add_argument(arg)
        o.set_capability("goog:loggingPrefs", {"browser": "ALL"})
        driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=o)
        driver.set_script_timeout(60)
        js = driver.execute_script
        driver.get(url)
        drawn = wait_for("the page's walkable map", lambda: js(
            "return window.penumbraViewer.npcMap;"), timeout=60)
        walkable = m["cells"].count("2") + m["cells"].count("3")
        check(drawn["cells"] == walkable and drawn["lanes"] == lanes,
              f"the page drew {drawn['cells']} walkable texels and {drawn['lanes']} lanes")
        # the camera is placed on the robot with the first state or, paused, from the scene
        # message's poses: let a few frames render, then compare with the map hidden
        time.sleep(2)
        shown = js(OVERVIEW_PNG)
        js("document.getElementById('showNpcMap').click();")
        time.sleep(1)
        hidden = js(OVERVIEW_PNG)
        js("document.getElementById('showNpcMap').click();")
        time.sleep(1)
        again = js(OVERVIEW_PNG)
        with open(os.path.join(artefacts, "viewer_npc_map_overview.png"), "wb") as f:
            f.write(base64.b64decode(shown))
        with open(os.path.join(artefacts, "viewer_npc_map_overview_hidden.png"), "wb") as f:
            f.write(base64.b64decode(hidden))
        driver.save_screenshot(os.path.join(artefacts, "viewer_npc_map.png"))
        d_off = driver.execute_async_script(DIFF_PNGS, shown, hidden)
        d_on = driver.execute_async_script(DIFF_PNGS, shown, again)
        check("mad" in d_off and d_off["mad"] > 1.0,
              f"hiding the map changes the scene view (mean difference {d_off})")
        check("mad" in d_on and d_on["mad"] < 0.25 * d_off["mad"],
              f"showing it again restores it (mean difference {d_on})")
        errors = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
        check(not errors, f"no errors in the page's console ({errors[:3]})")
        ok = True
    finally:
        if driver:
            driver.quit()
        rc = view.stop()
        if not ok:
            print("\n".join(view.lines[-40:]))
        shutil.rmtree(tmp, ignore_errors=True)
    check(rc == 0, f"penumbra view ends cleanly on SIGINT (exit {rc})")
    log("all checks passed")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""docs/viewer.png from the current build: `penumbra view WORLD` in a real headless Chromium
(Debian's chromium, chromium-driver, python3-selenium), played for some sim seconds, paused,
then the whole page saved as a PNG.

    /usr/bin/python3 scripts/viewer_screenshot.py                     # -> docs/viewer.png
    /usr/bin/python3 scripts/viewer_screenshot.py --preset minor --seconds 6 --out /tmp/v.png

It refuses to write a picture of a page that shows an error: the page's log box (#log) must
be empty, the console must hold no SEVERE entry and a camera frame must have been drawn.
Exit status 0 written, 1 the page showed an error or the run failed, 2 bad usage.
"""

import argparse
import os
import re
import signal
import subprocess
import sys
import tempfile
import threading
import time

REPO = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))


def wait_for(what, fn, timeout):
    end = time.monotonic() + timeout
    while True:
        v = fn()
        if v:
            return v
        if time.monotonic() > end:
            raise RuntimeError(f"timed out after {timeout} s waiting for {what}")
        time.sleep(0.1)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--binary", default=os.path.join(REPO, "build", "penumbra"))
    ap.add_argument("--world", default=os.path.join(REPO, "worlds", "default.yaml"))
    ap.add_argument("--out", default=os.path.join(REPO, "docs", "viewer.png"))
    ap.add_argument("--seconds", type=float, default=4.0, help="sim seconds played first")
    ap.add_argument("--preset", default=None, help="adversity preset chosen in the page first")
    ap.add_argument("--size", default="1600,900", help="window WIDTH,HEIGHT in pixels")
    args = ap.parse_args()
    if not os.access(args.binary, os.X_OK):
        ap.error(f"no penumbra binary at {args.binary} (build it, or pass --binary)")

    from selenium import webdriver
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.support.ui import Select

    tmp = tempfile.mkdtemp(prefix="penumbra_viewer_shot_")
    proc = subprocess.Popen([args.binary, "view", args.world, "--viewer", "127.0.0.1:0", "--out",
                             os.path.join(tmp, "out"), "--duration", str(args.seconds + 60)],
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True)
    lines, found = [], {}

    def read():
        for line in proc.stdout:
            lines.append(line.rstrip())
            m = re.search(r"viewer: open (http://\S+/\?token=[0-9a-f]{64}) ", line)
            if m:
                found["url"] = m.group(1)

    threading.Thread(target=read, daemon=True).start()
    driver = None
    try:
        wait_for("the viewer's URL", lambda: found.get("url") or proc.poll() is not None, 120)
        if "url" not in found:
            raise RuntimeError("penumbra view exited:\n" + "\n".join(lines[-20:]))
        o = webdriver.ChromeOptions()
        o.binary_location = "/usr/bin/chromium"
        for a in ["--headless=new", "--no-sandbox", "--disable-dev-shm-usage",
                  f"--window-size={args.size}", "--use-angle=swiftshader",
                  "--enable-unsafe-swiftshader", "--ignore-gpu-blocklist"]:
            o.add_argument(a)
        o.set_capability("goog:loggingPrefs", {"browser": "ALL"})
        driver = webdriver.Chrome(service=Service("/usr/bin/chromedriver"), options=o)
        js = driver.execute_script
        driver.get(found["url"])
        wait_for("hello and scene", lambda: js(
            "const v = window.penumbraViewer; return v.hello && v.scene && true;"), 60)
        if args.preset:
            Select(driver.find_element("id", "preset")).select_by_value(args.preset)
            wait_for("the preset's status", lambda: js(
                "const a = window.penumbraViewer.adversity; return a && a.preset;")
                == args.preset, 30)
        driver.find_element("id", "play").click()
        wait_for(f"{args.seconds} s of sim time", lambda: js(
            "const s = window.penumbraViewer.state; return s ? s.time_sec : 0;") >= args.seconds,
                 600)
        driver.find_element("id", "pause").click()
        wait_for("the pause reply and the page's paused badge", lambda: js(
            "return window.penumbraViewer.replies.some(r => r.cmd === 'pause' && r.ok) &&"
            " document.getElementById('runState').textContent === 'paused';"), 60)
        wait_for("a camera frame of the paused time", lambda: js(
            "const f = window.penumbraViewer.lastFrame['camera/front/rgb'];"
            f"return f && f.time_sec >= {args.seconds} - 0.15;"), 120)
        time.sleep(1.0)  # plots redraw every 0.1 s, the overview every animation frame
        page_log = js("return document.getElementById('log').textContent;")
        severe = [e for e in driver.get_log("browser") if e["level"] == "SEVERE"]
        if page_log.strip() or severe:
            print(f"viewer_screenshot: the page shows errors, nothing written:\n{page_log}\n"
                  f"{severe}", file=sys.stderr)
            return 1
        driver.save_screenshot(args.out)
        t = js("return window.penumbraViewer.state.time_sec;")
        print(f"viewer_screenshot: wrote {args.out} ({args.size} px, {args.world} at "
              f"t = {t:.3f} s)", file=sys.stderr)
        return 0
    finally:
        if driver:
            driver.quit()
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(timeout=60)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
        import shutil
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

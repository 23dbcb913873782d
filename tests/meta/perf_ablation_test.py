"""scripts/perf-ablation.sh end to end on one tiny world (a plane with a 5 % reflection and a
box) for 1 timed frame and 3 rounds, switching off two parts; checks the table's format only (a
row for all on and one per part, numbers that parse, ranges min <= median <= max). no timing is
asserted. also: `penumbra bench render --ablate` with an unknown part is a clear error that
names it and the known ones.

usage: perf_ablation_test.py PENUMBRA_BINARY REPO_ROOT
"""

import os
import re
import subprocess
import sys
import tempfile

ABLATION_STAGE_XML = """<mujoco model="stage">
  <asset><material name="floor" rgba="0.5 0.5 0.5 1" reflectance="0.05"/></asset>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1" material="floor"/>
    <geom name="box" type="box" pos="1 0 0.15" size="0.15 0.15 0.15" rgba="0.2 0.4 0.8 1"/>
  </worldbody>
</mujoco>
"""

ABLATION_WORLD_YAML = """seed: 1
duration_sec: 2
mjcf_cameras: {enabled: false}
models:
  - {name: stage, file: stage.xml}
lights:
  - {name: sun, type: sun, direction: [0.3, 0.4, -1], illuminance_lux: 20000}
cameras:
  - name: eye
    pose: {xyz: [-1, 0, 0.5], rpy_deg: [0, 10, 0]}
    width: 64
    height: 48
    rate_hz: 10
    outputs: [rgb]
"""

NUM = r"-?[0-9]+(?:\.[0-9]+)?"
DASH_RANGE = re.compile(rf"^({NUM}) \(({NUM})-({NUM})\)$")
TO_RANGE = re.compile(rf"^({NUM}) \(({NUM}) to ({NUM})\)$")


def check_range(cell, pattern):
    m = pattern.match(cell)
    assert m, f"'{cell}' is not 'MEDIAN (MIN..MAX)'"
    median, lo, hi = (float(x) for x in m.groups())
    assert lo <= median <= hi, cell


def main():
    binary, repo = sys.argv[1], sys.argv[2]
    script = os.path.join(repo, "scripts", "perf-ablation.sh")
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "stage.xml"), "w") as f:
            f.write(ABLATION_STAGE_XML)
        world = os.path.join(tmp, "tiny.yaml")
        with open(world, "w") as f:
            f.write(ABLATION_WORLD_YAML)
        r = subprocess.run(
            ["bash", script, binary, "--frames", "1", "--worlds", world,
             "--parts", "mirror", "sky-volume"],
            capture_output=True, text=True, timeout=600, check=False)
        assert r.returncode == 0, f"exit {r.returncode}\nstdout:\n{r.stdout}\nstderr:\n{r.stderr}"
        lines = [l for l in r.stdout.splitlines() if l.startswith("|")]
        assert len(lines) == 5, f"expected header, rule, all-on and two part rows:\n{r.stdout}"
        header = [c.strip() for c in lines[0].strip("|").split("|")]
        assert header == ["world", "part switched off", "frames/s", "CPU ms/frame",
                          "share of the frame's CPU time"], header
        rows = [[c.strip() for c in l.strip("|").split("|")] for l in lines[2:]]
        assert [row[1] for row in rows] == ["(none: all on)", "mirror", "sky-volume"], rows
        for row in rows:
            assert row[0] == world, row
            check_range(row[2], DASH_RANGE)
            check_range(row[3], DASH_RANGE)
        for row in rows[1:]:
            check_range(row[4], TO_RANGE)
        rounds = [l for l in r.stderr.splitlines() if " round " in l]
        assert len(rounds) == 3, r.stderr
        # an unknown part: exit code != 0, the part and the known names in the message
        bad = subprocess.run(
            [binary, "bench", "render", "--world", world, "--frames", "1", "--no-adversity",
             "--ablate", "mirrors"], capture_output=True, text=True, timeout=300, check=False)
        assert bad.returncode != 0, bad.stdout
        message = bad.stdout + bad.stderr
        assert "mirrors" in message and "sky-volume" in message, message
    print("perf-ablation table format: ok")


if __name__ == "__main__":
    main()

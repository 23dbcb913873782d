"""scripts/perf-compare.sh end to end: the same `penumbra` binary as OLD and NEW on one tiny
world (a plane and a box) for 1 timed frame and 3 rounds; checks the table's format only (frames/s
and CPU ms/frame of each binary with their ratios, one row for the world, numbers that parse,
ranges min <= median <= max). no timing is asserted.

usage: perf_compare_test.py PENUMBRA_BINARY REPO_ROOT
"""

import os
import re
import subprocess
import sys
import tempfile

STAGE_XML = """<mujoco model="stage">
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1" rgba="0.5 0.5 0.5 1"/>
    <geom name="box" type="box" pos="1 0 0.15" size="0.15 0.15 0.15" rgba="0.2 0.4 0.8 1"/>
  </worldbody>
</mujoco>
"""

WORLD_YAML = """seed: 1
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

NUMBER = r"[0-9]+(?:\.[0-9]+)?"
RANGE = re.compile(rf"^({NUMBER}) \(({NUMBER})-({NUMBER})\)$")


def main():
    binary, repo = sys.argv[1], sys.argv[2]
    script = os.path.join(repo, "scripts", "perf-compare.sh")
    with tempfile.TemporaryDirectory() as tmp:
        with open(os.path.join(tmp, "stage.xml"), "w") as f:
            f.write(STAGE_XML)
        world = os.path.join(tmp, "tiny.yaml")
        with open(world, "w") as f:
            f.write(WORLD_YAML)
        r = subprocess.run(
            ["bash", script, binary, binary, "--frames", "1", "--worlds", world],
            capture_output=True, text=True, timeout=600, check=False)
        assert r.returncode == 0, f"exit {r.returncode}\nstdout:\n{r.stdout}\nstderr:\n{r.stderr}"
        lines = [l for l in r.stdout.splitlines() if l.startswith("|")]
        assert len(lines) == 3, f"expected header, rule and one row:\n{r.stdout}"
        header = [c.strip() for c in lines[0].strip("|").split("|")]
        assert header == ["world", "old frames/s", "new frames/s", "ratio new/old",
                          "old cpu-ms/frame", "new cpu-ms/frame", "cpu ratio new/old"], header
        row = [c.strip() for c in lines[2].strip("|").split("|")]
        assert row[0] == world, row
        for cell in row[1:]:
            m = RANGE.match(cell)
            assert m, f"'{cell}' is not 'MEDIAN (MIN-MAX)'"
            median, lo, hi = (float(x) for x in m.groups())
            assert lo <= median <= hi and lo > 0, cell
        # the interleaved rounds: 3 of each binary, on stderr
        rounds = [l for l in r.stderr.splitlines() if " round " in l]
        assert len(rounds) == 3, r.stderr
        # bad input: a clear error, no table
        bad = subprocess.run(["bash", script, binary, binary, "--frames", "x"],
                             capture_output=True, text=True, check=False)
        assert bad.returncode == 2 and "--frames" in bad.stderr, bad.stderr
    print("perf-compare table format: ok")


if __name__ == "__main__":
    main()

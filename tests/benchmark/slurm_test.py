"""`penumbra benchmark --slurm` against a real single-node Slurm (tests/benchmark/slurm_cluster.py:
munged, slurmctld and slurmd started here on localhost): a 4-job array (one world, 2
conditions, 2 trials) gives the same rows as the local workers; re-submitting submits only
the unfinished job. Skipped (exit 77) with the reason when Slurm cannot start here.

usage: slurm_test.py PENUMBRA_BINARY SOURCE_DIR
"""

import csv
import io
import os
import shutil
import subprocess
import sys
import tempfile

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from slurm_cluster import SlurmCluster, SlurmUnavailable  # noqa: E402

TIMING = {"replay_sec", "export_sec", "method_sec", "eval_sec"}


def rows_without_timing(path):
    rows = list(csv.DictReader(io.StringIO(open(path).read())))
    return [{k: v for k, v in r.items() if k not in TIMING} for r in rows]


def run(args, env=None):
    r = subprocess.run(args, env=env, capture_output=True, text=True, timeout=300)
    if r.returncode != 0:
        raise AssertionError(f"{' '.join(args)} exited {r.returncode}:\n{r.stderr[-4000:]}")
    return r


def main():
    binary, source = sys.argv[1], sys.argv[2]
    tmp = tempfile.mkdtemp(prefix="penumbra_slurm_")
    try:
        spec = os.path.join(tmp, "spec.yaml")
        with open(spec, "w") as f:
            f.write(f"""name: slurm4
worlds:
  - name: room
    file: {source}/worlds/default.yaml
    duration_sec: 1
    camera: {{name: cam, attach: go1/camera_mount, width: 160, height: 120, fovy_deg: 70, rate_hz: 10}}
conditions: [none, major]
trials: 2
methods:
  - {{name: rgbd, bundled: opencv_rgbd}}
render: {{threads: 1}}
slurm: {{poll_sec: 0.5, sbatch: ["#SBATCH --time=00:10:00"]}}
""")
        local = os.path.join(tmp, "local")
        run([binary, "benchmark", spec, "--out", local, "--workers", "2", "--quiet"])
        expected = rows_without_timing(os.path.join(local, "results.csv"))
        assert len(expected) == 4, expected
        assert all(r["status"] == "ok" for r in expected if r["condition"] == "none"), expected
        try:
            cluster = SlurmCluster(os.path.join(tmp, "slurm"))
            cluster.__enter__()
        except SlurmUnavailable as e:
            print(f"SKIPPED: Slurm cannot start on this machine: {e}")
            return 77
        try:
            out = os.path.join(tmp, "out")
            run([binary, "benchmark", spec, "--out", out, "--slurm", "--quiet"], env=cluster.env())
            script = open(os.path.join(out, "slurm", "array.sbatch")).read()
            assert "#SBATCH --array=0,1,2,3\n" in script, script
            assert "#SBATCH --time=00:10:00\n" in script, script
            logs = [f for f in os.listdir(os.path.join(out, "slurm")) if f.endswith(".out")]
            assert len(logs) == 4, logs  # one log per array task: the jobs ran under Slurm
            got = rows_without_timing(os.path.join(out, "results.csv"))
            assert got == expected, f"slurm rows differ from local rows:\n{got}\n{expected}"
            # re-submitting submits only the unfinished job
            os.remove(os.path.join(out, "jobs", "room__major__t2", "result.json"))
            run([binary, "benchmark", spec, "--out", out, "--slurm", "--quiet"], env=cluster.env())
            script = open(os.path.join(out, "slurm", "array.sbatch")).read()
            assert "#SBATCH --array=3\n" in script, script
            assert rows_without_timing(os.path.join(out, "results.csv")) == expected
        finally:
            cluster.__exit__(None, None, None)
        print("slurm: 4-job array equals the local runner; re-submission ran only the unfinished job")
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

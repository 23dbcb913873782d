"""`penumbra benchmark --slurm` against a real single-node Slurm (tests/campaign/slurm_cluster.py:
munged, slurmctld and slurmd started here on localhost): a 4-job array (one world, 2
conditions, 2 trials) gives the same rows as the local workers; re-submitting submits only
the unfinished job; SIGINT while array tasks run a hanging method exits 130, cancels the
array (the queue empties), stops the methods and leaves no job folder behind. Skipped
(exit 77) with the reason when Slurm cannot start here.

usage: slurm_test.py PENUMBRA_BINARY SOURCE_DIR
"""

import csv
import io
import os
import shutil
import signal
import subprocess
import sys
import tempfile
import time

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


def wait_until(ok, limit_sec):
    end = time.time() + limit_sec
    while not ok():
        if time.time() > end:
            return False
        time.sleep(0.2)
    return True


def alive(pid):
    try:
        os.kill(pid, 0)
    except ProcessLookupError:
        return False
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


def interrupt_while_tasks_run(binary, source, tmp, cluster):
    spec = os.path.join(tmp, "hang.yaml")
    with open(spec, "w") as f:
        f.write(f"""name: hang
worlds:
  - name: room
    file: {source}/worlds/default.yaml
    duration_sec: 0.5
    camera: {{name: cam, attach: go1/camera_mount, width: 64, height: 48, fovy_deg: 70, rate_hz: 10}}
conditions: [none]
trials: 2
methods:
  - {{name: hang, command: "sh -c 'echo $$ > pid.txt; exec sleep 300'"}}
render: {{threads: 1}}
slurm: {{poll_sec: 0.5}}
""")
    out = os.path.join(tmp, "hang_out")
    bench = subprocess.Popen([binary, "benchmark", spec, "--out", out, "--slurm", "--quiet"],
                             env=cluster.env(), stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                             text=True)
    pid_files = [os.path.join(out, "jobs", f"room__none__t{t}", "hang", "pid.txt") for t in (1, 2)]

    def methods_running():
        return bench.poll() is not None or all(
            os.path.exists(p) and open(p).read().endswith("\n") for p in pid_files)
    assert wait_until(methods_running, 240), "the array's methods did not start"
    assert bench.poll() is None, bench.stderr.read()
    pids = [int(open(p).read()) for p in pid_files]
    bench.send_signal(signal.SIGINT)
    try:
        err = bench.communicate(timeout=120)[1]
    except subprocess.TimeoutExpired:
        bench.kill()
        raise AssertionError("penumbra benchmark --slurm still ran 120 s after SIGINT")
    assert bench.returncode == 130, f"exit {bench.returncode}:\n{err[-4000:]}"
    assert "Slurm job array" in err and "cancelled" in err, err[-4000:]

    def queue_empty():
        r = subprocess.run(["squeue", "-h"], env=cluster.env(), capture_output=True, text=True)
        return r.returncode == 0 and r.stdout.strip() == ""
    assert wait_until(queue_empty, 60), "the cancelled array is still queued"
    assert wait_until(lambda: not any(alive(p) for p in pids), 60), f"methods {pids} still run"
    jobs = os.path.join(out, "jobs")
    assert wait_until(lambda: not os.path.isdir(jobs) or not os.listdir(jobs), 60), os.listdir(jobs)
    with open(os.path.join(out, "results.csv")) as f:
        assert len(f.read().splitlines()) == 1, "an interrupted job was reported"


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
            interrupt_while_tasks_run(binary, source, tmp, cluster)
        finally:
            cluster.__exit__(None, None, None)
        print("slurm: 4-job array equals the local runner; re-submission ran only the unfinished job; "
              "SIGINT cancelled a running array and left no job behind")
        return 0
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


if __name__ == "__main__":
    sys.exit(main())

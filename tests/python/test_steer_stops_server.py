"""python/examples/steer_to_target.py stops the server it drove:
on a normal exit and on Ctrl-C (SIGINT) it sends `stop`, and the real `penumbra run --zmq
--lockstep` process exits (130, as on Ctrl-C) and writes run.json with "interrupted": true;
with --leave-running the server keeps running."""

import json
import os
import signal
import subprocess
import sys
import time
import unittest

sys.path.insert(0, os.path.dirname(__file__))
from penumbra_server import REPO, PenumbraServer  # noqa: E402

SCRIPT = os.path.join(REPO, "python", "examples", "steer_to_target.py")


def wait_exit(proc, timeout):
    try:
        return proc.wait(timeout=timeout)
    except subprocess.TimeoutExpired:
        return None


class SteerStopsServerTest(unittest.TestCase):
    def run_script(self, server, *args):
        return subprocess.Popen([sys.executable, SCRIPT, "--endpoint", server.endpoint, *args],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)

    def test_normal_exit_stops_the_server(self):
        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
            script = self.run_script(server, "--max-periods", "5")
            out, err = script.communicate(timeout=300)
            print(out, err, file=sys.stderr)
            self.assertEqual(script.returncode, 1, "5 periods: not arrived")
            self.assertEqual(json.loads(out.strip().splitlines()[-1])["periods"], 5)
            rc = wait_exit(server.proc, 60)
            self.assertEqual(rc, 0, "the server exited after the script")
            with open(os.path.join(server.out_dir, "run.json")) as f:
                self.assertTrue(json.load(f)["interrupted"])

    def test_ctrl_c_stops_the_server(self):
        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
            script = self.run_script(server, "--max-periods", "100000")
            # interrupt it while it steps: once the run has written camera frames
            frames = os.path.join(server.out_dir, "front", "rgb")
            end = time.monotonic() + 120
            while time.monotonic() < end and not (
                    os.path.isdir(frames) and len(os.listdir(frames)) >= 3):
                time.sleep(0.1)
            self.assertIsNone(script.poll(), "the script still runs")
            script.send_signal(signal.SIGINT)
            out, err = script.communicate(timeout=60)
            print(out, err, file=sys.stderr)
            self.assertEqual(script.returncode, 130)
            self.assertIn("stopped the server", err)
            self.assertEqual(wait_exit(server.proc, 60), 0, "the server exited after Ctrl-C")

    def test_leave_running_keeps_it(self):
        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
            script = self.run_script(server, "--max-periods", "2", "--leave-running")
            script.communicate(timeout=300)
            self.assertEqual(script.returncode, 1)
            self.assertIsNone(wait_exit(server.proc, 2), "--leave-running: the server runs on")
            client = server.connect(timeout_sec=60)
            self.assertGreater(client.get_state().time_sec, 0)
            client.close()


if __name__ == "__main__":
    unittest.main()

"""The navigator as an external process against a real lockstep `penumbra run --zmq`
(worlds/quadruped_target.yaml): a goal 3 m ahead in the open, and a goal behind the red
column, which the straight line would run through. Skipped without the penumbra binary
($PENUMBRA_BINARY or build/penumbra)."""

import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.abspath(os.path.join(HERE, "..", ".."))
sys.path.insert(0, os.path.join(REPO, "tests", "python"))
from penumbra_server import PenumbraServer  # noqa: E402

BINARY = os.environ.get("PENUMBRA_BINARY", os.path.join(REPO, "build", "penumbra"))
COLUMN_XY, COLUMN_RADIUS = (3.0, 1.5), 0.15  # worlds/models/target_course.xml


def navigate(server, goal, timeout_sec):
    """Runs `python3 -m penumbra_nav` against the server; returns the episode dict."""
    with tempfile.TemporaryDirectory() as tmp:
        out = os.path.join(tmp, "episode.json")
        env = dict(os.environ, PYTHONPATH=os.path.join(REPO, "python"))
        proc = subprocess.run(
            [sys.executable, "-m", "penumbra_nav", "--endpoint", server.endpoint, "--goal",
             str(goal[0]), str(goal[1]), "--radius", "0.5", "--timeout", str(timeout_sec),
             "--robot", "quadruped", "--out", out, "--verbose"],
            capture_output=True, text=True, timeout=600, env=env)
        sys.stderr.write(proc.stderr[-3000:])
        if proc.returncode not in (0, 1):
            raise AssertionError(f"penumbra_nav exited with {proc.returncode}:\n"
                                 f"{proc.stdout}\n{proc.stderr}\n{server.output()}")
        with open(out) as f:
            return json.load(f)


@unittest.skipUnless(os.access(BINARY, os.X_OK), f"no penumbra binary at {BINARY}")
class ClosedLoopTest(unittest.TestCase):
    def check_episode(self, ep, server, goal):
        self.assertTrue(ep["success"], {k: v for k, v in ep.items() if k != "config"})
        self.assertEqual(ep["reason"], "goal_reached")
        self.assertLessEqual(ep["final_goal_distance_m"], 0.5)
        # the server's own state agrees with the episode's final position
        client = server.connect(timeout_sec=60)
        qpos = client.get_state().qpos
        client.close()
        self.assertLessEqual(math.hypot(qpos[0] - goal[0], qpos[1] - goal[1]), 0.5)
        # nothing of the robot touched the column (the harness's collision test)
        touched = [c for c in ep["contacts"] if c["other_body"] == "course/target"]
        self.assertEqual(touched, [])

    def test_goal_3_m_ahead(self):
        goal = (3.0, 0.0)
        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
            ep = navigate(server, goal, 30.0)
            self.check_episode(ep, server, goal)
        print(f"goal 3 m ahead: {ep['time_to_goal_sec']:.1f} s, {ep['path_length_m']:.2f} m",
              file=sys.stderr)
        self.assertLess(ep["time_to_goal_sec"], 15.0)
        self.assertLess(ep["path_length_m"], 3.5)

    def test_goal_behind_the_column(self):
        goal = (5.0, 2.5)  # the straight line from the start runs through the column
        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
            ep = navigate(server, goal, 45.0)
            self.check_episode(ep, server, goal)
        print(f"goal behind the column: {ep['time_to_goal_sec']:.1f} s, "
              f"{ep['path_length_m']:.2f} m, {ep['replans']} plans", file=sys.stderr)
        self.assertGreater(ep["path_length_m"], math.hypot(*goal) - 0.5)


if __name__ == "__main__":
    unittest.main()

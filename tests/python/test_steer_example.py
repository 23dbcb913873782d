"""python/examples/steer_to_target.py closes the loop over a real lockstep `penumbra run --zmq`:
from its camera images alone it steers the quadruped to the red target, 27 deg off its
initial heading."""

import json
import math
import os
import subprocess
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from penumbra_server import REPO, PenumbraServer  # noqa: E402

TARGET_XY = np.array([3.0, 1.5])  # worlds/models/target_course.xml, body `target`


class SteerExampleTest(unittest.TestCase):
    def test_robot_ends_near_the_target(self):
        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
            client = server.connect(timeout_sec=60)
            start = client.get_state().qpos
            # the target's pose from the ground-truth stream (its body is static)
            client.subscribe(["ground_truth/poses"])
            gt = client.step(1).latest("ground_truth/poses").header
            target = np.array(gt["xyz"][gt["name"].index("course/target")][:2])
            np.testing.assert_allclose(target, TARGET_XY, atol=1e-9)
            client.subscription.remove("ground_truth/poses")

            proc = subprocess.run(
                [sys.executable, os.path.join(REPO, "python", "examples", "steer_to_target.py"),
                 "--endpoint", server.endpoint, "--leave-running"],
                capture_output=True, text=True, timeout=300)
            self.assertEqual(proc.returncode, 0, proc.stdout + proc.stderr)
            result = json.loads(proc.stdout.strip().splitlines()[-1])
            end = client.get_state().qpos
            client.close()

        d0 = np.linalg.norm(start[:2] - target)
        d1 = np.linalg.norm(end[:2] - target)
        # trunk quaternion w x y z -> yaw
        w, x, y, z = end[3:7]
        yaw = math.atan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
        print(f"steer_to_target: {result}; distance {d0:.2f} -> {d1:.2f} m, "
              f"yaw {math.degrees(yaw):.1f} deg", file=sys.stderr)
        self.assertTrue(result["arrived"])
        self.assertGreater(d0, 3.0)
        # it stops when the target's depth is < 0.8 m; the trunk origin is 0.215 m behind the
        # camera and the column's radius is 0.15 m
        self.assertLess(d1, 1.3)
        # walking straight ahead would pass the target at 1.5 m: it had to turn left
        self.assertGreater(math.degrees(yaw), 10)


if __name__ == "__main__":
    unittest.main()

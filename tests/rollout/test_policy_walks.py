#!/usr/bin/env python3
"""The shipped velocity-tracking policy (worlds/models/policies/go1_velocity.onnx) walks in
the training scene when run through OpenCV's dnn module (as the `type: policy` controller
runs it): a short episode forward and one turning, each upright, not fallen, covering the
distance / heading the command asks for within generous bounds. Exits 77 (skipped, with the
reason) when python3-opencv is not installed."""

import os
import sys
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))

try:
    import cv2
except ImportError:
    print("skipped: python3-opencv (cv2) is not installed")
    sys.exit(77)

from penumbra_rollout import QuadrupedEnvConfig, QuadrupedVelocityEnv  # noqa: E402

POLICY = os.path.join(ROOT, "worlds", "models", "policies", "go1_velocity.onnx")


def walk(command, seconds, seed):
    net = cv2.dnn.readNetFromONNX(POLICY)
    env = QuadrupedVelocityEnv(1, QuadrupedEnvConfig(num_threads=1, add_noise=False), seed=seed)
    obs, _ = env.reset(options={"commands": [command]})
    start = env.base_pos[0].copy()
    yaw = 0.0
    min_up = 1.0
    min_z = np.inf
    for _ in range(int(round(seconds / env.dt))):
        net.setInput(obs)
        obs, _, term, trunc, _ = env.step(net.forward().astype(np.float64))
        if term[0]:
            return None
        yaw += env.base_ang_vel[0, 2] * env.dt
        min_up = min(min_up, -env.projected_gravity[0, 2])
        min_z = min(min_z, env.base_pos[0, 2])
    # walking on its legs, not crawling on bent ones: the trunk origin stays above 0.2 m (it
    # stands at 0.27 m; the trunk box reaches 0.055 m below its origin)
    assert min_z > 0.2, f"trunk origin down to {min_z:.3f} m"
    return env.base_pos[0] - start, yaw, min_up


class PolicyWalksTest(unittest.TestCase):
    def test_onnx_is_small_and_opencv_reads_it(self):
        self.assertLess(os.path.getsize(POLICY), 1 << 20)
        net = cv2.dnn.readNetFromONNX(POLICY)
        net.setInput(np.zeros((1, 48), np.float32))
        self.assertEqual(net.forward().shape, (1, 12))

    def test_walks_forward(self):
        r = walk([0.5, 0.0, 0.0], 3.0, seed=0)
        self.assertIsNotNone(r, "fell")
        d, yaw, up = r
        # 0.5 m/s for 3 s less the start-up: at least 1.0 m forward, little sideways drift
        self.assertGreater(d[0], 1.0)
        self.assertLess(abs(d[1]), 0.3)
        self.assertGreater(up, 0.95)  # trunk z axis within 18 deg of vertical

    def test_turns(self):
        r = walk([0.0, 0.0, 0.5], 3.0, seed=1)
        self.assertIsNotNone(r, "fell")
        d, yaw, up = r
        self.assertGreater(yaw, 1.0)  # 0.5 rad/s for 3 s
        self.assertLess(np.linalg.norm(d[:2]), 0.4)
        self.assertGreater(up, 0.95)


if __name__ == "__main__":
    unittest.main(verbosity=2)

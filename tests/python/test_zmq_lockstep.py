"""Acceptance: the Python client runs 1000 lockstep steps of the quadruped world
against a real `penumbra run --zmq --lockstep`, receives every camera frame due, and two runs
give identical images and states."""

import math
import os
import sys
import time
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from penumbra_server import PenumbraServer  # noqa: E402

WORLD = "worlds/quadruped_target.yaml"
STEPS = 1000
TOPICS = ("rgb", "depth", "depth_mm")


def twist_at(i):
    # a fixed schedule of twist commands (changed every 100 steps), so the robot walks and
    # turns: the states of the two runs differ from step to step and must match bit for bit
    k = i // 100
    return (0.1 * (k % 4), 0.0, 0.3 * ((k % 3) - 1))


def run_once():
    """Steps the world STEPS times one step per request; returns (states, frames, wall s)."""
    with PenumbraServer(WORLD, lockstep=True) as server:
        client = server.connect(timeout_sec=60)
        hello = client.server
        assert hello["mode"] == "lockstep" and hello["step"] == 0, hello
        info = client.model_info()
        cam = info.camera("front")
        client.subscribe([f"camera/front/{t}" for t in TOPICS])
        states, frames = [], {t: [] for t in TOPICS}
        t0 = time.monotonic()
        for i in range(STEPS):
            if i % 100 == 0:
                client.twist(*twist_at(i))
            r = client.step(1, state=True)
            assert r.step == i + 1, (r.step, i)
            states.append(r.state)
            for m in r.messages:
                frames[m.topic.rsplit("/", 1)[1]].append(m)
        wall = time.monotonic() - t0
        client.close()
        server.stop()
        return info, cam, states, frames, wall


class LockstepTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.info, cls.cam, cls.states_a, cls.frames_a, wall_a = run_once()
        _, _, cls.states_b, cls.frames_b, wall_b = run_once()
        print(f"{STEPS} lockstep steps (1 per request, state + {len(TOPICS)} image topics): "
              f"{wall_a:.2f} s and {wall_b:.2f} s wall", file=sys.stderr)

    def test_every_camera_frame_due_arrives(self):
        dt = self.info.timestep_sec
        rate = self.cam["rate_hz"]
        t_end = STEPS * dt
        # frames fire at the first step whose time is >= k / rate (docs/zmq-protocol.md),
        # k = 0, 1, ...: the ones due by the last step. the world's camera is a real one
        # (profile realsense_d435_rgb: shutter up to 1/30 s, rolling-shutter readout 30 ms), so a
        # frame arrives once its exposure and readout ended: all due frames but those captured
        # within that span (< 0.1 s) of the last step
        due = [k for k in range(100000) if k / rate <= t_end + 1e-9]
        settled = [k for k in due if k / rate + 0.1 <= t_end]
        for topic in TOPICS:
            msgs = self.frames_a[topic]
            got = [m.header["index"] for m in msgs]
            self.assertEqual(got, due[:len(got)], topic)
            self.assertGreaterEqual(len(got), len(settled), topic)
            for m in msgs:
                k = m.header["index"]
                step_due = math.ceil(k / rate / dt - 1e-6)
                self.assertEqual(m.sim_step, step_due, (topic, k))
                # the stamp is the frame's mid-exposure time (sensors/camera_imager.h
                # mid_exposure_time_sec): within the shutter time after the capture step
                self.assertGreaterEqual(m.stamp, m.sim_step * dt - 1e-9)
                self.assertLess(m.stamp, m.sim_step * dt + 0.1)
                self.assertEqual(m.frame_id, "front/optical")

    def test_images_are_numpy_arrays_of_the_camera(self):
        h, w = self.cam["height"], self.cam["width"]
        for m in self.frames_a["rgb"]:
            img = m.image()
            self.assertEqual((img.shape, img.dtype), ((h, w, 3), np.uint8))
            self.assertGreater(int(img.max()) - int(img.min()), 30)  # a scene, not a blank
        for d, mm in zip(self.frames_a["depth"], self.frames_a["depth_mm"]):
            depth, depth_mm = d.image(), mm.image()
            self.assertEqual((depth.shape, depth.dtype), ((h, w), np.float32))
            self.assertEqual((depth_mm.shape, depth_mm.dtype), ((h, w), np.uint16))
            hit = depth > 0
            self.assertGreater(hit.mean(), 0.3)  # the floor fills the lower half
            self.assertTrue(np.all(np.isfinite(depth)))
            # the same z-depth in metres and in millimetres (rounded; clamped to 65535: the
            # floor is an infinite plane)
            near = hit & (depth < 65.535)
            np.testing.assert_array_less(
                np.abs(depth_mm[near].astype(np.float64) - depth[near] * 1000.0), 0.5 + 1e-3)
            self.assertTrue(np.all(depth_mm[hit & ~near] == 65535))
            self.assertTrue(np.all(depth_mm[~hit] == 0))

    def test_the_robot_moved(self):
        q0, q1 = self.states_a[0].qpos, self.states_a[-1].qpos
        self.assertGreater(np.linalg.norm(q1[:2] - q0[:2]), 0.05)

    def test_two_runs_are_bit_identical(self):
        self.assertEqual(len(self.states_a), len(self.states_b))
        for i, (a, b) in enumerate(zip(self.states_a, self.states_b)):
            self.assertEqual(a, b, f"state after step {i + 1}")
        for topic in TOPICS:
            fa, fb = self.frames_a[topic], self.frames_b[topic]
            self.assertEqual(len(fa), len(fb), topic)
            for ma, mb in zip(fa, fb):
                self.assertEqual(ma.header, mb.header, topic)
                self.assertEqual(bytes(ma.payload), bytes(mb.payload),
                                 f"{topic} frame {ma.header['index']}")


if __name__ == "__main__":
    unittest.main()

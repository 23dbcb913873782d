"""penumbra_nav.navigator: the whole loop against a kinematic stand-in for a lockstep run
(fake_sim.py): goal reached in the open and around a box, timeout, fall, the episode JSON."""

import io
import json
import math
import os
import sys
import tempfile
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from fake_sim import FakeLockstepClient, q_of  # noqa: E402
from penumbra_nav.geometry import quat_to_rotation  # noqa: E402
from penumbra_nav.navigator import (Navigator, NavigatorConfig, pick_camera,  # noqa: E402
                                    write_episode)


def run(client, **kw):
    config = NavigatorConfig(**kw)
    trace = io.StringIO()
    episode = Navigator(client, config, trace=trace).run()
    return episode, [json.loads(line) for line in trace.getvalue().splitlines()]


class FakeSimTest(unittest.TestCase):
    def test_quaternion_helper(self):
        rng = np.random.default_rng(3)
        for _ in range(20):
            q = rng.normal(size=4)
            q /= np.linalg.norm(q)
            X = np.eye(4)
            X[:3, :3] = quat_to_rotation(q)
            np.testing.assert_allclose(quat_to_rotation(q_of(X)), X[:3, :3], atol=1e-12)


class NavigatorTest(unittest.TestCase):
    def test_reaches_a_goal_in_the_open(self):
        sim = FakeLockstepClient()
        ep, trace = run(sim, goal_xy=(3.0, 0.0), goal_radius_m=0.5, timeout_sec=30.0)
        self.assertTrue(ep["success"])
        self.assertEqual(ep["reason"], "goal_reached")
        # 2.5 m at 0.4 m/s after one period standing (6.35 s), a little more for the speed
        # ramp over the last 0.5 m of the path, which ends 0.25 m short of the goal
        self.assertGreater(ep["time_to_goal_sec"], 6.35)
        self.assertLess(ep["time_to_goal_sec"], 6.8)
        self.assertEqual(ep["steps"], round(ep["time_to_goal_sec"] / 0.1))
        self.assertEqual(ep["physics_steps"], ep["steps"] * 50)
        self.assertLessEqual(ep["final_goal_distance_m"], 0.5)
        self.assertGreater(ep["final_goal_distance_m"], 0.5 - 0.04)
        self.assertAlmostEqual(ep["path_length_m"], 3.0 - ep["final_goal_distance_m"], delta=0.03)
        self.assertAlmostEqual(ep["planned_path_length_m"], 3.0 - 0.25, delta=0.05)
        self.assertEqual(ep["end_time_sec"], ep["time_to_goal_sec"])
        self.assertEqual(ep["camera"], "front")
        self.assertEqual(ep["robot_name"], "quadruped")
        self.assertEqual(ep["base_body"], "quadruped/trunk")
        self.assertEqual(ep["control_period_sec"], 0.1)
        self.assertIsNone(ep["fall"])
        # the foot-on-floor stand-in contact, logged at every physics step
        self.assertEqual(ep["contact_messages"], ep["physics_steps"])
        self.assertEqual(ep["contacts"], [{
            "robot_body": "quadruped/trunk", "other_body": "world", "first_time_sec": 0.002,
            "last_time_sec": ep["end_time_sec"], "samples": ep["physics_steps"],
            "max_normal_force_N": 120.0}])
        self.assertEqual(len(trace), ep["steps"] - 1)
        self.assertEqual(sim.twists[-1], (0.0, 0.0))  # stopped at the end
        # straight at the goal: the heading never strays by more than 3 degrees
        self.assertLess(max(abs(t["yaw_rad"]) for t in trace), math.radians(3.0))

    def test_goes_around_a_box_without_touching_it(self):
        box = (1.5, -0.6, 2.0, 0.6, 0.5)
        sim = FakeLockstepClient(boxes=[box])
        ep, trace = run(sim, goal_xy=(3.5, 0.0), goal_radius_m=0.3, timeout_sec=40.0)
        self.assertTrue(ep["success"], ep)
        traj = np.array(sim.trajectory)
        clearance = min(sim.box_distance(p) for p in traj)
        # the trunk is 0.19 m wide and its nose 0.23 m ahead: a 0.25 m margin means no touch
        self.assertGreater(clearance, 0.25)
        self.assertGreater(np.abs(traj[:, 1]).max(), 0.6)
        self.assertGreater(ep["path_length_m"], 3.2)
        self.assertGreater(ep["replans"], 1)
        self.assertLess(ep["time_to_goal_sec"], 25.0)

    def test_camera_pose_from_the_mount_when_not_published(self):
        box = (1.5, -0.6, 2.0, 0.6, 0.5)
        with_pose = FakeLockstepClient(boxes=[box])
        without = FakeLockstepClient(boxes=[box], publish_pose=False)
        a, _ = run(with_pose, goal_xy=(3.5, 0.0), goal_radius_m=0.3, timeout_sec=40.0)
        b, _ = run(without, goal_xy=(3.5, 0.0), goal_radius_m=0.3, timeout_sec=40.0)
        self.assertEqual(a["time_to_goal_sec"], b["time_to_goal_sec"])
        np.testing.assert_allclose(with_pose.trajectory, without.trajectory, atol=1e-9)

    def test_timeout(self):
        # a wall across the whole grid: the goal behind it cannot be reached
        sim = FakeLockstepClient(boxes=[(1.5, -20.0, 1.7, 20.0, 1.0)])
        ep, _ = run(sim, goal_xy=(4.0, 0.0), timeout_sec=3.0)
        self.assertFalse(ep["success"])
        self.assertEqual(ep["reason"], "timeout")
        self.assertIsNone(ep["time_to_goal_sec"])
        self.assertEqual(ep["steps"], 30)
        self.assertAlmostEqual(ep["episode_time_sec"], 3.0)
        self.assertLess(max(p[0] for p in sim.trajectory), 1.5 - 0.3)

    def test_fall(self):
        sim = FakeLockstepClient(fall_at_sec=1.0)
        ep, _ = run(sim, goal_xy=(3.0, 0.0), timeout_sec=30.0)
        self.assertFalse(ep["success"])
        self.assertEqual(ep["reason"], "fall")
        self.assertEqual(ep["steps"], 10)
        self.assertAlmostEqual(ep["fall"]["base_z_m"], 0.1)

    def test_episode_json_and_camera_choice(self):
        sim = FakeLockstepClient()
        ep, _ = run(sim, goal_xy=(0.2, 0.0), timeout_sec=5.0)
        self.assertTrue(ep["success"])
        self.assertEqual(ep["time_to_goal_sec"], 0.1)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "episode.json")
            write_episode(ep, path)
            with open(path) as f:
                back = json.load(f)
        for key in ("success", "reason", "time_to_goal_sec", "final_goal_distance_m",
                    "path_length_m", "steps"):
            self.assertIn(key, back)
        self.assertEqual(back["config"]["goal_xy"], [0.2, 0.0])
        info = sim.model_info()
        self.assertEqual(pick_camera(info)["name"], "front")
        with self.assertRaises(ValueError):
            pick_camera(info, "side")
        with self.assertRaises(ValueError):
            Navigator(sim, NavigatorConfig(goal_xy=(1, 0), robot="hexapod"))
        with self.assertRaises(ValueError):
            Navigator(sim, NavigatorConfig(goal_xy=(1, 0), robot="rover")).run()
        self.assertTrue(math.isfinite(back["wall_time_sec"]))


if __name__ == "__main__":
    unittest.main()

"""penumbra_nav.pure_pursuit: twists on straight and curved paths, limits, turning in place."""

import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "python"))
from penumbra_nav.pure_pursuit import PurePursuit, closest_point, point_at  # noqa: E402


def arc(radius, left=True, n=2001, sweep=math.pi / 2):
    """A path from the origin, heading +x, curving left (centre (0, r)) or right."""
    a = np.linspace(0.0, sweep, n)
    y = radius * (1.0 - np.cos(a))
    return np.stack([radius * np.sin(a), y if left else -y], axis=1)


class PathGeometryTest(unittest.TestCase):
    def test_closest_point_and_point_at(self):
        path = np.array([[0.0, 0.0], [2.0, 0.0], [2.0, 2.0]])
        k, q, s = closest_point(path, [1.0, 0.5])
        self.assertEqual(k, 0)
        np.testing.assert_allclose(q, [1.0, 0.0])
        self.assertAlmostEqual(s, 1.0)
        k, q, s = closest_point(path, [2.5, 1.5])
        self.assertEqual(k, 1)
        self.assertAlmostEqual(s, 3.5)
        np.testing.assert_allclose(point_at(path, 3.0), [2.0, 1.0])
        np.testing.assert_allclose(point_at(path, -1.0), [0.0, 0.0])
        np.testing.assert_allclose(point_at(path, 9.0), [2.0, 2.0])


class PurePursuitTest(unittest.TestCase):
    def test_straight_path_gives_zero_yaw_rate(self):
        pp = PurePursuit(lookahead_m=0.6, max_speed_m_s=0.4, max_yaw_rate_rad_s=1.0)
        pp.set_path([[0.0, 0.0], [5.0, 0.0]])
        vx, w = pp.command([0.0, 0.0], 0.0)
        self.assertEqual(w, 0.0)
        self.assertEqual(vx, 0.4)
        np.testing.assert_allclose(pp.target, [0.6, 0.0])

    def test_left_curving_path_gives_positive_yaw_rate_at_its_curvature(self):
        pp = PurePursuit(lookahead_m=0.6, max_speed_m_s=0.4, max_yaw_rate_rad_s=1.0)
        pp.set_path(arc(2.0, left=True))
        vx, w = pp.command([0.0, 0.0], 0.0)
        self.assertGreater(w, 0.0)
        self.assertEqual(vx, 0.4)
        # a robot on a circle, heading along it, is steered on that circle: kappa = 1 / r
        self.assertAlmostEqual(w / vx, 0.5, delta=1e-3)

    def test_right_curving_path_gives_negative_yaw_rate(self):
        pp = PurePursuit()
        pp.set_path(arc(2.0, left=False))
        vx, w = pp.command([0.0, 0.0], 0.0)
        self.assertLess(w, 0.0)
        self.assertAlmostEqual(w / vx, -0.5, delta=1e-3)

    def test_offset_robot_steers_back_to_the_path(self):
        pp = PurePursuit(lookahead_m=1.0)
        pp.set_path([[0.0, 0.0], [5.0, 0.0]])
        # 0.2 m left of the path, heading along it: turn right (clockwise, negative)
        _, w = pp.command([1.0, 0.2], 0.0)
        self.assertLess(w, 0.0)
        # the lookahead point is 1 m further along from the nearest point (1, 0)
        np.testing.assert_allclose(pp.target, [2.0, 0.0])

    def test_large_heading_error_turns_in_place(self):
        pp = PurePursuit(max_yaw_rate_rad_s=1.0, turn_in_place_rad=math.radians(60),
                         turn_gain=1.5)
        pp.set_path([[0.0, 0.0], [0.0, -5.0]])  # 90 deg to the right
        vx, w = pp.command([0.0, 0.0], 0.0)
        self.assertEqual(vx, 0.0)
        self.assertEqual(w, -1.0)  # 1.5 * -pi/2, clipped to the limit
        pp.set_path([[0.0, 0.0], [-5.0, 4.0]])  # 141 deg to the left
        vx, w = pp.command([0.0, 0.0], 0.0)
        self.assertEqual((vx, w), (0.0, 1.0))
        pp = PurePursuit(max_yaw_rate_rad_s=3.0, turn_gain=1.5)
        pp.set_path([[0.0, 0.0], [math.cos(1.2), math.sin(1.2)]])  # 68.8 deg left
        vx, w = pp.command([0.0, 0.0], 0.0)
        self.assertEqual(vx, 0.0)
        self.assertAlmostEqual(w, 1.5 * 1.2)

    def test_yaw_rate_limit_keeps_the_curvature(self):
        pp = PurePursuit(lookahead_m=0.6, max_speed_m_s=0.4, max_yaw_rate_rad_s=0.1)
        pp.set_path(arc(1.0, left=True))
        vx, w = pp.command([0.0, 0.0], 0.0)
        self.assertAlmostEqual(w, 0.1)
        self.assertLess(vx, 0.4)
        self.assertAlmostEqual(w / vx, 1.0, delta=2e-3)

    def test_slows_down_near_the_end_but_not_below_the_floor(self):
        pp = PurePursuit(max_speed_m_s=0.4, min_speed_m_s=0.1, slowdown_m=0.5)
        pp.set_path([[0.0, 0.0], [5.0, 0.0]])
        vx, _ = pp.command([4.75, 0.0], 0.0)
        self.assertAlmostEqual(vx, 0.2)
        vx, _ = pp.command([4.99, 0.0], 0.0)
        self.assertAlmostEqual(vx, 0.1)

    def test_progress_never_moves_back(self):
        pp = PurePursuit(lookahead_m=0.5)
        # a hairpin: out along y = 0, back along y = 0.4
        pp.set_path([[0.0, 0.0], [3.0, 0.0], [3.0, 0.4], [0.0, 0.4]])
        pp.command([2.95, 0.2], math.pi / 2)
        self.assertEqual(pp.progress_index, 1)
        # near the outbound leg again, it keeps to the return leg
        pp.command([1.0, 0.1], math.pi)
        self.assertEqual(pp.progress_index, 2)
        np.testing.assert_allclose(pp.target, [0.5, 0.4])

    def test_no_path_no_motion(self):
        self.assertEqual(PurePursuit().command([0.0, 0.0], 0.0), (0.0, 0.0))
        with self.assertRaises(ValueError):
            PurePursuit(lookahead_m=0.0)


if __name__ == "__main__":
    unittest.main()

"""penumbra_nav.occupancy_grid: depth images of known scenes mark the expected cells."""

import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "python"))
from penumbra_nav.geometry import R_BODY_OPTICAL, quat_to_rotation, yaw_quat  # noqa: E402
from penumbra_nav.occupancy_grid import OccupancyGrid  # noqa: E402

# a 64 x 48 camera: 40 px focal length, pixel centres at integer coordinates
W, H, FX, FY, CX, CY = 64, 48, 40.0, 40.0, 31.5, 23.5
CAMERA_HEIGHT = 0.3


def camera_pose(yaw=0.0, height=CAMERA_HEIGHT):
    """X_WC of an optical frame at (0, 0, height) looking horizontally along heading yaw."""
    X = np.eye(4)
    X[:3, :3] = quat_to_rotation(yaw_quat(yaw)) @ R_BODY_OPTICAL
    X[:3, 3] = [0.0, 0.0, height]
    return X


def quat_of(R):
    """[w, x, y, z] of a rotation matrix whose trace is > -1."""
    w = math.sqrt(1.0 + np.trace(R)) / 2.0
    return [w, (R[2, 1] - R[1, 2]) / (4 * w), (R[0, 2] - R[2, 0]) / (4 * w),
            (R[1, 0] - R[0, 1]) / (4 * w)]


def make_grid():
    # 10 m x 10 m at 0.1 m; centre (-0.05, -0.05) puts the cell centres on multiples of 0.1
    return OccupancyGrid(resolution_m=0.1, size_m=10.0, center_xy=(-0.05, -0.05))


def cells_xy(grid, mask):
    """Centres (rounded to mm) of the cells where mask is true, as a set of (x, y)."""
    i, j = np.nonzero(mask)
    return {(round(x, 3), round(y, 3)) for x, y in grid.cell_center(i, j)}


def state_at(grid, x, y):
    i, j = grid.cell_of([x, y])
    if grid.occupied()[i, j]:
        return "occupied"
    return "free" if grid.free()[i, j] else "unknown"


class GridGeometryTest(unittest.TestCase):
    def test_cells_and_centres(self):
        g = make_grid()
        self.assertEqual(g.shape, (100, 100))
        np.testing.assert_allclose(g.origin_xy, [-5.05, -5.05])
        i, j = g.cell_of([2.0, -1.0])
        np.testing.assert_allclose(g.cell_center(i, j), [2.0, -1.0], atol=1e-12)
        self.assertFalse(g.contains_xy([5.0, 0.0]))
        self.assertTrue(g.contains_xy([4.9, -5.0]))
        self.assertTrue(g.unknown().all())

    def test_bad_parameters(self):
        with self.assertRaises(ValueError):
            OccupancyGrid(resolution_m=0.0)
        with self.assertRaises(ValueError):
            OccupancyGrid(size_m=(-1.0, 2.0))


class DepthUpdateTest(unittest.TestCase):
    def test_wall_at_2_m_marks_one_column_of_cells(self):
        g = make_grid()
        depth = np.full((H, W), 2.0, dtype=np.float32)  # a wall at x = 2 m facing the camera
        stats = g.update_from_depth(depth, FX, FY, CX, CY, camera_pose(), floor_z=0.0,
                                    clearance_m=0.1, robot_height_m=0.4)
        # the wall's points span y = +-2 (31.5 / 40) = +-1.575 m: cells y = -1.6 .. 1.6
        expected = {(2.0, round(0.1 * k, 3)) for k in range(-16, 17)}
        self.assertEqual(cells_xy(g, g.occupied()), expected)
        self.assertEqual(stats["hit_cells"], 33)
        # rows whose points lie 0.1 .. 0.4 m above the floor: z = 0.3 - 2 (v - 23.5) / 40
        v = np.arange(H)
        z = CAMERA_HEIGHT - 2.0 * (v - CY) / FY
        self.assertEqual(stats["obstacle_points"], int(((z > 0.1) & (z < 0.4)).sum()) * W)
        i, j = g.cell_of([2.0, 0.0])
        self.assertAlmostEqual(g.log_odds[i, j], 0.85)
        self.assertAlmostEqual(g.probability()[i, j], 1.0 / (1.0 + math.exp(-0.85)))
        # cleared in front of the wall, unknown behind it, beside the view and behind the camera
        for x in (0.0, 0.5, 1.0, 1.5, 1.9):
            self.assertEqual(state_at(g, x, 0.0), "free", x)
        self.assertEqual(state_at(g, 1.0, 0.6), "free")
        for x, y in ((2.1, 0.0), (3.0, 0.0), (1.0, 1.5), (-1.0, 0.0), (0.0, 3.0)):
            self.assertEqual(state_at(g, x, y), "unknown", (x, y))
        self.assertFalse((g.occupied() & g.free()).any())

    def test_repeated_updates_saturate(self):
        g = make_grid()
        depth = np.full((H, W), 2.0, dtype=np.float32)
        for _ in range(10):
            g.update_from_depth(depth, FX, FY, CX, CY, camera_pose())
        i, j = g.cell_of([2.0, 0.0])
        self.assertEqual(g.log_odds[i, j], g.log_odds_max)
        i, j = g.cell_of([1.0, 0.0])
        self.assertEqual(g.log_odds[i, j], g.log_odds_min)

    def test_floor_only_clears_out_to_max_range(self):
        g = make_grid()
        yn = (np.arange(H) - CY) / FY
        # rows below the optical centre see the floor at z = 0: d = height / yn
        depth = np.where(yn > 0, CAMERA_HEIGHT / np.maximum(yn, 1e-9), 0.0)
        depth = np.repeat(depth[:, None], W, axis=1).astype(np.float32)
        stats = g.update_from_depth(depth, FX, FY, CX, CY, camera_pose(), max_range_m=4.0)
        self.assertEqual(stats["obstacle_points"], 0)
        self.assertFalse(g.occupied().any())
        for x in (0.5, 2.0, 3.5, 3.9):
            self.assertEqual(state_at(g, x, 0.0), "free", x)
        for x in (4.1, 4.5):
            self.assertEqual(state_at(g, x, 0.0), "unknown", x)

    def test_camera_turned_left_sees_wall_along_y(self):
        g = make_grid()
        depth = np.full((H, W), 2.0, dtype=np.float32)
        # the same camera turned 90 deg to the left, its pose given as (xyz, qwxyz)
        R = camera_pose(math.pi / 2)[:3, :3]
        q_WC = quat_of(R)
        np.testing.assert_allclose(quat_to_rotation(q_WC), R, atol=1e-12)
        g.update_from_depth(depth, FX, FY, CX, CY, ([0.0, 0.0, CAMERA_HEIGHT], q_WC))
        # image columns now run along world x: u = 0 (left) sees x = -1.575 m
        expected = {(round(0.1 * k, 3), 2.0) for k in range(-16, 17)}
        self.assertEqual(cells_xy(g, g.occupied()), expected)
        self.assertEqual(state_at(g, 0.0, 1.0), "free")
        self.assertEqual(state_at(g, 1.0, 0.0), "unknown")

    def test_points_above_robot_height_are_ignored(self):
        g = make_grid()
        # camera 1 m up; only the pixels whose wall points lie above 0.5 m have a return
        v = np.arange(H)
        z = 1.0 - 2.0 * (v - CY) / FY
        depth = np.where(z > 0.5, 2.0, 0.0)
        depth = np.repeat(depth[:, None], W, axis=1).astype(np.float32)
        stats = g.update_from_depth(depth, FX, FY, CX, CY, camera_pose(height=1.0),
                                    robot_height_m=0.4)
        self.assertEqual(stats["obstacle_points"], 0)
        self.assertEqual(stats["cleared_cells"], 0)
        self.assertTrue(g.unknown().all())

    def test_stride_and_no_hits(self):
        g = make_grid()
        depth = np.zeros((H, W), dtype=np.float32)
        depth[:, ::2] = np.nan
        stats = g.update_from_depth(depth, FX, FY, CX, CY, camera_pose(), stride=2)
        self.assertEqual(stats, {"obstacle_points": 0, "ground_points": 0, "hit_cells": 0,
                                 "cleared_cells": 0})
        depth = np.full((H, W), 2.0, dtype=np.float32)
        g.update_from_depth(depth, FX, FY, CX, CY, camera_pose(), stride=4)
        self.assertEqual(state_at(g, 2.0, 0.0), "occupied")
        with self.assertRaises(ValueError):
            g.update_from_depth(np.zeros(5), FX, FY, CX, CY, camera_pose())


if __name__ == "__main__":
    unittest.main()

"""penumbra_nav.planner: inflation, A* around walls, unknown cells at a cost."""

import math
import os
import sys
import unittest

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "python"))
from penumbra_nav.occupancy_grid import OccupancyGrid  # noqa: E402
from penumbra_nav.planner import (Planner, astar, build_cost_map, inflate,  # noqa: E402
                                  obstacle_distance, octile, path_length)

RES = 0.1
RADIUS = 0.3


def make_grid():
    # 10 m x 10 m at 0.1 m, cell centres on multiples of 0.1 m, every cell unknown
    return OccupancyGrid(resolution_m=RES, size_m=10.0, center_xy=(-0.05, -0.05))


def set_cells(grid, xs, ys, value):
    """Sets the log-odds of the cells holding the points (x, y) for x in xs, y in ys."""
    for x in np.atleast_1d(xs):
        for y in np.atleast_1d(ys):
            i, j = grid.cell_of([x, y])
            grid.log_odds[i, j] = value


def add_l_wall(grid):
    """An L: a wall along x = 1 from y = -2 to 2 and one along y = 2 from x = -1 to 1."""
    set_cells(grid, 1.0, np.arange(-2.0, 2.0 + 1e-9, RES), grid.log_odds_max)
    set_cells(grid, np.arange(-1.0, 1.0 + 1e-9, RES), 2.0, grid.log_odds_max)


def occupied_centres(grid):
    i, j = np.nonzero(grid.occupied())
    return grid.cell_center(i, j)


def min_clearance(path, centres):
    """Smallest distance (m) from any path point to any occupied cell centre."""
    d = np.hypot(path[:, None, 0] - centres[None, :, 0], path[:, None, 1] - centres[None, :, 1])
    return float(d.min())


class InflationTest(unittest.TestCase):
    def test_single_cell_inflates_to_a_disc(self):
        occ = np.zeros((9, 9), dtype=bool)
        occ[4, 4] = True
        # centres within 2 cells: offsets with di^2 + dj^2 <= 4
        self.assertEqual(int(inflate(occ, 2.0).sum()), 13)
        dist = obstacle_distance(occ, 3.0)
        self.assertEqual(dist[4, 4], 0.0)
        self.assertAlmostEqual(dist[4, 7], 3.0)
        self.assertAlmostEqual(dist[6, 6], math.sqrt(8))
        self.assertEqual(dist[0, 0], math.inf)  # beyond max_cells
        self.assertFalse(inflate(np.zeros((3, 3), dtype=bool), 5.0).any())

    def test_cost_map(self):
        occ = np.zeros((1, 12), dtype=bool)
        occ[0, 0] = True
        unknown = np.zeros_like(occ)
        unknown[0, 10] = True
        cm = build_cost_map(occ, unknown, 0.1, 0.3, unknown_cost=0.5, clearance_m=0.2,
                            clearance_cost=1.0)
        np.testing.assert_array_equal(cm.inflated[0], [True] * 4 + [False] * 8)
        # ramp: 1 - (d - 0.3) / 0.2 at d = 0.4, 0.5; none beyond
        np.testing.assert_allclose(cm.cost[0, 4:], [1.5, 1.0, 1, 1, 1, 1, 1.5, 1], atol=1e-12)


class AStarTest(unittest.TestCase):
    def test_empty_grid_gives_an_octile_shortest_path(self):
        passable = np.ones((10, 10), dtype=bool)
        cells = astar(passable, np.ones((10, 10)), (0, 0), (3, 5))
        self.assertEqual(cells[0], (0, 0))
        self.assertEqual(cells[-1], (3, 5))
        self.assertEqual(len(cells), 6)  # max(3, 5) moves
        steps = np.diff(np.array(cells), axis=0)
        self.assertAlmostEqual(sum(math.hypot(*s) for s in steps), octile(3, 5))

    def test_no_corner_cutting_and_no_path(self):
        passable = np.ones((3, 3), dtype=bool)
        passable[0, 1] = passable[1, 0] = False
        self.assertIsNone(astar(passable, np.ones((3, 3)), (0, 0), (2, 2)))
        passable[1, 0] = True
        cells = astar(passable, np.ones((3, 3)), (0, 0), (2, 2))
        # the diagonal (0, 0) -> (1, 1) would cut past the blocked (0, 1): down first
        self.assertEqual(cells[:2], [(0, 0), (1, 0)])
        self.assertEqual(cells[-1], (2, 2))
        steps = np.diff(np.array(cells), axis=0)
        self.assertAlmostEqual(sum(math.hypot(*s) for s in steps), 2 + math.sqrt(2))


class PlannerTest(unittest.TestCase):
    def test_goes_around_an_l_shaped_wall(self):
        g = make_grid()
        add_l_wall(g)
        planner = Planner(robot_radius_m=RADIUS)
        cm = planner.cost_map(g)
        start, goal = (-0.5, 0.0), (3.0, 0.0)
        path = planner.plan(g, start, goal, cost_map=cm)
        self.assertIsNotNone(path)
        np.testing.assert_allclose(path[0], start)
        np.testing.assert_allclose(path[-1], goal)
        # never through an inflated cell: every point more than the radius from the wall
        i, j = g.cell_of(path)
        self.assertFalse(cm.inflated[i, j].any())
        self.assertGreater(min_clearance(path, occupied_centres(g)), RADIUS)
        # neighbouring points are neighbouring cells (8-connected)
        steps = np.abs(np.diff(np.stack([i, j], axis=1), axis=0))
        self.assertLessEqual(int(steps.max()), 1)
        # around the open (lower) end of the wall, not over the closed top
        self.assertLess(path[:, 1].min(), -2.0 - RADIUS)
        self.assertLess(path[:, 1].max(), 2.0)
        # no shorter than the taut string past the wall's end, (1, -2.3): 2.75 + 3.05 m
        length = path_length(path)
        self.assertGreater(length, math.hypot(1.5, 2.3) + math.hypot(2.0, 2.3))
        self.assertLess(length, 7.5)
        self.assertIsNone(planner.first_blocked(path, g, cm))

    def test_unknown_cells_are_traversable_at_a_cost(self):
        g = make_grid()
        path = Planner(robot_radius_m=RADIUS).plan(g, (0.0, 0.0), (2.0, 0.0))
        np.testing.assert_allclose(path[:, 1], 0.0, atol=1e-12)
        self.assertAlmostEqual(path_length(path), 2.0)
        # a known-free detour 1 m to the side: taken only when unknown cells cost enough
        set_cells(g, 0.0, np.arange(0.0, 1.0 + 1e-9, RES), g.log_odds_min)
        set_cells(g, np.arange(0.0, 2.0 + 1e-9, RES), 1.0, g.log_odds_min)
        set_cells(g, 2.0, np.arange(0.0, 1.0 + 1e-9, RES), g.log_odds_min)
        cheap = Planner(robot_radius_m=RADIUS, unknown_cost=0.5).plan(g, (0.0, 0.0), (2.0, 0.0))
        self.assertAlmostEqual(float(np.abs(cheap[:, 1]).max()), 0.0)
        dear = Planner(robot_radius_m=RADIUS, unknown_cost=5.0).plan(g, (0.0, 0.0), (2.0, 0.0))
        self.assertAlmostEqual(float(dear[:, 1].max()), 1.0)
        i, j = g.cell_of(dear)
        self.assertTrue(g.free()[i, j].all())

    def test_enclosed_goal_has_no_path(self):
        g = make_grid()
        ring = np.linspace(0, 2 * math.pi, 200, endpoint=False)
        for a in ring:
            set_cells(g, 2.0 + 1.0 * math.cos(a), 1.0 * math.sin(a), g.log_odds_max)
        self.assertIsNone(Planner(robot_radius_m=RADIUS).plan(g, (-1.0, 0.0), (2.0, 0.0)))

    def test_goal_in_the_inflated_band_is_approached_within_tolerance(self):
        g = make_grid()
        set_cells(g, 2.0, np.arange(-2.0, 2.0 + 1e-9, RES), g.log_odds_max)
        planner = Planner(robot_radius_m=RADIUS)
        self.assertIsNone(planner.plan(g, (0.0, 0.0), (1.9, 0.0)))
        # the band reaches x = 1.7; the nearest free cell centre is (1.6, 0), 0.3 m away
        path = planner.plan(g, (0.0, 0.0), (1.9, 0.0), goal_tolerance_m=0.35)
        np.testing.assert_allclose(path[-1], [1.6, 0.0], atol=1e-9)
        self.assertGreater(min_clearance(path, occupied_centres(g)), RADIUS)

    def test_start_in_the_inflated_band_escapes_without_entering_obstacles(self):
        g = make_grid()
        set_cells(g, 1.0, np.arange(-2.0, 2.0 + 1e-9, RES), g.log_odds_max)
        planner = Planner(robot_radius_m=RADIUS)
        path = planner.plan(g, (0.8, 0.0), (-1.0, 0.0))
        self.assertIsNotNone(path)
        i, j = g.cell_of(path)
        self.assertFalse(g.occupied()[i, j].any())
        cm = planner.cost_map(g)
        # the robot's own spot is skipped; the rest of the path is clear
        self.assertIsNone(planner.first_blocked(path, g, cm, skip_radius_m=RADIUS,
                                                from_xy=(0.8, 0.0)))
        self.assertEqual(planner.first_blocked(path, g, cm), 0)

    def test_first_blocked_finds_a_new_obstacle_on_the_path(self):
        g = make_grid()
        planner = Planner(robot_radius_m=RADIUS)
        path = planner.plan(g, (0.0, 0.0), (3.0, 0.0))
        self.assertIsNone(planner.first_blocked(path, g, planner.cost_map(g)))
        # 0.2 m beside the path: blocks the points with |x - 2| <= sqrt(0.3^2 - 0.2^2) = 0.22
        set_cells(g, 2.0, 0.2, g.log_odds_max)
        k = planner.first_blocked(path, g, planner.cost_map(g))
        self.assertIsNotNone(k)
        self.assertAlmostEqual(path[k, 0], 1.8)
        self.assertEqual(planner.first_blocked(path, g, planner.cost_map(g), start_index=k), k)

    def test_start_or_goal_outside_the_grid(self):
        with self.assertRaises(ValueError):
            Planner().plan(make_grid(), (0.0, 0.0), (6.0, 0.0))


if __name__ == "__main__":
    unittest.main()

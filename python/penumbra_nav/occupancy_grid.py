"""A world-frame 2-D log-odds occupancy grid, updated from depth images.

Frames: the grid lies in the world frame W (REP-103: x forward, y left, z up) on a plane of
constant z; cell ``(i, j)`` is row ``i`` along world y and column ``j`` along world x, so
``log_odds[i, j]`` covers ``x in [x0 + j res, x0 + (j + 1) res)``, ``y in [y0 + i res, y0 +
(i + 1) res)`` with ``(x0, y0) = origin_xy``. Depth images are z-depth along the optical
axis of the camera's optical frame O (OpenCV: x right, y down, z forward), in metres, 0 = no
hit; ``X_WC`` is the pose of that optical frame in W.
"""

import math

import numpy as np

from .geometry import as_pose_matrix


class OccupancyGrid:
    """A fixed world-frame log-odds occupancy grid.

    Each update adds ``log_odds_hit`` to a cell that holds an obstacle point and
    ``log_odds_miss`` (negative) to a cell a camera ray crossed without an obstacle, at most
    once per cell and update, clamped to ``[log_odds_min, log_odds_max]``. A cell is
    occupied above ``occupied_threshold``, free below ``free_threshold`` and unknown in
    between (every cell starts at 0, unknown).

    :param resolution_m: cell edge, m.
    :param size_m: (x extent, y extent) of the grid, m (a number: a square); rounded up to
        whole cells.
    :param center_xy: world x, y (m) of the grid's centre.
    :param log_odds_hit: added per update to a cell holding an obstacle point (> 0).
    :param log_odds_miss: added per update to a cell cleared by a ray (< 0).
    :param log_odds_min: lower clamp.
    :param log_odds_max: upper clamp.
    :param occupied_threshold: log-odds above which a cell is occupied.
    :param free_threshold: log-odds below which a cell is free.
    """

    def __init__(self, resolution_m=0.05, size_m=16.0, center_xy=(0.0, 0.0),
                 log_odds_hit=0.85, log_odds_miss=-0.4, log_odds_min=-2.0, log_odds_max=3.5,
                 occupied_threshold=0.4, free_threshold=-0.2):
        if resolution_m <= 0:
            raise ValueError(f"resolution_m: {resolution_m}; must be > 0")
        sx, sy = (size_m, size_m) if np.isscalar(size_m) else size_m
        if sx <= 0 or sy <= 0:
            raise ValueError(f"size_m: {size_m}; must be > 0")
        self.resolution_m = float(resolution_m)
        #: cells along world x (columns) and world y (rows).
        self.nx = int(math.ceil(sx / resolution_m - 1e-9))
        self.ny = int(math.ceil(sy / resolution_m - 1e-9))
        #: world x, y (m) of the outer corner of cell (0, 0).
        self.origin_xy = np.array([center_xy[0] - 0.5 * self.nx * resolution_m,
                                   center_xy[1] - 0.5 * self.ny * resolution_m])
        self.log_odds_hit = float(log_odds_hit)
        self.log_odds_miss = float(log_odds_miss)
        self.log_odds_min = float(log_odds_min)
        self.log_odds_max = float(log_odds_max)
        self.occupied_threshold = float(occupied_threshold)
        self.free_threshold = float(free_threshold)
        #: (ny, nx) float64 log-odds of occupancy, 0 = unknown.
        self.log_odds = np.zeros((self.ny, self.nx))

    @property
    def shape(self):
        """(ny, nx): rows along world y, columns along world x."""
        return self.log_odds.shape

    # -- cells and world coordinates ---------------------------------------------------------

    def cell_of(self, xy):
        """Cell indices (i, j) of world points ``xy`` ((2,) or (N, 2), m) as int arrays; they
        may lie outside the grid (see :meth:`contains`)."""
        xy = np.asarray(xy, dtype=np.float64)
        ij = np.floor((xy - self.origin_xy) / self.resolution_m).astype(np.int64)
        return ij[..., 1], ij[..., 0]

    def contains(self, i, j):
        """True where cell (i, j) lies inside the grid."""
        i = np.asarray(i)
        j = np.asarray(j)
        return (i >= 0) & (i < self.ny) & (j >= 0) & (j < self.nx)

    def cell_center(self, i, j):
        """World x, y (m) of the centres of cells (i, j): shape (..., 2)."""
        i = np.asarray(i, dtype=np.float64)
        j = np.asarray(j, dtype=np.float64)
        return np.stack([self.origin_xy[0] + (j + 0.5) * self.resolution_m,
                         self.origin_xy[1] + (i + 0.5) * self.resolution_m], axis=-1)

    def contains_xy(self, xy):
        """True where world points ``xy`` (m) lie inside the grid."""
        return self.contains(*self.cell_of(xy))

    # -- cell states -------------------------------------------------------------------------

    def occupied(self):
        """(ny, nx) bool: log-odds above ``occupied_threshold``."""
        return self.log_odds > self.occupied_threshold

    def free(self):
        """(ny, nx) bool: log-odds below ``free_threshold``."""
        return self.log_odds < self.free_threshold

    def unknown(self):
        """(ny, nx) bool: neither occupied nor free."""
        return ~(self.occupied() | self.free())

    def probability(self):
        """(ny, nx) occupancy probability ``1 / (1 + exp(-log_odds))``."""
        return 1.0 / (1.0 + np.exp(-self.log_odds))

    # -- updates -----------------------------------------------------------------------------

    def _add(self, flat_cells, delta):
        lo = self.log_odds.reshape(-1)
        lo[flat_cells] = np.clip(lo[flat_cells] + delta, self.log_odds_min, self.log_odds_max)

    def _flat_in_grid(self, xy):
        i, j = self.cell_of(xy)
        inside = self.contains(i, j)
        return np.unique(i[inside] * self.nx + j[inside])

    def mark_occupied_xy(self, xy):
        """Applies one hit to the cells holding world points ``xy`` ((N, 2), m)."""
        self._add(self._flat_in_grid(np.reshape(xy, (-1, 2))), self.log_odds_hit)

    def mark_free_xy(self, xy):
        """Applies one miss to the cells holding world points ``xy`` ((N, 2), m)."""
        self._add(self._flat_in_grid(np.reshape(xy, (-1, 2))), self.log_odds_miss)

    def update_from_depth(self, depth, fx, fy, cx, cy, X_WC, floor_z=0.0, clearance_m=0.1,
                          robot_height_m=0.4, max_range_m=5.0, min_range_m=0.1, stride=1):
        """Integrates one depth image.

        Each pixel (u, v) with depth d > 0 back-projects to ``p_C = d ((u - cx) / fx,
        (v - cy) / fy, 1)`` in the optical frame and ``p_W = X_WC p_C`` in the world. With
        ``h = p_W.z - floor_z`` and ``rho`` the horizontal distance from the camera:

        - an obstacle point: ``clearance_m < h < robot_height_m`` and ``min_range_m <= rho
          <= max_range_m``; its cell gets a hit;
        - a ground point: ``h <= clearance_m``; points above ``robot_height_m`` are ignored
          (the robot passes under them);
        - free space, per image column: the column's horizontal ray (the bearing of its pixel
          on the optical centre's row) is cleared from the camera out to the nearest obstacle
          point of that column, or, without one, to its farthest ground point (at most
          ``max_range_m``), stopping half a cell short; cleared cells get a miss, except
          cells that got a hit in this update.

        :param depth: (H, W) float z-depth along the optical axis, m, 0 (or non-finite) = no
            hit.
        :param fx, fy, cx, cy: the camera's intrinsics, pixels (pixel centres at integer
            coordinates; pixel (u, v) is ``depth[v, u]``).
        :param X_WC: pose of the camera's optical frame in the world: a 4 x 4 matrix, a
            protocol pose map ``{"xyz", "qwxyz"}``, or an ``(xyz, qwxyz)`` pair.
        :param floor_z: world z of the ground under the robot, m.
        :param clearance_m: height above ``floor_z`` below which a point is ground, m.
        :param robot_height_m: height above ``floor_z`` from which a point is ignored, m.
        :param max_range_m: horizontal range of obstacle points and of free-space clearing, m.
        :param min_range_m: obstacle points nearer than this (horizontally) are ignored, m.
        :param stride: use every ``stride``-th row and column.
        :returns: a dict: ``obstacle_points``, ``ground_points``, ``hit_cells``,
            ``cleared_cells`` (ints).
        """
        depth = np.asarray(depth)
        if depth.ndim != 2:
            raise ValueError(f"depth: shape {depth.shape}; expected (H, W)")
        X = as_pose_matrix(X_WC)
        R, t = X[:3, :3], X[:3, 3]
        rows = np.arange(0, depth.shape[0], stride)
        cols = np.arange(0, depth.shape[1], stride)
        d = depth[np.ix_(rows, cols)].astype(np.float64)
        valid = np.isfinite(d) & (d > 0)
        d = np.where(valid, d, 0.0)

        # back-projection into the optical frame, then the world frame
        xn = (cols - cx) / fx
        yn = (rows - cy) / fy
        p_C = np.stack([d * xn[None, :], d * yn[:, None], d], axis=-1)
        p_W = p_C @ R.T + t
        rho = np.hypot(p_W[..., 0] - t[0], p_W[..., 1] - t[1])
        h = p_W[..., 2] - floor_z

        obstacle = (valid & (h > clearance_m) & (h < robot_height_m) &
                    (rho >= min_range_m) & (rho <= max_range_m))
        ground = valid & (h <= clearance_m)

        # per column: free out to the nearest obstacle, else to the farthest ground point
        nearest_obstacle = np.where(obstacle, rho, np.inf).min(axis=0)
        farthest_ground = np.where(ground, rho, 0.0).max(axis=0)
        free_range = np.where(np.isfinite(nearest_obstacle), nearest_obstacle,
                              np.minimum(farthest_ground, max_range_m))

        # each column's bearing: its optical ray through the centre row, in the world plane
        ray_W = np.stack([xn, np.zeros_like(xn), np.ones_like(xn)], axis=-1) @ R.T
        norm = np.hypot(ray_W[:, 0], ray_W[:, 1])
        has_bearing = norm > 1e-6
        bearing = ray_W[:, :2] / np.where(has_bearing, norm, 1.0)[:, None]
        step = 0.5 * self.resolution_m
        s = np.arange(int(math.ceil(max_range_m / step)) + 1) * step
        along = (s[None, :] < (free_range - 0.5 * self.resolution_m)[:, None]) & \
            has_bearing[:, None]
        free_xy = t[:2] + s[None, :, None] * bearing[:, None, :]

        hit = self._flat_in_grid(p_W[obstacle][:, :2])
        cleared = np.setdiff1d(self._flat_in_grid(free_xy[along]), hit, assume_unique=True)
        self._add(cleared, self.log_odds_miss)
        self._add(hit, self.log_odds_hit)
        return {"obstacle_points": int(obstacle.sum()), "ground_points": int(ground.sum()),
                "hit_cells": int(hit.size), "cleared_cells": int(cleared.size)}

"""Lookahead pure pursuit: a world-frame path and the robot's planar pose to a twist
``(vx, yaw_rate)``.

Frames: the path and the robot's position are world x, y in metres (REP-103 world frame W);
``yaw`` is the heading of the robot's base x axis, rad counter-clockwise from world x. The
twist is the protocol's: ``vx`` forward in m/s, ``yaw_rate`` counter-clockwise in rad/s.
"""

import math

import numpy as np

from .geometry import wrap_angle


def closest_point(path_xy, p, start_segment=0):
    """The point of a polyline nearest to ``p``, searching segments from ``start_segment``.

    :param path_xy: (N, 2) polyline, N >= 1, m.
    :param p: (2,) point, m.
    :returns: ``(segment, point, s)``: the segment index (0 .. N - 2; 0 for N = 1), the
        nearest point (2,), and its arc length from the path's start, m.
    """
    path = np.asarray(path_xy, dtype=np.float64)
    p = np.asarray(p, dtype=np.float64)
    if len(path) == 1:
        return 0, path[0].copy(), 0.0
    a = path[:-1]
    b = path[1:]
    ab = b - a
    seg_len2 = np.einsum("ij,ij->i", ab, ab)
    t = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.where(seg_len2 > 0, seg_len2, 1.0),
                0.0, 1.0)
    q = a + t[:, None] * ab
    d2 = np.einsum("ij,ij->i", q - p, q - p)
    first = min(max(0, int(start_segment)), len(a) - 1)
    k = first + int(np.argmin(d2[first:]))
    cumulative = np.concatenate([[0.0], np.cumsum(np.sqrt(seg_len2))])
    return k, q[k], float(cumulative[k] + t[k] * math.sqrt(seg_len2[k]))


def point_at(path_xy, s):
    """The point at arc length ``s`` (m) along a polyline, clamped to its ends."""
    path = np.asarray(path_xy, dtype=np.float64)
    if len(path) == 1:
        return path[0].copy()
    seg = np.hypot(*np.diff(path, axis=0).T)
    cumulative = np.concatenate([[0.0], np.cumsum(seg)])
    if s <= 0:
        return path[0].copy()
    if s >= cumulative[-1]:
        return path[-1].copy()
    k = int(np.searchsorted(cumulative, s, side="right") - 1)
    t = (s - cumulative[k]) / seg[k] if seg[k] > 0 else 0.0
    return path[k] + t * (path[k + 1] - path[k])


class PurePursuit:
    """Pure pursuit with speed limits and turning in place.

    Each call finds the path point nearest the robot (never moving back along the path),
    takes the lookahead point ``lookahead_m`` further along it (the path's end when closer),
    and with ``alpha`` the lookahead point's bearing in the robot frame and ``L`` its
    distance:

    - ``|alpha| > turn_in_place_rad``: ``vx = 0``, ``yaw_rate = clip(turn_gain * alpha)``;
    - else ``vx = max_speed_m_s`` (scaled down linearly within ``slowdown_m`` of the path's
      end, not below ``min_speed_m_s``), curvature ``kappa = 2 sin(alpha) / L``,
      ``yaw_rate = vx kappa``; when that exceeds ``max_yaw_rate_rad_s`` the yaw rate is
      clipped and ``vx`` reduced so the curvature is kept.

    :param lookahead_m: lookahead distance along the path, m.
    :param max_speed_m_s: forward speed limit, m/s.
    :param min_speed_m_s: forward speed floor while following (not turning in place), m/s.
    :param max_yaw_rate_rad_s: yaw-rate limit, rad/s.
    :param turn_in_place_rad: heading error above which the robot turns on the spot, rad.
    :param turn_gain: yaw rate per rad of heading error when turning in place, 1/s.
    :param slowdown_m: distance to the path's end over which the speed ramps down, m.
    """

    def __init__(self, lookahead_m=0.6, max_speed_m_s=0.4, min_speed_m_s=0.1,
                 max_yaw_rate_rad_s=1.0, turn_in_place_rad=math.radians(60), turn_gain=1.5,
                 slowdown_m=0.5):
        if lookahead_m <= 0:
            raise ValueError(f"lookahead_m: {lookahead_m}; must be > 0")
        self.lookahead_m = float(lookahead_m)
        self.max_speed_m_s = float(max_speed_m_s)
        self.min_speed_m_s = float(min_speed_m_s)
        self.max_yaw_rate_rad_s = float(max_yaw_rate_rad_s)
        self.turn_in_place_rad = float(turn_in_place_rad)
        self.turn_gain = float(turn_gain)
        self.slowdown_m = float(slowdown_m)
        self.path = None
        self._segment = 0
        #: the last lookahead point (world x, y, m), or None.
        self.target = None

    def set_path(self, path_xy):
        """Follows a new path ((N, 2) world x, y, m) from its start."""
        self.path = np.asarray(path_xy, dtype=np.float64).reshape(-1, 2)
        self._segment = 0
        self.target = None

    @property
    def progress_index(self):
        """The index of the first path point of the segment the robot is on."""
        return self._segment

    def remaining_m(self, xy):
        """Path length (m) from the point nearest ``xy`` to the path's end."""
        _, _, s = closest_point(self.path, xy, self._segment)
        total = float(np.hypot(*np.diff(self.path, axis=0).T).sum()) if len(self.path) > 1 \
            else 0.0
        return total - s

    def command(self, xy, yaw):
        """The twist ``(vx, yaw_rate)`` (m/s, rad/s) for the robot at world ``xy`` (m) with
        heading ``yaw`` (rad); (0, 0) without a path."""
        if self.path is None or len(self.path) == 0:
            return 0.0, 0.0
        xy = np.asarray(xy, dtype=np.float64)
        self._segment, _, s = closest_point(self.path, xy, self._segment)
        target = point_at(self.path, s + self.lookahead_m)
        self.target = target
        d = target - xy
        dist = math.hypot(d[0], d[1])
        if dist < 1e-9:
            return 0.0, 0.0
        alpha = wrap_angle(math.atan2(d[1], d[0]) - yaw)
        if abs(alpha) > self.turn_in_place_rad:
            w = max(-self.max_yaw_rate_rad_s, min(self.max_yaw_rate_rad_s,
                                                    self.turn_gain * alpha))
            return 0.0, w
        remaining = self.remaining_m(xy)
        vx = self.max_speed_m_s
        if self.slowdown_m > 0:
            vx *= min(1.0, remaining / self.slowdown_m)
        vx = max(self.min_speed_m_s, min(self.max_speed_m_s, vx))
        kappa = 2.0 * math.sin(alpha) / dist
        w = vx * kappa
        if abs(w) > self.max_yaw_rate_rad_s:
            w = math.copysign(self.max_yaw_rate_rad_s, w)
            vx = abs(w / kappa)
        return vx, w

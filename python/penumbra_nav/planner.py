"""A* on an inflated occupancy grid: 8-connected, octile heuristic, world-frame paths.

Cells are those of :class:`penumbra_nav.occupancy_grid.OccupancyGrid` (row i along world y,
column j along world x); paths are (N, 2) arrays of world x, y in metres (REP-103 world
frame W).
"""

import heapq
import math

import numpy as np

SQRT2 = math.sqrt(2.0)

# 8-connected moves: (di, dj, length in cells)
_MOVES = ((-1, -1, SQRT2), (-1, 0, 1.0), (-1, 1, SQRT2), (0, -1, 1.0),
          (0, 1, 1.0), (1, -1, SQRT2), (1, 0, 1.0), (1, 1, SQRT2))


def octile(di, dj):
    """The octile distance of a cell offset (cells): the length of the shortest
    8-connected path on an empty grid."""
    a, b = abs(di), abs(dj)
    return max(a, b) + (SQRT2 - 1.0) * min(a, b)


def obstacle_distance(occupied, max_cells):
    """Euclidean distance (cells, between cell centres) from every cell to the nearest
    occupied cell, exact up to ``max_cells`` and ``inf`` beyond.

    :param occupied: (ny, nx) bool.
    :param max_cells: the largest distance of interest, cells.
    :returns: (ny, nx) float64; 0 on occupied cells.
    """
    occupied = np.asarray(occupied, dtype=bool)
    ny, nx = occupied.shape
    dist = np.full(ny * nx, np.inf)
    oi, oj = np.nonzero(occupied)
    if oi.size == 0:
        return dist.reshape(ny, nx)
    r = int(math.floor(max_cells))
    di, dj = np.mgrid[-r:r + 1, -r:r + 1]
    d = np.hypot(di, dj)
    keep = d <= max_cells
    di, dj, d = di[keep], dj[keep], d[keep]
    ti = oi[:, None] + di[None, :]
    tj = oj[:, None] + dj[None, :]
    inside = (ti >= 0) & (ti < ny) & (tj >= 0) & (tj < nx)
    dd = np.broadcast_to(d[None, :], ti.shape)
    np.minimum.at(dist, (ti * nx + tj)[inside], dd[inside])
    return dist.reshape(ny, nx)


def inflate(occupied, radius_cells):
    """(ny, nx) bool: cells whose centre lies within ``radius_cells`` (cells, centre to
    centre) of an occupied cell's centre; occupied cells included."""
    return obstacle_distance(occupied, radius_cells) <= radius_cells


class CostMap:
    """What A* searches: which cells are passable and what a metre through each costs.

    :ivar occupied: (ny, nx) bool, the grid's occupied cells (never passable).
    :ivar inflated: (ny, nx) bool, cells within the inflation radius of an occupied cell
        (occupied ones included): where the robot's centre must not go.
    :ivar cost: (ny, nx) float64 >= 1, cost per metre of a cell (1 = known free, far from
        obstacles).
    :ivar resolution_m: cell edge, m.
    """

    def __init__(self, occupied, inflated, cost, resolution_m):
        self.occupied = occupied
        self.inflated = inflated
        self.cost = cost
        self.resolution_m = resolution_m


def build_cost_map(occupied, unknown, resolution_m, inflation_radius_m, unknown_cost=0.5,
                   clearance_m=0.2, clearance_cost=1.0):
    """Inflates the obstacles and prices the cells.

    A cell is inflated when its centre lies within ``inflation_radius_m`` (centre to centre)
    of an occupied cell. The cost per metre of the other cells is ``1 + unknown_cost`` (if
    unknown) ``+ clearance_cost * (1 - (dist - inflation_radius_m) / clearance_m)`` for
    cells whose distance ``dist`` to the nearest occupied cell is less than
    ``inflation_radius_m + clearance_m`` (a ramp that keeps paths off the inflated band).

    :param occupied: (ny, nx) bool.
    :param unknown: (ny, nx) bool, or None (all known).
    :param resolution_m: cell edge, m.
    :param inflation_radius_m: the robot's radius, m.
    :param unknown_cost: extra cost per metre through an unknown cell (>= 0).
    :param clearance_m: width of the cost ramp outside the inflated band, m (0 = none).
    :param clearance_cost: extra cost per metre at the inner edge of the ramp (>= 0).
    :returns: a :class:`CostMap`.
    """
    occupied = np.asarray(occupied, dtype=bool)
    reach = (inflation_radius_m + max(0.0, clearance_m)) / resolution_m
    dist = obstacle_distance(occupied, reach) * resolution_m
    inflated = dist <= inflation_radius_m + 1e-9
    cost = np.ones(occupied.shape)
    if unknown is not None:
        cost += unknown_cost * np.asarray(unknown, dtype=bool)
    if clearance_m > 0 and clearance_cost > 0:
        ramp = np.clip(1.0 - (dist - inflation_radius_m) / clearance_m, 0.0, 1.0)
        cost += clearance_cost * np.where(inflated, 0.0, ramp)
    return CostMap(occupied, inflated, cost, resolution_m)


def astar(passable, cost, start, goal, goal_tolerance_cells=0.0):
    """A* from cell ``start`` to cell ``goal`` (or to the first cell within
    ``goal_tolerance_cells`` octile distance of it).

    8-connected; a diagonal move needs both cells it cuts past to be passable. A move
    between neighbours a and b costs ``length * (cost[a] + cost[b]) / 2`` (length 1 or
    sqrt 2 cells); the heuristic is the octile distance to the goal minus the tolerance,
    admissible because every cost is >= 1.

    :param passable: (ny, nx) bool.
    :param cost: (ny, nx) float >= 1, cost per cell length.
    :param start: (i, j) cell; searched even when not passable itself.
    :param goal: (i, j) cell.
    :param goal_tolerance_cells: octile radius of the goal region, cells.
    :returns: the list of (i, j) cells from start to the reached cell, or None.
    """
    ny, nx = passable.shape
    pas = np.asarray(passable, dtype=bool).ravel().tolist()
    cst = np.asarray(cost, dtype=np.float64).ravel().tolist()
    si, sj = int(start[0]), int(start[1])
    gi, gj = int(goal[0]), int(goal[1])
    s = si * nx + sj
    tol = float(goal_tolerance_cells)
    g_score = {s: 0.0}
    came_from = {}
    closed = bytearray(ny * nx)
    heap = [(max(0.0, octile(si - gi, sj - gj) - tol), 0.0, s)]
    while heap:
        _, g, c = heapq.heappop(heap)
        if closed[c]:
            continue
        closed[c] = 1
        i, j = divmod(c, nx)
        if octile(i - gi, j - gj) <= tol + 1e-9:
            path = [(i, j)]
            while c in came_from:
                c = came_from[c]
                path.append(divmod(c, nx))
            path.reverse()
            return path
        cc = cst[c]
        for di, dj, length in _MOVES:
            ni, nj = i + di, j + dj
            if ni < 0 or ni >= ny or nj < 0 or nj >= nx:
                continue
            n = ni * nx + nj
            if closed[n] or not pas[n]:
                continue
            if di and dj and not (pas[i * nx + nj] and pas[ni * nx + j]):
                continue
            ng = g + length * 0.5 * (cc + cst[n])
            if ng < g_score.get(n, math.inf):
                g_score[n] = ng
                came_from[n] = c
                h = octile(ni - gi, nj - gj) - tol
                heapq.heappush(heap, (ng + (h if h > 0.0 else 0.0), ng, n))
    return None


def path_length(path_xy):
    """Length (m) of a polyline (N, 2)."""
    p = np.asarray(path_xy, dtype=np.float64)
    if len(p) < 2:
        return 0.0
    return float(np.hypot(*np.diff(p, axis=0).T).sum())


class Planner:
    """A* point-goal planner on an :class:`~penumbra_nav.occupancy_grid.OccupancyGrid`.

    Occupied cells are inflated by ``robot_radius_m`` (the robot is a disc); the robot's
    centre never enters an inflated cell, except to leave the inflated band when it starts
    inside one (then inflated, non-occupied cells cost ``escape_cost`` extra per metre).
    Unknown cells are traversable at ``unknown_cost`` extra per metre.

    :param robot_radius_m: inflation radius, m.
    :param unknown_cost: extra cost per metre through an unknown cell.
    :param clearance_m: width of the cost ramp outside the inflated band, m.
    :param clearance_cost: extra cost per metre at the ramp's inner edge.
    :param escape_cost: extra cost per metre through the inflated band when starting in it.
    """

    def __init__(self, robot_radius_m=0.3, unknown_cost=0.5, clearance_m=0.2,
                 clearance_cost=1.0, escape_cost=20.0):
        self.robot_radius_m = float(robot_radius_m)
        self.unknown_cost = float(unknown_cost)
        self.clearance_m = float(clearance_m)
        self.clearance_cost = float(clearance_cost)
        self.escape_cost = float(escape_cost)

    def cost_map(self, grid):
        """The :class:`CostMap` of the grid's current state."""
        return build_cost_map(grid.occupied(), grid.unknown(), grid.resolution_m,
                              self.robot_radius_m, self.unknown_cost, self.clearance_m,
                              self.clearance_cost)

    def plan(self, grid, start_xy, goal_xy, goal_tolerance_m=0.0, cost_map=None):
        """A world-frame path from ``start_xy`` to ``goal_xy`` (m).

        :param grid: the occupancy grid (start and goal must lie inside it).
        :param goal_tolerance_m: the search stops at the first cell whose centre lies within
            this octile distance of the goal's cell (so a goal inside the inflated band is
            approached as closely as the band allows).
        :param cost_map: a :class:`CostMap` of ``grid`` (default: built now).
        :returns: (N, 2) float64 world x, y: the start, the centres of the cells between, and
            the goal itself when its own cell was reached (else the last cell's centre); or
            None when no path exists.
        :raises ValueError: start or goal outside the grid.
        """
        cm = cost_map or self.cost_map(grid)
        start = grid.cell_of(start_xy)
        goal = grid.cell_of(goal_xy)
        for name, c in (("start", start), ("goal", goal)):
            if not grid.contains(*c):
                raise ValueError(f"{name} {start_xy if name == 'start' else goal_xy} lies "
                                 "outside the occupancy grid")
        start = (int(start[0]), int(start[1]))
        goal = (int(goal[0]), int(goal[1]))
        passable = ~cm.inflated
        cost = cm.cost
        if cm.inflated[start]:
            passable = ~cm.occupied
            cost = cost + self.escape_cost * (cm.inflated & ~cm.occupied)
        cells = astar(passable, cost, start, goal,
                      goal_tolerance_m / grid.resolution_m if goal_tolerance_m else 0.0)
        if cells is None:
            return None
        ij = np.array(cells)
        path = grid.cell_center(ij[:, 0], ij[:, 1])
        path[0] = start_xy
        if cells[-1] == goal and len(cells) > 1:
            path[-1] = goal_xy
        elif cells[-1] == goal:
            path = np.vstack([path, np.asarray(goal_xy, dtype=np.float64)])
        return path

    def first_blocked(self, path_xy, grid, cost_map, skip_radius_m=0.0, from_xy=None,
                      start_index=0):
        """Index of the first point of ``path_xy`` from ``start_index`` on that lies in an
        inflated cell of ``cost_map``, or None.

        :param skip_radius_m: points within this distance (m) of ``from_xy`` (the robot's
            world x, y) are not checked: the robot may stand in the band it is leaving.
        """
        p = np.asarray(path_xy, dtype=np.float64)[start_index:]
        i, j = grid.cell_of(p)
        inside = grid.contains(i, j)
        bad = np.zeros(len(p), dtype=bool)
        bad[inside] = cost_map.inflated[i[inside], j[inside]]
        if from_xy is not None and skip_radius_m > 0:
            bad &= np.hypot(p[:, 0] - from_xy[0], p[:, 1] - from_xy[1]) > skip_radius_m
        idx = np.flatnonzero(bad)
        return int(idx[0]) + start_index if idx.size else None

"""A classical point-goal navigator for Penumbra's mobile robots, run as an external process
over the ZeroMQ bridge (docs/navigation.md).

Depth camera -> world-frame log-odds occupancy grid (:mod:`.occupancy_grid`) -> A* on the
inflated grid (:mod:`.planner`) -> pure pursuit to a twist (:mod:`.pure_pursuit`), in a
lockstep loop (:mod:`.navigator`). Pure Python on Debian's python3-numpy, python3-zmq and
python3-msgpack, with the client in ``python/penumbra_client``.

    python3 -m penumbra_nav --endpoint tcp://127.0.0.1:5555 --goal 3 0 --robot quadruped \\
        --out episode.json
"""

from .contacts import ContactLog
from .navigator import Navigator, NavigatorConfig, write_episode
from .occupancy_grid import OccupancyGrid
from .planner import CostMap, Planner, astar, build_cost_map, inflate, obstacle_distance
from .pure_pursuit import PurePursuit
from .robots import PROFILES, QUADRUPED, ROVER, RobotProfile

__all__ = [
    "ContactLog", "Navigator", "NavigatorConfig", "write_episode", "OccupancyGrid", "CostMap",
    "Planner", "astar", "build_cost_map", "inflate", "obstacle_distance", "PurePursuit",
    "PROFILES", "QUADRUPED", "ROVER", "RobotProfile",
]

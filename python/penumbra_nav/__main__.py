"""Command line: ``python3 -m penumbra_nav --goal X Y [options]`` (docs/navigation.md).

Exit status: 0 the goal was reached, 1 the episode ended otherwise (timeout, fall, the run
ended), 2 bad arguments, a world the navigator cannot drive, or a server that did not answer
or refused a request (the message says which).
"""

import argparse
import sys

from penumbra_client import Client, PenumbraError

from .navigator import Navigator, NavigatorConfig, write_episode
from .robots import PROFILES


def parse_args(argv=None):
    """The parsed command line (argparse namespace)."""
    p = argparse.ArgumentParser(
        prog="python3 -m penumbra_nav",
        description="Point-goal navigation over a lockstep `penumbra run WORLD --zmq "
                    "--lockstep`: depth camera -> occupancy grid -> A* -> pure pursuit.")
    p.add_argument("--endpoint", default="tcp://127.0.0.1:5555", help="command endpoint")
    p.add_argument("--goal", nargs=2, type=float, required=True, metavar=("X", "Y"),
                   help="goal in the world frame, m")
    p.add_argument("--radius", type=float, default=0.5,
                   help="success when the base origin is this close to the goal, m (0.5)")
    p.add_argument("--timeout", type=float, default=60.0,
                   help="episode limit in sim seconds (60)")
    p.add_argument("--robot", choices=sorted(PROFILES), default="quadruped",
                   help="robot profile (quadruped)")
    p.add_argument("--robot-name", help="the world's name of the robot (default: the only "
                   "controller that takes twists)")
    p.add_argument("--camera", help="depth camera (default: the first with depth)")
    p.add_argument("--out", default="-", help="episode JSON file ('-' = stdout)")
    p.add_argument("--control-period", type=float,
                   help="s per control period (default: one frame period of the camera)")
    p.add_argument("--replan-every", type=int, default=5, help="control periods (5)")
    p.add_argument("--resolution", type=float, default=0.05, help="grid cell, m (0.05)")
    p.add_argument("--grid-size", type=float,
                   help="grid edge, m (default: max(12, 2 d + 6) for a goal d m away)")
    p.add_argument("--max-range", type=float, default=4.0, help="depth range used, m (4)")
    p.add_argument("--pixel-stride", type=int,
                   help="use every n-th depth row and column (default: ceil(width / 160))")
    p.add_argument("--robot-radius", type=float, help="inflation radius, m (profile)")
    p.add_argument("--unknown-cost", type=float, default=0.5,
                   help="extra cost per metre through unknown cells (0.5)")
    p.add_argument("--lookahead", type=float, default=0.6, help="pure pursuit lookahead, m")
    p.add_argument("--max-speed", type=float, help="m/s (profile)")
    p.add_argument("--max-yaw-rate", type=float, help="rad/s (profile)")
    p.add_argument("--floor-z", type=float,
                   help="world z of the floor, m (default: base z minus its standing height)")
    p.add_argument("--no-contacts", action="store_true",
                   help="do not subscribe to and log contacts")
    p.add_argument("--reset", action="store_true", help="reset the run before the episode")
    p.add_argument("--stop", action="store_true", help="end the run (`stop`) afterwards")
    p.add_argument("--trace", help="write one JSON line per control period to this file")
    p.add_argument("--request-timeout", type=float, default=60.0,
                   help="s to wait for each reply (60)")
    p.add_argument("--verbose", "-v", action="store_true", help="progress on stderr")
    return p.parse_args(argv)


def main(argv=None):
    """Runs one episode; returns the exit status."""
    a = parse_args(argv)
    config = NavigatorConfig(
        goal_xy=(a.goal[0], a.goal[1]), goal_radius_m=a.radius, timeout_sec=a.timeout,
        robot=a.robot, robot_name=a.robot_name, camera=a.camera,
        control_period_sec=a.control_period, replan_every=a.replan_every,
        resolution_m=a.resolution, grid_size_m=a.grid_size, max_range_m=a.max_range,
        pixel_stride=a.pixel_stride, robot_radius_m=a.robot_radius,
        unknown_cost=a.unknown_cost, lookahead_m=a.lookahead, max_speed_m_s=a.max_speed,
        max_yaw_rate_rad_s=a.max_yaw_rate, floor_z=a.floor_z, log_contacts=not a.no_contacts,
        reset=a.reset)
    trace = open(a.trace, "w") if a.trace else None
    try:
        with Client(a.endpoint, timeout_sec=a.request_timeout, name="penumbra_nav") as client:
            nav = Navigator(client, config, log=sys.stderr if a.verbose else None, trace=trace)
            episode = nav.run()
            write_episode(episode, a.out)
            if a.stop:
                try:
                    client.stop()
                except PenumbraError:
                    pass  # the run had ended already
    except ValueError as e:
        print(f"penumbra_nav: {e}", file=sys.stderr)
        return 2
    except PenumbraError as e:
        print(f"penumbra_nav: {type(e).__name__}: {e}", file=sys.stderr)
        return 2
    finally:
        if trace is not None:
            trace.close()
    return 0 if episode["success"] else 1


if __name__ == "__main__":
    sys.exit(main())

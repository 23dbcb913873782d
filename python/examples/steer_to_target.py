#!/usr/bin/python3
"""Closed loop over the ZeroMQ bridge: steer the quadruped toward the red target it sees.

Start the world in lockstep, then this script (from the repository root):

    ./build/penumbra run worlds/quadruped_target.yaml --zmq --lockstep --out out --force &
    /usr/bin/python3 python/examples/steer_to_target.py

Each control period (one frame of the nose camera `front`, 0.1 s) it

1. takes the newest RGB and depth images (numpy arrays, from the sensor stream),
2. segments the target: pixels whose sRGB red exceeds 100 and twice green and blue,
3. turns the target's mean image column u into a bearing: the optical frame's x axis points
   right, so the target lies ``atan((u - cx) / fx)`` to the right of the optical axis,
4. sends a twist to the trot_gait controller: ``yaw_rate = -k_yaw * bearing`` (counter-
   clockwise positive, so a target on the right turns the robot right), ``vx`` = cruise speed
   scaled down while the bearing is large; no target in view: turn in place to search,
5. stops when the median depth (z along the optical axis, m) of the target's pixels is
   below ``--stop-distance``.

It prints one JSON object: the number of control periods, whether it arrived, the last
seen depth and bearing, the sim time. Nothing here knows where the target is: only images.

On exit, also on Ctrl-C (SIGINT) or SIGTERM, it sends ``stop`` to the server, which then writes
its outputs and exits (as on Ctrl-C); ``--leave-running`` keeps the server running instead.
Exit status: 0 arrived, 1 not arrived, 130 / 143 interrupted.
"""

import argparse
import json
import math
import os
import signal
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), ".."))
from penumbra_client import Client, PenumbraError  # noqa: E402


def find_target(rgb, min_pixels=4):
    """Mask and mean column of the red target in an sRGB uint8 (H, W, 3) image, or
    (mask, None) when fewer than ``min_pixels`` pixels are red."""
    r = rgb[..., 0].astype(np.int32)
    g = rgb[..., 1].astype(np.int32)
    b = rgb[..., 2].astype(np.int32)
    mask = (r > 100) & (r > 2 * g) & (r > 2 * b)
    if mask.sum() < min_pixels:
        return mask, None
    _, cols = np.nonzero(mask)
    return mask, float(cols.mean())


def steer(client, camera="front", cruise_m_s=0.4, k_yaw=1.5, max_yaw_rate=1.0,
          search_yaw_rate=0.6, stop_distance_m=0.8, max_periods=300):
    """Runs the loop above on a connected :class:`penumbra_client.Client` (lockstep run).
    Returns a dict summary (see the module docstring)."""
    info = client.model_info()
    cam = info.camera(camera)
    fx, cx = cam["fx"], cam["cx"]
    steps = max(1, int(round(1.0 / (cam["rate_hz"] * info.timestep_sec))))
    rgb_topic, depth_topic = f"camera/{camera}/rgb", f"camera/{camera}/depth"
    client.subscribe([rgb_topic, depth_topic])

    rgb = depth = None
    bearing = distance = None
    arrived = False
    periods = 0
    time_sec = None
    for periods in range(1, max_periods + 1):
        if rgb is None:
            vx, yaw_rate = 0.0, 0.0
        else:
            mask, u = find_target(rgb)
            if u is None:
                vx, yaw_rate, bearing = 0.0, search_yaw_rate, None
            else:
                bearing = math.atan((u - cx) / fx)  # rad, positive = target on the right
                distance = float(np.median(depth[mask])) if depth is not None else None
                if distance is not None and 0 < distance < stop_distance_m:
                    arrived = True
                    client.twist(0.0, 0.0, 0.0)
                    break
                yaw_rate = float(np.clip(-k_yaw * bearing, -max_yaw_rate, max_yaw_rate))
                vx = cruise_m_s * max(0.0, math.cos(2.0 * bearing))
        client.twist(vx, 0.0, yaw_rate)
        r = client.step(steps)
        time_sec = r.time_sec
        if r.latest(rgb_topic) is not None:
            rgb = r.latest(rgb_topic).image()
        if r.latest(depth_topic) is not None:
            depth = r.latest(depth_topic).image()
        if r.ended:
            break
    return {"periods": periods, "arrived": arrived, "distance_m": distance,
            "bearing_rad": bearing, "time_sec": time_sec}


def main(argv=None):
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--endpoint", default="tcp://127.0.0.1:5555", help="command endpoint")
    p.add_argument("--camera", default="front")
    p.add_argument("--stop-distance", type=float, default=0.8, help="m")
    p.add_argument("--max-periods", type=int, default=300, help="control periods (frames)")
    p.add_argument("--timeout", type=float, default=60.0, help="s per request")
    p.add_argument("--leave-running", action="store_true",
                   help="do not stop the server on exit (default: send it `stop`)")
    args = p.parse_args(argv)

    # SIGTERM ends the loop as Ctrl-C does, so that the server is stopped either way
    got = {"signal": signal.SIGINT}

    def on_sigterm(signum, frame):
        got["signal"] = signum
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, on_sigterm)
    status = 130
    with Client(args.endpoint, timeout_sec=args.timeout, name="steer_to_target") as c:
        try:
            result = steer(c, camera=args.camera, stop_distance_m=args.stop_distance,
                           max_periods=args.max_periods)
            print(json.dumps(result))
            status = 0 if result["arrived"] else 1
        except KeyboardInterrupt:
            status = 128 + int(got["signal"])
            print("steer_to_target: interrupted", file=sys.stderr)
        finally:
            if not args.leave_running:
                stop_server(c)
    return status


def stop_server(client):
    """Sends ``stop`` (the server writes its outputs and exits); an interrupted request's late
    reply is skipped by its id. A server that is gone already is not an error."""
    client.timeout_sec = 10.0
    try:
        r = client.stop()
        print(f"steer_to_target: stopped the server at {r.get('time_sec', 0):.3f} s of sim time",
              file=sys.stderr)
    except PenumbraError as e:
        print(f"steer_to_target: could not stop the server: {e}", file=sys.stderr)


if __name__ == "__main__":
    sys.exit(main())

#!/usr/bin/env python3
"""Walks an exported policy (ONNX through OpenCV's dnn) around a waypoint loop in a world's
composed scene, with the velocity command of each policy step from pure pursuit of the next
waypoint: forward speed `--speed` scaled by the cosine of the heading error (0 when it
exceeds 90 deg), yaw rate 2 x the heading error clamped to `--max-yaw-rate-deg`. A check of
the policy in the furnished room of worlds/default.yaml before the `policy` controller runs it
there (worlds/quadruped_policy.yaml); its own pursuit law, not the controller's.

    penumbra run worlds/default.yaml --duration 0.004 --out /tmp/room   # writes composed.xml
    PYTHONPATH=build/python:python /usr/bin/python3 train/waypoint_check.py \
        worlds/models/policies/go1_velocity.onnx /tmp/room/composed.xml --seconds 60
"""

import argparse
import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
from penumbra_rollout import QuadrupedEnvConfig, QuadrupedVelocityEnv  # noqa: E402

DEFAULT_LOOP = "1.3,-1.0;1.9,0.0;1.4,1.0;0.0,1.6;-1.6,1.35;-2.5,0.1;-1.8,-1.2;-0.2,-1.45"


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("policy")
    p.add_argument("model", help="a world's composed.xml")
    p.add_argument("--name-prefix", default="go1/")
    p.add_argument("--waypoints", default=DEFAULT_LOOP, help="';'-separated x,y (m), looped")
    p.add_argument("--speed", type=float, default=0.45)
    p.add_argument("--max-yaw-rate-deg", type=float, default=55.0)
    p.add_argument("--tolerance", type=float, default=0.15)
    p.add_argument("--seconds", type=float, default=60.0)
    p.add_argument("--seed", type=int, default=0)
    args = p.parse_args()

    import cv2
    net = cv2.dnn.readNetFromONNX(args.policy)
    wps = [tuple(float(v) for v in w.split(",")) for w in args.waypoints.split(";")]
    cfg = QuadrupedEnvConfig(model_path=args.model, name_prefix=args.name_prefix, num_threads=1,
                             add_noise=False, spawn_at_model_pose=True, spawn_height=0.35,
                             episode_length_s=args.seconds + 1.0)
    env = QuadrupedVelocityEnv(1, cfg, seed=args.seed)
    cmd = np.zeros((1, 3))
    obs, _ = env.reset(options={"commands": cmd})
    k, reached, path = 0, 0, 0.0
    last = env.base_pos[0, :2].copy()
    max_wz = math.radians(args.max_yaw_rate_deg)
    min_up = 1.0
    for step in range(int(round(args.seconds / env.dt))):
        pos = env.base_pos[0, :2]
        q = env.base_quat[0]
        yaw = math.atan2(2 * (q[0] * q[3] + q[1] * q[2]), 1 - 2 * (q[2] ** 2 + q[3] ** 2))
        dx, dy = wps[k][0] - pos[0], wps[k][1] - pos[1]
        if math.hypot(dx, dy) < args.tolerance:
            reached += 1
            k = (k + 1) % len(wps)
            dx, dy = wps[k][0] - pos[0], wps[k][1] - pos[1]
        err = (math.atan2(dy, dx) - yaw + math.pi) % (2 * math.pi) - math.pi
        env.fixed_commands[0] = (args.speed * max(0.0, math.cos(err)), 0.0,
                                 max(-max_wz, min(max_wz, 2.0 * err)))
        env.commands[0] = env.fixed_commands[0]
        obs = env._observe()  # the observation with this step's command
        net.setInput(obs)
        obs, _, term, _, _ = env.step(net.forward().astype(np.float64))
        if term[0]:
            print(f"FELL at {(step + 1) * env.dt:.2f} s after {reached} waypoints, {path:.2f} m")
            sys.exit(1)
        path += float(np.linalg.norm(env.base_pos[0, :2] - last))
        last = env.base_pos[0, :2].copy()
        min_up = min(min_up, -env.projected_gravity[0, 2])
    print(f"{args.seconds:.0f} s: {reached} waypoints reached ({reached / len(wps):.2f} laps), "
          f"{path:.2f} m walked, no fall, trunk tilt at most "
          f"{math.degrees(math.acos(min_up)):.1f} deg")


if __name__ == "__main__":
    main()

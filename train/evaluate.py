#!/usr/bin/env python3
"""Velocity-tracking evaluation of an exported policy (ONNX, run through OpenCV's dnn module as
the `type: policy` controller runs it) on flat ground, in the training scene's physics.

For each command (default: 0.5 m/s forward; 0.5 rad/s yaw; both together) and each seed it
runs one episode of --seconds (default 10 s) from the training reset distribution (seeded),
with no observation noise, and measures in the body frame the mean forward speed vx, lateral
vy and yaw rate wz over the episode after the first --settle seconds, and whether the robot
fell (trunk contact or tilt past the training limit). A seed passes when it did not fall and
each commanded non-zero component is tracked within --tolerance (relative; 20 %) and each
zero component within tolerance x 0.5 (absolute, m/s or rad/s).

    PYTHONPATH=build/python:python /usr/bin/python3 train/evaluate.py \
        models/policies/go1_velocity.onnx --seeds 10 --json eval.json
"""

import argparse
import json
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
from penumbra_rollout import QuadrupedEnvConfig, QuadrupedVelocityEnv  # noqa: E402


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("policy", help="policy.onnx (input obs (1, 48), output actions (1, 12))")
    p.add_argument("--seeds", type=int, default=10)
    p.add_argument("--seconds", type=float, default=10.0)
    p.add_argument("--settle", type=float, default=1.0, help="seconds left out of the means")
    p.add_argument("--tolerance", type=float, default=0.2)
    p.add_argument("--commands", default="0.5,0,0;0,0,0.5;0.5,0,0.5",
                   help="';'-separated vx,vy,wz commands")
    p.add_argument("--threads", type=int, default=0)
    p.add_argument("--model", default="", help="MJCF scene instead of train/go1_flat.xml, e.g. "
                   "a world's composed.xml (with --name-prefix go1/ --spawn-at-model-pose)")
    p.add_argument("--name-prefix", default="")
    p.add_argument("--spawn-at-model-pose", action="store_true",
                   help="start at the model's robot pose (the world's), not at the origin")
    p.add_argument("--json", default="")
    args = p.parse_args()

    import cv2
    net = cv2.dnn.readNetFromONNX(args.policy)

    commands = [tuple(float(v) for v in c.split(",")) for c in args.commands.split(";")]
    cfg = QuadrupedEnvConfig(num_threads=args.threads, add_noise=False,
                             episode_length_s=args.seconds + 1.0, name_prefix=args.name_prefix,
                             spawn_at_model_pose=args.spawn_at_model_pose)
    if args.model:
        # on terrain the trunk's world z says nothing of its height above the ground
        cfg.model_path = args.model
        cfg.min_base_height = -np.inf
    results = []
    for cmd in commands:
        n = args.seeds
        vel = np.zeros((n, 3))
        fell = np.zeros(n, dtype=bool)
        fell_at = np.full(n, np.nan)
        per_seed_obs = []
        # one environment per seed: each reset with its own seed so that a seed's episode does
        # not depend on how many seeds run
        for i in range(n):
            sub = QuadrupedVelocityEnv(1, cfg, seed=i)
            o, _ = sub.reset(seed=i, options={"commands": np.array([cmd])})
            per_seed_obs.append((sub, o))
        dt = per_seed_obs[0][0].dt
        steps = int(round(args.seconds / dt))
        settle = int(round(args.settle / dt))
        count = 0
        min_z = np.full(n, np.inf)
        start_xy = np.array([s.base_pos[0, :2].copy() for s, _ in per_seed_obs])
        for t in range(steps):
            for i, (sub, o) in enumerate(per_seed_obs):
                if fell[i]:
                    continue
                net.setInput(o.astype(np.float32))
                a = net.forward().astype(np.float64)
                o, _, term, trunc, _ = sub.step(a)
                per_seed_obs[i] = (sub, o)
                if term[0]:
                    fell[i] = True
                    fell_at[i] = (t + 1) * dt
                    continue
                min_z[i] = min(min_z[i], sub.base_pos[0, 2])
                if t >= settle:
                    vel[i] += [sub.base_lin_vel[0, 0], sub.base_lin_vel[0, 1], sub.base_ang_vel[0, 2]]
            if t >= settle:
                count += 1
        vel /= max(count, 1)
        dist = np.array([np.linalg.norm(s.base_pos[0, :2] - start_xy[i])
                         for i, (s, _) in enumerate(per_seed_obs)])
        ok = ~fell
        for k in range(3):
            if cmd[k] != 0.0:
                ok &= np.abs(vel[:, k] - cmd[k]) <= args.tolerance * abs(cmd[k])
            else:
                ok &= np.abs(vel[:, k]) <= args.tolerance * 0.5
        r = {"command": cmd, "seeds": n, "seconds": args.seconds, "falls": int(fell.sum()),
             "passed": int(ok.sum()), "mean_vx": vel[:, 0].tolist(), "mean_vy": vel[:, 1].tolist(),
             "mean_wz": vel[:, 2].tolist(), "distance_m": dist.tolist(), "min_trunk_z_m": min_z.tolist(),
             "fell_at_s": [None if np.isnan(f) else float(f) for f in fell_at]}
        results.append(r)
        print(f"command vx={cmd[0]} vy={cmd[1]} wz={cmd[2]}: passed {r['passed']}/{n}, falls "
              f"{r['falls']}; vx {vel[:, 0].mean():.3f} [{vel[:, 0].min():.3f}, {vel[:, 0].max():.3f}] "
              f"vy {vel[:, 1].mean():.3f} [{vel[:, 1].min():.3f}, {vel[:, 1].max():.3f}] "
              f"wz {vel[:, 2].mean():.3f} [{vel[:, 2].min():.3f}, {vel[:, 2].max():.3f}] "
              f"min trunk z {min_z.min():.3f} m", flush=True)
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"policy": args.policy, "model": args.model or cfg.model_path, "tolerance": args.tolerance, "settle_s": args.settle,
                       "results": results}, f, indent=1)


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Batched rollout throughput: steps/s of N copies of the bundled Go1-class quadruped.

For each N it times (a) the C++ BatchStepper alone (joint PD towards the standing pose,
10 physics steps of 0.002 s per policy step) and (b) the Python vector environment
(QuadrupedVelocityEnv.step with zero actions: stepping plus NumPy observations, rewards and
resets). Prints one row per N: policy steps/s (copies x steps / s) and physics steps/s (x 10).

    PYTHONPATH=build/python:python nice /usr/bin/python3 bench/rollout_bench.py \
        --copies 1 64 1024 --threads 2 --seconds 5
"""

import argparse
import json
import os
import sys
import time

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
from penumbra_rollout import QuadrupedEnvConfig, QuadrupedVelocityEnv  # noqa: E402


def timed(fn, seconds, min_calls=3):
    fn()  # warm-up
    calls = 0
    t0 = time.perf_counter()
    while calls < min_calls or time.perf_counter() - t0 < seconds:
        fn()
        calls += 1
    return calls, time.perf_counter() - t0


def main():
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("--copies", type=int, nargs="+", default=[1, 64, 1024])
    p.add_argument("--threads", type=int, default=0, help="0 = all cores")
    p.add_argument("--seconds", type=float, default=5.0, help="minimum time per measurement")
    p.add_argument("--json", default="", help="also write the rows to this JSON file")
    args = p.parse_args()
    rows = []
    print(f"cores {os.cpu_count()} threads {args.threads or os.cpu_count()}")
    print(f"{'N':>6} {'stepper policy st/s':>20} {'physics st/s':>14} {'env policy st/s':>16}")
    for n in args.copies:
        env = QuadrupedVelocityEnv(n, QuadrupedEnvConfig(num_threads=args.threads), seed=0)
        env.reset()
        s = env.stepper
        targets = np.zeros((n, 12))
        targets[:, env.policy_to_act] = env.default_q
        calls, secs = timed(lambda: s.step(targets), args.seconds)
        stepper_sps = n * calls / secs
        zero = np.zeros((n, 12))
        calls2, secs2 = timed(lambda: env.step(zero), args.seconds)
        env_sps = n * calls2 / secs2
        row = {"copies": n, "threads": s.num_threads, "substeps": s.substeps,
               "stepper_policy_steps_per_s": stepper_sps,
               "physics_steps_per_s": stepper_sps * s.substeps, "env_policy_steps_per_s": env_sps}
        rows.append(row)
        print(f"{n:>6} {stepper_sps:>20.0f} {stepper_sps * s.substeps:>14.0f} {env_sps:>16.0f}", flush=True)
        env.close()
    if args.json:
        with open(args.json, "w") as f:
            json.dump({"cores": os.cpu_count(), "rows": rows}, f, indent=1)


if __name__ == "__main__":
    main()

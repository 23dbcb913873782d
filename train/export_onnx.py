#!/usr/bin/env python3
"""Exports the actor of a train/ppo.py checkpoint as ONNX (opset 11: input 'obs' (1, 48)
float32, output 'actions' (1, 12)) and checks that OpenCV's dnn module, when installed
(Debian's python3-opencv), reads it and computes the same actions as PyTorch.

    /usr/bin/python3 train/export_onnx.py RUN/checkpoint.pt models/policies/go1_velocity.onnx
"""

import os
import sys

import numpy as np
import torch

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "python"))
from ppo import ActorCritic, export_onnx  # noqa: E402


def main():
    if len(sys.argv) != 3:
        sys.exit("usage: export_onnx.py CHECKPOINT.pt OUT.onnx")
    ck = torch.load(sys.argv[1], map_location="cpu", weights_only=False)
    model = ActorCritic(tuple(ck["hidden"]))
    model.load_state_dict(ck["model"])
    export_onnx(model, sys.argv[2])
    size = os.path.getsize(sys.argv[2])
    print(f"{sys.argv[2]}: {size} bytes, iteration {ck['iteration']}, {ck['env_steps']} env steps")
    try:
        import cv2
    except ImportError:
        print("cv2 not installed: OpenCV check skipped")
        return
    rng = np.random.default_rng(0)
    obs = rng.standard_normal((1, 48)).astype(np.float32)
    net = cv2.dnn.readNetFromONNX(sys.argv[2])
    net.setInput(obs)
    got = net.forward()
    want = model.actor(torch.from_numpy(obs)).detach().numpy()
    err = float(np.max(np.abs(got - want)))
    print(f"OpenCV {cv2.__version__} dnn reads it; max |opencv - torch| = {err:.2e}")
    if err > 1e-4:
        sys.exit("OpenCV and PyTorch disagree")


if __name__ == "__main__":
    main()

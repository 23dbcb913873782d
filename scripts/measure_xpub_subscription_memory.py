#!/usr/bin/env python3
"""Measures what subscriptions cost a ZeroMQ XPUB socket's process (docs/zmq-protocol.md,
"Limits on subscriptions").

A child process binds an XPUB socket (default mode, or ZMQ_XPUB_MANUAL with no subscription
applied) on loopback and receives every subscription message; a SUB socket in this process
sends N distinct subscriptions of B bytes. The child prints its resident memory before and
after, and the metadata ZeroMQ attaches to a subscription message (what could tell peers
apart). Uses the system libzmq through Debian's python3-zmq:

    /usr/bin/python3 scripts/measure_xpub_subscription_memory.py --count 10000 --bytes 500
"""

import argparse
import os
import subprocess
import sys
import time

import zmq


def resident_mb():
    with open("/proc/self/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    return float("nan")


def serve(endpoint, manual, count):
    ctx = zmq.Context()
    xpub = ctx.socket(zmq.XPUB)
    if manual:
        xpub.setsockopt(zmq.XPUB_MANUAL, 1)
    xpub.bind(endpoint)
    before = resident_mb()
    print("ready", flush=True)
    received, metadata = 0, {}
    deadline = time.monotonic() + 60
    while received < count and time.monotonic() < deadline:
        if not xpub.poll(200):
            continue
        frame = xpub.recv(copy=False)
        received += 1
        if not metadata:
            for key in ("Socket-Type", "Peer-Address", "Routing-Id", "User-Id"):
                try:
                    metadata[key] = frame.get(key)
                except zmq.ZMQError:
                    metadata[key] = None
    print(f"mode={'manual' if manual else 'default'} subscriptions={received} "
          f"rss_before_mb={before:.0f} rss_after_mb={resident_mb():.0f} "
          f"grew_mb={resident_mb() - before:.0f} metadata={metadata}", flush=True)


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--count", type=int, default=10000)
    ap.add_argument("--bytes", type=int, default=500)
    ap.add_argument("--endpoint", default="tcp://127.0.0.1:47123")
    ap.add_argument("--serve", choices=["default", "manual"], help=argparse.SUPPRESS)
    args = ap.parse_args()
    if args.serve:
        serve(args.endpoint, args.serve == "manual", args.count)
        return
    for mode in ("default", "manual"):
        child = subprocess.Popen(
            [sys.executable, os.path.abspath(__file__), "--serve", mode, "--count",
             str(args.count), "--endpoint", args.endpoint],
            stdout=subprocess.PIPE, text=True)
        assert child.stdout.readline().strip() == "ready"
        ctx = zmq.Context()
        sub = ctx.socket(zmq.SUB)
        sub.setsockopt(zmq.SNDHWM, 0)  # queue every subscription, drop none
        sub.connect(args.endpoint)
        for i in range(args.count):
            prefix = f"{i:08d}".encode()
            sub.setsockopt(zmq.SUBSCRIBE, prefix + b"x" * max(0, args.bytes - len(prefix)))
        print(child.stdout.read().strip())
        child.wait()
        sub.close(linger=0)
        ctx.term()


if __name__ == "__main__":
    main()

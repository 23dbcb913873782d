#!/usr/bin/env python3
"""`penumbra run --ros2` is a ROS 2 node of this machine only, unless told otherwise.

A second host is made with a network namespace and a veth pair (iproute2): the namespace holds
10.201.N.2, this host 10.201.N.1. A ROS 2 participant in the namespace (ros2_remote_peer.py,
Cyclone DDS's Python binding, with this host as its discovery peer) tries to read /clock and to
call /penumbra/pause:
  1. bridge on its default interface (127.0.0.1): the remote peer gets no /clock sample and no
     reply, and the run is not paused by it; a peer on this host (loopback) gets both;
  2. bridge with --ros-interface 10.201.N.1: the remote peer gets /clock and its replies (so the
     first case fails if the bridge listens on the veth address).

exit status 77 (ctest SKIP_RETURN_CODE), saying why, when this build has no ROS 2, the venv lacks
cyclonedds, or network namespaces cannot be made (not root, no iproute2).

usage: ros2_remote_test.py PENUMBRA_BINARY SOURCE_DIR WORK_DIR
"""
import json
import os
import shutil
import signal
import subprocess
import sys
import time

BINARY, SOURCE, WORK = sys.argv[1:4]
WORLD = os.path.join(SOURCE, "tests/ros/ros2_lockstep_world.yaml")
PEER = os.path.join(SOURCE, "tests/ros/ros2_remote_peer.py")
N = os.getpid() % 250 + 1
NETNS = "pbros2-%d" % os.getpid()
HOST_IF, PEER_IF = "pbh%d" % (os.getpid() % 100000), "pbp%d" % (os.getpid() % 100000)
HOST_ADDR, PEER_ADDR = "10.201.%d.1" % N, "10.201.%d.2" % N


def skip(why):
    print("SKIP: " + why)
    sys.exit(77)


def ip(*args):
    return subprocess.run(["ip", *args], capture_output=True, text=True, timeout=30)


def make_remote_host():
    steps = [["netns", "add", NETNS],
             ["link", "add", HOST_IF, "type", "veth", "peer", "name", PEER_IF],
             ["link", "set", PEER_IF, "netns", NETNS],
             ["addr", "add", HOST_ADDR + "/24", "dev", HOST_IF],
             ["link", "set", HOST_IF, "up"],
             ["netns", "exec", NETNS, "ip", "addr", "add", PEER_ADDR + "/24", "dev", PEER_IF],
             ["netns", "exec", NETNS, "ip", "link", "set", PEER_IF, "up"],
             ["netns", "exec", NETNS, "ip", "link", "set", "lo", "up"]]
    for s in steps:
        r = ip(*s)
        if r.returncode != 0:
            return "`ip %s` failed: %s" % (" ".join(s), r.stderr.strip())
    return None


def remove_remote_host():
    ip("netns", "del", NETNS)  # removes the veth pair with it
    ip("link", "del", HOST_IF)


def clean_env():
    env = dict(os.environ)
    for k in ("CYCLONEDDS_URI", "ROS_DOMAIN_ID", "ROS_LOCALHOST_ONLY",
              "ROS_AUTOMATIC_DISCOVERY_RANGE"):
        env.pop(k, None)
    return env


class Bridge:
    """`penumbra run WORLD --ros2 --realtime` in its own process group."""

    def __init__(self, name, domain, *extra):
        self.log_path = os.path.join(WORK, name + ".log")
        args = [BINARY, "run", WORLD, "--ros2", "--ros-domain", str(domain), "--realtime",
                "--out", os.path.join(WORK, name), *extra]
        with open(self.log_path, "w") as log:
            self.proc = subprocess.Popen(args, stdout=log, stderr=subprocess.STDOUT,
                                         env=clean_env(), start_new_session=True)
        end = time.time() + 60
        while "ROS 2 bridge:" not in self.log() and time.time() < end:
            if self.proc.poll() is not None:
                break
            time.sleep(0.1)

    def log(self):
        with open(self.log_path, errors="replace") as f:
            return f.read()

    def stop(self):
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGINT)
            try:
                self.proc.wait(timeout=60)
            except subprocess.TimeoutExpired:
                os.killpg(self.proc.pid, signal.SIGKILL)
                self.proc.wait()
        return self.proc.returncode


def peer(domain, own, other, seconds, remote):
    args = [sys.executable, PEER, str(domain), own, other, str(seconds)]
    if remote:
        args = ["ip", "netns", "exec", NETNS, *args]
    r = subprocess.run(args, capture_output=True, text=True, env=clean_env(),
                       timeout=seconds + 60)
    if r.returncode != 0:
        raise AssertionError("peer failed (%d): %s" % (r.returncode, r.stderr[-2000:]))
    return json.loads(r.stdout.strip().splitlines()[-1])


def main():
    try:
        import cyclonedds  # noqa: F401
    except ImportError:
        skip("the project venv lacks cyclonedds (scripts/install-deps.sh installs it)")
    r = subprocess.run([BINARY, "run", "--help"], capture_output=True, text=True, timeout=60)
    if "--ros2" not in r.stdout:
        skip("`penumbra run` has no --ros2 option")
    if os.geteuid() != 0:
        skip("making a network namespace needs root")
    if shutil.which("ip") is None:
        skip("iproute2's `ip` is not installed")
    shutil.rmtree(WORK, ignore_errors=True)
    os.makedirs(WORK)
    why = make_remote_host()
    if why:
        remove_remote_host()
        skip("no second host: " + why)
    failures = []
    try:
        # 1. the default: loopback only
        domain = 20 + N % 200
        bridge = Bridge("loopback", domain)
        try:
            if "has no ROS 2" in bridge.log():
                skip("this build has no ROS 2: " + bridge.log()[-300:])
            remote = peer(domain, PEER_ADDR, HOST_ADDR, 8, remote=True)
            local = peer(domain, "127.0.0.1", "127.0.0.1", 4, remote=False)
        finally:
            rc = bridge.stop()
        print("loopback bridge: remote peer", remote, "local peer", local)
        if remote["clock_samples"] or remote["replies"]:
            failures.append("a peer on another host reached the loopback bridge: %s" % remote)
        if not local["clock_samples"] or not local["replies"]:
            failures.append("a peer on this host did not reach the bridge: %s" % local)
        elif local["last_clock_sec"] is None or local["last_clock_sec"] < 8:
            failures.append("the run stood still while the remote peer called pause: "
                            "sim time %s s after 8 s of it" % local["last_clock_sec"])
        if rc != 130:
            failures.append("loopback bridge exited %s: %s" % (rc, bridge.log()[-2000:]))
        # 2. told to serve the veth address: the remote peer reaches it
        bridge = Bridge("veth", domain + 1, "--ros-interface", HOST_ADDR)
        try:
            remote = peer(domain + 1, PEER_ADDR, HOST_ADDR, 8, remote=True)
        finally:
            rc = bridge.stop()
        print("bridge on %s: remote peer" % HOST_ADDR, remote)
        if not remote["clock_samples"] or not remote["replies"]:
            failures.append("a peer on another host did not reach the bridge told to serve %s: "
                            "%s\n%s" % (HOST_ADDR, remote, bridge.log()[-2000:]))
        if rc != 130:
            failures.append("veth bridge exited %s: %s" % (rc, bridge.log()[-2000:]))
    finally:
        remove_remote_host()
    if failures:
        print("FAIL:\n" + "\n".join(failures))
        sys.exit(1)
    print("PASS")


if __name__ == "__main__":
    main()

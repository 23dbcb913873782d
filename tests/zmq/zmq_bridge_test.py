#!/usr/bin/env python3
"""End-to-end tests of `penumbra run --zmq` (docs/zmq-protocol.md) with a real penumbra
process on loopback and Debian's python3-zmq / python3-msgpack as the client.

usage: zmq_bridge_test.py --binary PATH/penumbra --source REPO_ROOT [TEST ...]
tests: lockstep (determinism across two runs, every frame and IMU sample due is delivered),
       errors (each kind of bad request gets an error reply and the next request works),
       stop (the `stop` command and SIGINT end the run with outputs intact),
       free (free-running with --realtime: frames stream while the client only listens),
       live (set_adversity, set_effect, start/stop_recording),
       shutdown (500 requests sent while the run stops all get a reply; a start_recording
                 after `stop` is refused with `stopping` and leaves no file),
       subscriptions (beyond 1024 distinct prefixes or the prefix length cap a subscription is
                      dropped and logged),
       unsubscribe (40,000 subscriptions whose subscribers leave: the command socket keeps
                    answering),
       bridge_log (the run log of a ZeroMQ-driven run holds its commands: --resimulate refuses
                   it naming the first, --resimulate ctrl reproduces it bit-exactly).
"""
import argparse
import hashlib
import json
import os
import signal
import socket
import subprocess
import sys
import tempfile
import time

import msgpack
import zmq
from zmq.utils.monitor import recv_monitor_message

TIMEOUT_MS = 20000


def free_port_pair():
    """a port P with P and P + 1 free on 127.0.0.1 (the command and publish ports)."""
    for _ in range(50):
        with socket.socket() as s:
            s.bind(("127.0.0.1", 0))
            port = s.getsockname()[1]
        if port >= 65535:
            continue
        try:
            with socket.socket() as a, socket.socket() as b:
                a.bind(("127.0.0.1", port))
                b.bind(("127.0.0.1", port + 1))
            return port
        except OSError:
            continue
    raise RuntimeError("no free port pair")


def write_world(folder, source, duration=2.0):
    """the quadruped on the ramp, one small camera (rgb + depth at 10 Hz) and a 100 Hz IMU."""
    models = os.path.join(os.path.abspath(source), "worlds", "models")
    text = f"""
seed: 5
duration_sec: {duration}
physics: {{timestep_sec: 0.002}}
render: {{tier: realtime, threads: 1}}
sky: {{type: daylight, turbidity: 2.5, sun_elevation_deg: 40, sun_azimuth_deg: -60}}
lights:
  - {{name: sun, type: sun, direction: [-0.383, 0.663, -0.643], illuminance_lux: 80000}}
robots:
  - name: quadruped
    file: {models}/quadruped.xml
    pose: {{xyz: [0, 0, 0], rpy_deg: [0, 0, 0]}}
    controller:
      type: trot_gait
      base_body: trunk
      legs:
        FR: {{hip: FR_hip, thigh: FR_thigh, calf: FR_calf, foot: FR_foot}}
        FL: {{hip: FL_hip, thigh: FL_thigh, calf: FL_calf, foot: FL_foot}}
        RR: {{hip: RR_hip, thigh: RR_thigh, calf: RR_calf, foot: RR_foot}}
        RL: {{hip: RL_hip, thigh: RL_thigh, calf: RL_calf, foot: RL_foot}}
    sensors:
      - {{name: trunk_imu, type: imu, body: trunk, rate_hz: 100, preset: consumer_mems}}
models:
  - {{name: course, file: {models}/ramp.xml}}
cameras:
  - name: front
    attach: quadruped/camera_mount
    pose: {{xyz: [0, 0, 0], rpy_deg: [0, 0, 0]}}
    width: 64
    height: 48
    fovy_deg: 70
    rate_hz: 10
    outputs: [rgb, depth]
mjcf_cameras: {{enabled: false}}
output: {{dir: out}}
"""
    path = os.path.join(folder, "world.yaml")
    with open(path, "w") as f:
        f.write(text)
    return path


class Server:
    """a `penumbra run --zmq` child process."""

    def __init__(self, binary, world, out, extra):
        self.port = free_port_pair()
        self.endpoint = f"tcp://127.0.0.1:{self.port}"
        self.log_path = out + ".log"
        self.log = open(self.log_path, "w")
        self.proc = subprocess.Popen(
            [binary, "run", world, "--out", out, "-q", "--zmq", self.endpoint] + extra,
            stdout=self.log, stderr=subprocess.STDOUT)

    def wait(self, timeout=60):
        rc = self.proc.wait(timeout=timeout)
        self.log.close()
        return rc

    def kill(self):
        if self.proc.poll() is None:
            self.proc.kill()
            self.proc.wait()


class Client:
    """REQ + SUB client of one server."""

    def __init__(self, server, topics=(b"camera/", b"imu/", b"clock")):
        self.server = server
        endpoint = server.endpoint
        self.ctx = zmq.Context()
        self.req = self.ctx.socket(zmq.REQ)
        self.req.setsockopt(zmq.RCVTIMEO, TIMEOUT_MS)
        self.req.setsockopt(zmq.LINGER, 0)
        self.req.connect(endpoint)
        self.hello = self.call("hello", protocol=1, client="zmq_bridge_test")
        self.sub = self.ctx.socket(zmq.SUB)
        self.sub.setsockopt(zmq.RCVTIMEO, TIMEOUT_MS)
        self.sub.setsockopt(zmq.LINGER, 0)
        self.sub.connect(self.hello["pub_endpoint"])
        for t in tuple(topics) + (b"sync",):
            self.sub.setsockopt(zmq.SUBSCRIBE, t)
        # wait until the subscriptions have reached the server
        deadline = time.time() + TIMEOUT_MS / 1000
        while True:
            self.call("sync", token="s")
            if self.sub.poll(100):
                msg = self.sub.recv_multipart()
                if msg[0] == b"sync":
                    break
            assert time.time() < deadline, "the sync message never arrived"
        self.unsubscribe_sync()

    def unsubscribe_sync(self):
        self.sub.setsockopt(zmq.UNSUBSCRIBE, b"sync")
        # late sync messages; bounded, since a free-running run publishes all the time (only
        # sync messages reach a lockstep client before its first step)
        deadline = time.time() + 0.5
        while time.time() < deadline and self.sub.poll(100):
            self.sub.recv_multipart()

    def raw(self, body):
        self.req.send(body)
        deadline = time.time() + TIMEOUT_MS / 1000
        while not self.req.poll(500):
            rc = self.server.proc.poll()
            if rc is not None:
                with open(self.server.log_path) as f:
                    raise AssertionError(f"penumbra exited with {rc}:\n{f.read()}")
            assert time.time() < deadline, "no reply within the timeout"
        return msgpack.unpackb(self.req.recv(), raw=False)

    def call(self, cmd, **fields):
        return self.raw(msgpack.packb(dict(cmd=cmd, **fields), use_bin_type=True))

    def ok(self, cmd, **fields):
        r = self.call(cmd, **fields)
        assert r["ok"], f"{cmd} failed: {r}"
        return r

    def receive(self, counts):
        """every message the step reply announced (counts: topic -> n)."""
        want = dict(counts)
        got = []
        while any(v > 0 for v in want.values()):
            topic, header, payload = self.sub.recv_multipart()
            t = topic.decode()
            assert want.get(t, 0) > 0, f"unexpected {t} (still wanted: {want})"
            want[t] -= 1
            got.append((t, msgpack.unpackb(header, raw=False), payload))
        assert not self.sub.poll(0), "more messages than the step reply announced"
        return got

    def close(self):
        self.req.close()
        self.sub.close()
        self.ctx.term()


def lockstep_session(binary, source, tmp, name):
    """one lockstep run driven by a fixed request sequence; returns what it saw."""
    world = write_world(tmp, source)
    server = Server(binary, world, os.path.join(tmp, name), ["--lockstep"])
    try:
        c = Client(server)
        assert c.hello["mode"] == "lockstep" and c.hello["paused"], c.hello
        info = c.ok("model_info")
        assert [cam["name"] for cam in info["cameras"]] == ["front"], info["cameras"]
        assert info["cameras"][0]["width"] == 64 and info["cameras"][0]["fx"] > 0
        assert any(ctl["type"] == "trot_gait" and "twist" in ctl["commands"]
                   for ctl in info["controllers"]), info["controllers"]
        assert "camera/front/depth_mm" in c.hello["topics"]
        frames = {}
        imu = []
        clock = []
        c.ok("twist", vx=0.3, yaw_rate=0.2)
        for k in range(6):
            r = c.ok("step", n=50)
            assert r["step"] == 50 * (k + 1), r
            assert abs(r["time_sec"] - 0.1 * (k + 1)) < 1e-9, r
            # camera at 10 Hz on 2 ms steps fires at steps 0, 50, 100, ...: two frames in the
            # first request (steps 0 and 50), one in each later one; IMU at 100 Hz every 5 steps
            n_frames = 2 if k == 0 else 1
            assert r["published"].get("camera/front/rgb") == n_frames, r["published"]
            assert r["published"].get("camera/front/depth") == n_frames, r["published"]
            assert r["published"].get("camera/front/depth_mm") == n_frames, r["published"]
            assert r["published"].get("imu/trunk_imu") == (11 if k == 0 else 10), r["published"]
            assert r["published"].get("clock") == (51 if k == 0 else 50), r["published"]
            for topic, h, payload in c.receive(r["published"]):
                if topic.startswith("camera/"):
                    bpp = {"rgb8": 3, "32FC1": 4, "16UC1": 2}[h["encoding"]]
                    assert h["width"] == 64 and h["height"] == 48 and h["step"] == 64 * bpp, h
                    assert len(payload) == h["height"] * h["step"], (topic, len(payload))
                    assert h["sim_step"] == 50 * h["index"], h
                    frames[(topic, h["index"])] = hashlib.sha256(payload).hexdigest()
                    if topic.endswith("/rgb"):
                        assert len(set(payload)) > 4, "an rgb frame of one colour"
                elif topic.startswith("imu/"):
                    assert len(h["accel"]) == 3 and len(h["gyro"]) == 3
                    imu.append((h["sim_step"], tuple(h["accel"]), tuple(h["gyro"])))
                elif topic == "clock":
                    clock.append(h["sim_step"])
            if k == 2:
                c.ok("set_ctrl", ctrl={info["actuators"][0]["name"]: 0.0})
        assert clock == list(range(0, 301)), clock[:5]
        assert [s for s, _, _ in imu] == list(range(0, 301, 5)), [s for s, _, _ in imu][:5]
        # the trot with vx = 0.3 moved the trunk forward
        state = c.ok("get_state")
        assert state["step"] == 300 and len(state["qpos"]) == info["nq"]
        c.ok("stop")
        c.close()
        rc = server.wait()
        assert rc == 0, f"exit code {rc}"
        with open(os.path.join(tmp, name, "run.json")) as f:
            run = json.load(f)
        assert run["interrupted"] is True, run
        # the frames the client got are the frames written to the run folder
        assert len(os.listdir(os.path.join(tmp, name, "front", "rgb"))) == 7
        return frames, imu, state
    finally:
        server.kill()


def test_lockstep(binary, source):
    with tempfile.TemporaryDirectory() as tmp:
        a = lockstep_session(binary, source, tmp, "a")
        b = lockstep_session(binary, source, tmp, "b")
    frames_a, imu_a, state_a = a
    frames_b, imu_b, state_b = b
    assert len(frames_a) == 3 * 7, sorted(frames_a)  # rgb, depth, depth_mm x 7 frames
    assert frames_a == frames_b, "image bytes differ between two identical lockstep runs"
    assert imu_a == imu_b, "IMU samples differ between two identical lockstep runs"
    for key in ("qpos", "qvel", "ctrl", "act"):
        assert state_a[key] == state_b[key], f"{key} differs between two identical runs"
    assert state_a["qpos"][0] > 0.02, f"the trunk did not move forward: x = {state_a['qpos'][0]}"


def expect_error(c, body, code, field=None):
    r = c.raw(body)
    assert not r["ok"], f"expected a {code} error, got {r}"
    assert r["error"]["code"] == code, r
    if field is not None:
        assert r["error"]["field"] == field, r
    assert r["error"]["message"], r
    # the server keeps serving
    assert c.call("get_state")["ok"]
    return r


def test_errors(binary, source):
    pack = lambda d: msgpack.packb(d, use_bin_type=True)
    with tempfile.TemporaryDirectory() as tmp:
        world = write_world(tmp, source)
        server = Server(binary, world, os.path.join(tmp, "out"), ["--lockstep"])
        try:
            c = Client(server, topics=())
            state0 = c.ok("get_state")
            assert state0["step"] == 0, state0
            c.ok("step", n=1)
            expect_error(c, b"\xc1", "malformed")                       # reserved byte
            expect_error(c, pack({"cmd": "step"})[:-2], "malformed")    # truncated
            expect_error(c, pack(5), "malformed")                       # not a map
            expect_error(c, pack({"cmd": "step"}) + b"\x00", "malformed")  # trailing bytes
            expect_error(c, b"\x91" * 100 + b"\x00", "malformed")      # nested 100 deep
            expect_error(c, pack({"n": 1}), "malformed", "cmd")        # no cmd
            expect_error(c, pack({"cmd": 3}), "malformed", "cmd")
            expect_error(c, pack({"cmd": "step", "pad": b"x" * (2 << 20)}), "too_large")
            expect_error(c, pack({"cmd": "fly"}), "unknown_command", "cmd")
            expect_error(c, pack({"cmd": "step", "n": "ten"}), "bad_field", "n")
            expect_error(c, pack({"cmd": "step", "n": 0}), "bad_field", "n")
            expect_error(c, pack({"cmd": "step", "steps": 2}), "unknown_field", "steps")
            expect_error(c, pack({"cmd": "set_mocap", "xyz": [0, 0, 0]}), "missing_field", "body")
            expect_error(c, pack({"cmd": "set_ctrl", "ctrl": [1.0]}), "bad_field", "ctrl")
            expect_error(c, pack({"cmd": "set_ctrl", "ctrl": {"nope": 1.0}}), "bad_field",
                         "ctrl.nope")
            expect_error(c, pack({"cmd": "twist", "vx": float("nan")}), "bad_field", "vx")
            expect_error(c, pack({"cmd": "twist", "robot": "rover"}), "bad_field", "robot")
            expect_error(c, pack({"cmd": "joint_targets", "values": [0]}), "not_available")
            expect_error(c, pack({"cmd": "reset", "keyframe": "nope"}), "bad_field", "keyframe")
            expect_error(c, pack({"cmd": "reset", "seed": 6}), "bad_field", "seed")
            expect_error(c, pack({"cmd": "hello", "protocol": 2}), "version_mismatch", "protocol")
            expect_error(c, pack({"cmd": "resume", "x": 1}), "unknown_field", "x")
            expect_error(c, pack({"cmd": "set_adversity", "preset": "no_such_preset"}),
                         "bad_field", "adversity")
            expect_error(c, pack({"cmd": "set_effect", "effect": "fog", "params": [1]}),
                         "bad_field", "params")
            expect_error(c, pack({"cmd": "set_effect", "effect": "fog",
                                  "params": {"mor_m": "thick"}}), "bad_field")
            expect_error(c, pack({"cmd": "stop_recording"}), "conflict")
            expect_error(c, pack({"cmd": "sync"}), "missing_field", "token")
            # a DEALER sending two body frames, and one vanishing with a request in flight
            d = c.ctx.socket(zmq.DEALER)
            d.setsockopt(zmq.RCVTIMEO, TIMEOUT_MS)
            d.setsockopt(zmq.LINGER, 0)
            d.connect(server.endpoint)
            d.send_multipart([pack({"cmd": "get_state"}), pack({"cmd": "get_state"})])
            r = msgpack.unpackb(d.recv_multipart()[-1], raw=False)
            assert not r["ok"] and r["error"]["code"] == "malformed", r
            d.send_multipart([b"", pack({"cmd": "get_state", "id": 7})])
            frames = d.recv_multipart()
            assert frames[0] == b"", frames[:1]
            r = msgpack.unpackb(frames[-1], raw=False)
            assert r["ok"] and r["id"] == 7 and r["step"] == 1, r
            d.send(pack({"cmd": "step", "n": 5}))
            d.setsockopt(zmq.LINGER, 2000)
            d.close()  # gone before its reply
            time.sleep(0.2)
            r = c.ok("get_state")
            assert r["step"] == 6, r
            # a reset brings the initial state back; the step count goes on
            c.ok("twist", vx=0.5)
            c.ok("step", n=100)
            moved = c.ok("get_state")
            assert moved["qpos"] != state0["qpos"]
            reset = c.ok("reset")
            assert reset["step"] == 106, reset
            after = c.ok("get_state")
            assert after["step"] == 106
            for key in ("qpos", "qvel", "act", "mocap_pos", "mocap_quat"):
                assert after[key] == state0[key], f"{key} after reset differs from step 0"
            c.ok("pause")
            # running free at 5 % of real time (the run must not reach its end meanwhile)
            assert c.ok("set_realtime_factor", factor=0.05)["factor"] == 0.05
            r = c.ok("resume")
            assert r["paused"] is False
            r = c.call("step", n=1)
            assert not r["ok"] and r["error"]["code"] == "conflict", r
            c.ok("pause")
            c.ok("stop")
            c.close()
            assert server.wait() == 0
        finally:
            server.kill()


def test_stop(binary, source):
    with tempfile.TemporaryDirectory() as tmp:
        world = write_world(tmp, source)
        out = os.path.join(tmp, "out")
        server = Server(binary, world, out, ["--lockstep"])
        try:
            c = Client(server, topics=())
            c.ok("step", n=20)
            server.proc.send_signal(signal.SIGINT)
            rc = server.wait()
            assert rc == 128 + signal.SIGINT, f"exit code {rc} after SIGINT"
            with open(os.path.join(out, "run.json")) as f:
                run = json.load(f)
            assert run["interrupted"] is True
            assert abs(run["sim_duration_sec"] - 0.04) < 1e-9, run["sim_duration_sec"]
            c.close()
        finally:
            server.kill()


def test_free(binary, source):
    with tempfile.TemporaryDirectory() as tmp:
        world = write_world(tmp, source, duration=30.0)
        server = Server(binary, world, os.path.join(tmp, "out"), ["--realtime"])
        try:
            c = Client(server, topics=(b"camera/front/rgb",))
            assert c.hello["mode"] == "free" and not c.hello["paused"]
            r = c.call("step", n=1)
            assert not r["ok"] and r["error"]["code"] == "conflict", r
            indices = []
            for _ in range(5):
                topic, header, payload = c.sub.recv_multipart()
                assert topic == b"camera/front/rgb", topic
                indices.append(msgpack.unpackb(header, raw=False)["index"])
            assert indices == sorted(indices) and len(set(indices)) == 5, indices
            # realtime: 5 frames at 10 Hz take about 0.5 s of wall time (not checked here:
            # timings belong in benchmarks); a client's `stop` ends the run cleanly
            c.ok("stop")
            c.close()
            rc = server.wait(timeout=60)
            assert rc == 0, rc
        finally:
            server.kill()


def rgb_contrast(payload):
    """the standard deviation of a rgb8 frame's bytes (a contrast measure)."""
    values = list(payload)
    mean = sum(values) / len(values)
    return (sum((v - mean) ** 2 for v in values) / len(values)) ** 0.5


def test_live(binary, source):
    """set_adversity, set_effect, start/stop_recording through the command layer."""
    pack = lambda d: msgpack.packb(d, use_bin_type=True)  # noqa: E731
    with tempfile.TemporaryDirectory() as tmp:
        world = write_world(tmp, source)
        server = Server(binary, world, os.path.join(tmp, "out"), ["--lockstep"])
        try:
            c = Client(server, topics=(b"camera/front/rgb",))

            def frame_after(n):
                r = c.ok("step", n=n)
                want = {t: k for t, k in r["published"].items() if t == "camera/front/rgb"}
                got = [p for t, h, p in c.receive(want)]
                assert got, r["published"]
                return got[-1]

            clear = rgb_contrast(frame_after(50))
            r = c.ok("set_effect", effect="fog", params={"mor_m": 2.0})
            assert r["applies_from_step"] == r["step"] + 1, r
            foggy = rgb_contrast(frame_after(50))
            assert foggy < 0.7 * clear, f"fog MOR 2 m: contrast {clear:.1f} -> {foggy:.1f}"
            c.ok("set_effect", effect="fog", params=None)
            assert rgb_contrast(frame_after(50)) > 0.9 * clear, "removing the fog block"
            # the bundled presets bring NPCs: a live run reserves their bodies (parked)
            c.ok("set_adversity", preset="major")
            major = rgb_contrast(frame_after(50))
            assert major < 0.9 * clear, f"major: contrast {clear:.1f} -> {major:.1f}"
            # a preset file asking for more NPCs than any bundled preset is refused, naming why
            # (preset files are named relative to the world file's folder, here tmp)
            crowd = os.path.join(tmp, "crowd.yaml")
            with open(crowd, "w") as f:
                f.write("presets:\n  crowd:\n    npcs: {people: 9}\n")
            expect_error(c, pack({"cmd": "set_adversity", "preset": "crowd.yaml#crowd"}),
                         "bad_field", "npcs")
            preset = os.path.join(tmp, "smoky.yaml")
            with open(preset, "w") as f:
                f.write("presets:\n  smoky:\n    fog: {mor_m: 4}\n    lights: {scale: 0.4}\n")
            c.ok("set_adversity", preset="smoky.yaml#smoky")
            smoky = rgb_contrast(frame_after(50))
            assert smoky < 0.8 * clear, f"preset smoky: contrast {clear:.1f} -> {smoky:.1f}"
            c.ok("set_adversity", preset="none")
            # recordings are new files inside the output folder only (docs/zmq-protocol.md):
            # a path outside it is refused and nothing is written there
            outside = os.path.join(tmp, "outside.plog")
            for bad in (outside, "../outside.plog"):
                expect_error(c, pack({"cmd": "start_recording", "path": bad}), "bad_field",
                             "path")
            assert not os.path.exists(outside)
            # a live recording of 20 steps, with the camera's images
            plog = os.path.join(tmp, "out", "live.plog")
            r = c.ok("start_recording", path="live.plog", sensors=True)
            first = r["from_step"]
            expect_error(c, pack({"cmd": "start_recording", "path": "other.plog"}), "conflict",
                         "recording")
            c.ok("step", n=20)
            r = c.ok("stop_recording")
            assert r["steps"] == 20 and r["first_step"] == first, (first, r)
            assert r["last_step"] == first + 19, (first, r)
            assert os.path.getsize(plog) == r["bytes"] > 0, r
            c.ok("stop")
            c.close()
            assert server.wait() == 0
            # the log replays (docs/run-log.md)
            replay = subprocess.run([binary, "replay", plog, "--out", os.path.join(tmp, "replay"),
                                     "-q"], capture_output=True, text=True)
            assert replay.returncode == 0, replay.stderr
        finally:
            server.kill()


def test_shutdown(binary, source):
    """500 requests sent while the run stops: every one gets a reply, ok or `stopping`.
    200 go before the `stop` (the last of them), 300 right after its reply, while the run
    finishes; a start_recording among those is refused and leaves no file."""
    pack = lambda d: msgpack.packb(d, use_bin_type=True)  # noqa: E731
    with tempfile.TemporaryDirectory() as tmp:
        world = write_world(tmp, source)
        server = Server(binary, world, os.path.join(tmp, "out"), ["--lockstep"])
        late = os.path.join(tmp, "late.plog")
        try:
            c = Client(server, topics=())
            c.ok("step", n=10)
            d = c.ctx.socket(zmq.DEALER)
            d.setsockopt(zmq.LINGER, 0)
            d.setsockopt(zmq.RCVHWM, 0)
            d.setsockopt(zmq.SNDHWM, 0)
            d.connect(server.endpoint)
            poller = zmq.Poller()
            poller.register(d, zmq.POLLIN)
            replies = {}

            def body(i):
                if i == 199:
                    return {"cmd": "stop", "id": i}
                if i == 200:
                    return {"cmd": "start_recording", "id": i, "path": late}
                if i % 2:
                    return {"cmd": "get_state", "id": i}
                return {"cmd": "hello", "id": i, "protocol": 1}

            def collect(ids):
                deadline = time.time() + TIMEOUT_MS / 1000
                while not set(ids) <= set(replies) and time.time() < deadline:
                    if not poller.poll(200):
                        continue
                    r = msgpack.unpackb(d.recv_multipart()[-1], raw=False)
                    assert r["id"] not in replies, f"two replies to request {r['id']}"
                    replies[r["id"]] = r
                missing = sorted(set(ids) - set(replies))
                assert not missing, f"{len(missing)} requests got no reply: {missing[:10]} ..."

            for i in range(200):
                d.send_multipart([b"", pack(body(i))])
            collect(range(200))
            assert replies[199]["ok"], replies[199]
            for i in range(200, 500):
                d.send_multipart([b"", pack(body(i))])
            collect(range(500))
            codes = {}
            for i, r in replies.items():
                code = "ok" if r["ok"] else r["error"]["code"]
                codes[code] = codes.get(code, 0) + 1
                # run_ended: a request that reached the run's queue after its end (a reply too)
                assert code in ("ok", "stopping", "run_ended"), (i, r)
            # the requests before the stop were carried out
            assert all(replies[i]["ok"] for i in range(200)), codes
            assert codes.get("stopping", 0) > 0, codes
            # a recording asked for after the stop: refused, no file left behind
            r = replies[200]
            assert not r["ok"] and r["error"]["code"] == "stopping", r
            assert not os.path.exists(late), "start_recording after stop left a file"
            d.close()
            c.close()
            assert server.wait() == 0
        finally:
            server.kill()


def wait_for_sync(c, subs):
    """calls sync until every socket of `subs` received a sync message: each one's earlier
    subscriptions have then been taken in by the server (ZeroMQ keeps a peer's order)."""
    pending = list(subs)
    deadline = time.time() + TIMEOUT_MS / 1000
    while pending:
        assert time.time() < deadline, f"{len(pending)} sockets never got a sync message"
        c.call("sync", token="barrier")
        for s in list(pending):
            while s.poll(50):
                if s.recv_multipart()[0] == b"sync":
                    pending.remove(s)
                    break


def test_subscriptions(binary, source):
    """subscriptions beyond the caps are dropped (and logged), the rest still work."""
    with tempfile.TemporaryDirectory() as tmp:
        world = write_world(tmp, source)
        server = Server(binary, world, os.path.join(tmp, "out"), ["--lockstep"])
        try:
            c = Client(server, topics=())
            j = c.ctx.socket(zmq.SUB)
            j.setsockopt(zmq.LINGER, 0)
            j.setsockopt(zmq.SNDHWM, 0)
            j.connect(c.hello["pub_endpoint"])
            for i in range(1024):                  # 1024: the cap
                j.setsockopt(zmq.SUBSCRIBE, b"junk/%04d" % i)
            j.setsockopt(zmq.SUBSCRIBE, b"clock")      # beyond the cap: dropped
            j.setsockopt(zmq.SUBSCRIBE, b"c" * 300)    # longer than 256 bytes: dropped
            j.setsockopt(zmq.UNSUBSCRIBE, b"junk/0000")
            j.setsockopt(zmq.UNSUBSCRIBE, b"junk/0001")
            j.setsockopt(zmq.SUBSCRIBE, b"joint_states")  # room again: kept
            # "sync" last (room again: kept): a sync message on j then means the server took in
            # every subscription before it. subscribed first, a sync could pass its filter while
            # the others were still on their way, and the step below raced joint_states' (CI,
            # 2026-11-27: published {} once under load)
            j.setsockopt(zmq.SUBSCRIBE, b"sync")
            wait_for_sync(c, [j])
            r = c.ok("step", n=5)
            # joint_states (after an unsubscribe made room) is published, clock is not
            assert r["published"].get("joint_states") == 6, r["published"]
            assert "clock" not in r["published"], r["published"]
            j.close()
            c.ok("stop")
            c.close()
            assert server.wait() == 0
            with open(server.log_path) as f:
                log = f.read()
            assert "dropped the subscription 'clock': 1024 distinct subscriptions are held" in log, log
            assert "dropped a subscription of 300 bytes" in log, log
        finally:
            server.kill()


def test_unsubscribe(binary, source):
    """40,000 subscriptions of 500 bytes, then their subscribers leave: the command socket
    keeps answering (each request within a generous bound of 2 s) while the server removes
    them: a request every 50 ms for 3 s after they left. (before the fix it stopped answering
    for about 9 s here, 9.0 s without a reply in commit 285ab6a's measurement against 0.03 s
    worst after it: every unsubscribe searched a list of all subscriptions)"""
    with tempfile.TemporaryDirectory() as tmp:
        world = write_world(tmp, source)
        server = Server(binary, world, os.path.join(tmp, "out"), ["--lockstep"])
        try:
            c = Client(server, topics=(b"sync",))
            subs = []
            for k in range(40):
                s = c.ctx.socket(zmq.SUB)
                s.setsockopt(zmq.LINGER, 0)
                s.setsockopt(zmq.SNDHWM, 0)
                s.connect(c.hello["pub_endpoint"])
                for i in range(1000):
                    # prefixes that agree on their first 490 bytes
                    s.setsockopt(zmq.SUBSCRIBE, b"x" * 490 + b"%02d%08d" % (k, i))
                s.setsockopt(zmq.SUBSCRIBE, b"sync")
                subs.append(s)
            wait_for_sync(c, subs)
            for s in subs:
                s.close()
            c.req.setsockopt(zmq.RCVTIMEO, 2000)
            t_end = time.time() + 3
            n = 0
            while time.time() < t_end:
                c.req.send(msgpack.packb({"cmd": "get_state"}, use_bin_type=True))
                try:
                    r = msgpack.unpackb(c.req.recv(), raw=False)
                except zmq.Again:
                    raise AssertionError(f"no reply within 2 s to request {n} after the "
                                         "subscribers left")
                assert r["ok"], r
                n += 1
                time.sleep(0.05)
            c.req.setsockopt(zmq.RCVTIMEO, TIMEOUT_MS)
            c.ok("stop")
            c.close()
            assert server.wait() == 0
        finally:
            server.kill()


def resident_mb(pid):
    """resident memory of process `pid`, MB (/proc/PID/status VmRSS)."""
    with open(f"/proc/{pid}/status") as f:
        for line in f:
            if line.startswith("VmRSS:"):
                return int(line.split()[1]) / 1024.0
    raise AssertionError(f"no VmRSS in /proc/{pid}/status")


def test_subscription_memory(binary, source):
    """10,000 distinct subscriptions of 1 KB from one subscriber add less than 50 MB to the
    server (ZeroMQ disconnects a subscriber whose subscription message is over the size cap;
    without that cap they added about 330 MB), while a subscriber within the caps still gets
    its topic, and no longer once it unsubscribed."""
    with tempfile.TemporaryDirectory() as tmp:
        world = write_world(tmp, source)
        server = Server(binary, world, os.path.join(tmp, "out"), ["--lockstep"])
        try:
            c = Client(server, topics=(b"clock",))
            r = c.ok("step", n=1)
            assert r["published"].get("clock", 0) >= 1, r["published"]
            c.receive(r["published"])
            before = resident_mb(server.proc.pid)
            flood = c.ctx.socket(zmq.SUB)
            flood.setsockopt(zmq.LINGER, 0)
            flood.setsockopt(zmq.SNDHWM, 0)
            monitor = flood.get_monitor_socket(zmq.EVENT_DISCONNECTED)
            flood.connect(c.hello["pub_endpoint"])
            for i in range(10000):
                flood.setsockopt(zmq.SUBSCRIBE, b"%08d" % i + b"y" * 1016)
            # the server has read the flood once it disconnected the subscriber, or once its
            # memory grew by the bound (it took them in)
            deadline = time.time() + TIMEOUT_MS / 1000
            grown = 0.0
            while grown < 50:
                assert time.time() < deadline, "neither a disconnect nor memory growth"
                if monitor.poll(100):
                    event = recv_monitor_message(monitor)
                    assert event["event"] == zmq.EVENT_DISCONNECTED, event
                    break
                grown = resident_mb(server.proc.pid) - before
            grown = resident_mb(server.proc.pid) - before
            assert grown < 50, f"10,000 subscriptions of 1 KB added {grown:.0f} MB to the server"
            # the subscriber within the caps: clock still arrives, and stops after unsubscribing
            r = c.ok("step", n=1)
            assert r["published"].get("clock", 0) >= 1, r["published"]
            c.receive(r["published"])
            c.sub.setsockopt(zmq.UNSUBSCRIBE, b"clock")
            c.sub.setsockopt(zmq.SUBSCRIBE, b"sync")
            wait_for_sync(c, [c.sub])
            c.unsubscribe_sync()
            r = c.ok("step", n=1)
            assert "clock" not in r["published"], r["published"]
            assert not c.sub.poll(200), "a message arrived after the unsubscribe"
            flood.disable_monitor()
            monitor.close()
            flood.close()
            c.ok("stop")
            c.close()
            assert server.wait() == 0
        finally:
            server.kill()


def test_bridge_log(binary, source):
    """a run driven over ZeroMQ logs its commands; --resimulate refuses the log naming the
    first, --resimulate ctrl (the logged ctrl) reproduces it bit-exactly."""
    with tempfile.TemporaryDirectory() as tmp:
        world = write_world(tmp, source)
        plog = os.path.join(tmp, "driven.plog")
        server = Server(binary, world, os.path.join(tmp, "out"), ["--lockstep", "--record", plog])
        try:
            c = Client(server, topics=())
            c.ok("step", n=20)
            c.ok("twist", vx=0.3, yaw_rate=0.2)
            c.ok("step", n=100)
            c.ok("twist", clear=True)
            c.ok("step", n=30)
            c.ok("stop")
            c.close()
            assert server.wait() == 0
        finally:
            server.kill()
        r = subprocess.run([binary, "replay", plog, "--resimulate"], capture_output=True,
                           text=True)
        assert r.returncode == 2, (r.returncode, r.stdout, r.stderr)
        assert "diverged" not in r.stdout, r.stdout
        assert "the log holds 2 command event(s) (the first, 'twist', at step 20)" in r.stderr, \
            r.stderr
        r = subprocess.run([binary, "replay", plog, "--resimulate", "ctrl"], capture_output=True,
                           text=True)
        assert r.returncode == 0, (r.returncode, r.stdout, r.stderr)
        assert r.stdout.startswith("bit-exact ("), r.stdout


def test_stop_two_sockets(binary, source):
    """a start_recording sent from a second socket just after another socket's `stop`: refused
    with `stopping`, no log left. ZeroMQ takes waiting peers in turn, so the second socket's
    request could be carried out before the stop that was sent first (it left a 2-step log)."""
    pack = lambda d: msgpack.packb(d, use_bin_type=True)  # noqa: E731
    with tempfile.TemporaryDirectory() as tmp:
        world = write_world(tmp, source)
        out = os.path.join(tmp, "out")
        server = Server(binary, world, out, ["--lockstep"])
        try:
            c = Client(server, topics=())
            c.ok("step", n=5)
            a = c.ctx.socket(zmq.DEALER)
            b = c.ctx.socket(zmq.DEALER)
            for s in (a, b):
                s.setsockopt(zmq.LINGER, 0)
                s.setsockopt(zmq.RCVTIMEO, TIMEOUT_MS)
                s.connect(server.endpoint)
            # both connected (a reply each) before the race
            for s in (a, b):
                s.send_multipart([b"", pack({"cmd": "hello", "protocol": 1})])
                assert msgpack.unpackb(s.recv_multipart()[-1], raw=False)["ok"]
            # a backlog on the first socket, its stop, then the second socket's start_recording
            for i in range(40):
                a.send_multipart([b"", pack({"cmd": "get_state", "id": i})])
            a.send_multipart([b"", pack({"cmd": "stop", "id": "stop"})])
            b.send_multipart([b"", pack({"cmd": "start_recording", "id": "rec",
                                         "path": "late.plog"})])
            r = msgpack.unpackb(b.recv_multipart()[-1], raw=False)
            assert not r["ok"] and r["error"]["code"] == "stopping", r
            replies = {}
            while "stop" not in replies:
                m = msgpack.unpackb(a.recv_multipart()[-1], raw=False)
                replies[m.get("id")] = m
            assert replies["stop"]["ok"], replies["stop"]
            a.close()
            b.close()
            c.close()
            assert server.wait() == 0
            assert not os.path.exists(os.path.join(out, "late.plog")), \
                "a start_recording sent after a stop left a log"
        finally:
            server.kill()


TESTS = {"lockstep": test_lockstep, "stop_two_sockets": test_stop_two_sockets, "errors": test_errors, "stop": test_stop,
         "free": test_free, "live": test_live, "shutdown": test_shutdown,
         "subscriptions": test_subscriptions, "unsubscribe": test_unsubscribe,
         "subscription_memory": test_subscription_memory, "bridge_log": test_bridge_log}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--binary", required=True)
    ap.add_argument("--source", required=True)
    ap.add_argument("tests", nargs="*")
    args = ap.parse_args()
    names = args.tests or list(TESTS)
    for name in names:
        t0 = time.time()
        TESTS[name](args.binary, args.source)
        print(f"{name}: ok ({time.time() - t0:.1f} s)")
    return 0


if __name__ == "__main__":
    sys.exit(main())

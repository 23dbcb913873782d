#!/usr/bin/python3
"""`penumbra run --ros --realtime` against a real roscore and the real ROS 1 tools.

starts roscore on a free loopback port, runs tests/ros/ros_live_world.yaml (the quadruped with a
10 Hz camera and a 100 Hz IMU) with the ROS bridge in real time, and checks:
  - `rostopic hz` of the camera's image topic is within 5 % of 10 Hz;
  - `rostopic echo -n1` gives a valid CameraInfo (size, K, plumb_bob, optical frame) and Imu
    (gravity on the accelerometer, orientation marked unknown);
  - /tf_static has base_link -> the camera's optical frame (on the nose, looking forward);
  - `rosbag record` for 5 s reads back with `rosbag info` (images at about 10 Hz, IMU samples);
  - publishing cmd_vel (`rostopic pub`) moves the quadruped forward: ground-truth odometry x grows;
  - the step service advances a lockstep run by exactly the requested steps (/clock).
every process it starts is killed at the end, also on failure.

usage: ros_live_test.py PENUMBRA_BINARY SOURCE_DIR WORK_DIR
"""
import os
import re
import shutil
import signal
import socket
import subprocess
import sys
import time
import unittest

import yaml

BINARY, SOURCE, WORK = sys.argv[1:4]
WORLD = os.path.join(SOURCE, "tests/ros/ros_live_world.yaml")
CAMERA = "/quadruped/front"


def free_port():
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


class Processes:
    """processes started by the test, each in its own process group, all killed at the end."""

    def __init__(self, env):
        self.env = env
        self.procs = []

    def start(self, args, log):
        out = open(os.path.join(WORK, log), "w")
        p = subprocess.Popen(args, env=self.env, stdout=out, stderr=subprocess.STDOUT,
                             start_new_session=True)
        self.procs.append(p)
        return p

    def run(self, args, timeout):
        return subprocess.run(args, env=self.env, capture_output=True, text=True, timeout=timeout)

    def stop(self, p, sig=signal.SIGINT, wait=10):
        if p.poll() is None:
            try:
                os.killpg(p.pid, sig)
                p.wait(timeout=wait)
            except (subprocess.TimeoutExpired, ProcessLookupError):
                pass
        if p.poll() is None:
            try:
                os.killpg(p.pid, signal.SIGKILL)
            except ProcessLookupError:
                pass
            p.wait()

    def stop_all(self):
        for p in reversed(self.procs):
            self.stop(p)


def echo_many(procs, topic, n, timeout=30):
    r = procs.run(["rostopic", "echo", "-n%d" % n, topic], timeout)
    if r.returncode != 0:
        raise AssertionError("rostopic echo %s failed:\n%s" % (topic, r.stderr))
    return [yaml.safe_load(m) for m in r.stdout.split("\n---")[:n]]


def echo_once(procs, topic, timeout=30):
    return echo_many(procs, topic, 1, timeout)[0]


def wait_for(predicate, timeout, what):
    end = time.time() + timeout
    while time.time() < end:
        if predicate():
            return
        time.sleep(0.5)
    raise AssertionError("timed out waiting for " + what)


class RosLiveTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        shutil.rmtree(WORK, ignore_errors=True)
        os.makedirs(WORK)
        port = free_port()
        env = dict(os.environ)
        env.update({"ROS_MASTER_URI": "http://127.0.0.1:%d" % port, "ROS_IP": "127.0.0.1",
                    "ROS_HOME": os.path.join(WORK, "ros_home"),
                    "ROS_LOG_DIR": os.path.join(WORK, "ros_log"), "PYTHONUNBUFFERED": "1"})
        env.pop("ROS_HOSTNAME", None)
        cls.procs = Processes(env)
        try:
            cls.roscore = cls.procs.start(["roscore", "-p", str(port)], "roscore.log")
            wait_for(lambda: cls.procs.run(["rostopic", "list"], 10).returncode == 0, 30,
                     "roscore")
            cls.sim = cls.procs.start([BINARY, "run", WORLD, "--ros", "--realtime", "--out",
                                       os.path.join(WORK, "out")], "penumbra.log")
            wait_for(lambda: CAMERA + "/image_raw" in cls.procs.run(
                ["rostopic", "list"], 10).stdout or cls.sim.poll() is not None, 60,
                "the bridge's topics")
            if cls.sim.poll() is not None:
                raise AssertionError("penumbra exited:\n" + open(
                    os.path.join(WORK, "penumbra.log")).read())
        except BaseException:
            cls.procs.stop_all()
            raise

    @classmethod
    def tearDownClass(cls):
        cls.procs.stop_all()

    def test_1_camera_rate_info_imu_tf(self):
        # record 5 s while measuring the camera rate
        bag = os.path.join(WORK, "five.bag")
        record = self.procs.start(["rosbag", "record", "-O", bag, "--duration=5",
                                   CAMERA + "/image_raw", "/quadruped/trunk_imu/data"],
                                  "record.log")
        hz = self.procs.run(["timeout", "-s", "INT", "8", "rostopic", "hz", "-w", "40",
                             CAMERA + "/image_raw"], 20)
        rates = [float(x) for x in re.findall(r"average rate: ([0-9.]+)", hz.stdout)]
        self.assertTrue(rates, "rostopic hz printed no rate:\n" + hz.stdout + hz.stderr)
        self.assertAlmostEqual(rates[-1], 10.0, delta=0.5, msg=hz.stdout)

        info = echo_once(self.procs, CAMERA + "/camera_info")
        self.assertEqual((info["width"], info["height"]), (160, 120))
        self.assertEqual(info["distortion_model"], "plumb_bob")
        self.assertEqual(info["header"]["frame_id"], "front/optical")
        fx = 60 / __import__("math").tan(__import__("math").radians(35))  # fovy 70, 120 rows
        self.assertAlmostEqual(info["K"][4], fx, delta=0.01)
        self.assertAlmostEqual(info["K"][2], 79.5, delta=0.01)
        self.assertEqual(info["K"][8], 1)

        # 0.5 s of a trotting robot's IMU: gravity on z (specific force, REP-145) on average
        samples = echo_many(self.procs, "/quadruped/trunk_imu/data", 50)
        imu = samples[0]
        self.assertEqual(imu["header"]["frame_id"], "trunk_imu")
        self.assertEqual(imu["orientation_covariance"][0], -1)
        mean_z = sum(m["linear_acceleration"]["z"] for m in samples) / len(samples)
        self.assertAlmostEqual(mean_z, 9.81, delta=1.0)
        self.assertGreater(imu["angular_velocity_covariance"][0], 0)

        tf = echo_once(self.procs, "/tf_static")
        pairs = {(t["header"]["frame_id"], t["child_frame_id"]): t["transform"]
                 for t in tf["transforms"]}
        self.assertIn(("base_link", "front/optical"), pairs)
        self.assertIn(("map", "odom"), pairs)
        nose = pairs[("base_link", "front/optical")]["translation"]
        self.assertAlmostEqual(nose["x"], 0.215, delta=1e-6)
        self.assertAlmostEqual(nose["z"], 0.07, delta=1e-6)

        record.wait(timeout=30)
        info = self.procs.run(["rosbag", "info", "--yaml", bag], 30)
        self.assertEqual(info.returncode, 0, info.stderr)
        topics = {t["topic"]: t["messages"] for t in yaml.safe_load(info.stdout)["topics"]}
        self.assertGreaterEqual(topics.get(CAMERA + "/image_raw", 0), 40)
        self.assertGreaterEqual(topics.get("/quadruped/trunk_imu/data", 0), 400)

    def test_2_cmd_vel_moves_the_robot_forward(self):
        x0 = echo_once(self.procs, "/quadruped/odom")["pose"]["pose"]["position"]["x"]
        pub = self.procs.start(["rostopic", "pub", "-r", "20", "/quadruped/cmd_vel",
                                "geometry_msgs/Twist", "{linear: {x: 0.5}}"], "pub.log")
        time.sleep(4)
        self.procs.stop(pub)
        odom = echo_once(self.procs, "/quadruped/odom")
        self.assertEqual(odom["child_frame_id"], "base_link")
        self.assertGreater(odom["pose"]["pose"]["position"]["x"], x0 + 0.4)

    def test_3_clean_shutdown(self):
        self.procs.stop(self.sim, signal.SIGINT, wait=60)
        self.assertEqual(self.sim.returncode, 130, open(os.path.join(WORK, "penumbra.log")).read())
        with open(os.path.join(WORK, "out", "run.json")) as f:
            self.assertTrue(yaml.safe_load(f)["interrupted"])

    def test_4_lockstep_step_service(self):
        # a second run, paused: it advances only by /penumbra/step, 50 steps per call
        self.assertEqual(self.procs.run(["rosparam", "set", "/penumbra/steps_per_trigger", "50"],
                                        20).returncode, 0)
        out = os.path.join(WORK, "out_lockstep")
        sim = self.procs.start([BINARY, "run", WORLD, "--ros", "--lockstep", "--out", out],
                               "penumbra_lockstep.log")
        wait_for(lambda: "/penumbra/step" in self.procs.run(["rosservice", "list"], 10).stdout
                 or sim.poll() is not None, 60, "the step service")
        replies = []
        for _ in range(2):
            r = self.procs.run(["rosservice", "call", "/penumbra/step"], 30)
            self.assertEqual(r.returncode, 0, r.stdout + r.stderr)
            replies.append(r.stdout)
        self.assertIn("success: True", replies[0])
        self.assertIn("step 50,", replies[0])
        self.assertIn("step 100,", replies[1])
        self.assertIn("t = 0.200000 s", replies[1])
        self.procs.stop(sim, signal.SIGINT, wait=60)
        with open(os.path.join(out, "run.json")) as f:
            run = yaml.safe_load(f)
        self.assertAlmostEqual(run["sim_duration_sec"], 0.2, delta=1e-9)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)

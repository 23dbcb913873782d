#!/usr/bin/python3
"""`penumbra export RUN --format rosbag`, checked with the real ROS 1 tools.

runs the sensors demo world (quadruped with a camera, LiDAR and IMU) for a short time, exports
the run folder as a bag, and checks:
  - `rosbag info --yaml` (the real tool) lists every topic with the message count the run's own
    files imply (frames.csv rows, imu csv rows, LiDAR index rows, trajectory rows at the state
    rate) and the right message types;
  - the messages read back with the rosbag Python API hold the run's data: image size and bytes
    equal the PNG, depth is the PNG's millimetres in metres (0 -> +Inf), CameraInfo K equals
    camera_info.json, the IMU samples equal imu/<name>.csv, odometry is the trunk's pose,
    /tf_static has base_link -> the camera's optical frame;
  - a second export to an existing file is refused (exit 2) and leaves the file alone.

usage: rosbag_export_test.py PENUMBRA_BINARY SOURCE_DIR WORK_DIR
"""
import json
import math
import os
import shutil
import struct
import subprocess
import sys
import unittest

import yaml

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_folder import csv_rows, read_png, state_samples  # noqa: E402

BINARY, SOURCE, WORK = sys.argv[1:4]
DURATION = 0.6


def run(args, **kw):
    return subprocess.run(args, capture_output=True, text=True, timeout=300, **kw)


class RosbagExportTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        shutil.rmtree(WORK, ignore_errors=True)
        os.makedirs(WORK)
        cls.run_dir = os.path.join(WORK, "run")
        cls.bag = os.path.join(WORK, "run.bag")
        r = run([BINARY, "run", os.path.join(SOURCE, "worlds/sensors.yaml"), "--duration",
                 str(DURATION), "--outputs", "rgb,depth", "--out", cls.run_dir])
        if r.returncode != 0:
            raise RuntimeError("penumbra run failed:\n" + r.stderr)
        r = run([BINARY, "export", cls.run_dir, "--format", "rosbag", "--out", cls.bag])
        if r.returncode != 0:
            raise RuntimeError("penumbra export failed:\n" + r.stderr)
        info = run(["rosbag", "info", "--yaml", cls.bag])
        if info.returncode != 0:
            raise RuntimeError("rosbag info failed:\n" + info.stderr)
        cls.info = yaml.safe_load(info.stdout)

    def rows(self, path):
        return csv_rows(self.run_dir, path)

    def expected_state_samples(self, rate_hz=50.0):
        return state_samples(self.run_dir, rate_hz)

    def test_rosbag_info_lists_topics_and_counts(self):
        topics = {t["topic"]: t for t in self.info["topics"]}
        frames = len(self.rows("front/frames.csv"))
        imu = len(self.rows("imu/trunk_imu.csv"))
        scans = len(self.rows("lidar/top/index.csv"))
        states = self.expected_state_samples()
        self.assertGreater(frames, 0)
        self.assertGreater(imu, 50)
        self.assertGreater(scans, 1)
        expected = {
            "/go1/front/image_raw": (frames, "sensor_msgs/Image"),
            "/go1/front/camera_info": (frames, "sensor_msgs/CameraInfo"),
            "/go1/front/depth/image_raw": (frames, "sensor_msgs/Image"),
            "/go1/front/depth/camera_info": (frames, "sensor_msgs/CameraInfo"),
            "/go1/trunk_imu/data": (imu, "sensor_msgs/Imu"),
            "/go1/top/points": (scans, "sensor_msgs/PointCloud2"),
            "/go1/odom": (states, "nav_msgs/Odometry"),
            "/go1/joint_states": (states, "sensor_msgs/JointState"),
            # odom -> base_link per state sample (the camera, LiDAR and IMU are rigid: static)
            "/tf": (states, "tf2_msgs/TFMessage"),
            # map -> odom and the three sensors
            "/tf_static": (4, "tf2_msgs/TFMessage"),
        }
        self.assertEqual(sorted(topics), sorted(expected))
        for topic, (count, type_) in expected.items():
            self.assertEqual(topics[topic]["messages"], count, topic)
            self.assertEqual(topics[topic]["type"], type_, topic)

    def test_messages_hold_the_run_data(self):
        import rosbag  # python3-rosbag

        with open(os.path.join(self.run_dir, "camera_info.json")) as f:
            cam_info = json.load(f)["front"]
        frames = self.rows("front/frames.csv")
        imu_rows = self.rows("imu/trunk_imu.csv")
        traj = self.rows("trajectory.csv")
        bag = rosbag.Bag(self.bag)
        images = [m for _, m, _ in bag.read_messages(topics=["/go1/front/image_raw"])]
        self.assertEqual(images[0].encoding, "rgb8")
        self.assertEqual((images[0].width, images[0].height), (640, 480))
        self.assertEqual(images[0].header.frame_id, "front/optical")
        for img, row in zip(images, frames):
            self.assertEqual(img.header.stamp.to_nsec(), round(float(row["time_sec"]) * 1e9))
        infos = [m for _, m, _ in bag.read_messages(topics=["/go1/front/camera_info"])]
        for a, b in zip(infos[0].K, cam_info["K"]):
            self.assertAlmostEqual(a, b, places=9)
        self.assertEqual(infos[0].distortion_model, "plumb_bob")

        # depth: the PNG's millimetres as metres, no return as +Inf
        depth = next(m for _, m, _ in bag.read_messages(topics=["/go1/front/depth/image_raw"]))
        self.assertEqual(depth.encoding, "32FC1")
        self.assertEqual(depth.step, 640 * 4)
        values = struct.unpack("<%df" % (640 * 480), depth.data)
        w, h, ch, bits, mm = read_png(os.path.join(self.run_dir, "front/depth/000000.png"))
        self.assertEqual((w, h, ch, bits), (640, 480, 1, 16))
        hits = 0
        for i in range(0, w * h, 97):
            if mm[i] == 0:
                self.assertTrue(math.isinf(values[i]) and values[i] > 0)
            else:
                hits += 1
                self.assertAlmostEqual(values[i], mm[i] / 1000.0, places=6)
        self.assertGreater(hits, 100)
        # colour: the PNG's bytes
        w, h, ch, bits, rgb = read_png(os.path.join(self.run_dir, "front/rgb/000000.png"))
        self.assertEqual((w, h, ch, bits), (640, 480, 3, 8))
        self.assertEqual(bytes(images[0].data), rgb)

        # IMU: the csv's samples, stamped with the capture time, recorded 2 ms later
        imu = list(bag.read_messages(topics=["/go1/trunk_imu/data"]))
        self.assertEqual(len(imu), len(imu_rows))
        for (_, m, t), row in zip(imu, imu_rows):
            self.assertEqual(m.header.stamp.to_nsec(), round(float(row["capture_time_sec"]) * 1e9))
            self.assertEqual(t.to_nsec(), round(float(row["capture_time_sec"]) * 1e9) + 2000000)
            self.assertAlmostEqual(m.linear_acceleration.z, float(row["accel_z_m_s2"]), places=6)
            self.assertAlmostEqual(m.angular_velocity.x, float(row["gyro_x_rad_s"]), places=6)
            self.assertEqual(m.orientation_covariance[0], -1)
            self.assertEqual(m.header.frame_id, "trunk_imu")

        # odometry: the trunk starts at (-0.2, -1.45) and trots forward (yaw 17 deg)
        odom = [m for _, m, _ in bag.read_messages(topics=["/go1/odom"])]
        self.assertEqual(odom[0].header.frame_id, "odom")
        self.assertEqual(odom[0].child_frame_id, "base_link")
        self.assertAlmostEqual(odom[0].pose.pose.position.x, -0.2, delta=0.05)
        self.assertAlmostEqual(odom[0].pose.pose.position.y, -1.45, delta=0.05)
        self.assertGreater(odom[-1].pose.pose.position.x, odom[0].pose.pose.position.x)
        self.assertEqual(odom[0].header.stamp.to_nsec(), round(float(traj[0]["time_sec"]) * 1e9))

        joints = next(m for _, m, _ in bag.read_messages(topics=["/go1/joint_states"]))
        self.assertEqual(len(joints.name), 12)
        self.assertTrue(all(n.startswith("go1/") for n in joints.name))

        points = next(m for _, m, _ in bag.read_messages(topics=["/go1/top/points"]))
        self.assertEqual([f.name for f in points.fields],
                         ["x", "y", "z", "intensity", "ring", "time"])
        self.assertEqual(points.point_step, 24)
        self.assertGreater(points.width, 1000)

        static = [m for _, m, _ in bag.read_messages(topics=["/tf_static"])]
        pairs = {(t.header.frame_id, t.child_frame_id) for m in static for t in m.transforms}
        self.assertIn(("base_link", "front/optical"), pairs)
        self.assertIn(("map", "odom"), pairs)
        self.assertIn(("base_link", "top"), pairs)
        bag.close()

    def test_existing_bag_is_refused(self):
        before = os.path.getsize(self.bag)
        r = run([BINARY, "export", self.run_dir, "--format", "rosbag", "--out", self.bag])
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("--out", r.stderr)
        self.assertEqual(os.path.getsize(self.bag), before)


if __name__ == "__main__":
    unittest.main(argv=sys.argv[:1], verbosity=2)

"""`penumbra export RUN --format rosbag2`, read back by ROS 2 bag readers nobody here wrote.

runs the sensors demo world (quadruped with a camera, LiDAR and IMU) for a short time, exports
the run folder as a ROS 2 bag and checks it with
  - the official `mcap` reader and `mcap_ros2`'s decoder, which decodes every message from the
    schema (message definition) embedded in the file: profile, schemas, channels (encoding, QoS
    metadata, type hash against rosbags' own REP-2011 hashes), statistics, CRCs;
  - rosbags' rosbag2 Reader (metadata.yaml and its own MCAP reader) and its ROS 2 Jazzy typestore's
    deserialize_cdr: topics, types, counts the run's files imply, stamps and record times, image
    size, encoding and bytes against the PNGs, depth in metres, CameraInfo K, IMU values, odometry,
    joint names, point fields, /tf_static frames;
and that the message count equals the ROS 1 export's (when this build has ROS 1), that an
existing --out is refused, and that neither a completed nor a failed export (a write past a file
size limit; a full 2 MiB tmpfs where one can be mounted; SIGINT) leaves a temporary folder beside
the bag.

usage: rosbag2_export_test.py PENUMBRA_BINARY SOURCE_DIR WORK_DIR   (the project venv's python)
exits 77 (skipped, saying why) in a build without ROS 2 or without the venv's packages.
"""
import glob
import json
import math
import os
import re
import resource
import shutil
import signal
import struct
import subprocess
import sys
import unittest

try:
    from mcap.reader import make_reader
    from mcap.stream_reader import StreamReader
    from mcap_ros2.decoder import DecoderFactory
    from rosbags.rosbag2 import Reader
    from rosbags.typesys import Stores, get_typestore
    from ruamel.yaml import YAML
except ImportError as e:
    print("skipped: %s (run with the project venv's python, .venv: scripts/install-deps.sh)" % e)
    sys.exit(77)

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from run_folder import csv_rows, read_png, state_samples  # noqa: E402

BINARY, SOURCE, WORK = sys.argv[1:4]
DURATION = 0.6
NO_ROS2 = "built without ROS 2"

# the QoS the live bridge offers (docs/ros.md): (reliability, durability, depth)
SENSOR_QOS = ("best_effort", "volatile", 5)
EXPECTED_QOS = {
    "/go1/front/image_raw": SENSOR_QOS,
    "/go1/front/camera_info": SENSOR_QOS,
    "/go1/front/depth/image_raw": SENSOR_QOS,
    "/go1/front/depth/camera_info": SENSOR_QOS,
    "/go1/trunk_imu/data": SENSOR_QOS,
    "/go1/top/points": SENSOR_QOS,
    "/go1/odom": ("reliable", "volatile", 10),
    "/go1/joint_states": ("reliable", "volatile", 10),
    "/tf": ("reliable", "volatile", 100),
    "/tf_static": ("reliable", "transient_local", 1),
}


def run(args):
    return subprocess.run(args, capture_output=True, text=True, timeout=300)


class Rosbag2ExportTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        shutil.rmtree(WORK, ignore_errors=True)
        os.makedirs(WORK)
        cls.run_dir = os.path.join(WORK, "run")
        cls.bag = os.path.join(WORK, "run_bag")
        r = run([BINARY, "run", os.path.join(SOURCE, "worlds/sensors.yaml"), "--duration",
                 str(DURATION), "--outputs", "rgb,depth", "--out", cls.run_dir])
        if r.returncode != 0:
            raise RuntimeError("penumbra run failed:\n" + r.stderr)
        r = run([BINARY, "export", cls.run_dir, "--format", "rosbag2", "--out", cls.bag])
        if r.returncode != 0 and NO_ROS2 in r.stderr:
            raise unittest.SkipTest("this penumbra has no ROS 2: " + r.stderr.strip())
        if r.returncode != 0:
            raise RuntimeError("penumbra export failed:\n" + r.stderr)
        cls.export_log = r.stderr
        cls.mcap_path = os.path.join(cls.bag, "run_bag_0.mcap")
        cls.typestore = get_typestore(Stores.ROS2_JAZZY)
        with Reader(cls.bag) as reader:
            cls.connections = {c.topic: c for c in reader.connections}
            cls.metadata_count = reader.message_count
            cls.messages = {}
            for c, t, raw in reader.messages():
                msg = cls.typestore.deserialize_cdr(raw, c.msgtype)
                cls.messages.setdefault(c.topic, []).append((t, msg))

    def rows(self, path):
        return csv_rows(self.run_dir, path)

    def expected_state_samples(self, rate_hz=50.0):
        return state_samples(self.run_dir, rate_hz)

    def expected_topics(self):
        frames = len(self.rows("front/frames.csv"))
        imu = len(self.rows("imu/trunk_imu.csv"))
        scans = len(self.rows("lidar/top/index.csv"))
        states = self.expected_state_samples()
        self.assertGreater(frames, 0)
        self.assertGreater(imu, 50)
        self.assertGreater(scans, 1)
        return {
            "/go1/front/image_raw": (frames, "sensor_msgs/msg/Image"),
            "/go1/front/camera_info": (frames, "sensor_msgs/msg/CameraInfo"),
            "/go1/front/depth/image_raw": (frames, "sensor_msgs/msg/Image"),
            "/go1/front/depth/camera_info": (frames, "sensor_msgs/msg/CameraInfo"),
            "/go1/trunk_imu/data": (imu, "sensor_msgs/msg/Imu"),
            "/go1/top/points": (scans, "sensor_msgs/msg/PointCloud2"),
            "/go1/odom": (states, "nav_msgs/msg/Odometry"),
            "/go1/joint_states": (states, "sensor_msgs/msg/JointState"),
            "/tf": (states, "tf2_msgs/msg/TFMessage"),
            "/tf_static": (4, "tf2_msgs/msg/TFMessage"),
        }

    def test_layout_and_metadata_yaml(self):
        self.assertEqual(sorted(os.listdir(self.bag)), ["metadata.yaml", "run_bag_0.mcap"])
        with open(os.path.join(self.bag, "metadata.yaml")) as f:
            info = YAML(typ="safe").load(f)["rosbag2_bagfile_information"]
        self.assertEqual(info["version"], 9)
        self.assertEqual(info["storage_identifier"], "mcap")
        self.assertEqual(info["relative_file_paths"], ["run_bag_0.mcap"])
        self.assertEqual(info["files"][0]["path"], "run_bag_0.mcap")
        self.assertEqual(info["ros_distro"], "jazzy")
        expected = self.expected_topics()
        total = sum(n for n, _ in expected.values())
        self.assertEqual(info["message_count"], total)
        self.assertEqual(info["files"][0]["message_count"], total)
        self.assertEqual(self.metadata_count, total)
        # the last record time: the last state sample or the last IMU delivery
        self.assertGreater(info["duration"]["nanoseconds"], 0.5e9)
        for t in info["topics_with_message_count"]:
            m = t["topic_metadata"]
            self.assertEqual(t["message_count"], expected[m["name"]][0], m["name"])
            self.assertEqual(m["type"], expected[m["name"]][1])
            self.assertEqual(m["serialization_format"], "cdr")
            self.assertEqual(m["type_description_hash"], self.typestore.hash_rihs01(m["type"]))
            qos = m["offered_qos_profiles"][0]
            self.assertEqual((qos["reliability"], qos["durability"], qos["depth"]),
                             EXPECTED_QOS[m["name"]], m["name"])
            self.assertEqual(qos["history"], "keep_last")
        self.assertEqual(len(info["topics_with_message_count"]), len(expected))
        # nothing left beside the bag
        self.assertEqual(glob.glob(os.path.join(WORK, "*tmp*")), [])

    def test_official_mcap_reader_decodes_every_message_from_the_embedded_schemas(self):
        expected = self.expected_topics()
        counts = {}
        with open(self.mcap_path, "rb") as f:
            reader = make_reader(f, decoder_factories=[DecoderFactory()])
            self.assertEqual(reader.get_header().profile, "ros2")
            summary = reader.get_summary()
            for schema in summary.schemas.values():
                self.assertEqual(schema.encoding, "ros2msg")
                self.assertIn(schema.name, {t for _, t in expected.values()})
            for channel in summary.channels.values():
                self.assertEqual(channel.message_encoding, "cdr")
                self.assertEqual(summary.schemas[channel.schema_id].name,
                                 expected[channel.topic][1])
                qos = YAML(typ="safe").load(channel.metadata["offered_qos_profiles"])[0]
                self.assertEqual((qos["reliability"], qos["durability"], qos["depth"]),
                                 EXPECTED_QOS[channel.topic], channel.topic)
                self.assertEqual(channel.metadata["topic_type_hash"],
                                 self.typestore.hash_rihs01(expected[channel.topic][1]))
            self.assertEqual(summary.statistics.message_count,
                             sum(n for n, _ in expected.values()))
            self.assertGreater(summary.statistics.chunk_count, 1)
            rosbag2 = {m.name: m.metadata for m in reader.iter_metadata()}
            self.assertIn("version: 9", rosbag2["rosbag2"]["serialized_metadata"])
            last = -1
            for schema, channel, message, decoded in reader.iter_decoded_messages():
                counts[channel.topic] = counts.get(channel.topic, 0) + 1
                self.assertGreaterEqual(message.log_time, last)  # log-time order
                last = message.log_time
                if channel.topic == "/go1/front/image_raw":
                    self.assertEqual((decoded.width, decoded.height, decoded.encoding),
                                     (640, 480, "rgb8"))
                    self.assertEqual(len(decoded.data), 640 * 480 * 3)
                elif channel.topic == "/go1/trunk_imu/data":
                    self.assertEqual(decoded.header.frame_id, "trunk_imu")
                    self.assertEqual(decoded.orientation_covariance[0], -1)
        self.assertEqual(counts, {t: n for t, (n, _) in expected.items()})
        # every record in file order with the data section and chunk CRCs checked
        with open(self.mcap_path, "rb") as f:
            kinds = {type(r).__name__ for r in StreamReader(f, validate_crcs=True).records}
        self.assertTrue({"Header", "Schema", "Channel", "Message", "DataEnd", "Statistics",
                         "ChunkIndex", "SummaryOffset", "Footer"} <= kinds, kinds)

    def test_rosbags_reads_the_run_data(self):
        expected = self.expected_topics()
        self.assertEqual(sorted(self.connections), sorted(expected))
        for topic, (count, type_) in expected.items():
            self.assertEqual(self.connections[topic].msgtype, type_)
            self.assertEqual(self.connections[topic].msgcount, count, topic)
            self.assertEqual(len(self.messages[topic]), count, topic)

        with open(os.path.join(self.run_dir, "camera_info.json")) as f:
            cam_info = json.load(f)["front"]
        frames = self.rows("front/frames.csv")

        def ns(stamp):
            return stamp.sec * 1000000000 + stamp.nanosec

        images = self.messages["/go1/front/image_raw"]
        for (t, img), row in zip(images, frames):
            stamp = round(float(row["time_sec"]) * 1e9)
            self.assertEqual(ns(img.header.stamp), stamp)
            self.assertEqual(t, stamp)  # recorded at the frame time (0 stays 0)
            self.assertEqual(img.header.frame_id, "front/optical")
            self.assertEqual((img.width, img.height, img.encoding, img.step),
                             (640, 480, "rgb8", 640 * 3))
        w, h, ch, bits, rgb = read_png(os.path.join(self.run_dir, "front/rgb/000000.png"))
        self.assertEqual((w, h, ch, bits), (640, 480, 3, 8))
        self.assertEqual(bytes(images[0][1].data), rgb)

        info = self.messages["/go1/front/camera_info"][0][1]
        for a, b in zip(info.k, cam_info["K"]):
            self.assertAlmostEqual(a, b, places=9)
        self.assertEqual(info.distortion_model, "plumb_bob")
        self.assertEqual((info.width, info.height), (640, 480))

        # depth: the PNG's millimetres as metres, no return as +Inf
        depth = self.messages["/go1/front/depth/image_raw"][0][1]
        self.assertEqual((depth.encoding, depth.step), ("32FC1", 640 * 4))
        values = struct.unpack("<%df" % (640 * 480), bytes(depth.data))
        w, h, ch, bits, mm = read_png(os.path.join(self.run_dir, "front/depth/000000.png"))
        hits = 0
        for i in range(0, w * h, 97):
            if mm[i] == 0:
                self.assertTrue(math.isinf(values[i]) and values[i] > 0)
            else:
                hits += 1
                self.assertAlmostEqual(values[i], mm[i] / 1000.0, places=6)
        self.assertGreater(hits, 100)

        # IMU: the csv's samples, stamped with the capture time, recorded 2 ms later
        imu_rows = self.rows("imu/trunk_imu.csv")
        for (t, m), row in zip(self.messages["/go1/trunk_imu/data"], imu_rows):
            capture = round(float(row["capture_time_sec"]) * 1e9)
            self.assertEqual(ns(m.header.stamp), capture)
            self.assertEqual(t, capture + 2000000)
            self.assertAlmostEqual(m.linear_acceleration.z, float(row["accel_z_m_s2"]), places=6)
            self.assertAlmostEqual(m.angular_velocity.x, float(row["gyro_x_rad_s"]), places=6)

        odom = [m for _, m in self.messages["/go1/odom"]]
        self.assertEqual((odom[0].header.frame_id, odom[0].child_frame_id), ("odom", "base_link"))
        self.assertAlmostEqual(odom[0].pose.pose.position.x, -0.2, delta=0.05)
        self.assertAlmostEqual(odom[0].pose.pose.position.y, -1.45, delta=0.05)
        self.assertGreater(odom[-1].pose.pose.position.x, odom[0].pose.pose.position.x)

        joints = self.messages["/go1/joint_states"][0][1]
        self.assertEqual(len(joints.name), 12)
        self.assertTrue(all(n.startswith("go1/") for n in joints.name))

        points = self.messages["/go1/top/points"][0][1]
        self.assertEqual([f.name for f in points.fields],
                         ["x", "y", "z", "intensity", "ring", "time"])
        self.assertEqual(points.point_step, 24)
        self.assertGreater(points.width, 1000)
        self.assertEqual(len(points.data), points.width * 24)

        pairs = {(t.header.frame_id, t.child_frame_id)
                 for _, m in self.messages["/tf_static"] for t in m.transforms}
        self.assertTrue({("base_link", "front/optical"), ("map", "odom"), ("base_link", "top")}
                        <= pairs, pairs)

    def test_same_messages_as_the_ros1_export(self):
        bag1 = os.path.join(WORK, "run.bag")
        r = run([BINARY, "export", self.run_dir, "--format", "rosbag", "--out", bag1])
        if r.returncode != 0 and "ROS 1" in r.stderr:
            self.skipTest("this penumbra has no ROS 1: " + r.stderr.strip())
        self.assertEqual(r.returncode, 0, r.stderr)
        summary = re.compile(r"exported (\d+) messages on (\d+) topics")
        self.assertEqual(summary.search(r.stderr).groups(),
                         summary.search(self.export_log).groups())

    def test_a_failed_write_leaves_nothing(self):
        # a file size limit of 1 MiB (SIGXFSZ ignored: the write fails with EFBIG) stands in for
        # a full disk
        def limit():
            signal.signal(signal.SIGXFSZ, signal.SIG_IGN)
            resource.setrlimit(resource.RLIMIT_FSIZE, (1 << 20, 1 << 20))

        out = os.path.join(WORK, "small", "bag")
        os.makedirs(os.path.dirname(out))
        r = subprocess.run([BINARY, "export", self.run_dir, "--format", "rosbag2", "--out", out],
                           capture_output=True, text=True, timeout=300, preexec_fn=limit)
        self.assertEqual(r.returncode, 1, r.stderr)
        self.assertIn("File too large", r.stderr)
        self.assertEqual(os.listdir(os.path.dirname(out)), [])

    def test_a_full_disk_exits_one_with_the_reason_and_leaves_nothing(self):
        mnt = os.path.join(WORK, "full_disk")
        os.makedirs(mnt)
        m = run(["mount", "-t", "tmpfs", "-o", "size=2m", "tmpfs", mnt])
        if m.returncode != 0:
            self.skipTest("cannot mount a 2 MiB tmpfs here: " + m.stderr.strip())
        try:
            out = os.path.join(mnt, "bag")
            r = run([BINARY, "export", self.run_dir, "--format", "rosbag2", "--out", out])
            self.assertEqual(r.returncode, 1, r.stderr)
            self.assertIn("No space left on device", r.stderr)
            self.assertIn(out, r.stderr)
            self.assertEqual(os.listdir(mnt), [])
        finally:
            run(["umount", "-l", mnt])

    def test_an_interrupted_export_leaves_nothing(self):
        # SIGINT at several points of the export: each ends as exit 130 with nothing at or
        # beside --out (killed by it before the handler is set: nothing either), or (too late to
        # stop) as a complete bag
        import time

        stopped = 0
        for i in range(40):
            if stopped >= 2:
                break
            delay = 0.01 * (i + 1)
            parent = os.path.join(WORK, "stop%d" % i)
            os.makedirs(parent)
            out = os.path.join(parent, "bag")
            p = subprocess.Popen([BINARY, "export", self.run_dir, "--format", "rosbag2", "--out",
                                  out], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                                 text=True)
            time.sleep(delay)
            p.send_signal(signal.SIGINT)
            _, err = p.communicate(timeout=60)
            if p.returncode in (130, -signal.SIGINT):  # stopped, or before it set its handler
                stopped += p.returncode == 130
                self.assertEqual(os.listdir(parent), [], err)
            else:
                self.assertEqual(p.returncode, 0, err)
                self.assertEqual(os.listdir(parent), ["bag"])
                self.assertEqual(sorted(os.listdir(out)), ["bag_0.mcap", "metadata.yaml"])
        self.assertGreater(stopped, 0)

    def test_an_existing_folder_is_refused(self):
        before = sorted(os.listdir(self.bag))
        r = run([BINARY, "export", self.run_dir, "--format", "rosbag2", "--out", self.bag])
        self.assertEqual(r.returncode, 2, r.stderr)
        self.assertIn("--out", r.stderr)
        self.assertEqual(sorted(os.listdir(self.bag)), before)


if __name__ == "__main__":
    result = unittest.main(argv=sys.argv[:1], verbosity=2, exit=False).result
    if result.failures or result.errors:
        sys.exit(1)
    # a build without ROS 2: every test skipped (ctest's SKIP_RETURN_CODE)
    sys.exit(77 if result.skipped and result.testsRun == 0 else 0)

"""penumbra_client.protocol and .messages: request/reply encoding, error classes, typed results
(docs/zmq-protocol.md, protocol version 1)."""

import os
import sys
import unittest

import msgpack
import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "python"))
import penumbra_client as pc  # noqa: E402
from penumbra_client.messages import (LIDAR_POINT_DTYPE, Message, ModelInfo, State,  # noqa: E402
                                     StepResult)
from penumbra_client.protocol import decode_reply, encode_request  # noqa: E402


class EncodeRequestTest(unittest.TestCase):
    def test_map_with_cmd_id_and_fields(self):
        body = encode_request("twist", {"vx": 0.3, "robot": None, "yaw_rate": 1}, request_id=7)
        self.assertEqual(msgpack.unpackb(body), {"cmd": "twist", "id": 7, "vx": 0.3, "yaw_rate": 1})

    def test_numpy_values_become_msgpack_numbers(self):
        ctrl = np.array([0.5, -1.25], dtype=np.float32)
        body = encode_request("set_ctrl", {"ctrl": ctrl, "n": np.int64(3), "xyz": (1.0, 2.0, 3.0)})
        decoded = msgpack.unpackb(body)
        self.assertEqual(decoded["ctrl"], [0.5, -1.25])
        self.assertEqual(decoded["n"], 3)
        self.assertEqual(decoded["xyz"], [1.0, 2.0, 3.0])
        # reals go as float64 (msgpack 0xcb), as the protocol says
        self.assertIn(b"\xcb", msgpack.packb(decoded["ctrl"], use_single_float=False))
        self.assertIn(b"\xcb\x3f\xe0\x00\x00", body)  # 0.5 as float64

    def test_strings_are_msgpack_str_and_bytes_bin(self):
        body = encode_request("sync", {"token": "abc", "blob": b"\x00\x01"})
        self.assertIn(b"\xa5token\xa3abc", body)
        self.assertIn(b"\xc4\x02\x00\x01", body)

    def test_bad_values_are_refused_on_the_client(self):
        with self.assertRaises(TypeError):
            encode_request("", {})
        with self.assertRaises(TypeError):
            encode_request("step", {"id": 3})
        with self.assertRaises(TypeError):
            encode_request("step", {"n": object()})


class DecodeReplyTest(unittest.TestCase):
    def test_ok_reply(self):
        r = decode_reply(msgpack.packb({"ok": True, "cmd": "step", "id": 1, "step": 5}))
        self.assertEqual(r["step"], 5)

    def test_error_codes_map_to_classes(self):
        cases = {
            "malformed": pc.MalformedRequestError, "too_large": pc.RequestTooLargeError,
            "unknown_command": pc.UnknownCommandError, "missing_field": pc.MissingFieldError,
            "bad_field": pc.BadFieldError, "unknown_field": pc.UnknownFieldError,
            "version_mismatch": pc.VersionMismatchError, "conflict": pc.ConflictError,
            "not_available": pc.NotAvailableError, "run_ended": pc.RunEndedError,
            "stopping": pc.StoppingError, "failed": pc.CommandFailedError,
        }
        for code, cls in cases.items():
            body = msgpack.packb({"ok": False, "cmd": "set_ctrl", "id": 2, "error": {
                "code": code, "field": "ctrl[3]", "message": "expected a finite float"}})
            with self.assertRaises(cls) as ctx:
                decode_reply(body)
            e = ctx.exception
            self.assertIsInstance(e, pc.PenumbraError)
            self.assertEqual((e.code, e.field, e.cmd), (code, "ctrl[3]", "set_ctrl"))
            self.assertEqual(str(e), f"set_ctrl: {code} (field ctrl[3]): expected a finite float")

    def test_unknown_code_is_a_plain_penumbra_error(self):
        body = msgpack.packb({"ok": False, "cmd": None, "error": {"code": "new_code",
                                                                  "field": None, "message": "m"}})
        with self.assertRaises(pc.PenumbraError) as ctx:
            decode_reply(body)
        self.assertEqual(type(ctx.exception), pc.PenumbraError)
        self.assertEqual(ctx.exception.code, "new_code")

    def test_not_a_reply(self):
        for body in (b"\xc1", msgpack.packb([1, 2]), msgpack.packb({"ok": 1})):
            with self.assertRaises(pc.BadReplyError):
                decode_reply(body)


class MessageTest(unittest.TestCase):
    def test_camera_message_image(self):
        rgb = np.arange(2 * 3 * 3, dtype=np.uint8).reshape(2, 3, 3)
        header = {"stamp": 0.1, "sim_step": 50, "frame_id": "front/optical", "encoding": "rgb8",
                  "width": 3, "height": 2, "step": 9, "is_bigendian": False}
        m = Message("camera/front/rgb", header, memoryview(rgb.tobytes()))
        self.assertTrue(m.is_image)
        self.assertEqual((m.stamp, m.sim_step, m.frame_id), (0.1, 50, "front/optical"))
        np.testing.assert_array_equal(m.image(), rgb)
        with self.assertRaises(ValueError):
            Message("imu/imu", {}, b"").image()

    def test_lidar_points(self):
        pts = np.zeros(3, dtype=LIDAR_POINT_DTYPE)
        pts["x"] = [1, 2, 3]
        pts["time"] = [0.0, 0.05, 0.1]
        m = Message("lidar/os1", {"count": 3, "point_step": 20}, pts.tobytes())
        p = m.points()
        np.testing.assert_array_equal(p["x"], [1, 2, 3])
        np.testing.assert_allclose(p["time"], [0.0, 0.05, 0.1])

    def test_step_result_groups_by_topic(self):
        a = Message("camera/front/rgb", {"stamp": 0.0}, b"")
        b = Message("camera/front/depth", {"stamp": 0.0}, b"")
        c = Message("camera/front/rgb", {"stamp": 0.1}, b"")
        r = StepResult({"step": 100, "time_sec": 0.2, "ended": False,
                        "published": {"camera/front/rgb": 2}}, [a, b, c], None)
        self.assertEqual(r.by_topic("camera/front/rgb"), [a, c])
        self.assertIs(r.latest("camera/front/rgb"), c)
        self.assertIsNone(r.latest("imu/x"))

    def test_state_arrays_and_equality(self):
        reply = {"step": 3, "time_sec": 0.006, "qpos": [0.0, 1.0], "qvel": [2.0], "act": [],
                 "ctrl": [0.5], "mocap_pos": [1.0, 2.0, 3.0], "mocap_quat": [1.0, 0, 0, 0],
                 "sensordata": [], "paused": True}
        s = State(reply)
        self.assertEqual(s.qpos.dtype, np.float64)
        self.assertEqual(s.mocap_pos.shape, (1, 3))
        self.assertEqual(s.mocap_quat.shape, (1, 4))
        self.assertEqual(s, State(dict(reply)))
        self.assertNotEqual(s, State(dict(reply, qvel=[2.0000000001])))

    def test_model_info_lookups(self):
        info = ModelInfo({"ok": True, "nq": 2, "nu": 3, "seed": 4,
                          "actuators": [
                              {"id": 0, "name": "a", "ctrl_limited": True, "ctrl_range": [-1, 1]},
                              {"id": 1, "name": "b", "ctrl_limited": False, "ctrl_range": [0, 0]},
                              {"id": 2, "name": "c", "ctrl_limited": True, "ctrl_range": [0, 5]}],
                          "cameras": [{"name": "front", "width": 8}],
                          "controllers": [{"index": 0, "robot": "dog", "type": "trot_gait",
                                           "commands": ["twist"]}]})
        self.assertEqual(info.nq, 2)
        self.assertEqual(info.actuator("c")["id"], 2)
        self.assertEqual(info.camera("front")["width"], 8)
        lo, hi = info.ctrl_bounds()
        np.testing.assert_array_equal(lo, [-1, -np.inf, 0])
        np.testing.assert_array_equal(hi, [1, np.inf, 5])
        self.assertEqual(info.controller()["robot"], "dog")
        with self.assertRaisesRegex(KeyError, "no camera 'back'.*front"):
            info.camera("back")


if __name__ == "__main__":
    unittest.main()

"""Acceptance: malformed msgpack, an oversized frame, wrong field types and an unknown
command each get an error reply from a real `penumbra run --zmq`, and the next valid request
works; the client raises the error class of each code."""

import os
import sys
import unittest

import msgpack

sys.path.insert(0, os.path.dirname(__file__))
from penumbra_server import PenumbraServer  # noqa: E402

import penumbra_client as pc  # noqa: E402  (path set by penumbra_server)


class ErrorRepliesTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.server = PenumbraServer("worlds/quadruped_target.yaml", lockstep=True).__enter__()
        cls.client = cls.server.connect(timeout_sec=60)

    @classmethod
    def tearDownClass(cls):
        cls.client.close()
        cls.server.__exit__(None, None, None)

    def assert_next_request_works(self):
        before = self.client.get_state().step
        r = self.client.step(1)
        self.assertEqual(r.step, before + 1)

    def raw(self, frames, code, field=None):
        reply = self.client.request_raw(frames)
        self.assertIs(reply.get("ok"), False, reply)
        self.assertEqual(reply["error"]["code"], code, reply)
        self.assertTrue(reply["error"]["message"])
        if field is not None:
            self.assertEqual(reply["error"]["field"], field, reply)
        self.assert_next_request_works()
        return reply

    def test_malformed_msgpack(self):
        self.raw(b"\xc1\xff not msgpack", "malformed")
        self.raw(b"\x93\x01", "malformed")                      # truncated array
        self.raw(msgpack.packb([1, 2, 3]), "malformed")         # not a map
        self.raw(msgpack.packb({"n": 3}), "malformed")          # no cmd
        self.raw(msgpack.packb({"cmd": 5}), "malformed")        # cmd not a string
        self.raw([msgpack.packb({"cmd": "hello", "protocol": 1}), b"x"], "malformed")  # 2 frames

    def test_oversized_frame(self):
        cap = self.client.server["max_request_bytes"]
        self.assertGreater(cap, 0)
        body = msgpack.packb({"cmd": "set_ctrl", "ctrl": [0.0], "pad": b"\0" * cap})
        self.assertGreater(len(body), cap)
        self.raw(body, "too_large")
        # a request just under the cap is read (and refused for its content, not its size)
        body = msgpack.packb({"cmd": "set_ctrl", "ctrl": "x" * (cap - 100)})
        self.assertLessEqual(len(body), cap)
        self.raw(body, "bad_field", field="ctrl")

    def test_wrong_field_types(self):
        cases = [
            ({"cmd": "step", "n": "ten"}, "n"),
            ({"cmd": "step", "n": 1.5}, "n"),
            ({"cmd": "step", "n": 0}, "n"),
            ({"cmd": "step", "state": "yes"}, "state"),
            ({"cmd": "twist", "vx": "fast"}, "vx"),
            ({"cmd": "twist", "yaw_rate": [1.0]}, "yaw_rate"),
            ({"cmd": "set_ctrl", "ctrl": "x"}, "ctrl"),
            ({"cmd": "set_ctrl", "ctrl": [0.0, 1.0]}, "ctrl"),
            ({"cmd": "set_mocap", "body": "nope", "xyz": [0, 0, 0]}, "body"),
            ({"cmd": "hello", "protocol": "1"}, "protocol"),
        ]
        for request, field in cases:
            with self.subTest(request=request):
                self.raw(msgpack.packb(request), "bad_field", field=field)
        # one with a non-finite value inside the list
        nu = self.client.model_info().nu
        ctrl = [0.0] * nu
        ctrl[3] = float("nan")
        self.raw(msgpack.packb({"cmd": "set_ctrl", "ctrl": ctrl}), "bad_field", field="ctrl[3]")

    def test_unknown_command_and_field(self):
        reply = self.raw(msgpack.packb({"cmd": "fly", "id": 9}), "unknown_command")
        self.assertEqual(reply["id"], 9)
        self.assertIn("step", reply["error"]["message"])  # the message lists the valid ones
        self.raw(msgpack.packb({"cmd": "step", "n": 1, "speed": 2}), "unknown_field", field="speed")
        self.raw(msgpack.packb({"cmd": "set_mocap", "xyz": [0, 0, 0]}), "missing_field",
                 field="body")

    def test_client_raises_the_class_of_each_code(self):
        c = self.client
        with self.assertRaises(pc.UnknownCommandError):
            c.request("fly")
        with self.assertRaises(pc.BadFieldError) as ctx:
            c.step(n=-1)
        self.assertEqual(ctx.exception.field, "n")
        with self.assertRaises(pc.UnknownFieldError):
            c.request("get_state", verbose=True)
        with self.assertRaises(pc.VersionMismatchError):
            c.request("hello", protocol=2)
        with self.assertRaises(pc.BadFieldError):
            c.reset(seed=self.client.model_info().seed + 1)
        with self.assertRaises(pc.ConflictError):
            c.resume()
            try:
                c.step(1)
            finally:
                c.pause()
        self.assert_next_request_works()


if __name__ == "__main__":
    unittest.main()

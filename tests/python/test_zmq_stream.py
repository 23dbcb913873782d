"""The sensor stream of a free-running `penumbra run --zmq --realtime` through the Python client:
subscriptions, frames in order while the run runs on its own, pause -> lockstep steps ->
resume, and `stop` ending the run with its outputs (the `end` message, run.json)."""

import json
import os
import sys
import unittest

sys.path.insert(0, os.path.dirname(__file__))
from penumbra_server import PenumbraServer  # noqa: E402

import penumbra_client as pc  # noqa: E402


class StreamTest(unittest.TestCase):
    def test_free_running_stream_pause_step_resume_stop(self):
        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=False,
                            extra=["--realtime"]) as server:
            client = server.connect(timeout_sec=30)
            self.assertEqual(client.server["mode"], "free")
            sub = client.subscribe(["camera/front/rgb", "end"])
            frames = []
            while len(frames) < 4:
                msg = sub.recv(timeout_sec=10)
                self.assertIsNotNone(msg, "no frame within 10 s of a free-running run")
                if msg.topic == "camera/front/rgb":
                    frames.append(msg)
            idx = [m.header["index"] for m in frames]
            self.assertEqual(idx, list(range(idx[0], idx[0] + 4)))  # none lost, in order
            for a, b in zip(frames, frames[1:]):
                self.assertAlmostEqual(b.stamp - a.stamp, 0.1, delta=1e-9)
            self.assertEqual(frames[0].image().shape, (60, 80, 3))

            # stepping needs a paused run
            with self.assertRaises(pc.ConflictError):
                client.step(1)
            paused = client.pause()
            self.assertTrue(paused["paused"])
            while sub.recv(timeout_sec=0.2) is not None:  # frames of the running phase
                pass
            r = client.step(50)
            self.assertEqual(r.step, paused["step"] + 50)
            self.assertEqual(len(r.by_topic("camera/front/rgb")), 1)  # one 10 Hz frame in 0.1 s
            self.assertFalse(client.resume()["paused"])

            stopped = client.stop()
            end = None
            while end is None:
                msg = sub.recv(timeout_sec=30)
                self.assertIsNotNone(msg, "no `end` message after stop")
                if msg.topic == "end":
                    end = msg
            self.assertEqual(end.header["reason"], "stopped")
            self.assertGreaterEqual(end.sim_step, stopped["step"])
            client.close()
            self.assertEqual(server.wait(), 0, server.output())
            with open(os.path.join(server.out_dir, "run.json")) as f:
                self.assertTrue(json.load(f)["interrupted"])


if __name__ == "__main__":
    unittest.main()

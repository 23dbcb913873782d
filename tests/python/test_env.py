"""PenumbraEnv (Gymnasium-style reset/step) over a real lockstep `penumbra run --zmq`."""

import json
import os
import sys
import time
import unittest

import numpy as np

sys.path.insert(0, os.path.dirname(__file__))
from penumbra_server import PenumbraServer  # noqa: E402

import penumbra_client as pc  # noqa: E402


class PenumbraEnvTest(unittest.TestCase):
    def test_reset_step_spaces(self):
        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
            client = server.connect(timeout_sec=60)
            # the target's red pixels: the reward is the count of them in view
            reward = lambda obs, info: float(((obs["rgb"][..., 0] > 100) &  # noqa: E731
                                              (obs["rgb"][..., 1] < 50)).sum())
            env = pc.PenumbraEnv(client=client, outputs=("rgb", "depth"), reward_fn=reward,
                                 max_episode_steps=15)
            self.assertEqual(env.action_space.shape, (3,))
            self.assertEqual(env.observation_space["rgb"].shape, (60, 80, 3))
            self.assertEqual(env.observation_space["depth"].dtype, np.float32)
            self.assertEqual(env.observation_space["qpos"].shape, (client.model_info().nq,))
            self.assertEqual(env.steps_per_action, 50)  # 10 Hz camera, 2 ms steps

            obs, info = env.reset(seed=client.model_info().seed)
            self.assertTrue(env.observation_space.contains(obs), obs.keys())
            x0 = obs["qpos"][:2].copy()
            self.assertLess(np.linalg.norm(x0), 0.05)
            t0 = info["time_sec"]
            done, n, rewards = False, 0, []
            while not done:
                obs, r, terminated, truncated, info = env.step([0.5, 0.0, 0.0])
                self.assertTrue(env.observation_space.contains(obs))
                rewards.append(r)
                n += 1
                done = terminated or truncated
            self.assertEqual(n, 15)
            self.assertAlmostEqual(info["time_sec"] - t0, 15 * 0.1, places=9)
            # walking forward at up to 0.5 m/s for 1.5 s
            self.assertGreater(obs["qpos"][0] - x0[0], 0.3)
            self.assertGreater(max(rewards), 0)  # the red target is in view
            # an action outside the box is clipped, not refused
            env.step([10.0, 0.0, 0.0])
            # a reset goes back to the start pose
            obs, _ = env.reset()
            self.assertLess(np.linalg.norm(obs["qpos"][:2] - x0), 0.05)
            with self.assertRaises(ValueError):
                env.reset(seed=client.model_info().seed + 1)
            self.assertEqual(env.render().shape, (60, 80, 3))
            env.close()
            client.close()

    def test_same_actions_give_the_same_episode(self):
        # reset restores the controllers (gait phase, references) and restarts their clock and
        # the cameras' schedules and noise: the same actions after a reset give the first
        # episode's qpos and qvel and its images (the D435 profile's noise and auto exposure)
        # bit for bit, also after an episode of other actions
        actions = [[0.5, 0.0, 0.0]] * 10 + [[0.3, 0.2, 1.0]] * 10 + [[0.0, 0.0, -1.5]] * 10

        def episode(env, acts):
            obs, _ = env.reset()
            rows = [np.concatenate([obs["qpos"], obs["qvel"]])]
            images = [obs["rgb"].tobytes()]
            for a in acts:
                obs, _, _, _, _ = env.step(a)
                rows.append(np.concatenate([obs["qpos"], obs["qvel"]]))
                images.append(obs["rgb"].tobytes())
            return np.array(rows), images

        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
            client = server.connect(timeout_sec=60)
            env = pc.PenumbraEnv(client=client)
            first, first_images = episode(env, actions)
            self.assertGreater(first[-1, 0] - first[0, 0], 0.3)  # it walked
            episode(env, [[1.0, -0.5, 2.0]] * 7)
            second, second_images = episode(env, actions)
            self.assertEqual(first.shape, second.shape)
            self.assertEqual(first.tobytes(), second.tobytes(),
                             "first differing step: %d" %
                             int(np.argmax(np.any(first != second, axis=1))))
            self.assertEqual(len(set(first_images)), len(first_images))  # it saw new frames
            differ = [k for k, (a, b) in enumerate(zip(first_images, second_images)) if a != b]
            self.assertEqual(differ, [], "the images of these steps differ")
            env.close()
            client.close()

    def test_close_stops_the_server(self):
        # an environment that opened its own connection: close() ends the run, whose server
        # process exits with its outputs finished
        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
            server.connect(timeout_sec=60).close()  # up and answering
            env = pc.PenumbraEnv(server.endpoint, timeout_sec=60)
            env.reset()
            env.step([0.5, 0.0, 0.0])
            env.close()
            env.close()  # a second close does nothing
            self.assertEqual(server.wait(60), 0, "the server exited after env.close()")
            with open(os.path.join(server.out_dir, "run.json")) as f:
                self.assertTrue(json.load(f)["interrupted"])

    def test_close_can_leave_the_run_going(self):
        with PenumbraServer("worlds/quadruped_target.yaml", lockstep=True) as server:
            client = server.connect(timeout_sec=60)
            env = pc.PenumbraEnv(client=client)
            env.reset()
            env.close(stop_server=False)
            time.sleep(1.0)
            self.assertIsNone(server.proc.poll(), "the server still runs")
            step = client.get_state().step
            client.step(5)  # and still answers
            self.assertEqual(client.get_state().step, step + 5)
            client.close()


if __name__ == "__main__":
    unittest.main()

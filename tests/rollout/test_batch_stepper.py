#!/usr/bin/env python3
"""The batched MuJoCo stepper (src/penumbra/rollout, module _penumbra_rollout) and the vector
environment over it (python/penumbra_rollout): N copies stepped together are bit-identical to
each copy stepped alone, for any thread count; the joint PD law; errors; the VectorEnv API and
its observation layout. Run by ctest (Rollout.batch_stepper) with build/python and python on
PYTHONPATH."""

import os
import sys
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))

from _penumbra_rollout import BatchStepper  # noqa: E402
from penumbra_rollout import (DEFAULT_JOINT_POS, POLICY_JOINT_ORDER, QuadrupedEnvConfig,  # noqa: E402
                              QuadrupedVelocityEnv)

MODEL = os.path.join(ROOT, "train", "go1_flat.xml")
KP, KD = [20.0] * 12, [0.5] * 12


def make(n, threads, substeps=4):
    return BatchStepper(MODEL, n, threads, substeps, "joint_pd", KP, KD)


def initial_states(s, n, rng):
    qpos0 = np.array(s.qpos0)
    out = []
    for _ in range(n):
        q = qpos0.copy()
        q[2] = 0.33 + 0.05 * rng.random()
        q[7:] += rng.uniform(-0.3, 0.3, 12)
        v = np.zeros(s.nv)
        v[:6] = rng.uniform(-0.5, 0.5, 6)
        out.append((q, v))
    return out


def run(s, states, inputs):
    for i, (q, v) in enumerate(states):
        s.reset(i, q, v)
    for u in inputs:
        s.step(u)
    return s.read_state()


class BatchStepperTest(unittest.TestCase):
    def setUp(self):
        rng = np.random.default_rng(42)
        self.n, self.steps = 6, 40
        probe = make(1, 1)
        self.states = initial_states(probe, self.n, rng)
        stand = np.array(probe.qpos0)[7:]
        self.inputs = [stand + rng.uniform(-0.4, 0.4, (self.n, 12)) for _ in range(self.steps)]

    def test_copies_together_equal_each_copy_alone(self):
        together = run(make(self.n, 2), self.states, self.inputs)
        for i in range(self.n):
            alone = run(make(1, 1), [self.states[i]], [u[i:i + 1] for u in self.inputs])
            for a, b, name in zip(together, alone, ("qpos", "qvel", "ctrl", "sensordata")):
                self.assertTrue(np.array_equal(a[i], b[0]), f"copy {i}: {name} differs")
        # the copies really moved and differ from each other
        self.assertGreater(np.abs(together[0][:, 2] - 0.33).max(), 0.01)
        self.assertFalse(np.array_equal(together[0][0], together[0][1]))

    def test_any_thread_count_gives_identical_results(self):
        ref = run(make(self.n, 1), self.states, self.inputs)
        for threads in (2, 3, 8):
            got = run(make(self.n, threads), self.states, self.inputs)
            for a, b in zip(ref, got):
                self.assertTrue(np.array_equal(a, b), f"{threads} threads differ from 1")

    def test_joint_pd_law_on_the_state_before_the_substep(self):
        s = make(2, 1, substeps=1)
        for i, (q, v) in enumerate(self.states[:2]):
            s.reset(i, q, v)
        qpos, qvel, _, _ = s.read_state()
        target = self.inputs[0][:2]
        s.step(target)
        _, _, ctrl, _ = s.read_state()
        jn = list(s.joint_names)
        for a, joint in enumerate(s.actuator_joints):
            j = jn.index(joint)
            qa, va = s.joint_qpos_adr[j], s.joint_dof_adr[j]
            want = 20.0 * (target[:, a] - qpos[:, qa]) - 0.5 * qvel[:, va]
            np.testing.assert_allclose(ctrl[:, a], want, rtol=0, atol=1e-12)

    def test_direct_actuation_holds_ctrl(self):
        s = BatchStepper(MODEL, 3, 1, 5)
        u = np.random.default_rng(1).uniform(-5, 5, (3, 12))
        s.step(u)
        self.assertTrue(np.array_equal(s.read_state()[2], u))
        self.assertAlmostEqual(s.timestep, 0.002)

    def test_errors_name_the_problem(self):
        with self.assertRaisesRegex(RuntimeError, "no_such_model.xml"):
            BatchStepper(os.path.join(ROOT, "no_such_model.xml"), 1)
        with self.assertRaisesRegex(RuntimeError, "kp"):
            BatchStepper(MODEL, 1, 1, 1, "joint_pd", [1.0] * 3, KD)
        with self.assertRaisesRegex(RuntimeError, "num_copies"):
            BatchStepper(MODEL, 0)
        with self.assertRaisesRegex(ValueError, "actuation"):
            BatchStepper(MODEL, 1, 1, 1, "torque")
        s = make(2, 1)
        with self.assertRaisesRegex(ValueError, r"expected \(2, 12\)"):
            s.step(np.zeros((3, 12)))
        with self.assertRaises(IndexError):
            s.reset(2, np.zeros(s.nq), np.zeros(s.nv))
        with self.assertRaisesRegex(ValueError, "qpos"):
            s.reset(0, np.zeros(5), np.zeros(s.nv))


class VectorEnvTest(unittest.TestCase):
    def test_api_shapes_and_seeded_determinism(self):
        a = QuadrupedVelocityEnv(4, QuadrupedEnvConfig(num_threads=2), seed=3)
        b = QuadrupedVelocityEnv(4, QuadrupedEnvConfig(num_threads=1), seed=3)
        oa, _ = a.reset()
        ob, _ = b.reset()
        self.assertEqual(oa.shape, (4, 48))
        self.assertEqual(oa.dtype, np.float32)
        self.assertEqual(a.single_observation_space.shape, (48,))
        self.assertEqual(a.single_action_space.shape, (12,))
        self.assertEqual(a.action_space.shape, (4, 12))
        rng = np.random.default_rng(0)
        for _ in range(30):
            act = rng.normal(0, 0.5, (4, 12))
            ra = a.step(act)
            rb = b.step(act)
            for x, y in zip(ra[:4], rb[:4]):
                self.assertTrue(np.array_equal(x, y))
        self.assertEqual(ra[1].shape, (4,))
        self.assertEqual(ra[2].dtype, bool)

    def test_observation_layout_by_joint_name(self):
        cfg = QuadrupedEnvConfig(num_threads=1, add_noise=False)
        env = QuadrupedVelocityEnv(1, cfg, seed=0)
        env.reset(options={"commands": [[0.4, -0.2, 0.3]]})
        s = env.stepper
        # a known state: trunk rolled 0.3 rad about x, every joint at default + its index x 0.01
        q = np.array(s.qpos0)
        q[2] = 0.5
        q[3:7] = (np.cos(0.15), np.sin(0.15), 0.0, 0.0)
        jn = list(s.joint_names)
        for k, name in enumerate(POLICY_JOINT_ORDER):
            q[s.joint_qpos_adr[jn.index(name)]] = DEFAULT_JOINT_POS[name] + 0.01 * k
        v = np.zeros(s.nv)
        v[0:3] = (0.3, 0.0, 0.0)  # world frame
        v[3:6] = (0.0, 0.0, 0.8)  # body frame
        s.reset(0, q, v)
        env._read()
        obs = env._observe()[0].astype(np.float64)
        np.testing.assert_allclose(obs[0:3], [0.6, 0.0, 0.0], atol=1e-6)       # 2.0 x body vel
        np.testing.assert_allclose(obs[3:6], [0.0, 0.0, 0.2], atol=1e-6)       # 0.25 x gyro
        np.testing.assert_allclose(obs[6:9], [0.0, -np.sin(0.3), -np.cos(0.3)], atol=1e-6)
        np.testing.assert_allclose(obs[9:12], [0.8, -0.4, 0.075], atol=1e-6)  # command x scales
        np.testing.assert_allclose(obs[12:24], 0.01 * np.arange(12), atol=1e-6)
        np.testing.assert_allclose(obs[24:48], 0.0, atol=1e-6)


if __name__ == "__main__":
    unittest.main(verbosity=2)

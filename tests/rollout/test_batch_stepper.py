#!/usr/bin/env python3
"""The batched MuJoCo stepper (src/penumbra/rollout, module _penumbra_rollout) and the vector
environment over it (python/penumbra_rollout): N copies stepped together are bit-identical to
each copy stepped alone, for any thread count; the joint PD law; errors; the VectorEnv API and
its observation layout; hostile arguments (thread, copy and substep counts beyond their bounds,
NaN and infinite inputs, FIFOs and devices as model files, models MuJoCo fails on), the risky
ones in a child process under an address-space limit and a timeout. Run by ctest
(Rollout.batch_stepper) with build/python and python on PYTHONPATH."""

import os
import re
import resource
import subprocess
import sys
import tempfile
import textwrap
import unittest

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "python"))

import _penumbra_rollout  # noqa: E402
from _penumbra_rollout import BatchStepper  # noqa: E402
from penumbra_rollout import (DEFAULT_JOINT_POS, POLICY_JOINT_ORDER, QuadrupedEnvConfig,  # noqa: E402
                              QuadrupedVelocityEnv)

MODEL = os.path.join(ROOT, "train", "go1_flat.xml")
KP, KD = [20.0] * 12, [0.5] * 12
# the thread bound: 4 x the hardware threads (_penumbra_rollout.max_threads)
MAX_THREADS = 4 * max(1, os.cpu_count() or 1)


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
        for threads in (2, 3, min(8, MAX_THREADS)):
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
        with self.assertRaisesRegex(ValueError, "no_such_model.xml: model_path: model file not found"):
            BatchStepper(os.path.join(ROOT, "no_such_model.xml"), 1)
        with self.assertRaisesRegex(ValueError, "kp"):
            BatchStepper(MODEL, 1, 1, 1, "joint_pd", [1.0] * 3, KD)
        with self.assertRaisesRegex(ValueError, "num_copies"):
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


GIB = 1 << 30
# a child's prelude: the module, the model, and its own thread count (/proc/self/status)
PRELUDE = textwrap.dedent(f"""
    import os, sys
    sys.path.insert(0, {os.path.join(ROOT, "python")!r})
    import numpy as np
    import _penumbra_rollout
    from _penumbra_rollout import BatchStepper
    MODEL = {MODEL!r}

    def threads():
        with open("/proc/self/status") as f:
            return int(next(l for l in f if l.startswith("Threads:")).split()[1])

    def attempt(label, fn):
        try:
            fn()
            print(label, "OK", flush=True)
        except Exception as e:
            print(label, type(e).__name__, str(e).replace(chr(10), " "), flush=True)
    """)


def run_child(code, address_space=4 * GIB, stack=None, timeout=60, cwd=None):
    """runs PRELUDE + code in a child python under RLIMIT_AS (and RLIMIT_STACK, the default
    thread stack size); returns (returncode, stdout, stderr). a child that runs past `timeout`
    is killed and the test fails (the old code hung here)."""
    def limits():
        resource.setrlimit(resource.RLIMIT_AS, (address_space, address_space))
        if stack is not None:
            resource.setrlimit(resource.RLIMIT_STACK, (stack, stack))

    env = dict(os.environ, OPENBLAS_NUM_THREADS="1", OMP_NUM_THREADS="1", MKL_NUM_THREADS="1")
    try:
        p = subprocess.run([sys.executable, "-c", PRELUDE + textwrap.dedent(code)],
                           preexec_fn=limits, stdin=subprocess.DEVNULL, capture_output=True,
                           text=True, timeout=timeout, env=env, cwd=cwd)
    except subprocess.TimeoutExpired:
        raise AssertionError(f"the child ran past {timeout} s (hung)") from None
    return p.returncode, p.stdout, p.stderr


class HostileArgumentsTest(unittest.TestCase):
    def child(self, code, **kw):
        rc, out, err = run_child(code, **kw)
        self.assertEqual(rc, 0, f"child exited {rc}; stdout:\n{out}\nstderr:\n{err[-3000:]}")
        return out

    def test_threads_beyond_bound_refused_before_any_thread_starts(self):
        # 100000 threads exhausted the machine's thread limit; now ValueError naming the bound,
        # and not one thread started
        bound = MAX_THREADS
        out = self.child(f"""
            before = threads()
            attempt("100000", lambda: BatchStepper(MODEL, 1, 100000))
            attempt("bound+1", lambda: BatchStepper(MODEL, 1, {bound} + 1))
            attempt("2^40", lambda: BatchStepper(MODEL, 1, 2 ** 40))
            attempt("-1", lambda: BatchStepper(MODEL, 1, -1))
            print("threads", before, threads())
            """)
        for label in ("100000", "bound+1", "2^40", "-1"):
            self.assertRegex(out, re.escape(label) + r" ValueError num_threads: got .*; expected "
                                  rf"0 .*\[1, {bound}\]")
        before, after = out.split("threads ")[-1].split()
        self.assertEqual(before, after, out)
        s = BatchStepper(MODEL, 2, bound)
        self.assertEqual(s.num_threads, bound)
        self.assertEqual(_penumbra_rollout.max_threads, bound)

    def test_thread_start_failure_raises_and_joins(self):
        # 5000 threads under a 4 GiB address space started 505 and deadlocked; now the bound
        # refuses 5000, and a thread that cannot start within the bound (2 GiB stacks under
        # 4 GiB) ends in RuntimeError with the threads already started joined
        out = self.child(f"""
            attempt("5000", lambda: BatchStepper(MODEL, 4, 5000))
            attempt("bound", lambda: BatchStepper(MODEL, 4, {MAX_THREADS}))
            print("threads", threads())
            s = BatchStepper(MODEL, 2, 1)
            s.step(np.zeros((2, 12)))
            print("after OK")
            """, stack=2 * GIB)
        self.assertIn("5000 ValueError num_threads: got 5000", out)
        self.assertRegex(out, r"bound RuntimeError num_threads \d+: could not start the "
                              r"stepper's threads .*stopped")
        self.assertIn("threads 1\n", out)
        self.assertIn("after OK", out)

    def test_copies_beyond_memory_refused_and_process_lives(self):
        # 1e7 copies ended the process through MuJoCo's "Could not allocate memory" exit()
        out = self.child("""
            attempt("1e7", lambda: BatchStepper(MODEL, 10 ** 7))
            attempt("1e6", lambda: BatchStepper(MODEL, 10 ** 6))
            attempt("2^40", lambda: BatchStepper(MODEL, 2 ** 40))
            probe = BatchStepper(MODEL, 1)
            print("copy_bytes", probe.copy_bytes)
            # one copy more than the room left under the 4 GiB limit: refused by the estimate
            n = _penumbra_rollout.memory_cap_bytes() // probe.copy_bytes + 1
            attempt("cap", lambda: BatchStepper(MODEL, n))
            BatchStepper(MODEL, 2).step(np.zeros((2, 12)))
            print("alive")
            """, timeout=120)
        self.assertRegex(out, r"1e7 ValueError num_copies: got 10000000; expected an integer in "
                              r"\[1, 1048576\]")
        self.assertRegex(out, r"1e6 ValueError num_copies: got 1000000 copies of \d+ bytes "
                              r"each; expected at most \d+ copies of this model")
        self.assertRegex(out, r"2\^40 ValueError num_copies: got 1099511627776; expected an "
                              r"integer in \[1, 1048576\]")
        self.assertRegex(out, r"cap ValueError num_copies: got \d+ copies of \d+ bytes each")
        self.assertIn("alive", out)
        self.assertGreater(int(out.split("copy_bytes ")[1].split()[0]), 1000)

    def test_substeps_beyond_bound_refused(self):
        # 2^31 - 1 substeps hung in step with the GIL released
        for bad in (2 ** 31 - 1, 1001, 0, 2 ** 63 - 1):
            with self.assertRaisesRegex(ValueError, rf"substeps: got {bad}; expected an integer "
                                                    rf"in \[1, 1000\]"):
                BatchStepper(MODEL, 1, 1, bad)
        self.assertEqual(BatchStepper(MODEL, 1, 1, 1000).substeps, 1000)
        self.assertEqual(_penumbra_rollout.max_substeps, 1000)

    def test_non_finite_inputs_refused_naming_the_index(self):
        s = make(3, 2, substeps=2)
        before = s.read_state()
        for bad, text in ((np.nan, "nan"), (np.inf, "inf"), (-np.inf, "-inf")):
            u = np.tile(np.array(s.qpos0)[7:], (3, 1))
            u[1, 4] = bad
            with self.assertRaisesRegex(ValueError, rf"input\[1, 4\]: got {text}; expected a "
                                                    "finite number"):
                s.step(u)
        for a, b in zip(before, s.read_state()):
            self.assertTrue(np.array_equal(a, b), "a refused step moved a copy")
        q = np.array(s.qpos0)
        q[2] = np.nan
        with self.assertRaisesRegex(ValueError, r"qpos\[2\]: got nan"):
            s.reset(0, q, np.zeros(s.nv))
        v = np.zeros(s.nv)
        v[5] = np.inf
        with self.assertRaisesRegex(ValueError, r"qvel\[5\]: got inf"):
            s.reset(0, np.array(s.qpos0), v)
        with self.assertRaisesRegex(ValueError, r"kd\[3\]"):
            BatchStepper(MODEL, 1, 1, 1, "joint_pd", KP, [0.5, 0.5, 0.5, np.nan] + [0.5] * 8)

    def test_env_non_finite_actions_commands_and_settings_refused(self):
        # NaN actions and commands gave NaN observations and rewards silently
        env = QuadrupedVelocityEnv(2, QuadrupedEnvConfig(num_threads=1), seed=0)
        env.reset()
        a = np.zeros((2, 12))
        a[1, 7] = np.nan
        with self.assertRaisesRegex(ValueError, r"actions\[1, 7\]: got nan; expected a finite"):
            env.step(a)
        a[1, 7] = -np.inf
        with self.assertRaisesRegex(ValueError, r"actions\[1, 7\]: got -inf"):
            env.step(a)
        with self.assertRaisesRegex(ValueError, r"options\['commands'\]\[0, 2\]: got nan"):
            env.reset(options={"commands": [[0.5, 0.0, np.nan]]})
        with self.assertRaisesRegex(ValueError, r"options\['commands'\]"):
            env.reset(options={"commands": [[0.5, 0.0]]})
        obs, _ = env.reset(options={"commands": [[0.5, 0.0, 0.0]]})
        obs, rew, _, _, _ = env.step(np.zeros((2, 12)))
        self.assertTrue(np.isfinite(obs).all() and np.isfinite(rew).all())
        for field, value, text in (("kp", np.nan, "finite"), ("episode_length_s", np.inf, "finite"),
                                   ("clip_actions", 0.0, "> 0"), ("noise_level", -1.0, ">= 0"),
                                   ("lin_vel_x_range", (1.0, -1.0), "low <= high"),
                                   ("decimation", 2.5, "integer")):
            with self.assertRaisesRegex(ValueError, rf"config\.{field}: got .*{text}"):
                QuadrupedVelocityEnv(1, QuadrupedEnvConfig(**{field: value}))
        with self.assertRaisesRegex(ValueError, r"num_envs: got 0"):
            QuadrupedVelocityEnv(0)
        with self.assertRaisesRegex(ValueError, r"substeps: got 100000"):
            QuadrupedVelocityEnv(1, QuadrupedEnvConfig(decimation=100000))
        # terrain's -inf minimum height stays allowed
        QuadrupedVelocityEnv(1, QuadrupedEnvConfig(min_base_height=-np.inf, num_threads=1))

    def test_fifo_directory_and_device_refused_as_model_files(self):
        # a FIFO as the model path blocked in open() for ever
        with tempfile.TemporaryDirectory() as tmp:
            fifo = os.path.join(tmp, "model.xml")
            os.mkfifo(fifo)
            out = self.child(f"""
                attempt("fifo", lambda: BatchStepper({fifo!r}, 1))
                attempt("dir", lambda: BatchStepper({tmp!r}, 1))
                attempt("dev", lambda: BatchStepper("/dev/zero", 1))
                """, timeout=30)
        self.assertIn(f"fifo ValueError {fifo}: model_path: model file is not a regular file "
                      "(a FIFO); expected a regular file", out)
        self.assertIn(f"dir ValueError {tmp}: model_path: model file is a directory; expected a "
                      "regular file", out)
        self.assertIn("dev ValueError /dev/zero: model_path: model file is not a regular file "
                      "(a character device)", out)
        # open() would stop at the NUL and load train/go1_flat.xml
        with self.assertRaisesRegex(ValueError, "model path is empty or holds a NUL byte"):
            BatchStepper(MODEL + "\0.extra", 1)
        with self.assertRaisesRegex(ValueError, "model path is empty"):
            BatchStepper("", 1)

    def test_bad_models_raise_and_warnings_stay_quiet(self):
        # MuJoCo's default handlers exit() on errors and print warnings and append them to
        # MUJOCO_LOG.TXT in the working folder
        with tempfile.TemporaryDirectory() as tmp:
            bad = os.path.join(tmp, "bad.xml")
            with open(bad, "w") as f:
                f.write("<mujoco><worldbody><body><geom type='sphere'")
            stack = os.path.join(tmp, "stack.xml")
            with open(stack, "w") as f:
                f.write("<mujoco><size nstack='2000000000'/><worldbody><body><joint/>"
                        "<geom size='0.1'/></body></worldbody><actuator><motor joint='' "
                        "/></actuator></mujoco>".replace("<joint/>", "<joint name='j'/>")
                        .replace("joint=''", "joint='j'"))
            out = self.child(f"""
                attempt("bad", lambda: BatchStepper({bad!r}, 1))
                attempt("stack", lambda: BatchStepper({stack!r}, 2))
                s = BatchStepper(MODEL, 1, 1, 1)
                s.step(np.full((1, 12), 1e300))  # MuJoCo warns: huge value in CTRL
                print("alive")
                """, address_space=2 * GIB, cwd=tmp)
            self.assertFalse(os.path.exists(os.path.join(tmp, "MUJOCO_LOG.TXT")))
        self.assertRegex(out, rf"bad ValueError {bad}: model_path: MuJoCo could not load the "
                              "model: ")
        self.assertRegex(out, r"stack (ValueError|RuntimeError) .*(num_copies|Could not allocate)")
        self.assertNotIn("WARNING", out)
        self.assertIn("alive", out)


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

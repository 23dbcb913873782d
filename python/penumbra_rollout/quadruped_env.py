"""Velocity tracking for the bundled Go1-class quadruped as a vector environment.

Conventions follow legged_gym (Rudin et al., "Learning to Walk in Minutes Using Massively
Parallel Deep Reinforcement Learning", CoRL 2021; legged_gym/envs/base/legged_robot.py and
legged_robot_config.py, A1 config a1_config.py); train/README.md lists them exactly:

- policy rate 50 Hz: ``decimation`` 10 physics steps of 0.002 s (the bundled worlds' timestep);
- observation (48 float32, in this order): base linear velocity in the body frame x 2.0, base
  angular velocity in the body frame x 0.25, projected gravity (unit vector, body frame),
  command (vx, vy, wz) x (2.0, 2.0, 0.25), joint positions - default x 1.0, joint velocities x
  0.05, last action (unscaled), all clipped to +-100;
- action (12): joint position targets = default + 0.25 x action (action clipped to +-100),
  tracked by PD torque kp 20, kd 0.5 every physics step, clamped to the motors' torque limits;
- joint order FL, FR, RL, RR x (hip, thigh, calf) (legged_gym's A1 order), mapped by name to
  the model's actuators; default pose hip +0.1 (left) / -0.1 (right), thigh 0.8 (front) /
  1.0 (rear), calf -1.5 (a1_config.py's default_joint_angles).
"""

from __future__ import annotations

import dataclasses
import math
import operator
import os

import numpy as np

import _penumbra_rollout
from _penumbra_rollout import BatchStepper

from .spaces import Box

_REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
DEFAULT_MODEL = os.path.join(_REPO, "train", "go1_flat.xml")

LEGS = ("FL", "FR", "RL", "RR")
POLICY_JOINT_ORDER = tuple(f"{leg}_{j}" for leg in LEGS for j in ("hip", "thigh", "calf"))
DEFAULT_JOINT_POS = {
    "FL_hip": 0.1, "FL_thigh": 0.8, "FL_calf": -1.5,
    "FR_hip": -0.1, "FR_thigh": 0.8, "FR_calf": -1.5,
    "RL_hip": 0.1, "RL_thigh": 1.0, "RL_calf": -1.5,
    "RR_hip": -0.1, "RR_thigh": 1.0, "RR_calf": -1.5,
}
OBS_DIM = 48
ACT_DIM = 12


@dataclasses.dataclass
class QuadrupedEnvConfig:
    """Settings of :class:`QuadrupedVelocityEnv` (defaults: legged_gym's A1 values)."""

    model_path: str = DEFAULT_MODEL
    # prefix of the robot's joint, actuator and sensor names in the model (e.g. "go1/" in a
    # world's composed.xml)
    name_prefix: str = ""
    num_threads: int = 0
    decimation: int = 10
    kp: float = 20.0
    kd: float = 0.5
    action_scale: float = 0.25
    clip_actions: float = 100.0
    clip_observations: float = 100.0
    lin_vel_scale: float = 2.0
    ang_vel_scale: float = 0.25
    dof_pos_scale: float = 1.0
    dof_vel_scale: float = 0.05
    episode_length_s: float = 20.0
    resampling_time_s: float = 10.0
    lin_vel_x_range: tuple = (-1.0, 1.0)
    lin_vel_y_range: tuple = (-0.6, 0.6)
    ang_vel_yaw_range: tuple = (-1.0, 1.0)
    # observation noise (legged_gym noise_scales x noise_level, then x the term's obs scale)
    add_noise: bool = True
    noise_level: float = 1.0
    # reward weights (legged_gym's, scaled by the policy dt inside the env)
    tracking_sigma: float = 0.25
    w_tracking_lin_vel: float = 1.0
    w_tracking_ang_vel: float = 0.5
    w_lin_vel_z: float = -2.0
    w_ang_vel_xy: float = -0.05
    w_orientation: float = -0.2
    w_torques: float = -0.0002
    w_dof_acc: float = -2.5e-7
    w_feet_air_time: float = 1.0
    w_action_rate: float = -0.01
    w_dof_pos_limits: float = -10.0
    # (trunk height - target)^2: legged_gym's base_height term, weight 0 in its base config;
    # without it the policy learns to track commands crawling on bent legs
    w_base_height: float = -30.0
    base_height_target: float = 0.28
    soft_dof_pos_limit: float = 0.9
    only_positive_rewards: bool = True
    # spawn: trunk height (m) and legged_gym's reset randomisation
    spawn_height: float = 0.42
    # False: every episode starts at (0, 0, spawn_height) facing +x; True: at the model's own
    # base position and heading (qpos0, e.g. a world's robot pose) with z = spawn_height
    spawn_at_model_pose: bool = False
    # termination: trunk contact (trunk_touch > 0), or the body's z axis more than this far
    # below horizontal-up (projected gravity z above -cos(limit))
    max_tilt_rad: float = 1.2
    # and (training on flat ground) when the trunk origin sinks below this height (m); -inf
    # for terrain, where the world z of the trunk says nothing about its height above ground
    min_base_height: float = 0.15


# settings that must be > 0, and the one that may be -inf (every other number must be finite)
_POSITIVE = ("clip_actions", "clip_observations", "episode_length_s", "resampling_time_s",
             "tracking_sigma", "spawn_height")
_NON_NEGATIVE = ("kp", "kd", "action_scale", "noise_level")
_MAY_BE_MINUS_INF = ("min_base_height",)
_RANGES = ("lin_vel_x_range", "lin_vel_y_range", "ang_vel_yaw_range")


def _finite_index(name, a):
    """Raises ValueError naming the first non-finite value of array `a` as name[i, j]."""
    bad = np.argwhere(~np.isfinite(a))
    if len(bad):
        idx = tuple(int(i) for i in bad[0])
        where = ", ".join(str(i) for i in idx)
        raise ValueError(f"{name}[{where}]: got {a[idx]!r}; expected a finite number")


def check_config(c):
    """Raises ValueError naming the first setting of QuadrupedEnvConfig `c` out of range: every
    number finite (min_base_height may be -inf), gains, scales and noise >= 0, clips, times,
    tracking_sigma and spawn_height > 0, command ranges (low, high) with low <= high,
    decimation and num_threads integers (their bounds: BatchStepper's substeps and
    num_threads)."""
    for f in dataclasses.fields(c):
        v = getattr(c, f.name)
        if isinstance(v, bool) or isinstance(v, str):
            continue
        if f.name in _RANGES:
            r = tuple(v) if isinstance(v, (tuple, list)) else ()
            if (len(r) != 2 or not all(isinstance(x, (int, float)) and math.isfinite(x) for x in r)
                    or r[0] > r[1]):
                raise ValueError(f"config.{f.name}: got {v!r}; expected (low, high), finite, "
                                 "low <= high")
            continue
        if f.name in ("decimation", "num_threads"):
            try:
                operator.index(v)
            except TypeError:
                raise ValueError(f"config.{f.name}: got {v!r}; expected an integer") from None
            continue
        if not isinstance(v, (int, float)):
            raise ValueError(f"config.{f.name}: got {v!r}; expected a number")
        if math.isnan(v) or (math.isinf(v) and not (f.name in _MAY_BE_MINUS_INF and v < 0)):
            raise ValueError(f"config.{f.name}: got {v!r}; expected a finite number")
        if f.name in _POSITIVE and not v > 0:
            raise ValueError(f"config.{f.name}: got {v!r}; expected a number > 0")
        if f.name in _NON_NEGATIVE and not v >= 0:
            raise ValueError(f"config.{f.name}: got {v!r}; expected a number >= 0")


def quat_rotate_inverse(q, v):
    """v (N, 3) in the world frame expressed in the frame of unit quaternions q (N, 4; w x y z)."""
    w = q[:, 0:1]
    u = q[:, 1:4]
    a = v * (2.0 * w * w - 1.0)
    b = np.cross(u, v) * w * 2.0
    c = u * np.sum(u * v, axis=1, keepdims=True) * 2.0
    return a - b + c


class QuadrupedVelocityEnv:
    """``num_envs`` quadrupeds tracking velocity commands, stepped by one BatchStepper.

    Gymnasium ``VectorEnv`` signatures. Episodes end (``terminations``) when the trunk touches
    the ground or tilts past ``max_tilt_rad``, and are cut (``truncations``) after
    ``episode_length_s``; such environments are reset within the same ``step`` (Gymnasium
    0.29's autoreset): the returned observation is the new episode's first, and
    ``infos["final_observation"]`` (N, 48) holds every environment's observation before any
    reset, ``infos["_final_observation"]`` (N,) marks the reset ones.
    """

    metadata = {"autoreset_mode": "same_step"}

    def __init__(self, num_envs: int, config: QuadrupedEnvConfig | None = None, seed: int = 0):
        self.cfg = config or QuadrupedEnvConfig()
        c = self.cfg
        check_config(c)
        try:
            n = operator.index(num_envs)
        except TypeError:
            raise ValueError(f"num_envs: got {num_envs!r}; expected an integer") from None
        if isinstance(num_envs, bool) or not 1 <= n <= _penumbra_rollout.max_copies:
            raise ValueError(f"num_envs: got {num_envs!r}; expected an integer in "
                             f"[1, {_penumbra_rollout.max_copies}]")
        self.num_envs = n
        self.stepper = BatchStepper(c.model_path, self.num_envs, c.num_threads, c.decimation,
                                    "joint_pd", [c.kp] * 12, [c.kd] * 12)
        s = self.stepper
        if s.nu != ACT_DIM:
            raise ValueError(f"{c.model_path}: {s.nu} actuators; expected 12")
        self.dt = s.timestep * c.decimation
        self.max_episode_length = int(round(c.episode_length_s / self.dt))
        self.resample_steps = int(round(c.resampling_time_s / self.dt))
        # policy order -> actuator index, and the qpos / dof address of each policy joint
        pre = c.name_prefix
        act_joints = list(s.actuator_joints)
        jnames = list(s.joint_names)

        def find(names, name, what):
            if pre + name not in names:
                raise ValueError(f"{c.model_path}: no {what} named '{pre + name}'")
            return names.index(pre + name)

        self.policy_to_act = np.array([find(act_joints, n, "actuator driving joint")
                                       for n in POLICY_JOINT_ORDER])
        jidx = [find(jnames, n, "joint") for n in POLICY_JOINT_ORDER]
        self.q_adr = np.array([s.joint_qpos_adr[j] for j in jidx])
        self.v_adr = np.array([s.joint_dof_adr[j] for j in jidx])
        base = find(jnames, "trunk_free", "free joint")
        self.base_q = s.joint_qpos_adr[base]
        self.base_v = s.joint_dof_adr[base]
        rng_ = np.array([s.joint_range[j] for j in jidx])
        mid = rng_.mean(axis=1)
        half = (rng_[:, 1] - rng_[:, 0]) / 2 * c.soft_dof_pos_limit
        self.soft_lo, self.soft_hi = mid - half, mid + half
        self.default_q = np.array([DEFAULT_JOINT_POS[n] for n in POLICY_JOINT_ORDER])
        snames = list(s.sensor_names)
        self.foot_touch_adr = np.array([s.sensor_adr[find(snames, f"{leg}_foot_touch", "sensor")]
                                        for leg in LEGS])
        self.trunk_touch_adr = s.sensor_adr[find(snames, "trunk_touch", "sensor")]
        self.qpos0 = np.array(s.qpos0)

        self.single_observation_space = Box(-np.inf, np.inf, (OBS_DIM,), np.float32)
        self.single_action_space = Box(-c.clip_actions, c.clip_actions, (ACT_DIM,), np.float32)
        self.observation_space = Box(-np.inf, np.inf, (self.num_envs, OBS_DIM), np.float32)
        self.action_space = Box(-c.clip_actions, c.clip_actions, (self.num_envs, ACT_DIM),
                                np.float32)
        self.obs_scales = np.concatenate([
            [c.lin_vel_scale] * 3, [c.ang_vel_scale] * 3, [1.0] * 3,
            [c.lin_vel_scale, c.lin_vel_scale, c.ang_vel_scale],
            [c.dof_pos_scale] * 12, [c.dof_vel_scale] * 12, [1.0] * 12])
        self.noise_vec = np.concatenate([
            [0.1 * c.lin_vel_scale] * 3, [0.2 * c.ang_vel_scale] * 3, [0.05] * 3, [0.0] * 3,
            [0.01 * c.dof_pos_scale] * 12, [1.5 * c.dof_vel_scale] * 12, [0.0] * 12]) \
            * c.noise_level
        self.fixed_commands = None
        self._seed(seed)
        self._alloc()

    # ----- state ---------------------------------------------------------------------------
    def _seed(self, seed):
        self.rng = np.random.default_rng(seed)

    def _alloc(self):
        n = self.num_envs
        self.actions = np.zeros((n, ACT_DIM))
        self.last_actions = np.zeros((n, ACT_DIM))
        self.last_dof_vel = np.zeros((n, 12))
        self.commands = np.zeros((n, 3))
        self.episode_step = np.zeros(n, dtype=np.int64)
        self.feet_air_time = np.zeros((n, 4))
        self.last_contacts = np.zeros((n, 4), dtype=bool)
        self.episode_sums = {}

    def _read(self):
        qpos, qvel, ctrl, sens = self.stepper.read_state()
        bq, bv = self.base_q, self.base_v
        quat = qpos[:, bq + 3:bq + 7]
        self.base_pos = qpos[:, bq:bq + 3]
        self.base_quat = quat
        self.base_lin_vel = quat_rotate_inverse(quat, qvel[:, bv:bv + 3])
        self.base_ang_vel = qvel[:, bv + 3:bv + 6].copy()  # free joint: angular velocity in the body frame
        grav = np.zeros_like(self.base_lin_vel)
        grav[:, 2] = -1.0
        self.projected_gravity = quat_rotate_inverse(quat, grav)
        self.dof_pos = qpos[:, self.q_adr]
        self.dof_vel = qvel[:, self.v_adr]
        self.torques = ctrl[:, self.policy_to_act]
        self.foot_force = sens[:, self.foot_touch_adr]
        self.trunk_touch = sens[:, self.trunk_touch_adr]

    def _resample_commands(self, ids):
        if len(ids) == 0:
            return
        c = self.cfg
        if self.fixed_commands is not None:
            self.commands[ids] = self.fixed_commands[ids]
            return
        k = len(ids)
        cmd = np.stack([self.rng.uniform(*c.lin_vel_x_range, k),
                        self.rng.uniform(*c.lin_vel_y_range, k),
                        self.rng.uniform(*c.ang_vel_yaw_range, k)], axis=1)
        cmd[:, :2] *= (np.linalg.norm(cmd[:, :2], axis=1) > 0.2)[:, None]
        self.commands[ids] = cmd

    def _reset_envs(self, ids):
        c = self.cfg
        for i in ids:
            qpos = self.qpos0.copy()
            bq, bv = self.base_q, self.base_v
            if not c.spawn_at_model_pose:
                qpos[bq:bq + 2] = 0.0
                qpos[bq + 3:bq + 7] = (1.0, 0.0, 0.0, 0.0)
            qpos[bq + 2] = c.spawn_height
            qpos[self.q_adr] = self.default_q * self.rng.uniform(0.5, 1.5, 12)
            qvel = np.zeros(self.stepper.nv)
            qvel[bv:bv + 6] = self.rng.uniform(-0.5, 0.5, 6)
            self.stepper.reset(int(i), qpos, qvel)
        self.actions[ids] = 0.0
        self.last_actions[ids] = 0.0
        self.last_dof_vel[ids] = 0.0
        self.feet_air_time[ids] = 0.0
        self.last_contacts[ids] = False
        self.episode_step[ids] = 0
        self._resample_commands(ids)

    def _observe(self):
        c = self.cfg
        obs = np.concatenate([
            self.base_lin_vel, self.base_ang_vel, self.projected_gravity, self.commands,
            self.dof_pos - self.default_q, self.dof_vel, self.actions], axis=1) * self.obs_scales
        if c.add_noise:
            obs = obs + (2.0 * self.rng.random(obs.shape) - 1.0) * self.noise_vec
        return np.clip(obs, -c.clip_observations, c.clip_observations).astype(np.float32)

    # ----- VectorEnv API -------------------------------------------------------------------
    def reset(self, seed=None, options=None):
        """Resets every environment; returns (obs (N, 48) float32, infos dict).

        ``seed`` reseeds the environment's generator (numpy PCG64). ``options`` may hold
        ``commands``: an (N, 3) array of fixed (vx m/s, vy m/s, wz rad/s) commands used
        instead of sampled ones until a later reset passes ``commands=None``; they must be
        finite (else ValueError naming ``options['commands'][i, j]``, nothing changed).
        """
        if options is not None and "commands" in options:
            fc = options["commands"]
            if fc is None:
                self.fixed_commands = None
            else:
                try:
                    arr = np.broadcast_to(np.asarray(fc, dtype=np.float64),
                                          (self.num_envs, 3)).copy()
                except (ValueError, TypeError) as e:
                    raise ValueError(f"options['commands']: {e}; expected numbers broadcastable "
                                     f"to ({self.num_envs}, 3)") from None
                _finite_index("options['commands']", arr)
                self.fixed_commands = arr
        if seed is not None:
            self._seed(seed)
        self._alloc()
        self._reset_envs(np.arange(self.num_envs))
        self._read()
        return self._observe(), {}

    def step(self, actions):
        """Applies (N, 12) actions for one policy step (decimation physics steps).

        Returns (obs, rewards (N,) float32, terminations (N,) bool, truncations (N,) bool,
        infos) with infos["final_observation"], infos["_final_observation"], and
        infos["episode"] = {"r": return, "l": length} arrays for the environments that ended.
        Actions must be finite: NaN or infinity raises ValueError naming ``actions[i, j]``
        before anything moves.
        """
        c = self.cfg
        a = np.asarray(actions, dtype=np.float64)
        if a.shape != (self.num_envs, ACT_DIM):
            raise ValueError(f"actions: got shape {a.shape}; expected ({self.num_envs}, 12)")
        _finite_index("actions", a)
        a = np.clip(a, -c.clip_actions, c.clip_actions)
        self.actions = a
        targets = self.default_q + c.action_scale * a
        inp = np.empty_like(targets)
        inp[:, self.policy_to_act] = targets
        self.stepper.step(inp)
        self._read()
        self.episode_step += 1

        # terminations: base contact (legged_gym terminate_after_contacts_on = base) or tilt
        bad = ~np.isfinite(self.base_pos).all(axis=1)
        terminated = ((self.trunk_touch > 0.0) | (self.projected_gravity[:, 2] > -np.cos(c.max_tilt_rad))
                      | (self.base_pos[:, 2] < c.min_base_height) | bad)
        truncated = (self.episode_step >= self.max_episode_length) & ~terminated

        rew = self._rewards()
        self.last_actions = self.actions.copy()
        self.last_dof_vel = self.dof_vel.copy()

        # command resampling every resampling_time_s
        resample = np.nonzero((self.episode_step % self.resample_steps) == 0)[0]
        self._resample_commands(resample)

        obs = self._observe()
        done = terminated | truncated
        infos = {}
        ids = np.nonzero(done)[0]
        if len(ids):
            infos["final_observation"] = obs.copy()
            infos["_final_observation"] = done.copy()
            self._reset_envs(ids)
            self._read()
            obs = self._observe()
        return obs, rew.astype(np.float32), terminated, truncated, infos

    def close(self):
        """Releases the copies."""
        self.stepper = None

    # ----- rewards (legged_gym's terms) ----------------------------------------------------
    def _rewards(self):
        c = self.cfg
        dt = self.dt
        lin_err = np.sum((self.commands[:, :2] - self.base_lin_vel[:, :2]) ** 2, axis=1)
        ang_err = (self.commands[:, 2] - self.base_ang_vel[:, 2]) ** 2
        contact = self.foot_force > 1.0
        contact_filt = contact | self.last_contacts
        self.last_contacts = contact
        first_contact = (self.feet_air_time > 0.0) & contact_filt
        self.feet_air_time += dt
        air = np.sum((self.feet_air_time - 0.5) * first_contact, axis=1)
        air *= np.linalg.norm(self.commands[:, :2], axis=1) > 0.1
        self.feet_air_time *= ~contact_filt
        out_of_limits = (np.clip(self.soft_lo - self.dof_pos, 0, None)
                         + np.clip(self.dof_pos - self.soft_hi, 0, None)).sum(axis=1)
        terms = {
            "tracking_lin_vel": c.w_tracking_lin_vel * np.exp(-lin_err / c.tracking_sigma),
            "tracking_ang_vel": c.w_tracking_ang_vel * np.exp(-ang_err / c.tracking_sigma),
            "lin_vel_z": c.w_lin_vel_z * self.base_lin_vel[:, 2] ** 2,
            "ang_vel_xy": c.w_ang_vel_xy * np.sum(self.base_ang_vel[:, :2] ** 2, axis=1),
            "orientation": c.w_orientation * np.sum(self.projected_gravity[:, :2] ** 2, axis=1),
            "torques": c.w_torques * np.sum(self.torques ** 2, axis=1),
            "dof_acc": c.w_dof_acc * np.sum(((self.last_dof_vel - self.dof_vel) / dt) ** 2, axis=1),
            "feet_air_time": c.w_feet_air_time * air,
            "action_rate": c.w_action_rate * np.sum((self.last_actions - self.actions) ** 2, axis=1),
            "dof_pos_limits": c.w_dof_pos_limits * out_of_limits,
            "base_height": c.w_base_height * (self.base_pos[:, 2] - c.base_height_target) ** 2,
        }
        total = np.zeros(self.num_envs)
        for k, v in terms.items():
            v = v * dt
            total += v
            self.episode_sums[k] = self.episode_sums.get(k, 0.0) + float(v.sum())
        if c.only_positive_rewards:
            total = np.clip(total, 0.0, None)
        return total

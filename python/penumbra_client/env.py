"""A Gymnasium-style environment over a lockstep Penumbra run (gymnasium is not needed)."""

from __future__ import annotations

import numpy as np

from .client import DEFAULT_ENDPOINT, Client
from .protocol import RunEndedError
from .spaces import Box, Dict

# output -> (dtype, channels, low, high) of its observation
_OUTPUT_SPACES = {
    "rgb": (np.uint8, 3, 0, 255),
    "depth": (np.float32, 1, 0, np.inf),
    "depth_mm": (np.uint16, 1, 0, 65535),
    "range": (np.float32, 1, 0, np.inf),
    "normals": (np.float32, 3, -1, 1),
    "segmentation": (np.int32, 1, -1, np.iinfo(np.int32).max),
    "instance_segmentation": (np.int32, 1, -1, np.iinfo(np.int32).max),
    "semantic_segmentation": (np.int32, 1, 0, np.iinfo(np.int32).max),
}


class PenumbraEnv:
    """``reset()`` / ``step()`` over a run started with ``penumbra run WORLD --zmq --lockstep``
    (a free-running run is paused first), with Gymnasium's signatures:

    - ``reset(seed=None, options=None) -> (observation, info)``
    - ``step(action) -> (observation, reward, terminated, truncated, info)``

    **Observation** (a dict, :attr:`observation_space` is a :class:`~penumbra_client.Dict`):
    one image per requested camera output, the newest frame at the end of the step (``rgb``
    uint8 (H, W, 3) sRGB; ``depth`` float32 (H, W) z-depth in metres, 0 = no hit;
    ``depth_mm`` uint16 millimetres; ...), plus ``qpos`` (nq,) and ``qvel`` (nv,) float64 in
    MuJoCo's order and units.

    **Action** (:attr:`action_space` is a :class:`~penumbra_client.Box`):

    - ``action="twist"``: ``[vx, vy, yaw_rate]`` (m/s forward and left in the robot's
      heading frame, rad/s counter-clockwise) for the robot's controller, within
      ``±max_twist``;
    - ``action="ctrl"``: MuJoCo ``ctrl`` (nu,), within each actuator's ctrl range.

    Actions are clipped to the space. Each ``step`` holds the action for
    ``control_period_sec`` of simulated time (default: one frame period of the camera, so
    every step sees a new image), i.e. :attr:`steps_per_action` physics steps.

    **Episodes**: ``reset`` restores the run's step-0 state (``options={"keyframe": NAME}``
    applies an MJCF keyframe) and the controllers' (gait phase, references, integrators,
    histories) and the cameras' frame schedules and noise, then steps with a zero action until
    every image output has a frame captured in the new episode: the same actions give the
    same qpos, qvel and images, bit for bit. Sim time keeps increasing across episodes.
    ``reward_fn(obs, info)`` and
    ``terminate_fn(obs, info)`` (defaults: 0.0 and False) define the task; ``truncated`` is
    True after ``max_episode_steps`` steps or when the run reaches its end time. ``info`` has
    ``step`` and ``time_sec`` (the run's physics step count and sim time) and
    ``episode_steps``.

    :param endpoint: the server's command endpoint.
    :param camera: camera name (default: the first camera of the run, if any).
    :param outputs: image outputs of that camera to observe (published topics
        ``camera/<camera>/<output>``).
    :param robot: the robot whose controller takes twists (None: the only one).
    :param max_twist: (vx, vy, yaw_rate) bounds of the twist action, m/s, m/s, rad/s.
    :param client: an existing :class:`Client` to use instead of connecting.
    """

    metadata = {"render_modes": ["rgb_array"]}

    def __init__(self, endpoint=DEFAULT_ENDPOINT, camera=None, outputs=("rgb",), action="twist",
                 robot=None, control_period_sec=None, max_twist=(1.0, 0.5, 2.0),
                 reward_fn=None, terminate_fn=None, max_episode_steps=None, timeout_sec=30.0,
                 client=None):
        self._own_client = client is None
        self.client = client or Client(endpoint, timeout_sec=timeout_sec, name="PenumbraEnv")
        server = self.client.server or self.client.hello()
        if server["mode"] != "lockstep" and not server.get("paused"):
            self.client.pause()
        self.model = self.client.model_info()
        self.robot = robot
        self.reward_fn = reward_fn or (lambda obs, info: 0.0)
        self.terminate_fn = terminate_fn or (lambda obs, info: False)
        self.max_episode_steps = max_episode_steps
        self.render_mode = "rgb_array"

        cameras = self.model.raw.get("cameras", [])
        if camera is None and outputs:
            if not cameras:
                raise ValueError("the run has no camera; pass outputs=()")
            camera = cameras[0]["name"]
        self.camera = camera
        self.outputs = tuple(outputs)
        spaces = {}
        if self.outputs:
            cam = self.model.camera(camera)
            published = set(cam["outputs"]) | ({"depth_mm"} if "depth" in cam["outputs"] else set())
            for out in self.outputs:
                if out not in published:
                    raise ValueError(f"camera '{camera}' does not output '{out}'; it has "
                                     f"{sorted(published)}")
                dtype, ch, lo, hi = _OUTPUT_SPACES[out]
                shape = (cam["height"], cam["width"]) + ((ch,) if ch > 1 else ())
                spaces[out] = Box(lo, hi, shape=shape, dtype=dtype)
            rate_hz = cam["rate_hz"]
        else:
            rate_hz = None
        spaces["qpos"] = Box(-np.inf, np.inf, shape=(self.model.nq,))
        spaces["qvel"] = Box(-np.inf, np.inf, shape=(self.model.nv,))
        self.observation_space = Dict(spaces)

        if action == "twist":
            m = np.asarray(max_twist, dtype=np.float64)
            self.action_space = Box(-m, m)
        elif action == "ctrl":
            lo, hi = self.model.ctrl_bounds()
            self.action_space = Box(lo, hi)
        else:
            raise ValueError(f"action: '{action}'; expected 'twist' or 'ctrl'")
        self.action = action

        dt = self.model.timestep_sec
        if control_period_sec is None:
            control_period_sec = 1.0 / rate_hz if rate_hz else 10 * dt
        #: physics steps per ``step()`` call.
        self.steps_per_action = max(1, int(round(control_period_sec / dt)))
        self._topics = {f"camera/{camera}/{out}": out for out in self.outputs}
        if self._topics:
            self.client.subscribe(list(self._topics))
        self._latest = {}
        self._episode_steps = 0
        # the step the run's current episode started at (the run's start, then each reset)
        # and the newest step whose frames belong to an earlier episode
        self._episode_start = 0
        self._stale_until = -1
        self._closed = False

    def _apply(self, action):
        a = np.clip(np.asarray(action, dtype=np.float64).reshape(self.action_space.shape),
                    self.action_space.low, self.action_space.high)
        if self.action == "twist":
            self.client.twist(a[0], a[1], a[2], robot=self.robot)
        else:
            self.client.set_ctrl(a)

    def _advance(self):
        r = self.client.step(self.steps_per_action, state=True)
        for msg in r.messages:
            out = self._topics.get(msg.topic)
            # an exposure open at the reset ends after it: that frame shows the last episode
            if out is not None and msg.sim_step > self._stale_until:
                self._latest[out] = msg.image()
        obs = {out: self._latest.get(out) for out in self.outputs}
        obs["qpos"] = r.state.qpos
        obs["qvel"] = r.state.qvel
        info = {"step": r.step, "time_sec": r.time_sec, "episode_steps": self._episode_steps}
        return obs, info, r.ended

    def reset(self, seed=None, options=None):
        """Starts an episode (see the class docstring). ``seed`` must be None or the world's
        seed (``model.seed``): a different seed needs a new run."""
        options = options or {}
        if seed is not None and seed != self.model.seed:
            raise ValueError(f"seed: {seed}; this run's world seed is {self.model.seed} "
                             "(start a new run with --seed for another)")
        if self.client.get_state().step == self._episode_start:
            # nothing stepped since the episode began (the run's start): the cameras and
            # sensors see a reset as a new episode only after a step, so take one, so that
            # this episode starts as every later one does (no frame at its step 0)
            self.client.step(1)
        r = self.client.reset(keyframe=options.get("keyframe"))
        self._episode_start = self._stale_until = r["step"]
        self._latest = {}
        self._episode_steps = 0
        self._apply(np.zeros(self.action_space.shape) if self.action == "twist" else
                    self.client.get_state().ctrl)
        for _ in range(1000):
            obs, info, _ = self._advance()
            if all(obs[out] is not None for out in self.outputs):
                return obs, info
        raise RuntimeError(f"no frame of {self.outputs} within 1000 control periods")

    def step(self, action):
        """Applies ``action`` for :attr:`steps_per_action` physics steps. Returns
        ``(observation, reward, terminated, truncated, info)``."""
        self._apply(action)
        self._episode_steps += 1
        obs, info, ended = self._advance()
        reward = float(self.reward_fn(obs, info))
        terminated = bool(self.terminate_fn(obs, info))
        truncated = ended or (self.max_episode_steps is not None and
                              self._episode_steps >= self.max_episode_steps)
        return obs, reward, terminated, bool(truncated), info

    def render(self):
        """The newest ``rgb`` image (uint8 (H, W, 3)), or None when ``rgb`` is not observed."""
        return self._latest.get("rgb")

    def close(self, stop_server=True):
        """Ends the environment and, by default, the run: sends ``stop`` (as Ctrl-C: the run
        finishes its outputs, writes run.json with ``"interrupted": true`` and the server
        process exits). ``stop_server=False`` leaves the run going for another client. The
        connection is closed if this environment opened it. A second call does nothing.

        :raises PenumbraTimeoutError: the server did not answer ``stop`` within the client's
            timeout (a run that has already ended is not an error).
        """
        if self._closed:
            return
        self._closed = True
        try:
            if stop_server:
                self.client.stop()
        except RunEndedError:
            pass  # the run ended before: nothing to stop
        finally:
            if self._own_client:
                self.client.close()

"""The command client of Penumbra's ZeroMQ bridge (docs/zmq-protocol.md, protocol version 1)."""

from __future__ import annotations

import itertools
import time
import uuid

import zmq

from .messages import SYNC_TOPIC, ModelInfo, State, StepResult, Subscription, topic_matches
from .protocol import (PROTOCOL_VERSION, BadReplyError, PenumbraTimeoutError, decode_reply,
                       encode_request, unpack)

#: the server's default command endpoint (``penumbra run WORLD --zmq``).
DEFAULT_ENDPOINT = "tcp://127.0.0.1:5555"


class Client:
    """A connection to a ``penumbra run WORLD --zmq`` server.

    It holds a ``DEALER`` socket on the command endpoint (requests and replies, matched by
    ``id``) and, after :meth:`subscribe`, a ``SUB`` socket on the publish endpoint. Every
    method sends one request and returns its result; an error reply raises the
    :class:`~penumbra_client.PenumbraError` subclass of its code, and the connection stays
    usable. Not thread-safe: use one client per thread.

    Frames and units (docs/zmq-protocol.md): SI units; the world frame W is z up (REP-103:
    x forward, y left, z up); poses are ``xyz`` (m) and ``qwxyz`` (unit quaternion, w first);
    ``X_AB`` is the pose of B in A; camera images are in the OpenCV optical frame (x right,
    y down, z forward).

    :param endpoint: the command endpoint, e.g. ``"tcp://127.0.0.1:5555"``.
    :param timeout_sec: how long a request waits for its reply (and :meth:`step` for the
        messages it announces) before raising :class:`~penumbra_client.PenumbraTimeoutError`.
    :param name: the client's name in the server's logs.
    :param handshake: send ``hello`` now (checks the protocol version; its reply is
        :attr:`server`).
    :param context: a ``zmq.Context`` (default: the process-wide instance).

    Example (a lockstep run: ``penumbra run worlds/quadruped_target.yaml --zmq --lockstep``)::

        with Client() as c:
            c.subscribe(["camera/front/rgb"])
            c.twist(vx=0.3)
            r = c.step(50)                       # 0.1 s at a 2 ms timestep
            for img in r.images("camera/front/rgb"):
                print(img.shape, img.dtype)      # (60, 80, 3) uint8
    """

    def __init__(self, endpoint=DEFAULT_ENDPOINT, timeout_sec=30.0, name="penumbra_client",
                 handshake=True, context=None):
        self.endpoint = endpoint
        self.timeout_sec = timeout_sec
        self.name = name
        self._context = context or zmq.Context.instance()
        self._socket = self._context.socket(zmq.DEALER)
        self._socket.setsockopt(zmq.LINGER, 0)
        self._socket.connect(endpoint)
        self._ids = itertools.count(1)
        self._sub = None
        self._model = None
        #: the ``hello`` reply (protocol, version, mode, pub_endpoint, ...), or None.
        self.server = None
        if handshake:
            self.hello()

    # -- transport ---------------------------------------------------------------------------

    def _send_frames(self, body):
        # a DEALER sends [empty, body] so the server's ROUTER sees a REQ-style envelope
        frames = body if isinstance(body, list) else [body]
        self._socket.send_multipart([b""] + frames)

    def _recv_body(self, deadline, what):
        while True:
            left = deadline - time.monotonic()
            if left <= 0 or not self._socket.poll(int(left * 1000) + 1):
                raise PenumbraTimeoutError(
                    f"no reply within {self.timeout_sec} s from {self.endpoint}", cmd=what)
            frames = self._socket.recv_multipart()
            # the reply carries the same envelope: [empty, body]
            while frames and frames[0] == b"":
                frames = frames[1:]
            if len(frames) != 1:
                raise BadReplyError(f"reply of {len(frames)} frames; expected 1", cmd=what)
            return frames[0]

    def request(self, cmd, **fields):
        """Sends one request and returns its reply map (``ok`` true).

        Fields whose value is None are left out, so the server's defaults apply. Replies of
        earlier requests that timed out are skipped (matched by ``id``).

        :raises PenumbraError: the subclass of the error reply's code.
        :raises PenumbraTimeoutError: no reply within ``timeout_sec``.
        """
        request_id = next(self._ids)
        self._send_frames(encode_request(cmd, fields, request_id))
        deadline = time.monotonic() + self.timeout_sec
        while True:
            body = self._recv_body(deadline, cmd)
            reply = unpack(body)
            if isinstance(reply, dict) and "id" in reply and reply["id"] != request_id:
                continue  # a late reply to an earlier request
            return decode_reply(body)

    def request_raw(self, frames):
        """Sends raw frames as one request (``bytes`` or a list of ``bytes``) and returns the
        next reply as a map, error replies included (no exception). For testing a server's
        handling of malformed input.

        :raises PenumbraTimeoutError: no reply within ``timeout_sec``.
        """
        self._send_frames(frames)
        return unpack(self._recv_body(time.monotonic() + self.timeout_sec, None))

    def close(self):
        """Closes the sockets (the server's run goes on)."""
        if self._sub is not None:
            self._sub.close()
            self._sub = None
        self._socket.close(0)

    def __enter__(self):
        return self

    def __exit__(self, *exc):
        self.close()

    # -- session -----------------------------------------------------------------------------

    def hello(self):
        """The version handshake. Returns the reply map: ``protocol``, ``version`` (penumbra's),
        ``mode`` (``"lockstep"``/``"free"``), ``paused``, ``pub_endpoint``, ``step``,
        ``time_sec``, ``timestep_sec`` (s), ``end_time_sec``, ``max_request_bytes``,
        ``commands``, ``topics``.

        :raises VersionMismatchError: the server speaks another protocol version.
        """
        self.server = self.request("hello", protocol=PROTOCOL_VERSION, client=self.name)
        return self.server

    def model_info(self, refresh=False):
        """The model and the run's sensors as a :class:`ModelInfo` (bodies, joints,
        actuators, MuJoCo sensors, mocap bodies, keyframes, cameras with intrinsics fx fy cx
        cy in pixels, sensors, controllers and topics). Cached after the first call."""
        if self._model is None or refresh:
            self._model = ModelInfo(self.request("model_info"))
        return self._model

    def subscribe(self, topics, pub_endpoint=None, timeout_sec=None):
        """Subscribes to topic prefixes of the sensor stream (e.g. ``["camera/front/rgb",
        "imu/"]``) and returns once the server has seen the subscription (``sync`` round
        trips), so nothing published afterwards is lost. Later calls add topics.

        After this, :meth:`step` returns every subscribed message of its steps.

        :param topics: topic prefixes (str).
        :param pub_endpoint: default: ``pub_endpoint`` from ``hello``.
        :returns: the :class:`Subscription` (its ``recv()`` reads messages directly, e.g.
            in a free-running run).
        :raises PenumbraTimeoutError: the server never echoed the ``sync`` message.
        """
        if isinstance(topics, str):
            topics = [topics]
        if self._sub is None:
            endpoint = pub_endpoint or (self.server or self.hello())["pub_endpoint"]
            self._sub = Subscription(self._context, endpoint, [])
        for t in topics:
            self._sub.add(t)
        self._sync(timeout_sec or self.timeout_sec)
        return self._sub

    def _sync(self, timeout_sec):
        token = f"{self.name}-{uuid.uuid4().hex}"
        deadline = time.monotonic() + timeout_sec
        while time.monotonic() < deadline:
            self.request("sync", token=token)
            wait_until = min(deadline, time.monotonic() + 0.1)
            while True:
                msg = self._sub.recv_any(max(0.0, wait_until - time.monotonic()))
                if msg is None:
                    break
                if msg.topic == SYNC_TOPIC and msg.header.get("token") == token:
                    return
        raise PenumbraTimeoutError(f"no 'sync' message on {self._sub.endpoint} within "
                                   f"{timeout_sec} s", cmd="sync")

    @property
    def subscription(self):
        """The :class:`Subscription` of :meth:`subscribe`, or None."""
        return self._sub

    # -- stepping and state ------------------------------------------------------------------

    def step(self, n=1, state=False):
        """Advances a lockstep (or paused) run by ``n`` physics steps and returns a
        :class:`StepResult` with every subscribed message of those steps (the server
        publishes them before it replies; this waits until all have arrived).

        :param n: physics steps, 1 .. 1000000 (``model_info().timestep_sec`` s each).
        :param state: also return the state after the steps (``StepResult.state``).
        :raises ConflictError: the run is running free (see :meth:`pause`).
        :raises RunEndedError: the run has ended.
        :raises PenumbraTimeoutError: announced messages did not arrive in ``timeout_sec``.
        """
        reply = self.request("step", n=n, state=True if state else None)
        messages = []
        if self._sub is not None:
            want = {t: c for t, c in reply.get("published", {}).items()
                    if topic_matches(t, self._sub.topics)}
            messages = self._sub.collect(want, self.timeout_sec)
        return StepResult(reply, messages, State(reply) if state else None)

    def get_state(self):
        """The :class:`State` at the current step boundary (qpos, qvel, act, ctrl, mocap
        poses, sensordata)."""
        return State(self.request("get_state"))

    def reset(self, keyframe=None, seed=None):
        """Restores the state of step 0 (then applies MJCF ``keyframe``, a robot-prefixed
        name such as ``"go1/home"``) at the next step boundary, and every controller's state
        as at step 0 (gait phase, references, integrators, histories; programmatic commands
        are dropped), on a controller clock that restarts at 0: the same requests then give
        the same qpos and qvel. The world-file sensors and the cameras restart their
        schedules and noise streams with the episode, and the agents (paths, crowds) and
        effects start again on the episode's clock. Sim time and the step count keep
        increasing (docs/zmq-protocol.md ``reset``).

        :param seed: must be None or the world's seed (a new seed needs a new run).
        :returns: the reply (``step``, ``time_sec`` of the boundary).
        """
        return self.request("reset", keyframe=keyframe, seed=seed)

    def pause(self):
        """Stops a free-running run at the next step boundary (it then advances by
        :meth:`step`). Returns the reply (``step``, ``time_sec``, ``paused``)."""
        return self.request("pause")

    def resume(self):
        """Lets the run run free. Returns the reply (``step``, ``time_sec``, ``paused``)."""
        return self.request("resume")

    def set_realtime_factor(self, factor):
        """Sim seconds per wall-clock second while running free (0 = as fast as possible)."""
        return self.request("set_realtime_factor", factor=float(factor))

    def stop(self):
        """Ends the run as Ctrl-C does (outputs finished, run.json ``interrupted``)."""
        return self.request("stop")

    # -- commands ----------------------------------------------------------------------------

    def set_ctrl(self, ctrl):
        """Sets MuJoCo ``ctrl``: a sequence of nu values (actuator units: N, N m, or the
        position/velocity target of a servo), or a map actuator name -> value that sets only
        those. A controller overwrites its own actuators at each of its updates.

        :raises BadFieldError: wrong length, a non-finite value, or an unknown name.
        """
        if isinstance(ctrl, dict):
            ctrl = {str(k): float(v) for k, v in ctrl.items()}
        else:
            ctrl = [float(v) for v in ctrl]
        return self.request("set_ctrl", ctrl=ctrl)

    def twist(self, vx=0.0, vy=0.0, yaw_rate=0.0, robot=None):
        """Velocity command for a mobile robot's controller (``trot_gait``, ``policy``,
        ``waypoint_follower``); it holds until the next twist or :meth:`clear_twist`.

        :param vx: forward speed, m/s, in the heading frame.
        :param vy: leftward speed, m/s (0 for ``waypoint_follower``).
        :param yaw_rate: rad/s, counter-clockwise seen from above.
        :param robot: robot name; None when exactly one controller takes twists.
        :raises NotAvailableError: no controller of the world takes twists.
        """
        return self.request("twist", robot=robot, vx=float(vx), vy=float(vy),
                            yaw_rate=float(yaw_rate))

    def clear_twist(self, robot=None):
        """Drops the twist; the controller returns to its waypoints or script."""
        return self.request("twist", robot=robot, clear=True)

    def joint_targets(self, values, mode="position", robot=None):
        """Targets of a ``joint_pd`` controller, one per joint in its ``joints:`` order.

        :param mode: ``"position"`` (rad or m), ``"velocity"`` (rad/s or m/s) or ``"effort"``
            (N m or N).
        """
        return self.request("joint_targets", robot=robot, mode=mode,
                            values=[float(v) for v in values])

    def waypoints(self, points, loop=False, robot=None):
        """A new route (world x, y in m, at least one point) for a ``waypoint_follower``,
        ``trot_gait`` or ``policy`` controller; replaces the route and clears a twist."""
        return self.request("waypoints", robot=robot, loop=bool(loop),
                            points=[[float(p[0]), float(p[1])] for p in points])

    def set_mocap(self, body, xyz, qwxyz=None):
        """Moves a mocap body: ``xyz`` in the world frame (m), ``qwxyz`` a quaternion w x y z
        (normalised by the server; None keeps the orientation)."""
        return self.request("set_mocap", body=body, xyz=[float(v) for v in xyz],
                            qwxyz=None if qwxyz is None else [float(v) for v in qwxyz])

    def set_adversity(self, preset):
        """Switches the adversity preset (``"none"``, ``"minor"``, ``"major"``, or
        ``"FILE.yaml"`` / ``"FILE.yaml#NAME"`` inside the world file's folder, relative to it)
        at the next step boundary."""
        return self.request("set_adversity", preset=preset)

    def set_effect(self, effect, **params):
        """Changes one effect from the next step (docs/zmq-protocol.md ``set_effect``): an effect
        of the world file (its world-file keys), a block of the live adversity preset (``fog``,
        ``smoke``, ``rain``, ``snow``, ``lights``, ``npcs``, ``dust``), or a new effect (with
        ``type``), e.g. ``set_effect("fog", mor_m=5.0)``."""
        return self.request("set_effect", effect=effect, params=params)

    def start_recording(self, path, sensors=False):
        """Starts a run log (``.plog``, docs/run-log.md) at ``path``: a new file inside the
        run's output folder, relative to it (no absolute path, no ``..``, no symbolic link,
        never over an existing file; docs/zmq-protocol.md); ``sensors`` also records images
        and sensor outputs."""
        return self.request("start_recording", path=path, sensors=bool(sensors))

    def stop_recording(self):
        """Stops the run log. Returns the reply (``path``, ``bytes``, ``steps``)."""
        return self.request("stop_recording")

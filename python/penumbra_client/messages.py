"""Published messages (``[topic, header, payload]``), the sensor-stream socket, and the typed
results of ``step``, ``get_state`` and ``model_info`` (docs/zmq-protocol.md)."""

from __future__ import annotations

import time

import numpy as np
import zmq

from .images import image_from_buffer
from .protocol import PenumbraTimeoutError, unpack

#: the topic of ``sync`` messages (the client subscribes to it itself and hides it).
SYNC_TOPIC = "sync"

#: dtype of one LiDAR point record (``lidar/<sensor>`` payload, 20 bytes little-endian):
#: x, y, z in m in the sensor frame (REP-103) at the beam's firing time, intensity, and
#: time in s since the scan start.
LIDAR_POINT_DTYPE = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"),
                              ("intensity", "<f4"), ("time", "<f4")])


class Message:
    """One published message.

    :ivar topic: e.g. ``"camera/front/rgb"`` (str).
    :ivar header: the msgpack header map; always has ``stamp`` (sim time, s), ``sim_step``
        (physics steps since the run's start) and ``frame_id``.
    :ivar payload: the raw payload (bytes-like; empty for header-only topics).
    """

    __slots__ = ("topic", "header", "payload")

    def __init__(self, topic, header, payload):
        self.topic = topic
        self.header = header
        self.payload = payload

    @property
    def stamp(self):
        """Simulation time of the sample, s."""
        return self.header["stamp"]

    @property
    def sim_step(self):
        """The physics step the sample was taken at."""
        return self.header["sim_step"]

    @property
    def frame_id(self):
        return self.header["frame_id"]

    @property
    def is_image(self):
        return self.topic.startswith("camera/")

    def image(self):
        """The image of a ``camera/<camera>/<output>`` message as a read-only numpy array:
        ``rgb`` uint8 (H, W, 3) sRGB; ``depth``/``range`` float32 (H, W) metres (0 = no hit);
        ``depth_mm`` uint16 (H, W) millimetres (0 = no hit); segmentation outputs int32
        (H, W); ``normals`` float32 (H, W, 3) in the optical frame. Pixel (u, v) is
        ``array[v, u]``.

        :raises ValueError: not a camera topic.
        :raises penumbra_client.images.ImageFormatError: header and payload disagree.
        """
        if not self.is_image:
            raise ValueError(f"{self.topic}: not a camera topic")
        h = self.header
        return image_from_buffer(self.payload, h["width"], h["height"], h["encoding"],
                                 step=h.get("step"), is_bigendian=h.get("is_bigendian", False))

    def points(self):
        """The points of a ``lidar/<sensor>`` message as a structured array of
        :data:`LIDAR_POINT_DTYPE` (``p["x"]`` etc.), shape (count,)."""
        if not self.topic.startswith("lidar/"):
            raise ValueError(f"{self.topic}: not a lidar topic")
        count = self.header["count"]
        step = self.header.get("point_step", LIDAR_POINT_DTYPE.itemsize)
        raw = np.frombuffer(self.payload, dtype=np.uint8, count=count * step).reshape(count, step)
        return np.ascontiguousarray(raw[:, :LIDAR_POINT_DTYPE.itemsize]).view(
            LIDAR_POINT_DTYPE).reshape(count)

    def __repr__(self):
        return f"Message({self.topic!r}, stamp={self.header.get('stamp')}, {len(self.payload)} B)"


def topic_matches(topic, prefixes):
    """True when ``topic`` starts with one of ``prefixes`` (ZeroMQ's prefix subscriptions)."""
    return any(topic.startswith(p) for p in prefixes)


class Subscription:
    """A ``SUB`` socket on the server's publish endpoint (prefix subscriptions).

    Use :meth:`penumbra_client.Client.subscribe`, which also makes sure the server knows the
    subscription before it returns (ZeroMQ drops what is published before a subscription
    reaches the publisher). The receive queue is unbounded (``RCVHWM`` 0) so a lockstep
    ``step`` of many steps does not lose messages on the client's side.
    """

    def __init__(self, context, endpoint, topics, rcvhwm=0):
        self.endpoint = endpoint
        self.topics = []
        self._socket = context.socket(zmq.SUB)
        self._socket.setsockopt(zmq.RCVHWM, rcvhwm)
        self._socket.setsockopt(zmq.LINGER, 0)
        self._socket.connect(endpoint)
        self._socket.setsockopt(zmq.SUBSCRIBE, SYNC_TOPIC.encode())
        for t in topics:
            self.add(t)

    def add(self, topic):
        """Subscribes to every topic that starts with ``topic`` (e.g. ``"camera/"``)."""
        if topic not in self.topics:
            self.topics.append(topic)
            self._socket.setsockopt(zmq.SUBSCRIBE, topic.encode())

    def remove(self, topic):
        """Drops a subscription added with :meth:`add`."""
        if topic in self.topics:
            self.topics.remove(topic)
            self._socket.setsockopt(zmq.UNSUBSCRIBE, topic.encode())

    def matches(self, topic):
        """True when this subscription receives ``topic``."""
        return topic_matches(topic, self.topics)

    def recv_any(self, timeout_sec):
        """The next message, ``sync`` messages included, or None after ``timeout_sec``."""
        if not self._socket.poll(max(0, int(timeout_sec * 1000))):
            return None
        frames = self._socket.recv_multipart(copy=False)
        topic = bytes(frames[0].buffer).decode("utf-8", "replace")
        header = unpack(frames[1].bytes) if len(frames) > 1 else {}
        payload = frames[2].buffer if len(frames) > 2 else b""
        return Message(topic, header, payload)

    def recv(self, timeout_sec=None):
        """The next subscribed message (``sync`` messages skipped unless subscribed), or None
        after ``timeout_sec`` (None = wait forever)."""
        deadline = None if timeout_sec is None else time.monotonic() + timeout_sec
        while True:
            left = 3600.0 if deadline is None else deadline - time.monotonic()
            if left < 0:
                return None
            msg = self.recv_any(left)
            if msg is None:
                if deadline is None:
                    continue
                return None
            if msg.topic == SYNC_TOPIC and not self.matches(SYNC_TOPIC):
                continue
            return msg

    def collect(self, counts, timeout_sec):
        """Receives until it has ``counts[topic]`` messages of every topic in ``counts``.

        :param counts: map topic -> number of messages (e.g. a step reply's ``published``,
            restricted to subscribed topics).
        :returns: the messages in arrival order (other topics' messages, e.g. ``sync`` or
            ``end``, are left out).
        :raises PenumbraTimeoutError: not all arrived within ``timeout_sec`` (the message
            names what is missing; a slow subscriber behind the server's high-water mark
            loses messages, docs/zmq-protocol.md).
        """
        missing = {t: c for t, c in counts.items() if c > 0}
        out = []
        deadline = time.monotonic() + timeout_sec
        while missing:
            msg = self.recv_any(max(0.0, deadline - time.monotonic()))
            if msg is None:
                raise PenumbraTimeoutError(
                    f"after {timeout_sec} s still waiting for {missing} on {self.endpoint} "
                    "(messages dropped at the server's high-water mark?)", cmd="step")
            if msg.topic in missing:
                out.append(msg)
                missing[msg.topic] -= 1
                if missing[msg.topic] == 0:
                    del missing[msg.topic]
        return out

    def close(self):
        self._socket.close(0)


class StepResult:
    """The result of :meth:`penumbra_client.Client.step`.

    :ivar step: physics steps since the run's start, after this request.
    :ivar time_sec: simulation time after this request, s.
    :ivar ended: the run reached its end time within these steps.
    :ivar published: map topic -> messages the server published for these steps (all
        clients' subscriptions).
    :ivar messages: the subscribed messages of these steps, in arrival order.
    :ivar state: a :class:`State` when the step asked for it, else None.
    """

    def __init__(self, reply, messages, state):
        self.step = reply["step"]
        self.time_sec = reply["time_sec"]
        self.ended = reply.get("ended", False)
        self.published = reply.get("published", {})
        self.messages = messages
        self.state = state
        self.reply = reply

    def by_topic(self, topic):
        """The messages of one topic, oldest first."""
        return [m for m in self.messages if m.topic == topic]

    def images(self, topic):
        """The images of a camera topic (e.g. ``"camera/front/rgb"``), oldest first."""
        return [m.image() for m in self.by_topic(topic)]

    def latest(self, topic):
        """The newest message of ``topic`` in this step, or None."""
        for m in reversed(self.messages):
            if m.topic == topic:
                return m
        return None


class State:
    """The simulation state at a step boundary (``get_state``): MuJoCo's arrays as float64
    numpy arrays in MuJoCo's order and units.

    :ivar step: physics steps since the run's start.
    :ivar time_sec: simulation time, s.
    :ivar qpos: (nq,) joint positions (m, rad; a free joint: x y z in the world frame, then
        the unit quaternion w x y z of X_WB).
    :ivar qvel: (nv,) joint velocities (m/s, rad/s; a free joint: linear velocity in the
        world frame, angular velocity in the body frame, as MuJoCo).
    :ivar act: (na,) actuator activations.
    :ivar ctrl: (nu,) controls.
    :ivar mocap_pos: (nmocap, 3) mocap body positions in the world frame, m.
    :ivar mocap_quat: (nmocap, 4) mocap body orientations, w x y z.
    :ivar sensordata: (nsensordata,) MuJoCo sensor outputs.
    :ivar paused: the run is paused (lockstep).
    """

    ARRAYS = ("qpos", "qvel", "act", "ctrl", "sensordata")

    def __init__(self, reply):
        self.step = reply["step"]
        self.time_sec = reply["time_sec"]
        for name in self.ARRAYS:
            setattr(self, name, np.asarray(reply.get(name, []), dtype=np.float64))
        self.mocap_pos = np.asarray(reply.get("mocap_pos", []), dtype=np.float64).reshape(-1, 3)
        self.mocap_quat = np.asarray(reply.get("mocap_quat", []), dtype=np.float64).reshape(-1, 4)
        self.paused = reply.get("paused")

    def __eq__(self, other):
        return (isinstance(other, State) and self.step == other.step and
                self.time_sec == other.time_sec and
                all(np.array_equal(getattr(self, n), getattr(other, n))
                    for n in self.ARRAYS + ("mocap_pos", "mocap_quat")))

    def __repr__(self):
        return f"State(step={self.step}, time_sec={self.time_sec}, nq={self.qpos.size})"


class ModelInfo:
    """The reply of ``model_info`` with look-ups by name.

    The reply's keys are attributes (``info.nq``, ``info.cameras``, ...); ``raw`` is the map.
    """

    def __init__(self, reply):
        self.raw = reply
        for key, value in reply.items():
            if key not in ("ok", "cmd", "id"):
                setattr(self, key, value)

    def _find(self, kind, name):
        for item in self.raw.get(kind, []):
            if item.get("name") == name:
                return item
        names = [item.get("name") for item in self.raw.get(kind, [])]
        raise KeyError(f"no {kind[:-1]} '{name}'; the model has {names}")

    def body(self, name):
        """``{"id", "name", "parent"}`` of a body (prefixed name, e.g. ``"quadruped/trunk"``)."""
        return self._find("bodies", name)

    def joint(self, name):
        """A joint's map: ``id``, ``type``, ``qpos_adr``, ``dof_adr``, ``range`` (m or rad)."""
        return self._find("joints", name)

    def actuator(self, name):
        """An actuator's map: ``id`` (its index in ctrl), ``ctrl_range``, ``ctrl_limited``."""
        return self._find("actuators", name)

    def camera(self, name):
        """A camera's map: ``width``, ``height``, ``fx fy cx cy`` (pixels), ``rate_hz``,
        ``frame_id`` (its OpenCV optical frame), ``outputs``."""
        return self._find("cameras", name)

    def ctrl_bounds(self):
        """(low, high) float64 arrays of shape (nu,): each actuator's ctrl range, or
        -inf/+inf where it is not limited."""
        lo = np.full(self.raw["nu"], -np.inf)
        hi = np.full(self.raw["nu"], np.inf)
        for a in self.raw.get("actuators", []):
            if a.get("ctrl_limited"):
                lo[a["id"]], hi[a["id"]] = a["ctrl_range"]
        return lo, hi

    def controller(self, robot=None):
        """The controller of ``robot`` (or the only one): ``index``, ``robot``, ``type``,
        ``commands`` (the command names it accepts)."""
        ctrls = self.raw.get("controllers", [])
        if robot is None:
            if len(ctrls) != 1:
                raise KeyError(f"{len(ctrls)} controllers; name the robot")
            return ctrls[0]
        for c in ctrls:
            if c["robot"] == robot:
                return c
        raise KeyError(f"no controller for robot '{robot}'")

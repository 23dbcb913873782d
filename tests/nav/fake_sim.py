"""A stand-in for a lockstep Penumbra server, for testing the navigator loop without one.

It answers the client calls the navigator makes (model_info, subscribe, reset, get_state,
twist, step) with a kinematic unicycle (the twist is followed exactly) and ray-cast depth
images of a floor (z = 0) and axis-aligned boxes, published as the real server does: one
``camera/front/depth`` frame per 0.1 s with ``X_WO`` and the intrinsics in its header,
``ground_truth/poses`` and ``contacts`` at every physics step.
"""

import math
import os
import sys

import numpy as np

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..",
                                "python"))
from penumbra_client.messages import Message, ModelInfo, State, StepResult  # noqa: E402
from penumbra_nav.geometry import R_BODY_OPTICAL, pose_matrix, yaw_quat  # noqa: E402

DT = 0.002
W, H, FX, FY, CX, CY = 64, 48, 40.0, 40.0, 31.5, 23.5
BASE_HEIGHT = 0.285
MOUNT = (0.215, 0.0, 0.07)
FRAME_STEPS = 50  # 10 Hz


class FakeLockstepClient:
    """The navigator's view of a lockstep run of the quadruped among boxes.

    :param boxes: list of (xmin, ymin, xmax, ymax, height) in the world frame, m.
    :param fall_at_sec: from this sim time on, the trunk lies at z = 0.1 m (a fall).
    :param publish_pose: False: no ``X_WO`` in the camera header (the navigator then uses
        the camera mount on the base pose).
    """

    def __init__(self, boxes=(), fall_at_sec=None, publish_pose=True):
        self.boxes = [tuple(map(float, b)) for b in boxes]
        self.fall_at_sec = fall_at_sec
        self.publish_pose = publish_pose
        self.step_count = 0
        self.xy = np.zeros(2)
        self.yaw = 0.0
        self.twist_cmd = (0.0, 0.0)
        self.topics = []
        self.trajectory = []
        self.twists = []
        self.ended = False

    # -- client API --------------------------------------------------------------------------

    def model_info(self):
        return ModelInfo({
            "timestep_sec": DT, "nq": 7, "nv": 6, "nu": 0,
            "bodies": [{"id": 0, "name": "world", "parent": -1},
                       {"id": 1, "name": "quadruped/trunk", "parent": 0},
                       {"id": 2, "name": "course/box", "parent": 0}],
            "joints": [{"id": 0, "name": "quadruped/trunk_free", "type": "free", "body": 1,
                        "qpos_adr": 0, "dof_adr": 0}],
            "cameras": [{"name": "side", "width": 8, "height": 6, "fx": 5, "fy": 5, "cx": 3.5,
                         "cy": 2.5, "rate_hz": 10, "outputs": ["rgb"]},
                        {"name": "front", "width": W, "height": H, "fx": FX, "fy": FY,
                         "cx": CX, "cy": CY, "rate_hz": 10, "outputs": ["rgb", "depth"]}],
            "controllers": [{"index": 0, "robot": "quadruped", "type": "trot_gait",
                             "commands": ["twist", "waypoints"]}],
        })

    def subscribe(self, topics):
        self.topics += list(topics)

    def reset(self):
        self.xy = np.zeros(2)
        self.yaw = 0.0

    def get_state(self):
        return State({"step": self.step_count, "time_sec": self.step_count * DT,
                      "qpos": list(self._base_xyz()) + yaw_quat(self.yaw)})

    def twist(self, vx=0.0, vy=0.0, yaw_rate=0.0, robot=None):
        assert vy == 0.0 and robot == "quadruped"
        self.twist_cmd = (float(vx), float(yaw_rate))
        self.twists.append(self.twist_cmd)

    def step(self, n=1, state=False):
        messages = []
        published = {}

        def publish(topic, header, payload=b""):
            if any(topic.startswith(t) for t in self.topics):
                header.update(stamp=self.step_count * DT, sim_step=self.step_count)
                messages.append(Message(topic, header, payload))
                published[topic] = published.get(topic, 0) + 1

        for _ in range(n):
            vx, w = self.twist_cmd
            self.xy += DT * vx * np.array([math.cos(self.yaw), math.sin(self.yaw)])
            self.yaw += DT * w
            self.step_count += 1
            self.trajectory.append(self.xy.copy())
            xyz, q = self._base_xyz(), yaw_quat(self.yaw)
            publish("ground_truth/poses",
                    {"frame_id": "world", "name": ["quadruped/trunk", "course/box"],
                     "xyz": [list(xyz), [0.0, 0.0, 0.0]], "qwxyz": [q, [1.0, 0, 0, 0]]})
            publish("contacts", {"frame_id": "world", "contacts": [
                {"body1": 0, "body2": 1, "geom1": 0, "geom2": 1, "p_W": [0, 0, 0],
                 "normal_W": [0, 0, 1], "distance_m": 0.0, "force_N": [120.0, 0, 0]}]})
            if self.step_count % FRAME_STEPS == 0:
                X_WO = pose_matrix(xyz, q)
                X_BO = np.eye(4)
                X_BO[:3, :3] = R_BODY_OPTICAL
                X_BO[:3, 3] = MOUNT
                X_WO = X_WO @ X_BO
                header = {"frame_id": "front/optical", "camera": "front", "encoding": "32FC1",
                          "width": W, "height": H, "step": 4 * W, "is_bigendian": False,
                          "fx": FX, "fy": FY, "cx": CX, "cy": CY}
                if self.publish_pose:
                    header["X_WO"] = {"xyz": list(X_WO[:3, 3]), "qwxyz": list(q_of(X_WO))}
                publish("camera/front/depth", header, self.render(X_WO).tobytes())
        reply = {"step": self.step_count, "time_sec": self.step_count * DT,
                 "ended": self.ended, "published": published}
        return StepResult(reply, messages, None)

    # -- the fake world ----------------------------------------------------------------------

    def _base_xyz(self):
        t = self.step_count * DT
        z = 0.1 if self.fall_at_sec is not None and t >= self.fall_at_sec else BASE_HEIGHT
        return [float(self.xy[0]), float(self.xy[1]), z]

    def render(self, X_WO):
        """z-depth (H, W) float32 of the floor and the boxes seen from X_WO, 0 = no hit."""
        u, v = np.meshgrid(np.arange(W), np.arange(H))
        d_C = np.stack([(u - CX) / FX, (v - CY) / FY, np.ones((H, W))], axis=-1)
        d = d_C @ X_WO[:3, :3].T  # ray directions scaled so the parameter is the z-depth
        o = X_WO[:3, 3]
        best = np.full((H, W), np.inf)
        with np.errstate(divide="ignore", invalid="ignore"):
            t_floor = np.where(d[..., 2] < 0, -o[2] / d[..., 2], np.inf)
            best = np.minimum(best, t_floor)
            for x0, y0, x1, y1, hgt in self.boxes:
                lo = np.array([x0, y0, 0.0])
                hi = np.array([x1, y1, hgt])
                t0 = (lo - o) / d
                t1 = (hi - o) / d
                near = np.nanmax(np.minimum(t0, t1), axis=-1)
                far = np.nanmin(np.maximum(t0, t1), axis=-1)
                hit = (near <= far) & (far > 0)
                best = np.where(hit, np.minimum(best, np.maximum(near, 0.0)), best)
        best[~np.isfinite(best) | (best > 20.0)] = 0.0
        return best.astype(np.float32)

    def box_distance(self, xy):
        """Distance (m) from a world point to the nearest box in plan view."""
        out = math.inf
        for x0, y0, x1, y1, _ in self.boxes:
            dx = max(x0 - xy[0], 0.0, xy[0] - x1)
            dy = max(y0 - xy[1], 0.0, xy[1] - y1)
            out = min(out, math.hypot(dx, dy))
        return out


def q_of(X):
    """[w, x, y, z] of the rotation of a 4 x 4 pose (Shepperd's method)."""
    R = X[:3, :3]
    tr = np.trace(R)
    if tr > 0:
        s = 2.0 * math.sqrt(tr + 1.0)
        return [0.25 * s, (R[2, 1] - R[1, 2]) / s, (R[0, 2] - R[2, 0]) / s,
                (R[1, 0] - R[0, 1]) / s]
    k = int(np.argmax(np.diag(R)))
    i, j = (k + 1) % 3, (k + 2) % 3
    s = 2.0 * math.sqrt(1.0 + R[k, k] - R[i, i] - R[j, j])
    q = [0.0, 0.0, 0.0, 0.0]
    q[0] = (R[j, i] - R[i, j]) / s
    q[1 + k] = 0.25 * s
    q[1 + i] = (R[i, k] + R[k, i]) / s
    q[1 + j] = (R[j, k] + R[k, j]) / s
    return q

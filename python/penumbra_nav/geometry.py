"""Rigid transforms and angles in the protocol's conventions (docs/zmq-protocol.md).

Poses are ``xyz`` (m) and ``qwxyz`` (unit quaternion, w first). ``X_AB`` is the pose of frame
B in frame A as a 4 x 4 homogeneous matrix; ``R_AB`` its rotation. The world frame W is
REP-103 (x forward, y left, z up); a camera's optical frame O is OpenCV's (x right, y down,
z forward).
"""

import math

import numpy as np

#: R_BO: the optical frame O of a camera in the REP-103 frame B it is mounted on (x
#: forward, y left, z up): optical x = -y_B (right), optical y = -z_B (down), optical
#: z = x_B (forward).
R_BODY_OPTICAL = np.array([[0.0, 0.0, 1.0],
                           [-1.0, 0.0, 0.0],
                           [0.0, -1.0, 0.0]])


def quat_to_rotation(qwxyz):
    """The 3 x 3 rotation matrix of a quaternion ``[w, x, y, z]`` (normalised here)."""
    w, x, y, z = np.asarray(qwxyz, dtype=np.float64) / np.linalg.norm(qwxyz)
    return np.array([
        [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
        [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
        [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
    ])


def pose_matrix(xyz, qwxyz):
    """X_AB (4 x 4) from the position of B in A (m) and its orientation ``[w, x, y, z]``."""
    X = np.eye(4)
    X[:3, :3] = quat_to_rotation(qwxyz)
    X[:3, 3] = np.asarray(xyz, dtype=np.float64)
    return X


def pose_from_msg(pose):
    """X_AB (4 x 4) from a protocol pose map ``{"xyz": [..], "qwxyz": [..]}``."""
    return pose_matrix(pose["xyz"], pose["qwxyz"])


def as_pose_matrix(X):
    """Accepts a 4 x 4 matrix, a protocol pose map, or a ``(xyz, qwxyz)`` pair; returns the
    4 x 4 matrix (float64)."""
    if isinstance(X, dict):
        return pose_from_msg(X)
    if isinstance(X, (tuple, list)) and len(X) == 2:
        return pose_matrix(X[0], X[1])
    X = np.asarray(X, dtype=np.float64)
    if X.shape != (4, 4):
        raise ValueError(f"pose: shape {X.shape}; expected (4, 4)")
    return X


def yaw_of(qwxyz):
    """Yaw (rad, counter-clockwise about world z) of an orientation ``[w, x, y, z]``: the
    heading of the body's x axis projected on the ground plane."""
    w, x, y, z = qwxyz
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def roll_pitch_of(qwxyz):
    """(roll, pitch) in rad of an orientation ``[w, x, y, z]`` (z-y-x Euler angles, as
    REP-103's roll about x and pitch about y)."""
    w, x, y, z = qwxyz
    roll = math.atan2(2.0 * (w * x + y * z), 1.0 - 2.0 * (x * x + y * y))
    pitch = math.asin(max(-1.0, min(1.0, 2.0 * (w * y - z * x))))
    return roll, pitch


def wrap_angle(a):
    """``a`` (rad) wrapped to [-pi, pi)."""
    return (a + math.pi) % (2.0 * math.pi) - math.pi


def yaw_quat(yaw):
    """The quaternion ``[w, x, y, z]`` of a rotation by ``yaw`` rad about z."""
    return [math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0)]

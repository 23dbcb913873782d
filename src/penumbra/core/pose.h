#pragma once
// rigid transforms. naming: X_AB is the pose of frame B measured in frame A
// (p_A = X_AB * p_B). rotations as roll-pitch-yaw follow REP-103: extrinsic
// x-y-z (roll about x, then pitch about y, then yaw about z), i.e. R = Rz(yaw) Ry(pitch) Rx(roll).

#include <Eigen/Geometry>

namespace penumbra {

using Pose = Eigen::Isometry3d;

/// pose from a translation xyz (m) and roll, pitch, yaw in degrees (REP-103 order).
Pose PoseFromXyzRpyDeg(const Eigen::Vector3d& xyz, const Eigen::Vector3d& rpy_deg);

/// pose from a translation and a unit quaternion given as (w, x, y, z), as MuJoCo stores it.
Pose PoseFromPosQuat(const double pos[3], const double quat_wxyz[4]);

/// rotation that takes the OpenCV optical frame (x right, y down, z forward) to the
/// MuJoCo/OpenGL camera frame (x right, y up, -z forward): X_mjcam_optical.
Eigen::Matrix3d RotationMujocoCameraFromOptical();

/// rotation that takes the OpenCV optical frame to a REP-103 camera body frame
/// (x forward, y left, z up): X_body_optical.
Eigen::Matrix3d RotationBodyFromOptical();

}  // namespace penumbra

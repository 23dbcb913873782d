#pragma once
// Penumbra data as ROS 1 messages (ros/ros_messages.h), shared by the live bridge and the rosbag
// export. conventions (docs/ros.md):
//
//   - stamps: sim time in integer nanoseconds, rounded (dataset/run_folder.h SecondsToNs).
//   - colour: sensor_msgs/Image "rgb8", the camera's 8-bit sRGB bytes as they are.
//   - depth: "32FC1", z-depth along the optical axis in metres (REP-118); a pixel with no return
//     (Penumbra's 0) is +Inf, REP-117's "no detection within range".
//   - CameraInfo: plumb_bob D = (k1, k2, p1, p2, k3), K, R = I, P = K [I | t] with
//     P[3] = -fx * baseline for the right camera of a stereo pair (output/camera_info.h).
//   - PointCloud2: one row of the scan's points in beam order, fields x y z intensity (float32,
//     m / dimensionless) ring (uint16) time (float32, s since the scan start): point_step 24,
//     offsets 0 4 8 12 16 20 (the layout of the Velodyne and Ouster drivers).
//   - Imu: angular_velocity and linear_acceleration in the IMU frame; orientation is not measured
//     (orientation_covariance[0] = -1, the message's "no estimate"); the rate and acceleration
//     covariances are diag(sigma^2) with sigma = noise density * sqrt(rate) (discrete white noise
//     of the continuous density, Kalibr's convention).
//   - Odometry: ground truth: the base body's pose in the odom frame (= map, the world frame W)
//     and its twist in base_link axes (the message's rule), covariances 0 (exact).
//   - JointState: hinge and slide joints: qpos (rad, m), qvel (rad/s, m/s), qfrc_actuator
//     (N m, N) as effort.

#include <Eigen/Core>
#include <cstdint>
#include <string>
#include <vector>

#include "penumbra/control/model_info.h"
#include "penumbra/core/image.h"
#include "penumbra/core/pose.h"
#include "penumbra/ros/ros_graph.h"
#include "penumbra/ros/ros_messages.h"
#include "penumbra/scene/world_snapshot.h"
#include "penumbra/sensors/lidar_scanner.h"

namespace penumbra {

/// sim time in seconds -> integer nanoseconds, rounded to nearest.
int64_t RosStampNs(double time_sec);

/// a header at sim time `time_sec` in `frame_id`.
RosHeader MakeRosHeader(double time_sec, const std::string& frame_id);

/// (H x W x 3) 8-bit RGB -> "rgb8". @throws Error for another channel count.
RosImage RgbToRos(const ImageU8& rgb, const RosHeader& header);
/// rvalue overload: the pixel buffer is moved, not copied.
RosImage RgbToRos(ImageU8&& rgb, const RosHeader& header);

/// (H x W x 1) float z-depth in metres, 0 = no return -> "32FC1" (no return = +Inf).
/// @throws Error for another channel count.
RosImage DepthToRos(const ImageF& depth_m, const RosHeader& header);

/// 16-bit z-depth in millimetres (the run folder's depth PNGs), 0 = no return -> "32FC1" metres.
RosImage DepthMmToRos(int width, int height, const std::vector<uint16_t>& mm,
                      const RosHeader& header);

/// the CameraInfo of a camera.
RosCameraInfo CameraInfoToRos(const CameraIntrinsics& k, double baseline_m,
                              const RosHeader& header);

/// a LiDAR scan as PointCloud2 (layout in the file comment).
RosPointCloud2 PointsToRos(const std::vector<LidarPoint>& points, const RosHeader& header);

/// an IMU sample (specific force m/s^2, angular velocity rad/s, IMU frame) with covariances from
/// the noise densities at `rate_hz` (0 densities or rate = covariance 0).
RosImu ImuToRos(const Eigen::Vector3d& accel_m_s2, const Eigen::Vector3d& gyro_rad_s,
                double accel_noise_density, double gyro_noise_density, double rate_hz,
                const RosHeader& header);

/// X_PC as the transform of `child` in `parent` at `stamp_ns`.
RosTransform TransformToRos(const Pose& X_PC, const std::string& parent, const std::string& child,
                            int64_t stamp_ns);

/// ground-truth odometry of a body: X_WB and V_WB (angular; linear, world axes, at B's origin).
RosOdometry OdometryToRos(const Pose& X_WB, const Eigen::Matrix<double, 6, 1>& V_WB,
                          const std::string& odom_frame, const std::string& base_frame,
                          int64_t stamp_ns);

/// the joint state of `joints` (ModelInfo::joints indices) from qpos / qvel / qfrc_actuator
/// (empty qvel or qfrc_actuator leave velocity / effort empty).
RosJointState JointStateToRos(const ModelInfo& model, const std::vector<int>& joints,
                              const std::vector<double>& qpos, const std::vector<double>& qvel,
                              const std::vector<double>& qfrc_actuator, int64_t stamp_ns);

/// X_WS of a sensor at `snapshot` (needs X_WB, and X_W_mjcam for MJCF cameras).
/// @throws Error if the snapshot lacks the body or camera.
Pose SensorPoseInWorld(const RosSensorGraph& s, const WorldSnapshot& snapshot);

/// the static transforms of `graph` (/tf_static) at the snapshot: map -> odom (identity) of every
/// robot, and parent -> sensor of every sensor rigid to its parent.
std::vector<RosTransform> StaticTransforms(const RosGraph& graph, const WorldSnapshot& snapshot);

/// the moving transforms (/tf) at the snapshot: odom -> base_link of every robot and parent ->
/// sensor of every sensor not rigid to its parent.
std::vector<RosTransform> DynamicTransforms(const RosGraph& graph, const WorldSnapshot& snapshot);

}  // namespace penumbra

#pragma once
// ROS 1 messages as plain C++ structs, field for field as the .msg definitions of sensor_msgs,
// nav_msgs, geometry_msgs and tf2_msgs (ROS Noetic; http://docs.ros.org/en/noetic/api/). the
// conversions (ros/ros_convert.h) fill these; only the ROS-linked files (ros/ros1/) turn them
// into the real message types, so that the rest of Penumbra never includes a ROS header.
//
// this header is C++17 (the ROS 1 message headers do not compile as C++20: they use
// std::allocator<void>::rebind, removed in C++20), so the ROS-linked files can include it.
//
// units SI, frames REP-103 (x forward, y left, z up) and REP-105 (map, odom, base_link); optical
// frames x right, y down, z forward. quaternions (x, y, z, w) as in geometry_msgs/Quaternion.
// stamps are integer nanoseconds of sim time (ros::Time(sec, nsec) = stamp_ns / 1e9).

#include <array>
#include <cstdint>
#include <string>
#include <vector>

namespace penumbra {

/// std_msgs/Header (seq is left to the publisher).
struct RosHeader {
  int64_t stamp_ns = 0;
  std::string frame_id;
};

/// sensor_msgs/Image.
struct RosImage {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::string encoding;  ///< "rgb8", "32FC1", ... (sensor_msgs/image_encodings.h)
  uint8_t is_bigendian = 0;
  uint32_t step = 0;  ///< bytes per row
  std::vector<uint8_t> data;
};

/// sensor_msgs/CameraInfo (binning and ROI left at their defaults: full resolution).
struct RosCameraInfo {
  RosHeader header;
  uint32_t height = 0, width = 0;
  std::string distortion_model = "plumb_bob";
  std::vector<double> D;  ///< k1 k2 p1 p2 k3
  std::array<double, 9> K{};
  std::array<double, 9> R{};
  std::array<double, 12> P{};
};

/// sensor_msgs/PointField datatypes.
enum RosPointFieldType : uint8_t {
  kRosInt8 = 1,
  kRosUint8 = 2,
  kRosInt16 = 3,
  kRosUint16 = 4,
  kRosInt32 = 5,
  kRosUint32 = 6,
  kRosFloat32 = 7,
  kRosFloat64 = 8,
};

/// sensor_msgs/PointField.
struct RosPointField {
  std::string name;
  uint32_t offset = 0;
  uint8_t datatype = kRosFloat32;
  uint32_t count = 1;
};

/// sensor_msgs/PointCloud2.
struct RosPointCloud2 {
  RosHeader header;
  uint32_t height = 1, width = 0;
  std::vector<RosPointField> fields;
  uint8_t is_bigendian = 0;
  uint32_t point_step = 0, row_step = 0;
  std::vector<uint8_t> data;
  uint8_t is_dense = 1;
};

/// sensor_msgs/Imu. a covariance with element 0 = -1 means "no estimate" (the message's rule).
struct RosImu {
  RosHeader header;
  std::array<double, 4> orientation{0, 0, 0, 1};  ///< x y z w
  std::array<double, 9> orientation_covariance{};
  std::array<double, 3> angular_velocity{};  ///< rad/s
  std::array<double, 9> angular_velocity_covariance{};
  std::array<double, 3> linear_acceleration{};  ///< m/s^2
  std::array<double, 9> linear_acceleration_covariance{};
};

/// sensor_msgs/JointState.
struct RosJointState {
  RosHeader header;
  std::vector<std::string> name;
  std::vector<double> position, velocity, effort;
};

/// geometry_msgs/TransformStamped: the pose of child_frame_id in header.frame_id.
struct RosTransform {
  RosHeader header;
  std::string child_frame_id;
  std::array<double, 3> translation{};
  std::array<double, 4> rotation{0, 0, 0, 1};  ///< x y z w
};

/// nav_msgs/Odometry: pose in header.frame_id, twist in child_frame_id's axes.
struct RosOdometry {
  RosHeader header;
  std::string child_frame_id;
  std::array<double, 3> position{};
  std::array<double, 4> orientation{0, 0, 0, 1};  ///< x y z w
  std::array<double, 36> pose_covariance{};
  std::array<double, 3> linear{};   ///< m/s
  std::array<double, 3> angular{};  ///< rad/s
  std::array<double, 36> twist_covariance{};
};

/// geometry_msgs/Twist (cmd_vel).
struct RosTwist {
  std::array<double, 3> linear{};   ///< m/s
  std::array<double, 3> angular{};  ///< rad/s
};

/// geometry_msgs/PoseStamped (mocap poses).
struct RosPoseStamped {
  RosHeader header;
  std::array<double, 3> position{};
  std::array<double, 4> orientation{0, 0, 0, 1};  ///< x y z w
};

}  // namespace penumbra

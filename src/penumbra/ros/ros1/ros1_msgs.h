#pragma once
// the plain messages of ros/ros_messages.h as ROS 1 message types, and back (cmd_vel, poses).
// included only by the ROS-linked files of this folder (C++17, ROS headers).

#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <nav_msgs/Odometry.h>
#include <ros/time.h>
#include <sensor_msgs/CameraInfo.h>
#include <sensor_msgs/Image.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <sensor_msgs/PointCloud2.h>
#include <tf2_msgs/TFMessage.h>

#include <algorithm>
#include <utility>

#include "penumbra/ros/ros_messages.h"

namespace penumbra::ros1 {

/// integer nanoseconds -> ros::Time (clamped to >= 0).
inline ros::Time ToRosTime(int64_t ns) {
  if (ns < 0) ns = 0;
  ros::Time t;
  t.fromNSec(static_cast<uint64_t>(ns));
  return t;
}

inline std_msgs::Header ToMsg(const RosHeader& h) {
  std_msgs::Header m;
  m.stamp = ToRosTime(h.stamp_ns);
  m.frame_id = h.frame_id;
  return m;
}

// the image data is moved when `m` is an rvalue (large buffers)
inline sensor_msgs::Image ToMsg(RosImage m) {
  sensor_msgs::Image r;
  r.header = ToMsg(m.header);
  r.height = m.height;
  r.width = m.width;
  r.encoding = m.encoding;
  r.is_bigendian = m.is_bigendian;
  r.step = m.step;
  r.data = std::move(m.data);
  return r;
}

inline sensor_msgs::CameraInfo ToMsg(const RosCameraInfo& m) {
  sensor_msgs::CameraInfo r;
  r.header = ToMsg(m.header);
  r.height = m.height;
  r.width = m.width;
  r.distortion_model = m.distortion_model;
  r.D = m.D;
  std::copy(m.K.begin(), m.K.end(), r.K.begin());
  std::copy(m.R.begin(), m.R.end(), r.R.begin());
  std::copy(m.P.begin(), m.P.end(), r.P.begin());
  return r;
}

inline sensor_msgs::PointCloud2 ToMsg(RosPointCloud2 m) {
  sensor_msgs::PointCloud2 r;
  r.header = ToMsg(m.header);
  r.height = m.height;
  r.width = m.width;
  for (const RosPointField& f : m.fields) {
    sensor_msgs::PointField pf;
    pf.name = f.name;
    pf.offset = f.offset;
    pf.datatype = f.datatype;
    pf.count = f.count;
    r.fields.push_back(pf);
  }
  r.is_bigendian = m.is_bigendian;
  r.point_step = m.point_step;
  r.row_step = m.row_step;
  r.data = std::move(m.data);
  r.is_dense = m.is_dense;
  return r;
}

inline geometry_msgs::Quaternion ToQuat(const std::array<double, 4>& q) {
  geometry_msgs::Quaternion r;
  r.x = q[0];
  r.y = q[1];
  r.z = q[2];
  r.w = q[3];
  return r;
}

inline geometry_msgs::Vector3 ToVec(const std::array<double, 3>& v) {
  geometry_msgs::Vector3 r;
  r.x = v[0];
  r.y = v[1];
  r.z = v[2];
  return r;
}

inline sensor_msgs::Imu ToMsg(const RosImu& m) {
  sensor_msgs::Imu r;
  r.header = ToMsg(m.header);
  r.orientation = ToQuat(m.orientation);
  std::copy(m.orientation_covariance.begin(), m.orientation_covariance.end(),
            r.orientation_covariance.begin());
  r.angular_velocity = ToVec(m.angular_velocity);
  std::copy(m.angular_velocity_covariance.begin(), m.angular_velocity_covariance.end(),
            r.angular_velocity_covariance.begin());
  r.linear_acceleration = ToVec(m.linear_acceleration);
  std::copy(m.linear_acceleration_covariance.begin(), m.linear_acceleration_covariance.end(),
            r.linear_acceleration_covariance.begin());
  return r;
}

inline sensor_msgs::JointState ToMsg(const RosJointState& m) {
  sensor_msgs::JointState r;
  r.header = ToMsg(m.header);
  r.name = m.name;
  r.position = m.position;
  r.velocity = m.velocity;
  r.effort = m.effort;
  return r;
}

inline nav_msgs::Odometry ToMsg(const RosOdometry& m) {
  nav_msgs::Odometry r;
  r.header = ToMsg(m.header);
  r.child_frame_id = m.child_frame_id;
  r.pose.pose.position.x = m.position[0];
  r.pose.pose.position.y = m.position[1];
  r.pose.pose.position.z = m.position[2];
  r.pose.pose.orientation = ToQuat(m.orientation);
  std::copy(m.pose_covariance.begin(), m.pose_covariance.end(), r.pose.covariance.begin());
  r.twist.twist.linear = ToVec(m.linear);
  r.twist.twist.angular = ToVec(m.angular);
  std::copy(m.twist_covariance.begin(), m.twist_covariance.end(), r.twist.covariance.begin());
  return r;
}

inline geometry_msgs::TransformStamped ToMsg(const RosTransform& m) {
  geometry_msgs::TransformStamped r;
  r.header = ToMsg(m.header);
  r.child_frame_id = m.child_frame_id;
  r.transform.translation = ToVec(m.translation);
  r.transform.rotation = ToQuat(m.rotation);
  return r;
}

inline tf2_msgs::TFMessage ToTfMsg(const std::vector<RosTransform>& ts) {
  tf2_msgs::TFMessage r;
  for (const RosTransform& t : ts) r.transforms.push_back(ToMsg(t));
  return r;
}

inline RosTwist FromMsg(const geometry_msgs::Twist& m) {
  RosTwist r;
  r.linear = {m.linear.x, m.linear.y, m.linear.z};
  r.angular = {m.angular.x, m.angular.y, m.angular.z};
  return r;
}

inline RosPoseStamped FromMsg(const geometry_msgs::PoseStamped& m) {
  RosPoseStamped r;
  r.header.stamp_ns = static_cast<int64_t>(m.header.stamp.toNSec());
  r.header.frame_id = m.header.frame_id;
  r.position = {m.pose.position.x, m.pose.position.y, m.pose.position.z};
  r.orientation = {m.pose.orientation.x, m.pose.orientation.y, m.pose.orientation.z,
                   m.pose.orientation.w};
  return r;
}

inline RosJointState FromMsg(const sensor_msgs::JointState& m) {
  RosJointState r;
  r.header.stamp_ns = static_cast<int64_t>(m.header.stamp.toNSec());
  r.header.frame_id = m.header.frame_id;
  r.name = m.name;
  r.position = m.position;
  r.velocity = m.velocity;
  r.effort = m.effort;
  return r;
}

}  // namespace penumbra::ros1

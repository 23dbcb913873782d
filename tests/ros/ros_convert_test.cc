// Penumbra data as ROS messages (ros/ros_convert.h): encodings, units, layouts and frames.
#include "penumbra/ros/ros_convert.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "penumbra/core/error.h"
#include "penumbra/core/pose.h"

namespace penumbra {
namespace {

template <typename T>
T At(const std::vector<uint8_t>& data, size_t offset) {
  T v;
  std::memcpy(&v, data.data() + offset, sizeof(T));
  return v;
}

TEST(RosConvert, StampsAreRoundedNanoseconds) {
  EXPECT_EQ(RosStampNs(0.1), 100000000);
  EXPECT_EQ(RosStampNs(0.002 * 3), 6000000);
  const RosHeader h = MakeRosHeader(1.5, "f");
  EXPECT_EQ(h.stamp_ns, 1500000000);
  EXPECT_EQ(h.frame_id, "f");
}

TEST(RosConvert, RgbKeepsBytes) {
  ImageU8 rgb(3, 2, 3);
  for (size_t i = 0; i < rgb.data.size(); ++i) rgb.data[i] = static_cast<uint8_t>(i * 7);
  const RosImage m = RgbToRos(rgb, MakeRosHeader(0, "cam"));
  EXPECT_EQ(m.encoding, "rgb8");
  EXPECT_EQ(m.width, 3u);
  EXPECT_EQ(m.height, 2u);
  EXPECT_EQ(m.step, 9u);
  EXPECT_EQ(m.data, rgb.data);
  EXPECT_THROW(RgbToRos(ImageU8(2, 2, 1), RosHeader{}), Error);
}

TEST(RosConvert, DepthIsMetresWithNoReturnAsInfinity) {
  ImageF d(2, 1, 1);
  d.data = {0.0f, 2.5f};
  const RosImage m = DepthToRos(d, RosHeader{});
  EXPECT_EQ(m.encoding, "32FC1");
  EXPECT_EQ(m.step, 8u);
  ASSERT_EQ(m.data.size(), 8u);
  EXPECT_TRUE(std::isinf(At<float>(m.data, 0)) && At<float>(m.data, 0) > 0);
  EXPECT_EQ(At<float>(m.data, 4), 2.5f);
  const RosImage mm = DepthMmToRos(2, 1, {1234, 0}, RosHeader{});
  EXPECT_FLOAT_EQ(At<float>(mm.data, 0), 1.234f);
  EXPECT_TRUE(std::isinf(At<float>(mm.data, 4)));
}

TEST(RosConvert, CameraInfoIsPlumbBobWithStereoBaseline) {
  CameraIntrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = 500;
  k.fy = 510;
  k.cx = 319.5;
  k.cy = 239.5;
  k.k1 = -0.1;
  k.p2 = 0.001;
  const RosCameraInfo m = CameraInfoToRos(k, 0.12, MakeRosHeader(0, "right/optical"));
  EXPECT_EQ(m.distortion_model, "plumb_bob");
  EXPECT_EQ(m.D, (std::vector<double>{-0.1, 0, 0, 0.001, 0}));
  EXPECT_EQ(m.K, (std::array<double, 9>{500, 0, 319.5, 0, 510, 239.5, 0, 0, 1}));
  EXPECT_EQ(m.R, (std::array<double, 9>{1, 0, 0, 0, 1, 0, 0, 0, 1}));
  EXPECT_DOUBLE_EQ(m.P[3], -500 * 0.12);
  EXPECT_EQ(m.P[0], 500);
  EXPECT_EQ(m.P[10], 1);
}

TEST(RosConvert, PointCloudLayout) {
  LidarPoint p;
  p.x = 1;
  p.y = -2;
  p.z = 3.5f;
  p.intensity = 0.25f;
  p.ring = 17;
  p.time = 0.05f;
  const RosPointCloud2 m = PointsToRos({p, p}, RosHeader{});
  EXPECT_EQ(m.width, 2u);
  EXPECT_EQ(m.height, 1u);
  EXPECT_EQ(m.point_step, 24u);
  EXPECT_EQ(m.row_step, 48u);
  ASSERT_EQ(m.fields.size(), 6u);
  EXPECT_EQ(m.fields[4].name, "ring");
  EXPECT_EQ(m.fields[4].datatype, kRosUint16);
  EXPECT_EQ(m.fields[5].offset, 20u);
  EXPECT_EQ(At<float>(m.data, 24 + 4), -2.0f);
  EXPECT_EQ(At<uint16_t>(m.data, 24 + 16), 17);
  EXPECT_EQ(At<float>(m.data, 24 + 20), 0.05f);
}

TEST(RosConvert, ImuCovariancesFromNoiseDensity) {
  const RosImu m = ImuToRos({0, 0, 9.81}, {0.1, 0, 0}, 0.002, 0.0001, 400, MakeRosHeader(0, "i"));
  EXPECT_EQ(m.orientation_covariance[0], -1);
  EXPECT_DOUBLE_EQ(m.linear_acceleration[2], 9.81);
  EXPECT_DOUBLE_EQ(m.angular_velocity[0], 0.1);
  EXPECT_DOUBLE_EQ(m.linear_acceleration_covariance[0], 0.002 * 0.002 * 400);
  EXPECT_DOUBLE_EQ(m.linear_acceleration_covariance[8], 0.002 * 0.002 * 400);
  EXPECT_DOUBLE_EQ(m.linear_acceleration_covariance[1], 0);
  EXPECT_DOUBLE_EQ(m.angular_velocity_covariance[4], 0.0001 * 0.0001 * 400);
}

TEST(RosConvert, OdometryTwistInBaseAxes) {
  // yawed 90 deg: moving along world +x is moving to the base's right (-y)
  const Pose X_WB = PoseFromXyzRpyDeg({1, 2, 0.3}, {0, 0, 90});
  Eigen::Matrix<double, 6, 1> V;
  V << 0, 0, 0.5, 1, 0, 0;
  const RosOdometry m = OdometryToRos(X_WB, V, "odom", "base_link", 42);
  EXPECT_EQ(m.header.frame_id, "odom");
  EXPECT_EQ(m.child_frame_id, "base_link");
  EXPECT_EQ(m.header.stamp_ns, 42);
  EXPECT_DOUBLE_EQ(m.position[1], 2);
  EXPECT_NEAR(m.orientation[2], std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(m.orientation[3], std::sqrt(0.5), 1e-12);
  EXPECT_NEAR(m.linear[0], 0, 1e-12);
  EXPECT_NEAR(m.linear[1], -1, 1e-12);
  EXPECT_NEAR(m.angular[2], 0.5, 1e-12);
}

TEST(RosConvert, TransformsOfAGraph) {
  RosGraph g;
  RosRobotGraph r;
  r.robot = "r";
  r.base_body = 1;
  r.base_frame = "base_link";
  r.odom_frame = "odom";
  g.robots.push_back(r);
  RosSensorGraph cam;
  cam.mount.name = "front";
  cam.mount.body = 2;
  cam.mount.X_BS = PoseFromXyzRpyDeg({0.1, 0, 0}, {0, 0, 0});
  cam.robot = 0;
  cam.frame_id = "front/optical";
  cam.parent_frame = "base_link";
  cam.rigid_to_parent = true;
  g.sensors.push_back(cam);
  WorldSnapshot s;
  s.time_sec = 0.5;
  s.X_WB = {Pose::Identity(), PoseFromXyzRpyDeg({1, 0, 0.3}, {0, 0, 90}),
            PoseFromXyzRpyDeg({1, 0.2, 0.3}, {0, 0, 90})};
  const std::vector<RosTransform> st = StaticTransforms(g, s);
  ASSERT_EQ(st.size(), 2u);
  EXPECT_EQ(st[0].header.frame_id, "map");
  EXPECT_EQ(st[0].child_frame_id, "odom");
  EXPECT_EQ(st[1].header.frame_id, "base_link");
  EXPECT_EQ(st[1].child_frame_id, "front/optical");
  // the camera body sits 0.2 m ahead of the base (base x = world y), the camera 0.1 m further
  EXPECT_NEAR(st[1].translation[0], 0.3, 1e-12);
  EXPECT_NEAR(st[1].translation[1], 0, 1e-12);
  const std::vector<RosTransform> dy = DynamicTransforms(g, s);
  ASSERT_EQ(dy.size(), 1u);
  EXPECT_EQ(dy[0].header.frame_id, "odom");
  EXPECT_EQ(dy[0].child_frame_id, "base_link");
  EXPECT_EQ(dy[0].header.stamp_ns, 500000000);
  EXPECT_DOUBLE_EQ(dy[0].translation[2], 0.3);
}

TEST(RosConvert, JointStatesFromQposQvel) {
  ModelInfo model;
  JointInfo j;
  j.name = "r/knee";
  j.qpos_adr = 7;
  j.dof_adr = 6;
  model.joints = {j};
  std::vector<double> qpos(8, 0.0), qvel(7, 0.0), tau(7, 0.0);
  qpos[7] = 0.4;
  qvel[6] = -1.5;
  tau[6] = 3;
  const RosJointState m = JointStateToRos(model, {0}, qpos, qvel, tau, 7);
  EXPECT_EQ(m.name, std::vector<std::string>{"r/knee"});
  EXPECT_EQ(m.position, std::vector<double>{0.4});
  EXPECT_EQ(m.velocity, std::vector<double>{-1.5});
  EXPECT_EQ(m.effort, std::vector<double>{3});
  EXPECT_TRUE(JointStateToRos(model, {0}, qpos, {}, {}, 7).velocity.empty());
}

}  // namespace
}  // namespace penumbra

#include "penumbra/ros/ros_convert.h"

#include <Eigen/Geometry>
#include <cmath>
#include <cstring>
#include <limits>

#include "penumbra/core/error.h"

namespace penumbra {

namespace {

std::array<double, 4> QuatXyzw(const Eigen::Matrix3d& R) {
  Eigen::Quaterniond q(R);
  q.normalize();
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  return {q.x(), q.y(), q.z(), q.w()};
}

template <typename T>
void Put(std::vector<uint8_t>& data, size_t offset, T v) {
  std::memcpy(data.data() + offset, &v, sizeof(T));
}

RosImage MakeRgb(int width, int height, const RosHeader& header) {
  RosImage m;
  m.header = header;
  m.width = static_cast<uint32_t>(width);
  m.height = static_cast<uint32_t>(height);
  m.encoding = "rgb8";
  m.step = m.width * 3;
  return m;
}

RosImage MakeDepth(int width, int height, const RosHeader& header) {
  RosImage m;
  m.header = header;
  m.width = static_cast<uint32_t>(width);
  m.height = static_cast<uint32_t>(height);
  m.encoding = "32FC1";
  m.step = m.width * 4;
  m.data.resize(static_cast<size_t>(m.step) * m.height);
  return m;
}

}  // namespace

int64_t RosStampNs(double time_sec) { return std::llround(time_sec * 1e9); }

RosHeader MakeRosHeader(double time_sec, const std::string& frame_id) {
  return RosHeader{RosStampNs(time_sec), frame_id};
}

RosImage RgbToRos(const ImageU8& rgb, const RosHeader& header) {
  return RgbToRos(ImageU8(rgb), header);
}

RosImage RgbToRos(ImageU8&& rgb, const RosHeader& header) {
  if (rgb.channels != 3)
    throw Error("rgb8 image with " + std::to_string(rgb.channels) + " channels; expected 3");
  RosImage m = MakeRgb(rgb.width, rgb.height, header);
  m.data = std::move(rgb.data);
  return m;
}

RosImage DepthToRos(const ImageF& depth_m, const RosHeader& header) {
  if (depth_m.channels != 1)
    throw Error("depth image with " + std::to_string(depth_m.channels) + " channels; expected 1");
  RosImage m = MakeDepth(depth_m.width, depth_m.height, header);
  const float inf = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < depth_m.data.size(); ++i) {
    const float d = depth_m.data[i] > 0 ? depth_m.data[i] : inf;
    Put(m.data, 4 * i, d);
  }
  return m;
}

RosImage DepthMmToRos(int width, int height, const std::vector<uint16_t>& mm,
                      const RosHeader& header) {
  RosImage m = MakeDepth(width, height, header);
  const float inf = std::numeric_limits<float>::infinity();
  for (size_t i = 0; i < mm.size() && i < static_cast<size_t>(width) * height; ++i) {
    const float d = mm[i] > 0 ? static_cast<float>(mm[i] * 1e-3) : inf;
    Put(m.data, 4 * i, d);
  }
  return m;
}

RosCameraInfo CameraInfoToRos(const CameraIntrinsics& k, double baseline_m,
                              const RosHeader& header) {
  RosCameraInfo m;
  m.header = header;
  m.width = static_cast<uint32_t>(k.width);
  m.height = static_cast<uint32_t>(k.height);
  m.distortion_model = "plumb_bob";
  m.D = {k.k1, k.k2, k.p1, k.p2, k.k3};
  m.K = {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1};
  m.R = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  m.P = {k.fx, 0, k.cx, -k.fx * baseline_m, 0, k.fy, k.cy, 0, 0, 0, 1, 0};
  return m;
}

RosPointCloud2 PointsToRos(const std::vector<LidarPoint>& points, const RosHeader& header) {
  RosPointCloud2 m;
  m.header = header;
  m.height = 1;
  m.width = static_cast<uint32_t>(points.size());
  m.fields = {{"x", 0, kRosFloat32, 1},    {"y", 4, kRosFloat32, 1},
              {"z", 8, kRosFloat32, 1},    {"intensity", 12, kRosFloat32, 1},
              {"ring", 16, kRosUint16, 1}, {"time", 20, kRosFloat32, 1}};
  m.point_step = 24;
  m.row_step = m.point_step * m.width;
  m.data.assign(static_cast<size_t>(m.row_step), 0);
  for (size_t i = 0; i < points.size(); ++i) {
    const LidarPoint& p = points[i];
    const size_t o = i * m.point_step;
    Put(m.data, o + 0, p.x);
    Put(m.data, o + 4, p.y);
    Put(m.data, o + 8, p.z);
    Put(m.data, o + 12, p.intensity);
    Put(m.data, o + 16, p.ring);
    Put(m.data, o + 20, p.time);
  }
  m.is_dense = 1;
  return m;
}

RosImu ImuToRos(const Eigen::Vector3d& accel_m_s2, const Eigen::Vector3d& gyro_rad_s,
                double accel_noise_density, double gyro_noise_density, double rate_hz,
                const RosHeader& header) {
  RosImu m;
  m.header = header;
  m.orientation = {0, 0, 0, 1};
  m.orientation_covariance.fill(0);
  m.orientation_covariance[0] = -1;
  m.angular_velocity = {gyro_rad_s.x(), gyro_rad_s.y(), gyro_rad_s.z()};
  m.linear_acceleration = {accel_m_s2.x(), accel_m_s2.y(), accel_m_s2.z()};
  const double rate = rate_hz > 0 ? rate_hz : 0;
  const double var_g = gyro_noise_density * gyro_noise_density * rate;
  const double var_a = accel_noise_density * accel_noise_density * rate;
  for (int i = 0; i < 3; ++i) {
    m.angular_velocity_covariance[4 * i] = var_g;
    m.linear_acceleration_covariance[4 * i] = var_a;
  }
  return m;
}

RosTransform TransformToRos(const Pose& X_PC, const std::string& parent, const std::string& child,
                            int64_t stamp_ns) {
  RosTransform t;
  t.header = RosHeader{stamp_ns, parent};
  t.child_frame_id = child;
  const Eigen::Vector3d p = X_PC.translation();
  t.translation = {p.x(), p.y(), p.z()};
  t.rotation = QuatXyzw(X_PC.rotation());
  return t;
}

RosOdometry OdometryToRos(const Pose& X_WB, const Eigen::Matrix<double, 6, 1>& V_WB,
                          const std::string& odom_frame, const std::string& base_frame,
                          int64_t stamp_ns) {
  RosOdometry m;
  m.header = RosHeader{stamp_ns, odom_frame};
  m.child_frame_id = base_frame;
  const Eigen::Vector3d p = X_WB.translation();
  m.position = {p.x(), p.y(), p.z()};
  const Eigen::Matrix3d R_WB = X_WB.rotation();
  m.orientation = QuatXyzw(R_WB);
  const Eigen::Vector3d w_B = R_WB.transpose() * V_WB.head<3>();
  const Eigen::Vector3d v_B = R_WB.transpose() * V_WB.tail<3>();
  m.angular = {w_B.x(), w_B.y(), w_B.z()};
  m.linear = {v_B.x(), v_B.y(), v_B.z()};
  return m;
}

RosJointState JointStateToRos(const ModelInfo& model, const std::vector<int>& joints,
                              const std::vector<double>& qpos, const std::vector<double>& qvel,
                              const std::vector<double>& qfrc_actuator, int64_t stamp_ns) {
  RosJointState m;
  m.header = RosHeader{stamp_ns, ""};
  for (int j : joints) {
    const JointInfo& ji = model.joints[j];
    m.name.push_back(ji.name);
    m.position.push_back(ji.qpos_adr < static_cast<int>(qpos.size()) ? qpos[ji.qpos_adr] : 0.0);
    if (!qvel.empty())
      m.velocity.push_back(ji.dof_adr < static_cast<int>(qvel.size()) ? qvel[ji.dof_adr] : 0.0);
    if (!qfrc_actuator.empty())
      m.effort.push_back(
          ji.dof_adr < static_cast<int>(qfrc_actuator.size()) ? qfrc_actuator[ji.dof_adr] : 0.0);
  }
  return m;
}

Pose SensorPoseInWorld(const RosSensorGraph& s, const WorldSnapshot& snapshot) {
  const RosSensorMount& m = s.mount;
  if (m.body < 0) {
    if (m.mjcf_camera < 0 || m.mjcf_camera >= static_cast<int>(snapshot.X_W_mjcam.size()))
      throw Error("snapshot has no pose of MJCF camera '" + m.name + "'");
    Pose X_mjcam_O = Pose::Identity();
    X_mjcam_O.linear() = RotationMujocoCameraFromOptical();
    return snapshot.X_W_mjcam[m.mjcf_camera] * X_mjcam_O;
  }
  if (m.body >= static_cast<int>(snapshot.X_WB.size()))
    throw Error("snapshot has no pose of the body of sensor '" + m.name + "'");
  return snapshot.X_WB[m.body] * m.X_BS;
}

namespace {

Pose ParentPose(const RosGraph& graph, const RosSensorGraph& s, const WorldSnapshot& snapshot) {
  if (s.robot < 0) return Pose::Identity();
  const int b = graph.robots[s.robot].base_body;
  if (b >= static_cast<int>(snapshot.X_WB.size()))
    throw Error("snapshot has no pose of the base body of robot '" + graph.robots[s.robot].robot +
                "'");
  return snapshot.X_WB[b];
}

RosTransform SensorTransform(const RosGraph& graph, const RosSensorGraph& s,
                             const WorldSnapshot& snapshot) {
  const Pose X_WP = ParentPose(graph, s, snapshot);
  const Pose X_PS = X_WP.inverse() * SensorPoseInWorld(s, snapshot);
  return TransformToRos(X_PS, s.parent_frame, s.frame_id, RosStampNs(snapshot.time_sec));
}

}  // namespace

std::vector<RosTransform> StaticTransforms(const RosGraph& graph, const WorldSnapshot& snapshot) {
  std::vector<RosTransform> out;
  const int64_t stamp = RosStampNs(snapshot.time_sec);
  for (const RosRobotGraph& r : graph.robots)
    out.push_back(TransformToRos(Pose::Identity(), graph.map_frame, r.odom_frame, stamp));
  for (const RosSensorGraph& s : graph.sensors)
    if (s.rigid_to_parent) out.push_back(SensorTransform(graph, s, snapshot));
  return out;
}

std::vector<RosTransform> DynamicTransforms(const RosGraph& graph, const WorldSnapshot& snapshot) {
  std::vector<RosTransform> out;
  const int64_t stamp = RosStampNs(snapshot.time_sec);
  for (const RosRobotGraph& r : graph.robots) {
    if (r.base_body >= static_cast<int>(snapshot.X_WB.size()))
      throw Error("snapshot has no pose of the base body of robot '" + r.robot + "'");
    out.push_back(TransformToRos(snapshot.X_WB[r.base_body], r.odom_frame, r.base_frame, stamp));
  }
  for (const RosSensorGraph& s : graph.sensors)
    if (!s.rigid_to_parent) out.push_back(SensorTransform(graph, s, snapshot));
  return out;
}

}  // namespace penumbra

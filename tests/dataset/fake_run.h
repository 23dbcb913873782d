#pragma once
// a small hand-made run folder (the files `penumbra run` writes, dataset/run_folder.h) with
// known values, for the dataset export tests: camera "cam" (and "cam/right", 0.1 m to its right)
// with rgb and depth images, an IMU "imu" with samples and true states, rig.json.

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <cstdint>
#include <filesystem>
#include <fstream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"

namespace penumbra::testing {

/// what the fake run holds.
struct FakeRunSpec {
  int frames = 4;
  double frame_dt_sec = 0.05;
  int imu_samples = 12;
  double imu_dt_sec = 0.005;
  bool depth = true;
  bool right_camera = true;
  std::string imu_rigid_body = "robot/base";  ///< the camera's is "robot/base"
  double k3 = 0;
};

/// the depth values (mm) of the fake depth image's 8 x 6 pixels: row y, column x.
inline uint16_t FakeDepthMm(int x, int y, int frame) {
  static const uint16_t special[] = {0, 1, 1234, 13107, 13108, 65535};
  if (y == 0 && x < 6) return special[x];
  return static_cast<uint16_t>(500 + 37 * x + 101 * y + 7 * frame);
}

/// X_WO of the fake camera at frame i: moving along world x, turning about world z.
inline Pose FakeCameraPose(int i) {
  Pose X = Pose::Identity();
  X.linear() = (Eigen::AngleAxisd(0.1 * i, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.3 * i, 0.02 * i, 1.0);
  return X;
}

/// the right camera: 0.1 m along the left camera's optical x.
inline Pose FakeRightPose(int i) { return FakeCameraPose(i) * Eigen::Translation3d(0.1, 0, 0); }

/// X_RS of the camera and the IMU in their rigid body.
inline Pose FakeCameraMount() {
  Pose X = Pose::Identity();
  X.linear() = Eigen::AngleAxisd(-M_PI / 2, Eigen::Vector3d::UnitX()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0.2, 0, 0.05);
  return X;
}
inline Pose FakeImuMount() {
  Pose X = Pose::Identity();
  X.linear() = Eigen::AngleAxisd(0.3, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(0, 0.01, 0.02);
  return X;
}

inline std::string PoseJson(const Pose& X) {
  const Eigen::Quaterniond q(X.linear());
  const Eigen::Vector3d& p = X.translation();
  return fmt::format(R"({{"xyz": [{}, {}, {}], "qwxyz": [{}, {}, {}, {}]}})", p.x(), p.y(), p.z(),
                     q.w(), q.x(), q.y(), q.z());
}

inline std::string PoseCsv(const Pose& X) {
  Eigen::Quaterniond q(X.linear());
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d& p = X.translation();
  return fmt::format("{},{},{},{},{},{},{}", p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z());
}

/// writes the fake run into `dir`.
inline void WriteFakeRun(const std::filesystem::path& dir, const FakeRunSpec& spec = {}) {
  namespace fs = std::filesystem;
  const std::vector<std::string> cams = spec.right_camera
                                            ? std::vector<std::string>{"cam", "cam/right"}
                                            : std::vector<std::string>{"cam"};
  std::string info = "{";
  for (size_t c = 0; c < cams.size(); ++c)
    info += fmt::format(
        R"({}"{}": {{"frame_id": "{}/optical", "width": 8, "height": 6, "distortion_model": "plumb_bob", "D": [0, 0, 0, 0, {}], "K": [10, 0, 4, 0, 11, 3, 0, 0, 1]}})",
        c ? ", " : "", cams[c], cams[c], spec.k3);
  std::ofstream(dir / "camera_info.json") << info << "}\n";
  for (size_t c = 0; c < cams.size(); ++c) {
    const fs::path folder = dir / cams[c];
    fs::create_directories(folder / "rgb");
    if (spec.depth) fs::create_directories(folder / "depth");
    std::ofstream csv(folder / "frames.csv");
    csv << "frame,time_sec,x,y,z,qw,qx,qy,qz\n";
    for (int i = 0; i < spec.frames; ++i) {
      const Pose X = c == 0 ? FakeCameraPose(i) : FakeRightPose(i);
      csv << i << "," << fmt::format("{}", i * spec.frame_dt_sec) << "," << PoseCsv(X) << "\n";
      cv::Mat rgb(6, 8, CV_8UC3);
      for (int y = 0; y < 6; ++y)
        for (int x = 0; x < 8; ++x)
          rgb.at<cv::Vec3b>(y, x) =
              cv::Vec3b(static_cast<uint8_t>(20 * x), static_cast<uint8_t>(30 * y),
                        static_cast<uint8_t>(40 * i + 10 * c));
      cv::imwrite((folder / "rgb" / fmt::format("{:06d}.png", i)).string(), rgb);
      if (spec.depth) {
        cv::Mat depth(6, 8, CV_16UC1);
        for (int y = 0; y < 6; ++y)
          for (int x = 0; x < 8; ++x) depth.at<uint16_t>(y, x) = FakeDepthMm(x, y, i);
        cv::imwrite((folder / "depth" / fmt::format("{:06d}.png", i)).string(), depth);
      }
    }
  }
  std::ofstream(dir / "rig.json") << fmt::format(
      R"({{"cameras": {{"cam": {{"body": "robot/head", "X_BS": {}, "rigid_body": "robot/base", "X_RS": {}}},
"cam/right": {{"body": "robot/head", "X_BS": {}, "rigid_body": "robot/base", "X_RS": {}}}}},
"imus": {{"imu": {{"body": "robot/base", "X_BS": {}, "rigid_body": "{}", "X_RS": {}, "rate_hz": 200,
"gyroscope_noise_density": 0.00024, "gyroscope_random_walk": 1.3e-06, "accelerometer_noise_density": 0.0017, "accelerometer_random_walk": 2.1e-05}}}},
"lidars": {{}}}})",
      PoseJson(FakeCameraMount()), PoseJson(FakeCameraMount()),
      PoseJson(FakeCameraMount() * Pose(Eigen::Translation3d(0.1, 0, 0))),
      PoseJson(FakeCameraMount() * Pose(Eigen::Translation3d(0.1, 0, 0))), PoseJson(FakeImuMount()),
      spec.imu_rigid_body, PoseJson(FakeImuMount()));
  fs::create_directories(dir / "imu");
  std::ofstream imu(dir / "imu" / "imu.csv");
  std::ofstream truth(dir / "imu" / "imu_truth.csv");
  imu << "sample,capture_time_sec,delivery_time_sec,accel_x_m_s2,accel_y_m_s2,accel_z_m_s2,"
         "gyro_x_rad_s,gyro_y_rad_s,gyro_z_rad_s\n";
  truth << "sample,capture_time_sec,x_m,y_m,z_m,qw,qx,qy,qz,vx_m_s,vy_m_s,vz_m_s,bgx_rad_s,"
           "bgy_rad_s,bgz_rad_s,bax_m_s2,bay_m_s2,baz_m_s2\n";
  for (int k = 0; k < spec.imu_samples; ++k) {
    const double t = k * spec.imu_dt_sec;
    imu << fmt::format("{},{:.9f},{:.9f},{},{},{},{},{},{}\n", k, t, t + 0.002, 0.1 * k, 0.2, 9.81,
                       0.01, -0.02 * k, 0.03);
    Pose X = Pose::Identity();
    X.linear() = Eigen::AngleAxisd(0.05 * k, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    X.translation() = Eigen::Vector3d(0.01 * k, 0, 0.3);
    truth << fmt::format("{},{:.9f},{},{},{},{},{},{},{},{},{},{}\n", k, t, PoseCsv(X), 2.0, 0.0,
                         -0.5, 1e-4 * k, 0, 0, 0, 2e-3, 0);
  }
}

}  // namespace penumbra::testing

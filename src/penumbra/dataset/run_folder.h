#pragma once
// reading the output folder of `penumbra run` (README "Outputs") for dataset export
// (dataset/dataset_export.h). the files read, as the run writes them:
//
//   camera_info.json            per camera: width, height, K (3x3 row-major), D (k1 k2 p1 p2 k3)
//                               (output/camera_info.h)
//   <camera>/frames.csv         frame,time_sec,x,y,z,qw,qx,qy,qz: X_WO, the OpenCV optical frame
//                               (x right, y down, z forward) in the REP-103 world (z up)
//   <camera>/rgb|depth/NNNNNN.png  8-bit sRGB; 16-bit z-depth in millimetres (0 = no return)
//   imu/<name>.csv              sample,capture_time_sec,delivery_time_sec,accel_{x,y,z}_m_s2,
//                               gyro_{x,y,z}_rad_s (IMU frame S)
//   imu/<name>_truth.csv        sample,capture_time_sec,X_WS,v_WS,gyro and accel biases
//                               (output/sensor_writers.h)
//   rig.json                    mounts of cameras, IMUs, LiDARs (sinks/sensor_sink.h)
//
// every error is a ConfigError naming the file, the 1-based line (0 for a whole file) and the
// column or key, and what was expected. every file is read through dataset/run_file.h: nothing
// is read through a symbolic link below the run folder, and camera and IMU names (from
// camera_info.json and rig.json) must be plain relative names (no "..", not absolute).

#include <Eigen/Core>
#include <array>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"

namespace penumbra {

/// one row of a camera's frames.csv.
struct RunFrame {
  int64_t index = 0;             ///< frame index (image file NNNNNN.png)
  double time_sec = 0;           ///< sim time of the frame
  Pose X_WO = Pose::Identity();  ///< optical frame (OpenCV) in the world
};

/// one camera of a run: calibration, frames and which images it has.
struct RunCamera {
  std::string name;
  std::filesystem::path run_dir;          ///< the run folder
  std::filesystem::path folder;           ///< <run>/<camera> ('/' in the name gives nested folders)
  int width = 0, height = 0;              ///< pixels
  double fx = 0, fy = 0, cx = 0, cy = 0;  ///< pinhole intrinsics, pixels
  std::array<double, 5> distortion{};     ///< plumb_bob k1 k2 p1 p2 k3 (OpenCV order)
  std::vector<RunFrame> frames;           ///< in file order (strictly increasing index and time)
  bool has_rgb = false;                   ///< <folder>/rgb exists
  bool has_depth = false;                 ///< <folder>/depth exists

  /// <folder>/<kind>/NNNNNN.png of frame `index` (kind "rgb" or "depth").
  std::filesystem::path ImagePath(const std::string& kind, int64_t index) const;
  /// the same path relative to run_dir (<camera>/<kind>/NNNNNN.png), for ReadRunFile.
  std::filesystem::path RelativeImagePath(const std::string& kind, int64_t index) const;
  /// frames per second over the run: (frames - 1) / (last time - first time); 0 for < 2 frames.
  double MeanRateHz() const;
};

/// where a sensor is mounted (rig.json): X_BS in its body, X_RS in the rigid body it moves with.
struct RunMount {
  std::string body;        ///< body name, "world" for the world
  std::string rigid_body;  ///< the rigid body R (B or its first ancestor with a joint, or world)
  Pose X_BS = Pose::Identity();
  Pose X_RS = Pose::Identity();
};

/// one IMU sample (imu/<name>.csv), in the IMU frame S.
struct RunImuSample {
  int64_t index = 0;
  double time_sec = 0;  ///< capture time (the physics step it was taken at)
  Eigen::Vector3d accel_m_s2{0, 0, 0};
  Eigen::Vector3d gyro_rad_s{0, 0, 0};
};

/// the true IMU state at one sample (imu/<name>_truth.csv).
struct RunImuTruth {
  int64_t index = 0;
  double time_sec = 0;
  Pose X_WS = Pose::Identity();
  Eigen::Vector3d v_WS{0, 0, 0};        ///< m/s, world axes
  Eigen::Vector3d gyro_bias{0, 0, 0};   ///< rad/s, S axes
  Eigen::Vector3d accel_bias{0, 0, 0};  ///< m/s^2, S axes
};

/// one IMU of a run.
struct RunImu {
  std::string name;
  RunMount mount;
  double rate_hz = 0;
  /// Kalibr noise parameters as the run used them (sensors/imu_model.h).
  double gyro_noise_density = 0, gyro_random_walk = 0;
  double accel_noise_density = 0, accel_random_walk = 0;
  std::vector<RunImuSample> samples;
  std::vector<RunImuTruth> truth;  ///< same samples as `samples`
};

/// a run's output folder.
class RunFolder {
 public:
  /// @throws ConfigError if `dir` is not a folder or has no camera_info.json and no rig.json
  ///         (not the output folder of `penumbra run`).
  explicit RunFolder(std::filesystem::path dir);

  const std::filesystem::path& dir() const { return dir_; }
  /// cameras listed in camera_info.json, in file order.
  std::vector<std::string> CameraNames() const;
  /// IMUs listed in rig.json, in file order.
  std::vector<std::string> ImuNames() const;

  /// reads a camera's calibration, frames.csv and which image folders exist.
  /// @throws ConfigError naming the file, line and column of the first bad value, or the
  ///         camera names the run has when `name` is not one of them; a name that is not a
  ///         plain relative path, a symbolic link on the way to its files, or a width or
  ///         height outside 1 .. 65535.
  RunCamera ReadCamera(const std::string& name) const;
  /// the camera's mount from rig.json; nullopt for a camera rig.json does not list (an MJCF
  /// camera, or a run made before rig.json existed).
  std::optional<RunMount> CameraMount(const std::string& name) const;
  /// reads an IMU's samples, true states and mount.
  /// @throws ConfigError as ReadCamera, also when the samples and true states differ in count
  ///         or time.
  RunImu ReadImu(const std::string& name) const;

 private:
  std::filesystem::path dir_;
};

/// sim time in seconds -> integer nanoseconds, rounded to nearest.
int64_t SecondsToNs(double time_sec);

}  // namespace penumbra

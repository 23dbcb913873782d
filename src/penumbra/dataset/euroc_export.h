#pragma once
// EuRoC MAV / ASL dataset layout (Burri et al., IJRR 2016, "The EuRoC micro aerial vehicle
// datasets"; ASL dataset format) of a run's camera (and optional second camera) and IMU:
//
//   OUT/mav0/cam0/data/<ns>.png     8-bit greyscale images (image_convert.h WriteGreyPng)
//   OUT/mav0/cam0/data.csv          "#timestamp [ns],filename" then "<ns>,<ns>.png"
//   OUT/mav0/cam0/sensor.yaml       sensor_type camera, T_BS (4x4 row-major), rate_hz,
//                                   resolution [w, h], camera_model pinhole, intrinsics
//                                   [fu, fv, cu, cv], distortion_model radial-tangential,
//                                   distortion_coefficients [k1, k2, p1, p2]
//   OUT/mav0/cam1/...               the same for the second camera
//   OUT/mav0/imu0/data.csv          "#timestamp [ns],w_RS_S_{x,y,z} [rad s^-1],
//                                   a_RS_S_{x,y,z} [m s^-2]": the IMU's noisy samples
//   OUT/mav0/imu0/sensor.yaml       sensor_type imu, T_BS = identity, rate_hz and the noise
//                                   parameters the run used
//   OUT/mav0/state_groundtruth_estimate0/data.csv  "#timestamp, p_RS_R_{x,y,z} [m],
//                                   q_RS_{w,x,y,z} [], v_RS_R_{x,y,z} [m s^-1],
//                                   b_w_RS_S_{x,y,z} [rad s^-1], b_a_RS_S_{x,y,z} [m s^-2]":
//                                   the IMU's true pose, velocity and biases at its samples
//   OUT/mav0/state_groundtruth_estimate0/sensor.yaml  T_BS = identity
//
// frames: the body frame B is the IMU frame S (as in EuRoC); R is Penumbra's REP-103 world; a
// camera's sensor frame is its OpenCV optical frame (x right, y down, z forward), and its T_BS
// is X_BC, the camera in the IMU frame, from the run's rig.json (both must be fixed to the
// same rigid body). timestamps: sim time in integer nanoseconds (rounded), the capture time of
// each sample.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>

#include "penumbra/dataset/run_folder.h"

namespace penumbra {

/// a camera to export with its mount.
struct EurocCamera {
  RunCamera camera;
  RunMount mount;
};

/// what ExportEuroc wrote.
struct EurocExportResult {
  int64_t frames = 0;       ///< images of cam0 (cam1 has as many or its own count)
  int64_t imu_samples = 0;  ///< rows of imu0/data.csv (and of the ground truth)
};

/// X_SC: camera mount `cam` in the frame of IMU mount `imu`.
/// @throws ConfigError naming both when they are fixed to different rigid bodies (EuRoC's T_BS
///         is constant; a camera moving relative to the IMU has none).
Pose CameraInImuFrame(const RunMount& imu, const std::string& imu_name, const RunMount& cam,
                      const std::string& cam_name);

/// the sensor.yaml text of a camera with T_BS = X_BC.
/// @throws ConfigError if the camera has a k3 distortion term (radial-tangential has 4
///         coefficients) or fewer than 2 frames (no rate).
std::string EurocCameraYaml(const RunCamera& cam, const Pose& X_BC);

/// writes cam0 (and cam1), imu0 and state_groundtruth_estimate0 under OUT/mav0 (`out`: an
/// existing, empty folder).
/// @throws ConfigError as CameraInImuFrame and EurocCameraYaml, if a camera has no rgb images
///         or an image is missing or fails the checks of dataset/image_convert.h, or if two
///         samples share a nanosecond timestamp; Error if a file cannot be written;
///         ExportStopped when `stop_request` (may be null) reads non-zero between frames.
EurocExportResult ExportEuroc(const EurocCamera& cam0, const std::optional<EurocCamera>& cam1,
                              const RunImu& imu, const std::filesystem::path& out,
                              const std::atomic<int>* stop_request = nullptr);

}  // namespace penumbra

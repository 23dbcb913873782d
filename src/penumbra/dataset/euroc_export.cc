#include "penumbra/dataset/euroc_export.h"

#include <fmt/format.h>

#include <Eigen/Geometry>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/dataset/export_stop.h"
#include "penumbra/dataset/image_convert.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

std::string MatrixYaml(const Pose& X) {
  const Eigen::Matrix4d M = X.matrix();
  std::string s = "T_BS:\n  cols: 4\n  rows: 4\n  data: [";
  for (int r = 0; r < 4; ++r) {
    if (r > 0) s += ",\n         ";
    for (int c = 0; c < 4; ++c)
      s += fmt::format("{}{}", c ? ", " : "", M(r, c) == 0 ? 0.0 : M(r, c));
  }
  return s + "]\n";
}

// nanosecond stamps, strictly increasing
void CheckIncreasing(int64_t previous, int64_t ns, const fs::path& file, int64_t index) {
  if (ns <= previous)
    throw ConfigError(file.string(), 0, "",
                      fmt::format("sample {} at {} ns is not after the one before it ({} ns); "
                                  "expected strictly increasing nanosecond timestamps",
                                  index, ns, previous));
}

int64_t WriteCamera(const RunCamera& cam, const Pose& X_BC, const fs::path& dir,
                    const std::atomic<int>* stop_request) {
  if (!cam.has_rgb)
    throw ConfigError(cam.folder.string(), 0, "",
                      "camera '" + cam.name + "' has no rgb images; expected rgb in its outputs");
  const std::string yaml = EurocCameraYaml(cam, X_BC);
  fs::create_directories(dir / "data");
  std::string csv = "#timestamp [ns],filename\n";
  int64_t previous = -1;
  for (const RunFrame& f : cam.frames) {
    CheckExportStop(stop_request);
    const int64_t ns = SecondsToNs(f.time_sec);
    CheckIncreasing(previous, ns, cam.folder / "frames.csv", f.index);
    previous = ns;
    const std::string name = fmt::format("{}.png", ns);
    WriteGreyPng(cam, f.index, dir / "data" / name);
    csv += fmt::format("{},{}\n", ns, name);
  }
  WriteFileAtomic(dir / "data.csv", csv);
  WriteFileAtomic(dir / "sensor.yaml", yaml);
  return static_cast<int64_t>(cam.frames.size());
}

}  // namespace

Pose CameraInImuFrame(const RunMount& imu, const std::string& imu_name, const RunMount& cam,
                      const std::string& cam_name) {
  if (imu.rigid_body != cam.rigid_body)
    throw ConfigError("rig.json", 0, "",
                      "camera '" + cam_name + "' moves with body '" + cam.rigid_body +
                          "' and IMU '" + imu_name + "' with body '" + imu.rigid_body +
                          "': they move relative to each other; expected both fixed to the same "
                          "rigid body (EuRoC's T_BS is constant)");
  return imu.X_RS.inverse() * cam.X_RS;
}

std::string EurocCameraYaml(const RunCamera& cam, const Pose& X_BC) {
  if (cam.distortion[4] != 0)
    throw ConfigError(cam.name, 0, "distortion.k3",
                      fmt::format("k3 = {}; EuRoC's radial-tangential model has k1, k2, p1, p2 "
                                  "only, expected k3 = 0",
                                  cam.distortion[4]));
  if (cam.frames.size() < 2)
    throw ConfigError((cam.folder / "frames.csv").string(), 0, "",
                      fmt::format("{} frame(s); expected at least 2 (sensor.yaml needs a rate)",
                                  cam.frames.size()));
  std::string s = "# General sensor definitions.\n";
  s += "sensor_type: camera\n";
  s += "comment: Penumbra camera '" + cam.name + "' (rendered)\n\n";
  s += "# Sensor extrinsics wrt. the body-frame.\n";
  s += MatrixYaml(X_BC);
  s += "\n# Camera specific definitions.\n";
  s += fmt::format("rate_hz: {:.9g}\n", cam.MeanRateHz());
  s += fmt::format("resolution: [{}, {}]\n", cam.width, cam.height);
  s += "camera_model: pinhole\n";
  s +=
      fmt::format("intrinsics: [{}, {}, {}, {}] #fu, fv, cu, cv\n", cam.fx, cam.fy, cam.cx, cam.cy);
  s += "distortion_model: radial-tangential\n";
  s += fmt::format("distortion_coefficients: [{}, {}, {}, {}]\n", cam.distortion[0] + 0.0,
                   cam.distortion[1] + 0.0, cam.distortion[2] + 0.0, cam.distortion[3] + 0.0);
  return s;
}

EurocExportResult ExportEuroc(const EurocCamera& cam0, const std::optional<EurocCamera>& cam1,
                              const RunImu& imu, const fs::path& out,
                              const std::atomic<int>* stop_request) {
  const fs::path mav = out / "mav0";
  EurocExportResult result;
  const Pose X_B0 = CameraInImuFrame(imu.mount, imu.name, cam0.mount, cam0.camera.name);
  std::optional<Pose> X_B1;
  if (cam1) X_B1 = CameraInImuFrame(imu.mount, imu.name, cam1->mount, cam1->camera.name);
  result.frames = WriteCamera(cam0.camera, X_B0, mav / "cam0", stop_request);
  if (cam1) WriteCamera(cam1->camera, *X_B1, mav / "cam1", stop_request);

  // imu0: noisy samples at their capture times; the body frame is the IMU frame
  fs::create_directories(mav / "imu0");
  fs::create_directories(mav / "state_groundtruth_estimate0");
  const fs::path imu_csv = fs::path("imu") / (imu.name + ".csv");
  std::string data =
      "#timestamp [ns],w_RS_S_x [rad s^-1],w_RS_S_y [rad s^-1],w_RS_S_z [rad s^-1],"
      "a_RS_S_x [m s^-2],a_RS_S_y [m s^-2],a_RS_S_z [m s^-2]\n";
  std::string truth =
      "#timestamp, p_RS_R_x [m], p_RS_R_y [m], p_RS_R_z [m], q_RS_w [], q_RS_x [], q_RS_y [], "
      "q_RS_z [], v_RS_R_x [m s^-1], v_RS_R_y [m s^-1], v_RS_R_z [m s^-1], "
      "b_w_RS_S_x [rad s^-1], b_w_RS_S_y [rad s^-1], b_w_RS_S_z [rad s^-1], "
      "b_a_RS_S_x [m s^-2], b_a_RS_S_y [m s^-2], b_a_RS_S_z [m s^-2]\n";
  int64_t previous = -1;
  for (size_t i = 0; i < imu.samples.size(); ++i) {
    const RunImuSample& m = imu.samples[i];
    const RunImuTruth& t = imu.truth[i];
    const int64_t ns = SecondsToNs(m.time_sec);
    CheckIncreasing(previous, ns, imu_csv, m.index);
    previous = ns;
    data += fmt::format("{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g}\n", ns, m.gyro_rad_s.x(),
                        m.gyro_rad_s.y(), m.gyro_rad_s.z(), m.accel_m_s2.x(), m.accel_m_s2.y(),
                        m.accel_m_s2.z());
    Eigen::Quaterniond q(t.X_WS.linear());
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    const Eigen::Vector3d& p = t.X_WS.translation();
    truth += fmt::format(
        "{},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},{:.9g},"
        "{:.9g},{:.9g},{:.9g},{:.9g}\n",
        ns, p.x(), p.y(), p.z(), q.w(), q.x(), q.y(), q.z(), t.v_WS.x(), t.v_WS.y(), t.v_WS.z(),
        t.gyro_bias.x(), t.gyro_bias.y(), t.gyro_bias.z(), t.accel_bias.x(), t.accel_bias.y(),
        t.accel_bias.z());
  }
  result.imu_samples = static_cast<int64_t>(imu.samples.size());
  std::string imu_yaml = "#Default imu sensor yaml file\nsensor_type: imu\n";
  imu_yaml += "comment: Penumbra IMU '" + imu.name + "' (body frame B = this IMU's frame)\n\n";
  imu_yaml += "# Sensor extrinsics wrt. the body-frame.\n" + MatrixYaml(Pose::Identity());
  imu_yaml += fmt::format("rate_hz: {:.9g}\n\n", imu.rate_hz);
  imu_yaml += "# inertial sensor noise model parameters (static)\n";
  imu_yaml += fmt::format(
      "gyroscope_noise_density: {}     # [ rad / s / sqrt(Hz) ]   ( gyro \"white noise\" )\n",
      imu.gyro_noise_density);
  imu_yaml += fmt::format(
      "gyroscope_random_walk: {}       # [ rad / s^2 / sqrt(Hz) ] ( gyro bias diffusion )\n",
      imu.gyro_random_walk);
  imu_yaml += fmt::format(
      "accelerometer_noise_density: {}  # [ m / s^2 / sqrt(Hz) ]   ( accel \"white noise\" )\n",
      imu.accel_noise_density);
  imu_yaml += fmt::format(
      "accelerometer_random_walk: {}    # [ m / s^3 / sqrt(Hz) ].  ( accel bias diffusion )\n",
      imu.accel_random_walk);
  std::string truth_yaml = "# Sensor extrinsics wrt. the body-frame.\n";
  truth_yaml += "sensor_type: visual-inertial\n";
  truth_yaml += "comment: Penumbra ground truth (exact simulator state) of IMU '" + imu.name +
                "': pose and velocity in the world R, biases of the IMU noise model\n";
  truth_yaml += MatrixYaml(Pose::Identity());
  WriteFileAtomic(mav / "imu0" / "data.csv", data);
  WriteFileAtomic(mav / "imu0" / "sensor.yaml", imu_yaml);
  WriteFileAtomic(mav / "state_groundtruth_estimate0" / "data.csv", truth);
  WriteFileAtomic(mav / "state_groundtruth_estimate0" / "sensor.yaml", truth_yaml);
  return result;
}

}  // namespace penumbra

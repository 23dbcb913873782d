#include "penumbra/dataset/kitti_export.h"

#include <fmt/format.h>

#include <Eigen/Geometry>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/dataset/export_stop.h"
#include "penumbra/dataset/image_convert.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

std::string Row12(const Eigen::Matrix<double, 3, 4>& M) {
  std::string s;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) s += fmt::format("{}{:.12e}", s.empty() ? "" : " ", M(r, c) + 0.0);
  return s;
}

Eigen::Matrix<double, 3, 4> Projection(const RunCamera& cam, const Pose& X) {
  Eigen::Matrix3d K;
  K << cam.fx, 0, cam.cx, 0, cam.fy, cam.cy, 0, 0, 1;
  return K * X.matrix().topRows<3>();
}

void CheckCamera(const RunCamera& cam) {
  for (double d : cam.distortion)
    if (d != 0)
      throw ConfigError(cam.name, 0, "distortion",
                        "camera '" + cam.name +
                            "' has lens distortion; KITTI's images are undistorted, expected a "
                            "camera without distortion");
  if (!cam.has_rgb)
    throw ConfigError(cam.folder.string(), 0, "",
                      "camera '" + cam.name + "' has no rgb images; expected rgb in its outputs");
}

void WriteImages(const RunCamera& cam, const fs::path& grey, const fs::path& colour,
                 const std::atomic<int>* stop_request) {
  fs::create_directories(grey);
  fs::create_directories(colour);
  for (size_t i = 0; i < cam.frames.size(); ++i) {
    CheckExportStop(stop_request);
    const std::string name = fmt::format("{:06d}.png", i);
    const fs::path copy = colour / name;
    WriteGreyPng(cam, cam.frames[i].index, grey / name, &copy);
  }
}

}  // namespace

Pose StereoExtrinsics(const RunCamera& cam0, const RunCamera& cam1) {
  const std::string file = (cam1.folder / "frames.csv").string();
  if (cam0.frames.size() != cam1.frames.size() || cam0.frames.empty())
    throw ConfigError(file, 0, "",
                      fmt::format("camera '{}' has {} frames and camera '{}' {}; KITTI's stereo "
                                  "pairs are synchronised, expected the same frames (same rate)",
                                  cam0.name, cam0.frames.size(), cam1.name, cam1.frames.size()));
  const Pose X_10 = cam1.frames[0].X_WO.inverse() * cam0.frames[0].X_WO;
  for (size_t i = 0; i < cam0.frames.size(); ++i) {
    if (cam0.frames[i].time_sec != cam1.frames[i].time_sec)
      throw ConfigError(
          file, 0, "time_sec",
          fmt::format("frame {} at {} s, camera '{}''s at {} s; expected "
                      "synchronised frames",
                      i, cam1.frames[i].time_sec, cam0.name, cam0.frames[i].time_sec));
    const Pose X = cam1.frames[i].X_WO.inverse() * cam0.frames[i].X_WO;
    const double dp = (X.translation() - X_10.translation()).norm();
    const double da = Eigen::AngleAxisd(X.linear() * X_10.linear().transpose()).angle();
    if (dp > 1e-6 || da > 1e-6)
      throw ConfigError(file, 0, "",
                        fmt::format("the pose of camera '{}' relative to camera '{}' changes by "
                                    "{:.3g} m, {:.3g} rad at frame {}; expected a rigid stereo "
                                    "pair",
                                    cam1.name, cam0.name, dp, da, i));
  }
  return X_10;
}

std::string KittiCalib(const RunCamera& cam0, const RunCamera* cam1, const Pose& X_10) {
  const Eigen::Matrix<double, 3, 4> P0 = Projection(cam0, Pose::Identity());
  const Eigen::Matrix<double, 3, 4> P1 = cam1 ? Projection(*cam1, X_10) : P0;
  return "P0: " + Row12(P0) + "\nP1: " + Row12(P1) + "\nP2: " + Row12(P0) + "\nP3: " + Row12(P1) +
         "\nTr: " + Row12(Pose::Identity().matrix().topRows<3>()) + "\n";
}

int64_t ExportKitti(const RunCamera& cam0, const RunCamera* cam1, const std::string& sequence,
                    const fs::path& out, const std::atomic<int>* stop_request) {
  CheckCamera(cam0);
  if (cam1) CheckCamera(*cam1);
  if (cam0.frames.empty())
    throw ConfigError((cam0.folder / "frames.csv").string(), 0, "",
                      "no frames; expected at least one");
  const Pose X_10 = cam1 ? StereoExtrinsics(cam0, *cam1) : Pose::Identity();
  const fs::path seq = out / "sequences" / sequence;
  WriteImages(cam0, seq / "image_0", seq / "image_2", stop_request);
  if (cam1) WriteImages(*cam1, seq / "image_1", seq / "image_3", stop_request);
  std::string times, poses;
  const Pose X_0W = cam0.frames[0].X_WO.inverse();
  for (const RunFrame& f : cam0.frames) {
    times += fmt::format("{:.6e}\n", f.time_sec);
    // frame 0 is the reference: exactly the identity
    const Pose T_0i = &f == &cam0.frames[0] ? Pose::Identity() : X_0W * f.X_WO;
    std::string row;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 4; ++c)
        row += fmt::format("{}{:.9e}", row.empty() ? "" : " ", T_0i.matrix()(r, c) + 0.0);
    poses += row + "\n";
  }
  WriteFileAtomic(seq / "times.txt", times);
  WriteFileAtomic(seq / "calib.txt", KittiCalib(cam0, cam1, X_10));
  fs::create_directories(out / "poses");
  WriteFileAtomic(out / "poses" / (sequence + ".txt"), poses);
  return static_cast<int64_t>(cam0.frames.size());
}

}  // namespace penumbra

#include "penumbra/dataset/tum_export.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <array>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/dataset/export_stop.h"
#include "penumbra/dataset/image_convert.h"

namespace penumbra {

namespace fs = std::filesystem;

std::string TumTimestamp(double time_sec) { return fmt::format("{:.6f}", time_sec); }

std::string TumCameraText(const RunCamera& cam, const std::string& source) {
  const std::array<double, 5>& d = cam.distortion;
  // "+ 0.0": a -0 prints as 0
  return fmt::format(
      "# camera intrinsics: {} x {} pixels; d0 .. d4 = OpenCV k1 k2 p1 p2 k3\n"
      "# file: '{}'\n"
      "# fx fy cx cy d0 d1 d2 d3 d4\n"
      "{} {} {} {} {} {} {} {} {}\n",
      cam.width, cam.height, source, cam.fx, cam.fy, cam.cx, cam.cy, d[0] + 0.0, d[1] + 0.0,
      d[2] + 0.0, d[3] + 0.0, d[4] + 0.0);
}

TumExportResult ExportTum(const RunCamera& cam, const std::string& source, const fs::path& out,
                          const std::atomic<int>* stop_request) {
  if (!cam.has_rgb || !cam.has_depth)
    throw ConfigError(
        cam.folder.string(), 0, "",
        "camera '" + cam.name + "' has no " + (cam.has_rgb ? "depth" : "rgb") +
            " images; TUM RGB-D needs both: list rgb and depth in the camera's `outputs` "
            "(or run with --outputs rgb,depth)");
  fs::create_directories(out / "rgb");
  fs::create_directories(out / "depth");
  const std::string file_line = "# file: '" + source + "'\n";
  std::string rgb = "# color images\n" + file_line + "# timestamp filename\n";
  std::string depth = "# depth maps\n" + file_line + "# timestamp filename\n";
  std::string truth =
      "# ground truth trajectory\n" + file_line + "# timestamp tx ty tz qx qy qz qw\n";
  std::string assoc;
  TumExportResult result;
  std::string previous;
  for (const RunFrame& f : cam.frames) {
    CheckExportStop(stop_request);
    const std::string t = TumTimestamp(f.time_sec);
    if (!previous.empty() && std::stod(t) <= std::stod(previous))
      throw ConfigError((cam.folder / "frames.csv").string(), 0, "time_sec",
                        fmt::format("frame {} at {} s has the TUM timestamp {} of the frame "
                                    "before it; expected frames at least 1 us apart",
                                    f.index, f.time_sec, t));
    previous = t;
    const std::string rgb_name = "rgb/" + t + ".png", depth_name = "depth/" + t + ".png";
    CopyImage(cam, "rgb", f.index, out / rgb_name);
    result.depth_beyond_range += WriteTumDepthPng(cam, f.index, out / depth_name);
    rgb += t + " " + rgb_name + "\n";
    depth += t + " " + depth_name + "\n";
    assoc += t + " " + rgb_name + " " + t + " " + depth_name + "\n";
    Eigen::Quaterniond q(f.X_WO.linear());
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    const Eigen::Vector3d& p = f.X_WO.translation();
    truth += fmt::format("{} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f} {:.9f}\n", t, p.x(), p.y(),
                         p.z(), q.x(), q.y(), q.z(), q.w());
    ++result.frames;
  }
  WriteFileAtomic(out / "rgb.txt", rgb);
  WriteFileAtomic(out / "depth.txt", depth);
  WriteFileAtomic(out / "groundtruth.txt", truth);
  WriteFileAtomic(out / "associations.txt", assoc);
  WriteFileAtomic(out / "camera.txt", TumCameraText(cam, source));
  return result;
}

}  // namespace penumbra

#include "penumbra/output/camera_info.h"

#include <fmt/format.h>

#include <array>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"

namespace penumbra {
namespace {

std::array<double, 5> D(const CameraIntrinsics& k) { return {k.k1, k.k2, k.p1, k.p2, k.k3}; }
std::array<double, 9> K(const CameraIntrinsics& k) {
  return {k.fx, 0, k.cx, 0, k.fy, k.cy, 0, 0, 1};
}
std::array<double, 9> R() { return {1, 0, 0, 0, 1, 0, 0, 0, 1}; }
std::array<double, 12> P(const CameraInfo& c) {
  const CameraIntrinsics& k = c.intrinsics;
  return {k.fx, 0, k.cx, -k.fx * c.baseline_m, 0, k.fy, k.cy, 0, 0, 0, 1, 0};
}

template <size_t N>
std::string List(const std::array<double, N>& v) {
  std::string s = "[";
  for (size_t i = 0; i < N; ++i) s += fmt::format("{}{}", i ? ", " : "", v[i] == 0 ? 0.0 : v[i]);
  return s + "]";
}

void WriteText(const std::filesystem::path& path, const std::string& text) {
  WriteFileAtomic(path, text);
}

}  // namespace

std::vector<CameraInfo> CameraInfosFor(const std::vector<CameraSpec>& cameras) {
  std::vector<CameraInfo> out;
  for (const CameraSpec& c : cameras) {
    CameraInfo info;
    info.name = c.name;
    info.intrinsics = c.intrinsics;
    const std::string suffix = "/right";
    if (c.name.size() > suffix.size() &&
        c.name.compare(c.name.size() - suffix.size(), suffix.size(), suffix) == 0) {
      const std::string left = c.name.substr(0, c.name.size() - suffix.size()) + "/left";
      for (const CameraSpec& l : cameras)
        if (l.name == left && l.body == c.body && l.mjcf_camera < 0)
          info.baseline_m = (c.X_BO.translation() - l.X_BO.translation()).norm();
    }
    out.push_back(info);
  }
  return out;
}

std::string CameraInfoYaml(const std::vector<CameraInfo>& infos) {
  std::string s =
      "# ROS sensor_msgs/CameraInfo fields per camera (penumbra output/camera_info.h)\n";
  for (const CameraInfo& c : infos) {
    const CameraIntrinsics& k = c.intrinsics;
    s += fmt::format("\"{}\":\n", c.name);
    s += fmt::format("  frame_id: \"{}/optical\"\n", c.name);
    s += fmt::format("  width: {}\n  height: {}\n", k.width, k.height);
    s += "  distortion_model: plumb_bob\n";
    s += "  D: " + List(D(k)) + "\n";
    s += "  K: " + List(K(k)) + "\n";
    s += "  R: " + List(R()) + "\n";
    s += "  P: " + List(P(c)) + "\n";
    if (c.baseline_m > 0) s += fmt::format("  baseline_m: {}\n", c.baseline_m);
  }
  return s;
}

std::string CameraInfoJson(const std::vector<CameraInfo>& infos) {
  nlohmann::ordered_json j = nlohmann::ordered_json::object();
  for (const CameraInfo& c : infos) {
    const CameraIntrinsics& k = c.intrinsics;
    nlohmann::ordered_json e;
    e["frame_id"] = c.name + "/optical";
    e["width"] = k.width;
    e["height"] = k.height;
    e["distortion_model"] = "plumb_bob";
    e["D"] = D(k);
    e["K"] = K(k);
    e["R"] = R();
    e["P"] = P(c);
    if (c.baseline_m > 0) e["baseline_m"] = c.baseline_m;
    j[c.name] = e;
  }
  return j.dump(2) + "\n";
}

void WriteCameraInfo(const std::string& output_dir, const std::vector<CameraInfo>& infos) {
  const std::filesystem::path dir(output_dir);
  WriteText(dir / "camera_info.yaml", CameraInfoYaml(infos));
  WriteText(dir / "camera_info.json", CameraInfoJson(infos));
}

}  // namespace penumbra

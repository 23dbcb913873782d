#include "penumbra/slam/rgbd_sequence.h"

#include <cmath>
#include <nlohmann/json.hpp>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/core/text_match.h"

namespace penumbra {

void PinholeIntrinsics::ValidateOrThrow() const {
  if (!(std::isfinite(fx) && fx > 0 && std::isfinite(fy) && fy > 0 && std::isfinite(cx) &&
        std::isfinite(cy)))
    throw ConfigError("", 0, "intrinsics",
                      "fx, fy, cx, cy must be finite with fx, fy > 0 (pixels)");
}

std::vector<RgbdFrameFiles> ReadTumRgbdSequence(const std::filesystem::path& folder) {
  const std::filesystem::path list = folder / "associations.txt";
  // a regular file only (core/input_file.h): a FIFO there blocked in open() for ever
  std::istringstream in(ReadInputFile(list, "association list of a TUM RGB-D folder"));
  std::vector<RgbdFrameFiles> frames;
  std::string line;
  int line_no = 0;
  while (std::getline(in, line)) {
    ++line_no;
    const size_t first = line.find_first_not_of(" \t\r");
    if (first == std::string::npos || line[first] == '#') continue;
    std::istringstream fields(line);
    std::string t_rgb, rgb, t_depth, depth, extra;
    if (!(fields >> t_rgb >> rgb >> t_depth >> depth) || (fields >> extra))
      throw ConfigError(list.string(), line_no, "",
                        "expected 4 fields 'rgb_time rgb_path depth_time depth_path'");
    const std::optional<double> t = ParseDecimal(t_rgb);
    if (!t || !ParseDecimal(t_depth))
      throw ConfigError(list.string(), line_no, "", "a timestamp is not a finite decimal number");
    if (!frames.empty() && !(*t > frames.back().time_sec))
      throw ConfigError(
          list.string(), line_no, "",
          "timestamp " + t_rgb + " does not increase; expected strictly increasing times");
    frames.push_back({*t, folder / rgb, folder / depth});
  }
  if (frames.empty()) throw ConfigError(list.string(), 0, "", "no frame; expected at least one");
  return frames;
}

PinholeIntrinsics ReadCameraInfoIntrinsics(const std::filesystem::path& camera_info_json,
                                           const std::string& camera) {
  const std::string file = camera_info_json.string();
  const std::string text = ReadInputFile(camera_info_json, "camera_info.json");
  nlohmann::json doc;
  try {
    doc = nlohmann::json::parse(text);
  } catch (const nlohmann::json::exception& e) {
    throw ConfigError(file, 0, "", std::string("not valid JSON: ") + e.what());
  }
  if (!doc.is_object() || doc.empty())
    throw ConfigError(file, 0, "", "expected an object of cameras");
  std::string name = camera;
  if (name.empty()) {
    if (doc.size() != 1) throw ConfigError(file, 0, "", "several cameras; name one (--camera)");
    name = doc.begin().key();
  }
  if (!doc.contains(name)) {
    std::string names;
    for (const auto& [k, v] : doc.items()) names += (names.empty() ? "" : ", ") + k;
    throw ConfigError(file, 0, name, "no such camera; expected one of: " + names);
  }
  const nlohmann::json& k = doc[name]["K"];
  if (!k.is_array() || k.size() != 9)
    throw ConfigError(file, 0, name + ".K", "expected 9 numbers (row-major 3x3)");
  PinholeIntrinsics in_px;
  try {
    in_px = {k[0].get<double>(), k[4].get<double>(), k[2].get<double>(), k[5].get<double>()};
  } catch (const nlohmann::json::exception&) {
    throw ConfigError(file, 0, name + ".K", "expected 9 numbers (row-major 3x3)");
  }
  in_px.ValidateOrThrow();
  return in_px;
}

}  // namespace penumbra

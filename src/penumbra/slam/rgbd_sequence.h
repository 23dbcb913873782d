#pragma once
// an RGB-D image sequence in the TUM RGB-D layout (Sturm et al., IROS 2012; the layout
// `penumbra export --format tum` writes, docs/datasets.md): associations.txt lines
// `rgb_t rgb/<t>.png depth_t depth/<t>.png` (times in s), 8-bit colour PNGs and 16-bit depth
// PNGs at 5000 units per metre (0 = no data). the images are read lazily, one frame at a time.

#include <filesystem>
#include <string>
#include <vector>

namespace penumbra {

/// one associated colour / depth pair.
struct RgbdFrameFiles {
  double time_sec = 0;  ///< the colour image's timestamp, s
  std::filesystem::path rgb, depth;
};

/// pinhole intrinsics of the (registered) colour and depth images, pixels.
struct PinholeIntrinsics {
  double fx = 0, fy = 0, cx = 0, cy = 0;
  /// @throws ConfigError (key "intrinsics") unless fx, fy > 0 and all are finite.
  void ValidateOrThrow() const;
};

/// the frames of a TUM RGB-D folder, read from its associations.txt.
/// @throws ConfigError naming the file and 1-based line of a line that is not
///         `rgb_t rgb_path depth_t depth_path`, a timestamp that does not increase, a missing
///         associations.txt or a folder with no frame.
std::vector<RgbdFrameFiles> ReadTumRgbdSequence(const std::filesystem::path& folder);

/// fx fy cx cy of camera `camera` ("" = the only one) from a run's camera_info.json
/// (output/camera_info.h: K row-major).
/// @throws ConfigError naming the file for a missing file, bad JSON or an unknown camera.
PinholeIntrinsics ReadCameraInfoIntrinsics(const std::filesystem::path& camera_info_json,
                                           const std::string& camera);

}  // namespace penumbra

#pragma once
// TUM RGB-D layout (Sturm et al., IROS 2012; the benchmark's "File Formats" page) of one camera
// of a run:
//
//   OUT/rgb/<t>.png         the camera's 8-bit RGB images, byte for byte
//   OUT/depth/<t>.png       16-bit depth, 5000 per metre (a value of 5000 = 1 m of z-depth
//                           along the optical axis), 0 = no data (image_convert.h)
//   OUT/rgb.txt, depth.txt  '#' header lines as the benchmark's, then "timestamp filename"
//   OUT/groundtruth.txt     '#' header lines, then "timestamp tx ty tz qx qy qz qw": the pose
//                           of the camera's optical centre (OpenCV optical frame: x right,
//                           y down, z forward) in the world (Penumbra's REP-103 world, z up)
//   OUT/associations.txt    "rgb_timestamp rgb/<t>.png depth_timestamp depth/<t>.png", as
//                           TUM's associate.py prints it (no header)
//   OUT/camera.txt          '#' header lines, then "fx fy cx cy d0 d1 d2 d3 d4": the camera's
//                           intrinsics as the benchmark's "File Formats" page lists those of
//                           its Kinects (pixels; d0 .. d4 = OpenCV's k1 k2 p1 p2 k3), from the
//                           run's camera_info.json; the image size is in the first header line
//
// <t> and every timestamp: the frame's sim time in seconds with 6 decimals (the benchmark
// counts from the Unix epoch; Penumbra's sim time starts at 0). colour and depth come from the
// same camera and frame, so they are registered 1:1 and associate with a time difference of 0.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <string>

#include "penumbra/dataset/run_folder.h"

namespace penumbra {

/// what ExportTum wrote.
struct TumExportResult {
  int64_t frames = 0;
  /// depth pixels with a return beyond 13.107 m, written as 0 (no data).
  int64_t depth_beyond_range = 0;
};

/// the TUM timestamp of a sim time: 6 decimals, as the benchmark prints them.
std::string TumTimestamp(double time_sec);

/// the text of camera.txt (see above); `source` as in ExportTum.
std::string TumCameraText(const RunCamera& cam, const std::string& source);

/// writes camera `cam`'s frames to `out` (an existing, empty folder) in the TUM layout.
/// `source` names the run in the lists' and camera.txt's "# file:" header line.
/// @throws ConfigError if the camera has no rgb or no depth images (naming the camera and the
///         world-file key that adds them), a frame's image is missing, or two frames share a
///         6-decimal timestamp, or an image that fails the checks of dataset/image_convert.h;
///         Error if a file cannot be written; ExportStopped when `stop_request` (may be null)
///         reads non-zero between frames.
TumExportResult ExportTum(const RunCamera& cam, const std::string& source,
                          const std::filesystem::path& out,
                          const std::atomic<int>* stop_request = nullptr);

}  // namespace penumbra

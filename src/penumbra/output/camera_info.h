#pragma once
// camera calibration records in the fields of ROS sensor_msgs/CameraInfo
// (http://docs.ros.org/en/api/sensor_msgs/html/msg/CameraInfo.html), one per camera, written as
// DIR/camera_info.yaml and DIR/camera_info.json:
//
//   <camera name>:
//     frame_id: "<camera name>/optical"     (OpenCV optical frame: x right, y down, z forward)
//     width, height
//     distortion_model: "plumb_bob"
//     D: [k1, k2, p1, p2, k3]
//     K: [fx, 0, cx, 0, fy, cy, 0, 0, 1]    (row-major 3x3)
//     R: identity                            (the images are not rectified; stereo pairs are
//                                             parallel with equal intrinsics, so rectification
//                                             is the identity)
//     P: [fx, 0, cx, Tx, 0, fy, cy, 0, 0, 0, 1, 0]  (row-major 3x4) with Tx = -fx * baseline for
//                                             the right camera of a stereo pair, else 0
//     baseline_m: stereo baseline (right camera only)

#include <string>
#include <vector>

#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// one camera's record.
struct CameraInfo {
  std::string name;
  CameraIntrinsics intrinsics;
  double baseline_m = 0;  ///< > 0 for the right camera of a stereo pair
};

/// the records of `cameras`: a camera named "<x>/right" whose "<x>/left" exists is the right
/// camera of a stereo pair, its baseline the distance between the two optical centres.
std::vector<CameraInfo> CameraInfosFor(const std::vector<CameraSpec>& cameras);

/// the YAML text of the records (keys in the order above; numbers in shortest round-trip form).
std::string CameraInfoYaml(const std::vector<CameraInfo>& infos);

/// the JSON text of the records.
std::string CameraInfoJson(const std::vector<CameraInfo>& infos);

/// writes DIR/camera_info.yaml and DIR/camera_info.json.
/// @throws Error naming the path if a file cannot be written.
void WriteCameraInfo(const std::string& output_dir, const std::vector<CameraInfo>& infos);

}  // namespace penumbra

#pragma once
// frame-to-frame RGB-D odometry over a TUM RGB-D sequence (slam/rgbd_sequence.h), the bundled
// SLAM methods of `penumbra slam METHOD DATASET OUT` (docs/benchmarks.md):
//
//   opencv_rgbd       cv::rgbd::RgbdOdometry (photometric; Steinbruecker et al., "Real-time
//                     visual odometry from dense RGB-D images", ICCV workshops 2011)
//   opencv_icp        cv::rgbd::ICPOdometry (point-to-plane ICP on depth, as KinectFusion's
//                     tracking; Newcombe et al., ISMAR 2011)
//   opencv_rgbd_icp   cv::rgbd::RgbdICPOdometry (both terms)
//   open3d_rgbd       open3d::pipelines::odometry::ComputeRGBDOdometry, hybrid term (Park et
//                     al., "Colored point cloud registration revisited", ICCV 2017); in its
//                     own executable, penumbra-slam-open3d (tools/slam_open3d.cc), so that
//                     only it loads libOpen3D; RunRgbdOdometry runs the OpenCV methods
//
// OpenCV's KinectFusion (cv::kinfu) is not offered: Debian's OpenCV 4.6 is built without
// OPENCV_ENABLE_NONFREE, and KinFu::create throws "This algorithm is patented and is excluded
// in this configuration" (method name `opencv_kinfu` reports that).
//
// frames: pose k is X_C0_Ck, the optical frame (x right, y down, z forward) of frame k in the
// optical frame of frame 0 (identity at frame 0). each frame is registered to the previous
// one: X_C0_Ck = X_C0_Ck-1 * X_Ck-1_Ck. a failed registration is a lost frame: it gets no
// pose, and the next frame is registered to it from the last pose (zero motion assumed
// across the loss), so losses show as gaps in the trajectory (eval's tracked time).

#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include "penumbra/eval/trajectory.h"
#include "penumbra/slam/rgbd_sequence.h"

namespace penumbra {

/// settings shared by the methods (SI units).
struct RgbdOdometryOptions {
  PinholeIntrinsics intrinsics;
  double min_depth_m = 0.2;        ///< depth below is ignored
  double max_depth_m = 6.0;        ///< depth above is ignored
  double max_depth_diff_m = 0.07;  ///< OpenCV: largest depth change of a correspondence
  /// called after each frame with (frames done, frames in all); may be empty.
  std::function<void(int64_t, int64_t)> progress;
  /// @throws ConfigError naming the key for bad intrinsics or depth limits.
  void ValidateOrThrow() const;
};

/// what a method produced.
struct RgbdOdometryResult {
  Trajectory trajectory;  ///< one pose per tracked frame, X_C0_Ck, at the colour timestamps
  int64_t frames = 0;     ///< frames in the sequence
  int64_t lost = 0;       ///< frames whose registration failed
};

/// the method names above, in that order (open3d_rgbd included).
const std::vector<std::string>& RgbdOdometryMethodNames();

/// runs `method` over `frames`.
/// @throws ConfigError for an unknown method (listing the names), open3d_rgbd (pointing to
///         penumbra-slam-open3d), opencv_kinfu (naming the OpenCV build gap), or an image that
///         cannot be read or has another size than the first (naming the file); Error for a failure
///         inside the library.
RgbdOdometryResult RunRgbdOdometry(const std::string& method,
                                   const std::vector<RgbdFrameFiles>& frames,
                                   const RgbdOdometryOptions& options);

}  // namespace penumbra

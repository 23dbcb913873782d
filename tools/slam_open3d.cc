// `penumbra-slam-open3d`: the open3d_rgbd method of `penumbra slam` (slam/rgbd_odometry.h),
// Open3D's RGB-D odometry (open3d::pipelines::odometry::ComputeRGBDOdometry, hybrid term;
// Park et al., "Colored point cloud registration revisited", ICCV 2017). a separate
// executable so that only it loads libOpen3D (VTK, filament, GL: ~0.3 s at every start);
// `penumbra slam open3d_rgbd ...` runs it from the folder of the `penumbra` binary.
//
//   penumbra-slam-open3d DATASET OUT FX FY CX CY MIN_DEPTH_M MAX_DEPTH_M
//
// exit codes: 0 written, 2 bad input, 3 no frame tracked after the first, 1 other failures.
#include <open3d/camera/PinholeCameraIntrinsic.h>
#include <open3d/geometry/Image.h>
#include <open3d/geometry/RGBDImage.h>
#include <open3d/pipelines/odometry/Odometry.h>

#include <cmath>
#include <cstring>
#include <fstream>
#include <iostream>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "penumbra/core/error.h"
#include "penumbra/core/image_file_limits.h"
#include "penumbra/core/text_match.h"
#include "penumbra/slam/rgbd_odometry.h"

namespace penumbra {
namespace {

open3d::geometry::Image ToOpen3d(const cv::Mat& m, int channels, int bytes_per_channel) {
  open3d::geometry::Image img;
  img.Prepare(m.cols, m.rows, channels, bytes_per_channel);
  const size_t row = size_t(m.cols) * channels * bytes_per_channel;
  for (int r = 0; r < m.rows; ++r) std::memcpy(img.data_.data() + r * row, m.ptr(r), row);
  return img;
}

std::shared_ptr<open3d::geometry::RGBDImage> ReadFrame(const RgbdFrameFiles& f,
                                                       const RgbdOdometryOptions& options,
                                                       cv::Size& size) {
  CheckImageFileSize(f.rgb);  // declared sizes against the caps before decoding
  cv::Mat bgr = cv::imread(f.rgb.string(), cv::IMREAD_COLOR);
  if (bgr.empty())
    throw ConfigError(f.rgb.string(), 0, "", "cannot read the colour image; expected an 8-bit PNG");
  CheckImageFileSize(f.depth);
  const cv::Mat depth = cv::imread(f.depth.string(), cv::IMREAD_ANYDEPTH);
  if (depth.empty() || depth.type() != CV_16U)
    throw ConfigError(f.depth.string(), 0, "",
                      "cannot read the depth image; expected a 16-bit PNG (5000 per metre)");
  if (bgr.size() != depth.size() || (size.area() > 0 && bgr.size() != size))
    throw ConfigError(f.rgb.string(), 0, "",
                      "image size differs from the depth image's or the first frame's");
  size = bgr.size();
  cv::Mat rgb;
  cv::cvtColor(bgr, rgb, cv::COLOR_BGR2RGB);
  return open3d::geometry::RGBDImage::CreateFromColorAndDepth(
      ToOpen3d(rgb, 3, 1), ToOpen3d(depth, 1, 2), 5000.0, options.max_depth_m, true);
}

RgbdOdometryResult RunOpen3dRgbdOdometry(const std::vector<RgbdFrameFiles>& frames,
                                         const RgbdOdometryOptions& options) {
  options.ValidateOrThrow();
  RgbdOdometryResult result;
  result.frames = static_cast<int64_t>(frames.size());
  open3d::pipelines::odometry::OdometryOption option({20, 10, 5}, options.max_depth_diff_m,
                                                     options.min_depth_m, options.max_depth_m);
  cv::Size size;
  std::shared_ptr<open3d::geometry::RGBDImage> prev;
  open3d::camera::PinholeCameraIntrinsic intrinsic;
  Pose X_C0_prev = Pose::Identity();
  for (size_t i = 0; i < frames.size(); ++i) {
    std::shared_ptr<open3d::geometry::RGBDImage> cur = ReadFrame(frames[i], options, size);
    if (i == 0)
      intrinsic = open3d::camera::PinholeCameraIntrinsic(
          size.width, size.height, options.intrinsics.fx, options.intrinsics.fy,
          options.intrinsics.cx, options.intrinsics.cy);
    bool tracked = true;
    if (i > 0) {
      // source = current, target = previous: T maps current-frame points into the previous
      // frame, T = X_prev_cur
      const auto [ok, T, info] = open3d::pipelines::odometry::ComputeRGBDOdometry(
          *cur, *prev, intrinsic, Eigen::Matrix4d::Identity(),
          open3d::pipelines::odometry::RGBDOdometryJacobianFromHybridTerm(), option);
      tracked = ok && T.allFinite();
      if (tracked) {
        Pose X_prev_cur = Pose::Identity();
        X_prev_cur.matrix() = T;
        X_C0_prev = X_C0_prev * X_prev_cur;
      }
    }
    if (tracked) {
      result.trajectory.time_sec.push_back(frames[i].time_sec);
      result.trajectory.X_WB.push_back(X_C0_prev);
    } else {
      ++result.lost;
    }
    prev = std::move(cur);
    if (options.progress) options.progress(static_cast<int64_t>(i + 1), result.frames);
  }
  return result;
}

}  // namespace
}  // namespace penumbra

int main(int argc, char** argv) {
  using namespace penumbra;
  if (argc != 9) {
    std::cerr << "usage: penumbra-slam-open3d DATASET OUT FX FY CX CY MIN_DEPTH_M MAX_DEPTH_M\n";
    return 2;
  }
  try {
    double v[6];
    for (int i = 0; i < 6; ++i) {
      const std::optional<double> d = ParseDecimal(argv[3 + i]);
      if (!d)
        throw ConfigError("", 0, "argument " + std::to_string(3 + i), "expected a decimal number");
      v[i] = *d;
    }
    RgbdOdometryOptions options;
    options.intrinsics = {v[0], v[1], v[2], v[3]};
    options.min_depth_m = v[4];
    options.max_depth_m = v[5];
    const RgbdOdometryResult r = RunOpen3dRgbdOdometry(ReadTumRgbdSequence(argv[1]), options);
    if (r.trajectory.size() < 2) {
      std::cerr << "open3d_rgbd tracked no frame after the first (" << r.frames << " frames, "
                << r.lost << " lost); no trajectory written\n";
      return 3;
    }
    std::ofstream out(argv[2], std::ios::binary | std::ios::trunc);
    out << FormatTumTrajectory(r.trajectory);
    if (!out.flush()) throw Error(std::string("cannot write ") + argv[2]);
    std::cerr << "open3d_rgbd over " << r.frames << " frames: " << r.trajectory.size()
              << " tracked, " << r.lost << " lost -> " << argv[2] << "\n";
    return 0;
  } catch (const ConfigError& e) {
    std::cerr << "penumbra-slam-open3d: " << e.what() << "\n";
    return 2;
  } catch (const std::exception& e) {
    std::cerr << "penumbra-slam-open3d: " << e.what() << "\n";
    return 1;
  }
}

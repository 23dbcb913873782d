#include "penumbra/slam/rgbd_odometry.h"

#include <cmath>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>
#include <opencv2/rgbd/depth.hpp>

#include "penumbra/core/error.h"
#include "penumbra/core/image_file_limits.h"

namespace penumbra {
namespace {

struct CvFrame {
  cv::Mat gray;   // CV_8U
  cv::Mat depth;  // CV_32F, m (0 = none)
};

CvFrame ReadFrame(const RgbdFrameFiles& f, cv::Size expected) {
  CvFrame out;
  CheckImageFileSize(f.rgb);  // declared sizes against the caps before decoding
  const cv::Mat rgb = cv::imread(f.rgb.string(), cv::IMREAD_COLOR);
  if (rgb.empty())
    throw ConfigError(f.rgb.string(), 0, "", "cannot read the colour image; expected an 8-bit PNG");
  CheckImageFileSize(f.depth);
  const cv::Mat depth = cv::imread(f.depth.string(), cv::IMREAD_ANYDEPTH);
  if (depth.empty() || depth.type() != CV_16U)
    throw ConfigError(f.depth.string(), 0, "",
                      "cannot read the depth image; expected a 16-bit PNG (5000 per metre)");
  if (rgb.size() != depth.size() || (expected.area() > 0 && rgb.size() != expected))
    throw ConfigError(f.rgb.string(), 0, "",
                      "image size differs from the depth image's or the first frame's");
  cv::cvtColor(rgb, out.gray, cv::COLOR_BGR2GRAY);
  depth.convertTo(out.depth, CV_32F, 1.0 / 5000.0);
  return out;
}

Pose PoseFromRt(const cv::Mat& rt) {
  Pose p = Pose::Identity();
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 4; ++c) p.matrix()(r, c) = rt.at<double>(r, c);
  return p;
}

}  // namespace

void RgbdOdometryOptions::ValidateOrThrow() const {
  intrinsics.ValidateOrThrow();
  if (!(std::isfinite(min_depth_m) && min_depth_m >= 0))
    throw ConfigError("", 0, "min_depth_m", "expected a finite number >= 0 (m)");
  if (!(std::isfinite(max_depth_m) && max_depth_m > min_depth_m))
    throw ConfigError("", 0, "max_depth_m", "expected a finite number > min_depth_m (m)");
  if (!(std::isfinite(max_depth_diff_m) && max_depth_diff_m > 0))
    throw ConfigError("", 0, "max_depth_diff_m", "expected a finite number > 0 (m)");
}

const std::vector<std::string>& RgbdOdometryMethodNames() {
  static const std::vector<std::string> kNames = {"opencv_rgbd", "opencv_icp", "opencv_rgbd_icp",
                                                  "open3d_rgbd"};
  return kNames;
}

RgbdOdometryResult RunRgbdOdometry(const std::string& method,
                                   const std::vector<RgbdFrameFiles>& frames,
                                   const RgbdOdometryOptions& options) {
  options.ValidateOrThrow();
  if (method == "open3d_rgbd")
    throw ConfigError("", 0, "method",
                      "open3d_rgbd runs in its own executable, penumbra-slam-open3d "
                      "(`penumbra slam open3d_rgbd` starts it)");
  if (method == "opencv_kinfu")
    throw ConfigError("", 0, "method",
                      "opencv_kinfu is not available: Debian's OpenCV 4.6 is built without "
                      "OPENCV_ENABLE_NONFREE, so cv::kinfu::KinFu::create refuses to run; "
                      "expected one of: opencv_rgbd, opencv_icp, opencv_rgbd_icp, open3d_rgbd");
  const PinholeIntrinsics& k = options.intrinsics;
  const cv::Mat camera = (cv::Mat_<float>(3, 3) << float(k.fx), 0.f, float(k.cx), 0.f, float(k.fy),
                          float(k.cy), 0.f, 0.f, 1.f);
  const float min_d = float(options.min_depth_m), max_d = float(options.max_depth_m),
              max_diff = float(options.max_depth_diff_m);
  cv::Ptr<cv::rgbd::Odometry> odometry;
  if (method == "opencv_rgbd")
    odometry = cv::rgbd::RgbdOdometry::create(camera, min_d, max_d, max_diff);
  else if (method == "opencv_icp")
    odometry = cv::rgbd::ICPOdometry::create(camera, min_d, max_d, max_diff);
  else if (method == "opencv_rgbd_icp")
    odometry = cv::rgbd::RgbdICPOdometry::create(camera, min_d, max_d, max_diff);
  else {
    std::string names;
    for (const std::string& n : RgbdOdometryMethodNames()) names += (names.empty() ? "" : ", ") + n;
    throw ConfigError("", 0, "method",
                      "unknown method '" + method + "'; expected one of: " + names);
  }

  RgbdOdometryResult result;
  result.frames = static_cast<int64_t>(frames.size());
  Pose X_C0_prev = Pose::Identity();
  CvFrame prev;
  cv::Size size;
  for (size_t i = 0; i < frames.size(); ++i) {
    CvFrame cur = ReadFrame(frames[i], size);
    size = cur.gray.size();
    bool tracked = true;
    if (i > 0) {
      cv::Mat rt;
      try {
        // src = current, dst = previous: Rt = X_prev_cur (dst_p = Rt src_p)
        tracked =
            odometry->compute(cur.gray, cur.depth, cv::Mat(), prev.gray, prev.depth, cv::Mat(), rt);
      } catch (const cv::Exception&) {
        tracked = false;  // too few valid pixels etc.: a lost frame
      }
      if (tracked && !rt.empty() && cv::checkRange(rt))
        X_C0_prev = X_C0_prev * PoseFromRt(rt);
      else
        tracked = false;
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

}  // namespace penumbra

// the PNG figure: decodes at the requested size, draws the trajectories in the left panel and
// the error in the right one, is deterministic and rejects bad input.
#include "penumbra/eval/trajectory_plot.h"

#include <gtest/gtest.h>

#include <cmath>
#include <opencv2/imgcodecs.hpp>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

TrajectoryPlot Example() {
  TrajectoryPlot p;
  p.title = "ATE: est.txt vs ground truth gt.txt (se3 alignment)";
  const int n = 100;
  p.ground_truth_m.resize(3, n);
  p.estimate_m.resize(3, n);
  for (int k = 0; k < n; ++k) {
    const double a = 0.06 * k;
    p.ground_truth_m.col(k) = Eigen::Vector3d(3 * std::cos(a), 2 * std::sin(a), 0);
    p.estimate_m.col(k) = Eigen::Vector3d(3.1 * std::cos(a), 2.2 * std::sin(a), 0.1);
    p.ground_truth_time_sec.push_back(0.1 * k);
    p.estimate_time_sec.push_back(0.1 * k);
    p.error_time_sec.push_back(0.1 * k);
    p.error.push_back((p.ground_truth_m.col(k) - p.estimate_m.col(k)).norm());
  }
  p.error_label = "ATE (m)";
  p.error_rmse = 0.15;
  p.max_gap_sec = 0.3;
  return p;
}

// pixels of exactly `bgr` in columns [x0, x1)
int CountColour(const cv::Mat& img, int x0, int x1, cv::Vec3b bgr) {
  int n = 0;
  for (int y = 0; y < img.rows; ++y)
    for (int x = x0; x < x1; ++x) n += img.at<cv::Vec3b>(y, x) == bgr;
  return n;
}

TEST(TrajectoryPlot, DrawsBothPanelsAtTheRequestedSize) {
  const TrajectoryPlot p = Example();
  const std::vector<uint8_t> png = RenderTrajectoryPlotPng(p);
  ASSERT_GT(png.size(), 8u);
  EXPECT_EQ(std::string(png.begin() + 1, png.begin() + 4), "PNG");
  const cv::Mat img = cv::imdecode(png, cv::IMREAD_COLOR);
  ASSERT_EQ(img.cols, 1280);
  ASSERT_EQ(img.rows, 640);
  const cv::Vec3b estimate(200, 110, 20), error(40, 40, 210), ground_truth(70, 70, 70);
  // the estimate and ground truth lines (2 px wide) only in the left panel, the error only in
  // the right one
  EXPECT_GT(CountColour(img, 0, 640, estimate), 500);
  EXPECT_GT(CountColour(img, 0, 640, ground_truth), 500);
  EXPECT_EQ(CountColour(img, 640, 1280, estimate), 0);
  EXPECT_GT(CountColour(img, 640, 1280, error), 200);
  EXPECT_EQ(CountColour(img, 0, 640, error), 0);
  // deterministic
  EXPECT_EQ(RenderTrajectoryPlotPng(p), png);
}

TEST(TrajectoryPlot, AGapBreaksTheLine) {
  // two runs of the estimate 5 s and 4 m apart: without the break a long straight segment
  // joins them
  TrajectoryPlot p = Example();
  for (int k = 50; k < 100; ++k) {
    p.estimate_time_sec[static_cast<size_t>(k)] += 5.0;
    p.estimate_m(1, k) -= 4.0;
  }
  const cv::Vec3b estimate(200, 110, 20);
  const cv::Mat broken = cv::imdecode(RenderTrajectoryPlotPng(p), cv::IMREAD_COLOR);
  p.max_gap_sec = 0;  // never break
  const cv::Mat joined = cv::imdecode(RenderTrajectoryPlotPng(p), cv::IMREAD_COLOR);
  EXPECT_LT(CountColour(broken, 0, 640, estimate) + 100, CountColour(joined, 0, 640, estimate));
}

TEST(TrajectoryPlot, RejectsBadInput) {
  TrajectoryPlot p = Example();
  p.width = 100;
  EXPECT_THROW(RenderTrajectoryPlotPng(p), Error);
  p = Example();
  p.error.pop_back();
  EXPECT_THROW(RenderTrajectoryPlotPng(p), Error);
  p = Example();
  p.estimate_m(0, 3) = std::nan("");
  EXPECT_THROW(RenderTrajectoryPlotPng(p), Error);
  // empty series are drawn as empty panels
  p = TrajectoryPlot{};
  EXPECT_FALSE(RenderTrajectoryPlotPng(p).empty());
}

}  // namespace
}  // namespace penumbra

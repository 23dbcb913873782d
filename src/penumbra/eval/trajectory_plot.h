#pragma once
// a PNG figure of a trajectory evaluation: on the left the top view (x-y plane of the
// ground truth's world frame, equal scale on both axes, metres) of the ground truth and the
// aligned estimate, each drawn as a line broken where consecutive poses are more than the
// gap limit apart in time, with a circle at each start; on the right an error over time
// (seconds) with its RMSE as a dashed line. axes carry ticks at 1, 2 or 5 x 10^k and labels
// with units. drawn with OpenCV (Hershey fonts, anti-aliased); the same input gives the same
// bytes.

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace penumbra {

/// the content of the figure.
struct TrajectoryPlot {
  std::string title;                          ///< top line, e.g. the files and the alignment
  Eigen::Matrix3Xd ground_truth_m;            ///< ground-truth positions in W (m), x and y drawn
  std::vector<double> ground_truth_time_sec;  ///< one per column of ground_truth_m
  Eigen::Matrix3Xd estimate_m;                ///< aligned estimated positions in W (m)
  std::vector<double> estimate_time_sec;      ///< one per column of estimate_m
  std::string estimate_label = "estimate";    ///< legend entry of the estimate
  /// lines are broken between consecutive poses (and error samples) further apart than
  /// this, s; <= 0 never breaks them
  double max_gap_sec = 0;
  std::vector<double> error_time_sec;  ///< s
  std::vector<double> error;           ///< one per error_time_sec, in the unit of error_label
  std::string error_label = "error";   ///< y axis label with unit, e.g. "ATE (m)"
  std::string error_unit = "m";        ///< unit of the RMSE in the legend
  std::optional<double> error_rmse;    ///< drawn as a dashed horizontal line when set
  int width = 1280, height = 640;      ///< image size, px (each >= 320)
};

/// the figure, PNG-encoded (8-bit RGB).
/// @throws Error if a size is below 320 px, a time sequence's length differs from its
///         positions / errors, or a value is not finite.
std::vector<uint8_t> RenderTrajectoryPlotPng(const TrajectoryPlot& plot);

}  // namespace penumbra

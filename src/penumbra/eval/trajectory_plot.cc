#include "penumbra/eval/trajectory_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// colours (BGR)
const cv::Scalar kWhite(255, 255, 255);
const cv::Scalar kBlack(0, 0, 0);
const cv::Scalar kGrid(225, 225, 225);
const cv::Scalar kGroundTruth(70, 70, 70);
const cv::Scalar kEstimate(200, 110, 20);  // blue
const cv::Scalar kError(40, 40, 210);      // red
const cv::Scalar kRmse(40, 140, 40);       // green

constexpr int kFont = cv::FONT_HERSHEY_SIMPLEX;
constexpr double kTickFontScale = 0.5;
constexpr double kLabelFontScale = 0.6;
constexpr double kTitleFontScale = 0.65;
constexpr int kShift = 4;  // sub-pixel bits of line end points
constexpr double kSubPixel = 1 << kShift;

// a data rectangle mapped onto a pixel rectangle (y up)
struct Axes {
  cv::Rect area;
  double x0 = 0, x1 = 1, y0 = 0, y1 = 1;

  cv::Point2d ToPixel(double x, double y) const {
    return {area.x + (x - x0) / (x1 - x0) * area.width,
            area.y + area.height - (y - y0) / (y1 - y0) * area.height};
  }
};

cv::Point SubPixel(const cv::Point2d& p) {
  return {static_cast<int>(std::lround(p.x * kSubPixel)),
          static_cast<int>(std::lround(p.y * kSubPixel))};
}

void Line(cv::Mat& img, const cv::Point2d& a, const cv::Point2d& b, const cv::Scalar& colour,
          int thickness = 1) {
  cv::line(img, SubPixel(a), SubPixel(b), colour, thickness, cv::LINE_AA, kShift);
}

void Text(cv::Mat& img, const std::string& text, cv::Point origin, double scale,
          const cv::Scalar& colour = kBlack) {
  cv::putText(img, text, origin, kFont, scale, colour, 1, cv::LINE_AA);
}

cv::Size TextSize(const std::string& text, double scale) {
  int baseline = 0;
  return cv::getTextSize(text, kFont, scale, 1, &baseline);
}

// a tick step of 1, 2 or 5 x 10^k giving about `target` intervals over `range`
double NiceStep(double range, int target) {
  const double raw = range / target;
  const double p = std::pow(10.0, std::floor(std::log10(raw)));
  const double m = raw / p;
  return (m < 1.5 ? 1 : m < 3.5 ? 2 : m < 7.5 ? 5 : 10) * p;
}

std::string TickLabel(double v, double step) {
  const int decimals = std::max(0, static_cast<int>(-std::floor(std::log10(step) + 1e-9)));
  if (std::abs(v) < step * 1e-6) v = 0;  // no "-0"
  return fmt::format("{:.{}f}", v, decimals);
}

// frame, grid, ticks with labels, axis labels
void DrawAxes(cv::Mat& img, const Axes& ax, const std::string& x_label,
              const std::string& y_label) {
  const double x_step = NiceStep(ax.x1 - ax.x0, 6);
  const double y_step = NiceStep(ax.y1 - ax.y0, 6);
  const int bottom = ax.area.y + ax.area.height;
  for (double x = std::ceil(ax.x0 / x_step) * x_step; x <= ax.x1 + 1e-9 * x_step; x += x_step) {
    const cv::Point2d p = ax.ToPixel(x, ax.y0);
    Line(img, {p.x, static_cast<double>(ax.area.y)}, {p.x, static_cast<double>(bottom)}, kGrid);
    Line(img, {p.x, static_cast<double>(bottom)}, {p.x, bottom + 5.0}, kBlack);
    const std::string label = TickLabel(x, x_step);
    const cv::Size s = TextSize(label, kTickFontScale);
    Text(img, label, {static_cast<int>(std::lround(p.x)) - s.width / 2, bottom + 8 + s.height},
         kTickFontScale);
  }
  for (double y = std::ceil(ax.y0 / y_step) * y_step; y <= ax.y1 + 1e-9 * y_step; y += y_step) {
    const cv::Point2d p = ax.ToPixel(ax.x0, y);
    Line(img, {static_cast<double>(ax.area.x), p.y},
         {static_cast<double>(ax.area.x + ax.area.width), p.y}, kGrid);
    Line(img, {ax.area.x - 5.0, p.y}, {static_cast<double>(ax.area.x), p.y}, kBlack);
    const std::string label = TickLabel(y, y_step);
    const cv::Size s = TextSize(label, kTickFontScale);
    Text(img, label, {ax.area.x - 8 - s.width, static_cast<int>(std::lround(p.y)) + s.height / 2},
         kTickFontScale);
  }
  cv::rectangle(img, ax.area, kBlack, 1);
  const cv::Size xs = TextSize(x_label, kLabelFontScale);
  Text(img, x_label, {ax.area.x + (ax.area.width - xs.width) / 2, bottom + 28 + xs.height},
       kLabelFontScale);
  Text(img, y_label, {ax.area.x - 8, ax.area.y - 10}, kLabelFontScale);
}

// a polyline through the samples, broken where consecutive times are more than max_gap apart;
// an isolated sample is a dot
void DrawSeries(cv::Mat& img, const Axes& ax, const std::vector<double>& t,
                const std::vector<double>& x, const std::vector<double>& y, double max_gap,
                const cv::Scalar& colour) {
  const auto broken = [&](size_t k) { return max_gap > 0 && t[k] - t[k - 1] > max_gap; };
  for (size_t k = 0; k < t.size(); ++k) {
    const cv::Point2d p = ax.ToPixel(x[k], y[k]);
    const bool joined_before = k > 0 && !broken(k);
    const bool joined_after = k + 1 < t.size() && !broken(k + 1);
    if (joined_before) Line(img, ax.ToPixel(x[k - 1], y[k - 1]), p, colour, 2);
    if (!joined_before && !joined_after)
      cv::circle(img, SubPixel(p), 2 << kShift, colour, cv::FILLED, cv::LINE_AA, kShift);
  }
}

// the smallest [lo, hi] holding every value; widened to at least `min_span`
std::pair<double, double> Span(const std::vector<double>& a, const std::vector<double>& b,
                               double min_span) {
  double lo = INFINITY, hi = -INFINITY;
  for (double v : a) lo = std::min(lo, v), hi = std::max(hi, v);
  for (double v : b) lo = std::min(lo, v), hi = std::max(hi, v);
  if (!(lo <= hi)) lo = 0, hi = 1;
  if (hi - lo < min_span) {
    const double c = 0.5 * (lo + hi);
    lo = c - 0.5 * min_span;
    hi = c + 0.5 * min_span;
  }
  return {lo, hi};
}

std::vector<double> Row(const Eigen::Matrix3Xd& m, int row) {
  std::vector<double> v(static_cast<size_t>(m.cols()));
  for (Eigen::Index k = 0; k < m.cols(); ++k) v[static_cast<size_t>(k)] = m(row, k);
  return v;
}

void LegendEntry(cv::Mat& img, cv::Point at, const cv::Scalar& colour, const std::string& text) {
  Line(img, {at.x + 0.0, at.y - 4.0}, {at.x + 28.0, at.y - 4.0}, colour, 2);
  Text(img, text, {at.x + 36, at.y}, kTickFontScale);
}

void Check(bool ok, const std::string& what) {
  if (!ok) throw Error("RenderTrajectoryPlotPng: " + what);
}

}  // namespace

std::vector<uint8_t> RenderTrajectoryPlotPng(const TrajectoryPlot& plot) {
  Check(plot.width >= 320 && plot.height >= 320,
        fmt::format("image {} x {} px; expected at least 320 x 320", plot.width, plot.height));
  Check(static_cast<size_t>(plot.ground_truth_m.cols()) == plot.ground_truth_time_sec.size(),
        "ground-truth positions and times differ in number; expected one time per position");
  Check(static_cast<size_t>(plot.estimate_m.cols()) == plot.estimate_time_sec.size(),
        "estimated positions and times differ in number; expected one time per position");
  Check(plot.error.size() == plot.error_time_sec.size(),
        "errors and their times differ in number; expected one time per error");
  const auto finite = [](const std::vector<double>& v) {
    return std::all_of(v.begin(), v.end(), [](double x) { return std::isfinite(x); });
  };
  Check(plot.ground_truth_m.allFinite() && plot.estimate_m.allFinite() &&
            finite(plot.ground_truth_time_sec) && finite(plot.estimate_time_sec) &&
            finite(plot.error_time_sec) && finite(plot.error),
        "a value is not finite; expected finite positions, times and errors");

  cv::Mat img(plot.height, plot.width, CV_8UC3, kWhite);
  const int half = plot.width / 2;
  constexpr int kLeft = 80, kRight = 30, kTop = 70, kBottom = 84;

  // title
  const cv::Size ts = TextSize(plot.title, kTitleFontScale);
  Text(img, plot.title, {std::max(10, (plot.width - ts.width) / 2), 12 + ts.height},
       kTitleFontScale);

  // top view, equal scale: the shorter data span is widened to the panel's aspect
  Axes top;
  top.area = cv::Rect(kLeft, kTop, half - kLeft - kRight, plot.height - kTop - kBottom);
  const std::vector<double> gx = Row(plot.ground_truth_m, 0), gy = Row(plot.ground_truth_m, 1);
  const std::vector<double> ex = Row(plot.estimate_m, 0), ey = Row(plot.estimate_m, 1);
  auto [x0, x1] = Span(gx, ex, 1e-3);
  auto [y0, y1] = Span(gy, ey, 1e-3);
  const double pad = 0.05 * std::max(x1 - x0, y1 - y0);
  x0 -= pad, x1 += pad, y0 -= pad, y1 += pad;
  const double m_per_px = std::max((x1 - x0) / top.area.width, (y1 - y0) / top.area.height);
  const double cx = 0.5 * (x0 + x1), cy = 0.5 * (y0 + y1);
  top.x0 = cx - 0.5 * m_per_px * top.area.width;
  top.x1 = cx + 0.5 * m_per_px * top.area.width;
  top.y0 = cy - 0.5 * m_per_px * top.area.height;
  top.y1 = cy + 0.5 * m_per_px * top.area.height;
  DrawAxes(img, top, "x (m)", "y (m)");
  DrawSeries(img, top, plot.ground_truth_time_sec, gx, gy, plot.max_gap_sec, kGroundTruth);
  DrawSeries(img, top, plot.estimate_time_sec, ex, ey, plot.max_gap_sec, kEstimate);
  if (!gx.empty())
    cv::circle(img, SubPixel(top.ToPixel(gx[0], gy[0])), 5 << kShift, kGroundTruth, 1, cv::LINE_AA,
               kShift);
  if (!ex.empty())
    cv::circle(img, SubPixel(top.ToPixel(ex[0], ey[0])), 5 << kShift, kEstimate, 1, cv::LINE_AA,
               kShift);
  const int legend_y = top.area.y + top.area.height + 70;
  LegendEntry(img, {top.area.x, legend_y}, kGroundTruth, "ground truth");
  LegendEntry(img, {top.area.x + 170, legend_y}, kEstimate, plot.estimate_label);

  // error over time
  Axes err;
  err.area = cv::Rect(half + kLeft, kTop, plot.width - half - kLeft - kRight,
                      plot.height - kTop - kBottom);
  std::tie(err.x0, err.x1) = Span(plot.ground_truth_time_sec, plot.error_time_sec, 1e-3);
  double e_max = 0;
  for (double e : plot.error) e_max = std::max(e_max, e);
  if (plot.error_rmse) e_max = std::max(e_max, *plot.error_rmse);
  err.y0 = 0;
  err.y1 = e_max > 0 ? 1.08 * e_max : 1.0;
  DrawAxes(img, err, "time (s)", plot.error_label);
  if (plot.error_rmse) {
    const double y = err.ToPixel(err.x0, *plot.error_rmse).y;
    for (double x = err.area.x; x < err.area.x + err.area.width; x += 12)
      Line(img, {x, y}, {std::min(x + 6.0, err.area.x + err.area.width + 0.0), y}, kRmse, 1);
    LegendEntry(img, {err.area.x + 170, legend_y}, kRmse,
                fmt::format("RMSE {:.4g} {}", *plot.error_rmse, plot.error_unit));
  }
  DrawSeries(img, err, plot.error_time_sec, plot.error_time_sec, plot.error, plot.max_gap_sec,
             kError);
  LegendEntry(img, {err.area.x, legend_y}, kError, "error");

  std::vector<uint8_t> png;
  Check(cv::imencode(".png", img, png, {cv::IMWRITE_PNG_COMPRESSION, 9}), "PNG encoding failed");
  return png;
}

}  // namespace penumbra

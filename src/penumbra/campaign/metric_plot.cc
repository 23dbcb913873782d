#include "penumbra/campaign/metric_plot.h"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "penumbra/core/error.h"

namespace penumbra {

cv::Scalar PlotColour(size_t i) {
  static const cv::Scalar kColours[] = {{180, 119, 31}, {14, 127, 255},  {44, 160, 44},
                                        {40, 39, 214},  {189, 103, 148}, {75, 86, 140}};
  return kColours[i % 6];
}

void PlotMetricVsCondition(const BenchmarkSpec& spec, const std::string& world,
                           const std::string& label, const std::vector<MetricSeries>& series,
                           const MetricPlotStyle& style, const std::filesystem::path& file) {
  const int W = 900, H = 560, left = 90, right = 220, top = 50, bottom = 70;
  cv::Mat img(H, W, CV_8UC3, cv::Scalar(255, 255, 255));
  const double ymax = style.ymax;
  const int pw = W - left - right, ph = H - top - bottom;
  const size_t nc = spec.conditions.size();
  auto X = [&](size_t c) {
    return left + static_cast<int>(std::lround(pw * (nc == 1 ? 0.5 : (c + 0.5) / nc)));
  };
  auto Y = [&](double v) {
    return top + ph -
           static_cast<int>(
               std::lround(style.clamp ? ph * std::clamp(v / ymax, 0.0, 1.05) : ph * v / ymax));
  };
  const cv::Scalar black(0, 0, 0), grey(200, 200, 200);
  for (double v : style.ticks) {
    cv::line(img, {left, Y(v)}, {left + pw, Y(v)}, grey, 1, cv::LINE_AA);
    cv::putText(img, fmt::format("{:g}", v), {8, Y(v) + 5}, cv::FONT_HERSHEY_SIMPLEX, 0.45, black,
                1, cv::LINE_AA);
  }
  cv::rectangle(img, {left, top}, {left + pw, top + ph}, black, 1);
  for (size_t c = 0; c < nc; ++c)
    cv::putText(img, spec.conditions[c].name, {X(c) - 20, top + ph + 25}, cv::FONT_HERSHEY_SIMPLEX,
                0.55, black, 1, cv::LINE_AA);
  cv::putText(img, "adversity condition", {left + pw / 2 - 80, H - 15}, cv::FONT_HERSHEY_SIMPLEX,
              0.55, black, 1, cv::LINE_AA);
  cv::putText(img, spec.name + " / " + world + ": " + label, {left, 30}, cv::FONT_HERSHEY_SIMPLEX,
              0.65, black, 1, cv::LINE_AA);
  for (size_t m = 0; m < spec.methods.size() && m < series.size(); ++m) {
    const cv::Scalar col = PlotColour(m);
    std::vector<cv::Point> pts;
    for (const auto& [c, v] : series[m]) {
      if (v.n == 0) {
        if (style.mark_empty)
          cv::drawMarker(img, {X(c), top + ph - 8}, col, cv::MARKER_TILTED_CROSS, 12, 2);
        continue;
      }
      const cv::Point p(X(c) + static_cast<int>(m) * 4, Y(v.mean));
      pts.push_back(p);
      cv::line(img, {p.x, Y(std::max(0.0, v.mean - v.std))}, {p.x, Y(v.mean + v.std)}, col, 1,
               cv::LINE_AA);
      cv::circle(img, p, 4, col, cv::FILLED, cv::LINE_AA);
    }
    if (pts.size() > 1) cv::polylines(img, pts, false, col, 2, cv::LINE_AA);
    const int ly = top + 20 + 24 * static_cast<int>(m);
    cv::line(img, {left + pw + 15, ly - 4}, {left + pw + 40, ly - 4}, col, 2, cv::LINE_AA);
    cv::putText(img, spec.methods[m].name, {left + pw + 46, ly}, cv::FONT_HERSHEY_SIMPLEX, 0.5,
                black, 1, cv::LINE_AA);
  }
  cv::putText(img, style.footer, {left, H - 40}, cv::FONT_HERSHEY_SIMPLEX, 0.4,
              cv::Scalar(90, 90, 90), 1, cv::LINE_AA);
  if (!cv::imwrite(file.string(), img)) throw Error("cannot write " + file.string());
}

}  // namespace penumbra

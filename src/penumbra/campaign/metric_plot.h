#pragma once
// the "metric vs adversity" line plot of the benchmark reports (SLAM and navigation,
// docs/benchmarks.md): x = the spec's conditions in order, one line per method with mean +- std
// error bars, a legend on the right.

#include <cstddef>
#include <filesystem>
#include <opencv2/core.hpp>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/campaign/benchmark_report.h"
#include "penumbra/campaign/benchmark_spec.h"

namespace penumbra {

/// the colour (BGR) of method or trial `i` in the report plots; six colours, repeating.
cv::Scalar PlotColour(size_t i);

/// one method's values in a metric plot: (condition index in spec order, cell), in that order.
using MetricSeries = std::vector<std::pair<size_t, SummaryCell>>;

/// the y axis and the marks of a metric plot.
struct MetricPlotStyle {
  double ymax = 1;            ///< the value at the top of the plot area (> 0)
  std::vector<double> ticks;  ///< values of the horizontal grid lines, labelled `{:g}`
  /// true: a value v stands at ph * clamp(v / ymax, 0, 1.05) pixels above the x axis (values
  /// beyond ymax stay near the frame); false: at ph * v / ymax
  bool clamp = false;
  /// true: a tilted cross just above the x axis where a method's cell is empty (n = 0);
  /// false: such a cell is left out
  bool mark_empty = false;
  std::string footer;  ///< the grey note at the bottom left
};

/// one series per method of `spec` (in spec order): the `metric` cell of every summary line of
/// `world` that matches the method and a condition, conditions in spec order. `Line` is a
/// summary line type with `world`, `condition` and `method` strings (SummaryLine,
/// NavSummaryLine).
template <typename Line>
std::vector<MetricSeries> SeriesByMethod(const BenchmarkSpec& spec, const std::vector<Line>& lines,
                                         const std::string& world, SummaryCell Line::*metric) {
  std::vector<MetricSeries> series(spec.methods.size());
  for (size_t m = 0; m < spec.methods.size(); ++m)
    for (size_t c = 0; c < spec.conditions.size(); ++c)
      for (const Line& l : lines)
        if (l.world == world && l.condition == spec.conditions[c].name &&
            l.method == spec.methods[m].name)
          series[m].emplace_back(c, l.*metric);
  return series;
}

/// writes a 900x560 PNG to `file`: the title "<spec name> / <world>: <label>", x = the
/// conditions of `spec`, one line per method (`series[m]` for spec.methods[m]) with mean +- std
/// error bars, offset 4 px per method so that the bars do not hide each other.
/// @throws Error if the file cannot be written.
void PlotMetricVsCondition(const BenchmarkSpec& spec, const std::string& world,
                           const std::string& label, const std::vector<MetricSeries>& series,
                           const MetricPlotStyle& style, const std::filesystem::path& file);

}  // namespace penumbra

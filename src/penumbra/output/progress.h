#pragma once
// progress of a run for the person watching it. on a terminal: one line redrawn in
// place, e.g. "[#########           ] 45% sim 4.50/10.00 s  123 frames  31.2 fps";
// otherwise (logs, CI) a spdlog info line every 10 % of progress. reads the wall
// clock for the frame rate and redraw throttling only; nothing here feeds back into
// the simulation.

#include <cstdint>
#include <cstdio>
#include <functional>
#include <string>

namespace penumbra {

/// how and where ProgressReporter reports.
struct ProgressOptions {
  enum class Mode {
    kAuto,  ///< kBar if `stream` is a terminal, else kLog
    kBar,   ///< single line redrawn with '\r' on `stream`
    kLog,   ///< one line through `log` per 10 % of progress
    kOff,   ///< silent
  };
  Mode mode = Mode::kAuto;
  std::FILE* stream = stderr;            ///< where the bar is drawn
  int bar_width = 20;                    ///< characters between the brackets
  double min_redraw_interval_sec = 0.1;  ///< bar: at most 10 redraws per second
  /// wall-clock seconds (monotonic); empty = std::chrono::steady_clock.
  std::function<double()> clock;
  /// sink of kLog lines; empty = spdlog::info.
  std::function<void(const std::string&)> log;
};

/// the progress line without '\r' or newline: bar, percent (rounded down), simulated time,
/// frames written and frame rate.
std::string FormatProgressLine(double sim_time_sec, double total_sim_sec, int64_t frames,
                               double fps, int bar_width);

/// reports progress of a run of `total_sim_sec` simulated seconds. not thread-safe.
class ProgressReporter {
 public:
  /// @param total_sim_sec simulated duration of the run (> 0; smaller values count as done).
  explicit ProgressReporter(double total_sim_sec, ProgressOptions options = {});
  /// calls Finish() if it was not called.
  ~ProgressReporter();

  ProgressReporter(const ProgressReporter&) = delete;
  ProgressReporter& operator=(const ProgressReporter&) = delete;

  /// reports that simulated time reached `sim_time_sec` and `frames` frames were written
  /// in total. the bar is redrawn if min_redraw_interval_sec passed since the last redraw;
  /// a log line is written for each 10 % step crossed.
  void Update(double sim_time_sec, int64_t frames);

  /// draws the last state and ends the bar's line (bar), or logs a final summary (log).
  /// later calls do nothing.
  void Finish();

  /// the mode in use (kAuto resolved).
  ProgressOptions::Mode mode() const { return options_.mode; }

 private:
  double Now() const;
  double Fps(double now) const;
  void Draw(double now);

  double total_sim_sec_;
  ProgressOptions options_;
  double start_ = 0;
  double last_draw_ = -1e300;
  size_t last_len_ = 0;
  int logged_decile_ = 0;
  double sim_time_sec_ = 0;
  int64_t frames_ = 0;
  bool finished_ = false;
};

}  // namespace penumbra

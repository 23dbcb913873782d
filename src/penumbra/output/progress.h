#pragma once
// progress of a run for the person watching it. on a terminal: one line redrawn in
// place, e.g. "[#########           ] 45% sim 4.50/10.00 s  123 frames  31.2 fps"
// (below 1 frame/s the rate reads "160.0 s/frame");
// otherwise (logs, CI) a spdlog info line every 10 % of progress. a slow frame (the
// pathtraced tier) also gets a line per sample pass with its ETA (RenderPass), at most one
// per ProgressOptions::pass_interval_sec. reads the wall clock for the frame rate, the ETA
// and redraw throttling only; nothing here feeds back into the simulation or the images.

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
  /// sample-pass lines (RenderPass): the least wall time from a frame's start to its first
  /// line and between lines, s (>= 0; 0 = a line for every pass of every frame).
  double pass_interval_sec = 1.0;
};

/// the progress line without '\r' or newline: bar, percent (rounded down), simulated time,
/// frames written and frame rate ("{:.1f} fps"; "{:.1f} s/frame" when 0 < fps < 1).
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

  /// the sample-pass line of one frame: "LABEL: sample pass P/N (PCT%), E s, ETA R s" with E
  /// the wall time since the frame's pass 0 and R = E (N - P) / P.
  static std::string FormatPassLine(const std::string& label, int pass, int passes,
                                    double elapsed_sec);

  /// a slow frame's progress: `pass` of `passes` sample passes done (0 = the frame starts).
  /// writes FormatPassLine when pass_interval_sec has passed since the frame started and since
  /// the last such line, and for the last pass of a frame that had a line: above the bar (bar)
  /// or through `log` (log).
  void RenderPass(const std::string& label, int pass, int passes);

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
  double frame_start_ = 0;  // wall time of the current frame's pass 0
  double last_pass_line_ = -1e300;
  int frame_pass_lines_ = 0;  // pass lines of the current frame
};

}  // namespace penumbra

#include "penumbra/output/progress.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace penumbra {
namespace {

double Fraction(double sim_time_sec, double total_sim_sec) {
  if (!(total_sim_sec > 0)) return 1.0;
  return std::clamp(sim_time_sec / total_sim_sec, 0.0, 1.0);
}

}  // namespace

std::string FormatProgressLine(double sim_time_sec, double total_sim_sec, int64_t frames,
                               double fps, int bar_width) {
  const double f = Fraction(sim_time_sec, total_sim_sec);
  bar_width = std::max(bar_width, 1);
  const int filled = std::clamp(static_cast<int>(std::floor(f * bar_width)), 0, bar_width);
  const int percent = std::clamp(static_cast<int>(std::floor(f * 100.0 + 1e-9)), 0, 100);
  // a slow tier (pathtraced: minutes a frame) would read "0.0 fps": seconds per frame instead
  const std::string rate = fps > 0 && fps < 1 ? fmt::format("{:.1f} s/frame", 1.0 / fps)
                                              : fmt::format("{:.1f} fps", fps);
  return fmt::format("[{}{}] {:3d}% sim {:.2f}/{:.2f} s  {} frames  {}", std::string(filled, '#'),
                     std::string(bar_width - filled, ' '), percent, sim_time_sec, total_sim_sec,
                     frames, rate);
}

std::string ProgressReporter::FormatPassLine(const std::string& label, int pass, int passes,
                                             double elapsed_sec) {
  const int percent = passes > 0 ? static_cast<int>(100.0 * pass / passes) : 100;
  const double eta = pass > 0 ? elapsed_sec * (passes - pass) / pass : 0.0;
  return fmt::format("{}: sample pass {}/{} ({}%), {:.1f} s, ETA {:.1f} s", label, pass, passes,
                     percent, elapsed_sec, eta);
}

void ProgressReporter::RenderPass(const std::string& label, int pass, int passes) {
  if (finished_ || options_.mode == ProgressOptions::Mode::kOff) return;
  const double now = Now();
  if (pass <= 0) {
    frame_start_ = now;
    frame_pass_lines_ = 0;
    return;
  }
  const double interval = std::max(0.0, options_.pass_interval_sec);
  const bool due = now - frame_start_ >= interval && now - last_pass_line_ >= interval;
  const bool last_of_shown_frame = pass >= passes && frame_pass_lines_ > 0;
  if (!due && !last_of_shown_frame) return;
  const std::string line = FormatPassLine(label, pass, passes, now - frame_start_);
  last_pass_line_ = now;
  ++frame_pass_lines_;
  if (options_.mode == ProgressOptions::Mode::kBar) {
    // the line above the bar, then the bar again
    const size_t pad = last_len_ > line.size() ? last_len_ - line.size() : 0;
    std::fprintf(options_.stream, "\r%s%*s\n", line.c_str(), static_cast<int>(pad), "");
    last_len_ = 0;
    Draw(now);
  } else {
    options_.log(line);
  }
}

ProgressReporter::ProgressReporter(double total_sim_sec, ProgressOptions options)
    : total_sim_sec_(total_sim_sec), options_(std::move(options)) {
  if (options_.mode == ProgressOptions::Mode::kAuto) {
    const bool tty = options_.stream != nullptr && isatty(fileno(options_.stream)) == 1;
    options_.mode = tty ? ProgressOptions::Mode::kBar : ProgressOptions::Mode::kLog;
  }
  if (options_.mode == ProgressOptions::Mode::kBar && options_.stream == nullptr) {
    options_.mode = ProgressOptions::Mode::kOff;
  }
  if (!options_.log) options_.log = [](const std::string& s) { spdlog::info("{}", s); };
  start_ = Now();
}

ProgressReporter::~ProgressReporter() { Finish(); }

double ProgressReporter::Now() const {
  if (options_.clock) return options_.clock();
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

double ProgressReporter::Fps(double now) const {
  const double elapsed = now - start_;
  return elapsed > 1e-6 ? static_cast<double>(frames_) / elapsed : 0.0;
}

void ProgressReporter::Draw(double now) {
  const std::string line =
      FormatProgressLine(sim_time_sec_, total_sim_sec_, frames_, Fps(now), options_.bar_width);
  // pad with spaces so that a shorter line fully covers the previous one
  const size_t pad = last_len_ > line.size() ? last_len_ - line.size() : 0;
  std::fprintf(options_.stream, "\r%s%*s", line.c_str(), static_cast<int>(pad), "");
  std::fflush(options_.stream);
  last_len_ = line.size();
  last_draw_ = now;
}

void ProgressReporter::Update(double sim_time_sec, int64_t frames) {
  if (finished_) return;
  sim_time_sec_ = sim_time_sec;
  frames_ = frames;
  switch (options_.mode) {
    case ProgressOptions::Mode::kBar: {
      const double now = Now();
      if (now - last_draw_ >= options_.min_redraw_interval_sec) Draw(now);
      break;
    }
    case ProgressOptions::Mode::kLog: {
      const int decile =
          static_cast<int>(std::floor(Fraction(sim_time_sec, total_sim_sec_) * 10.0 + 1e-9));
      if (decile > logged_decile_) {
        logged_decile_ = decile;
        options_.log(FormatProgressLine(sim_time_sec_, total_sim_sec_, frames_, Fps(Now()),
                                        options_.bar_width));
      }
      break;
    }
    default:
      break;
  }
}

void ProgressReporter::Finish() {
  if (finished_) return;
  finished_ = true;
  if (options_.mode == ProgressOptions::Mode::kBar) {
    Draw(Now());
    std::fputc('\n', options_.stream);
    std::fflush(options_.stream);
  } else if (options_.mode == ProgressOptions::Mode::kLog && logged_decile_ < 10) {
    options_.log(
        FormatProgressLine(sim_time_sec_, total_sim_sec_, frames_, Fps(Now()), options_.bar_width));
  }
}

}  // namespace penumbra

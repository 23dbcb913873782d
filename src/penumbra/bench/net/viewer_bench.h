#pragma once
// `penumbra bench viewer`: the live viewer's costs (docs/viewer.md): frames/s delivered to a
// page, input-to-photon latency of teleop commands at real-time pacing, and physics steps/s
// with and without a viewer attached, measured with a WebSocket client in this process. a
// benchmark, never a pass/fail test: it prints numbers and targets.

#include <string>

namespace penumbra {

/// options of `penumbra bench viewer`.
struct BenchViewerOptions {
  std::string world_file;    ///< default: the bundled default world
  double seconds = 4;        ///< simulated seconds per timed run (as fast as possible)
  int rounds = 2;            ///< A/B pairs (no viewer, viewer with one page attached)
  double camera_hz = 30;     ///< rate of the streamed camera (the world's first, rgb only)
  int latency_samples = 10;  ///< teleop commands timed at real-time pacing
};

/// runs the benchmark and prints its table to stdout; returns 0.
/// @throws ConfigError for a bad world; Error when the viewer cannot start.
int BenchViewer(const BenchViewerOptions& options);

}  // namespace penumbra

#pragma once
// `penumbra export RUN_DIR --format tum|euroc|kitti --out DIR [--camera NAME]
// [--camera2 NAME] [--imu NAME] [--sequence NN]`: a run's output folder in a public dataset
// layout (dataset/dataset_export.h, docs/datasets.md); `--format rosbag --out FILE.bag`: a ROS 1
// bag of every sensor and robot state (ros/rosbag_export.h, docs/ros.md). RUN may also be a run log
// (.plog): it is first replayed (replay/replay_runner.h; --world and --adversity as `penumbra
// replay`'s) into a temporary folder beside --out ("<out>.replay-tmp-<random>"), removed
// afterwards.
//
// SIGINT / SIGTERM (the stop request): the replay stops at its next step, the export between
// frames; the partial dataset or bag and the replay folder are removed, --out is left as it was,
// and Run returns 128 + the signal (130 / 143).

#include <CLI/CLI.hpp>
#include <atomic>
#include <memory>
#include <string>

namespace penumbra {

/// the `export` verb: its options, filled by CLI11 while parsing.
class ExportCommand {
 public:
  /// true when the command line chose `export`.
  bool selected() const;
  /// runs the export; returns the exit code: 0, or 128 + signal when `stop_request` (may be
  /// null; set by the SIGINT / SIGTERM handler) was set (nothing written).
  /// @throws ConfigError for bad input (a missing run folder, an unknown camera, a non-empty
  ///         --out, a symbolic link or a bad image in the run folder, ...: exit code 2 in
  ///         cli.cc); Error if a file cannot be written (exit code 1).
  int Run(const std::atomic<int>* stop_request = nullptr) const;

 private:
  friend ExportCommand AddExportCommand(CLI::App& app);
  int RunRosbag(const std::atomic<int>* stop_request) const;
  struct State;
  std::shared_ptr<State> state_;
};

/// adds the `export` subcommand to `app`; the returned command reads its options after
/// app.parse().
ExportCommand AddExportCommand(CLI::App& app);

}  // namespace penumbra

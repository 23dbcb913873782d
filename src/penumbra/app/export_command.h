#pragma once
// `penumbra export RUN_DIR --format tum|euroc|kitti --out DIR [--camera NAME]
// [--camera2 NAME] [--imu NAME] [--sequence NN]`: a run's output folder in a public dataset
// layout (dataset/dataset_export.h, docs/datasets.md); `--format rosbag --out FILE.bag`: a ROS 1
// bag of every sensor and robot state (ros/rosbag_export.h, docs/ros.md). RUN may also be a run log
// (.plog): it is first replayed (replay/replay_runner.h; --world and --adversity as `penumbra
// replay`'s) into a temporary folder beside --out, removed afterwards.

#include <CLI/CLI.hpp>
#include <memory>
#include <string>

namespace penumbra {

/// the `export` verb: its options, filled by CLI11 while parsing.
class ExportCommand {
 public:
  /// true when the command line chose `export`.
  bool selected() const;
  /// runs the export; returns the exit code (0).
  /// @throws ConfigError for bad input (a missing run folder, an unknown camera, a non-empty
  ///         --out, ...: exit code 2 in cli.cc); Error if a file cannot be written.
  int Run() const;

 private:
  friend ExportCommand AddExportCommand(CLI::App& app);
  int RunRosbag() const;
  struct State;
  std::shared_ptr<State> state_;
};

/// adds the `export` subcommand to `app`; the returned command reads its options after
/// app.parse().
ExportCommand AddExportCommand(CLI::App& app);

}  // namespace penumbra

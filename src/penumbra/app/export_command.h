#pragma once
// `penumbra export RUN_DIR --format tum|euroc|kitti --out DIR [--camera NAME]
// [--camera2 NAME] [--imu NAME] [--sequence NN]`: a run's output folder in a public dataset
// layout (dataset/dataset_export.h, docs/datasets.md); `--format rosbag --out FILE.bag`: a ROS 1
// bag of every sensor and robot state (ros/rosbag_export.h, docs/ros.md). RUN may also be a run log
// (.plog): it is first replayed (replay/kinematic/replay_runner.h; --world and --adversity as
// `penumbra replay`'s) into a temporary folder beside --out ("<out>.replay-tmp-<random>"), removed
// afterwards. what the options and the log tell is checked before the replay: the options
// (DatasetExportOptions::ValidateOrThrow) and, for EuRoC, the IMU (the replayed world must have
// the --imu named, or exactly one).
//
// SIGINT / SIGTERM (the stop request): the replay stops at its next step, the export between
// frames; the partial dataset or bag and the replay folder are removed, --out is left as it was,
// and Run returns 128 + the signal (130 / 143).

#include <atomic>
#include <memory>
#include <string>

#include "penumbra/app/command.h"

namespace penumbra {

/// the `export` verb (app/command.h).
class ExportCommand : public Command {
 public:
  ExportCommand();
  ~ExportCommand() override;
  ExportCommand(const ExportCommand&) = delete;
  ExportCommand& operator=(const ExportCommand&) = delete;

  std::string name() const override;
  std::string summary() const override;
  /// adds the run argument and the options to `export`.
  void AddOptions(CLI::App* command) override;
  /// runs the export with SIGINT / SIGTERM handlers installed (app/stop_signals.h); returns the
  /// exit code: 0, or 128 + signal when a signal stopped it (nothing written).
  /// @throws ConfigError for bad input (a missing run folder, an unknown camera, a non-empty
  ///         --out, a symbolic link or a bad image in the run folder, ...: exit code 2 in
  ///         RunCli); Error if a file cannot be written (exit code 1).
  int Run(const CommandArgs& args) override;

 private:
  int RunRosbag(const std::atomic<int>* stop_request) const;
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace penumbra

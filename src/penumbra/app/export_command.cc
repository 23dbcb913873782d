#include "penumbra/app/export_command.h"

#include <spdlog/spdlog.h>

#include <filesystem>

#include "penumbra/core/error.h"
#include "penumbra/dataset/dataset_export.h"
#include "penumbra/dataset/run_folder.h"

namespace penumbra {

struct ExportCommand::State {
  CLI::App* command = nullptr;
  std::string input;
  std::string format;
  DatasetExportOptions options;
  std::string out;
};

bool ExportCommand::selected() const {
  return state_ && state_->command && static_cast<bool>(*state_->command);
}

int ExportCommand::Run() const {
  const State& s = *state_;
  DatasetExportOptions options = s.options;
  options.format = ParseDatasetFormat(s.format);
  options.out_dir = s.out;
  namespace fs = std::filesystem;
  const fs::path input(s.input);
  // a run log is first replayed into a temporary run folder, then exported from there. the
  // replay verb (issue 18 point 2) plugs in here: replay `input` into a temp folder and pass
  // that folder to RunFolder below.
  if (input.extension() == ".plog")
    throw ConfigError(s.input, 0, "",
                      "a run log; export reads a run folder: replay it first "
                      "(penumbra replay FILE.plog --out DIR), then penumbra export DIR");
  const RunFolder run(input);
  const DatasetExportSummary summary = ExportDataset(run, options);
  std::string sensors = "camera '" + summary.camera + "'";
  if (!summary.camera2.empty()) sensors += ", camera '" + summary.camera2 + "'";
  if (!summary.imu.empty())
    sensors += ", IMU '" + summary.imu + "' (" + std::to_string(summary.imu_samples) + " samples)";
  spdlog::info("exported {} frames of {} as {} -> {}", summary.frames, sensors, s.format, s.out);
  if (summary.depth_beyond_range > 0)
    spdlog::warn(
        "{} depth pixels lie beyond 13.107 m (the largest TUM depth) and were written "
        "as 0 (no data)",
        summary.depth_beyond_range);
  return 0;
}

ExportCommand AddExportCommand(CLI::App& app) {
  ExportCommand c;
  c.state_ = std::make_shared<ExportCommand::State>();
  ExportCommand::State& s = *c.state_;
  s.command = app.add_subcommand(
      "export", "write a run's output folder as a TUM RGB-D, EuRoC/ASL or KITTI odometry dataset");
  s.command->add_option("run", s.input, "output folder of `penumbra run`")->required();
  s.command->add_option("--format,-f", s.format, "dataset layout")
      ->required()
      ->check(CLI::IsMember({"tum", "euroc", "kitti"}));
  s.command->add_option("--out,-o", s.out, "output folder (new or empty)")->required();
  s.command->add_option("--camera", s.options.camera,
                        "camera to export (default: the run's only camera)");
  s.command->add_option("--camera2", s.options.camera2,
                        "second camera: EuRoC cam1, KITTI image_1 (a synchronised stereo pair)");
  s.command->add_option("--imu", s.options.imu, "IMU for EuRoC (default: the run's only IMU)");
  s.command->add_option("--sequence", s.options.sequence, "KITTI sequence number (two digits)");
  return c;
}

}  // namespace penumbra

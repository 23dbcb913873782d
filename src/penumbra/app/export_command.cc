#include "penumbra/app/export_command.h"

#include <signal.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/app/backend_flag.h"
#include "penumbra/app/stop_signals.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/dataset/dataset_export.h"
#include "penumbra/dataset/export_stop.h"
#include "penumbra/dataset/run_folder.h"
#include "penumbra/replay/kinematic/replay_runner.h"
#include "penumbra/replay/recorded_world.h"
#include "penumbra/replay/world_override.h"
#include "penumbra/ros/rosbag2_writer.h"
#include "penumbra/ros/rosbag_export.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

struct ExportCommand::State {
  CLI::App* command = nullptr;
  std::string input;
  std::string format;
  DatasetExportOptions options;
  std::string out;
  std::string replay_world;  // --world for a .plog input
  std::string replay_adversity;
  std::string depth = "sensor";  // --depth: sensor | ground-truth
  CLI::Option* depth_option = nullptr;
  BackendFlag backend;  // --backend for a .plog input's replay
};

namespace {

// a run log named as the export's input: missing, or not a regular file (a FIFO, which the
// replay's open() would wait on, a folder, a device), refused naming what it is
void CheckRunLogInput(const std::filesystem::path& input) {
  std::error_code ec;
  if (!std::filesystem::exists(std::filesystem::symlink_status(input, ec)))
    throw ConfigError(input.string(), 0, "", "no such run log; expected a .plog file");
  OpenInputFile(input, "run log");
}

// a temporary folder that is removed with everything in it when it goes out of scope
class TempFolder {
 public:
  explicit TempFolder(std::filesystem::path path) : path_(std::move(path)) {}
  TempFolder(const TempFolder&) = delete;
  TempFolder& operator=(const TempFolder&) = delete;
  ~TempFolder() {
    std::error_code ec;
    std::filesystem::remove_all(path_, ec);
  }
  const std::filesystem::path& path() const { return path_; }

 private:
  std::filesystem::path path_;
};

// replays the run log `log_path` (replay/kinematic/replay_runner.h, with the recorded conditions or
// the given --world / --adversity) into a new temporary run folder "<out>.replay-tmp-<random>"
// beside `out`, kept in `replayed` (removed when it is destroyed); returns that folder.
// @throws ExportStopped when the stop request ended the replay.
std::filesystem::path ReplayLogBeside(
    const std::string& log_path, const std::string& world_override, const std::string& adversity,
    std::optional<RenderSettings::Backend> backend, ReplayDepth depth,
    const std::filesystem::path& out, const std::atomic<int>* stop_request,
    std::optional<TempFolder>* replayed, ReplaySummary* summary_out = nullptr) {
  replayed->emplace(MakeSiblingTempFolder(out, ".replay-tmp"));
  ReplayOptions replay;
  replay.log_path = log_path;
  replay.out_dir = (*replayed)->path().string();
  replay.world_override = world_override;
  replay.adversity = adversity;
  replay.backend = backend;
  replay.progress = false;
  replay.stop_request = stop_request;
  replay.depth = depth;
  spdlog::info("replaying {} into {} for the export", log_path, replay.out_dir);
  const ReplaySummary summary = ReplayLog(replay);
  if (summary_out) *summary_out = summary;
  if (summary.interrupted) throw ExportStopped(stop_request ? stop_request->load() : SIGINT);
  CheckExportStop(stop_request);
  return (*replayed)->path();
}

// EuRoC's imu0 from a run log: the world the replay sets up (the recorded world, with --world's
// keys replaced) must have the IMU named by --imu, or exactly one when none is named. checked
// before the replay renders anything.
void CheckEurocImuOfLog(const std::string& log_path, const std::string& world_override,
                        const std::string& imu) {
  const RunLogReader reader = RunLogReader::Open(log_path, RunLogReadMode::kRecover);
  WorldConfig world = RecordedWorld(reader.header());
  if (!world_override.empty()) world = ApplyWorldOverride(world, world_override);
  std::vector<std::string> names;
  std::string list;
  for (const SensorConfig& c : world.sensors)
    if (c.kind() == SensorKind::kImu) {
      names.push_back(c.name);
      list += (list.empty() ? "" : ", ") + c.name;
    }
  const std::string world_name = "the run log's world (" + world.file + ")";
  if (names.empty())
    throw ConfigError(log_path, 0, "--format",
                      "EuRoC needs an IMU (imu0) and " + world_name +
                          " has none; expected a world with an IMU (`type: imu` in its "
                          "`sensors:`, docs/world-file.md), recorded again, or --format tum or "
                          "kitti, which need cameras only");
  if (!imu.empty() && std::find(names.begin(), names.end(), imu) == names.end())
    throw ConfigError(
        log_path, 0, "--imu",
        "'" + imu + "' is not an IMU of " + world_name + "; expected one of: " + list);
  if (imu.empty() && names.size() > 1)
    throw ConfigError(log_path, 0, "--imu",
                      world_name + " has " + std::to_string(names.size()) +
                          " IMUs; expected one named with --imu (" + list + ")");
}

// --backend with a run folder: nothing is rendered
ConfigError BackendNotForRunFolder() {
  return ConfigError("", 0, "--backend",
                     "only for a run log (.plog) input, whose replay renders; a run folder's "
                     "images are exported as they were written");
}

// the exit code and message of a stopped export
int Stopped(const ExportStopped& e, const std::string& out) {
  spdlog::warn("interrupted by {}; the partial export was removed, nothing was written to {}",
               e.signal() == SIGTERM ? "SIGTERM" : "SIGINT", out);
  return 128 + e.signal();
}

}  // namespace

ExportCommand::ExportCommand() : state_(std::make_unique<State>()) {}
ExportCommand::~ExportCommand() = default;

std::string ExportCommand::name() const { return "export"; }

std::string ExportCommand::summary() const {
  return "write a run's output folder as a TUM RGB-D, EuRoC/ASL or KITTI odometry dataset, or as "
         "a ROS 1 or ROS 2 (MCAP) bag";
}

int ExportCommand::Run(const CommandArgs& args) {
  const StopSignals stop_signals(kExportStopMessage);
  const std::atomic<int>* stop_request = args.stop_signal;
  const State& s = *state_;
  namespace fs = std::filesystem;
  const fs::path input(s.input);
  if (s.format == "rosbag" || s.format == "rosbag2") return RunRosbag(stop_request);
  const std::optional<RenderSettings::Backend> backend = s.backend.Resolve();
  DatasetExportOptions options = s.options;
  options.format = ParseDatasetFormat(s.format);
  options.out_dir = s.out;
  options.stop_request = stop_request;
  // a run log is first replayed (replay/kinematic/replay_runner.h, with the recorded conditions or
  // the given --world / --adversity) into a temporary run folder beside --out, exported from there
  std::optional<TempFolder> replayed;
  fs::path run_dir = input;
  if (input.extension() == ".plog") {
    CheckRunLogInput(input);
    CheckExportFolder(options.out_dir);
    // what can be told from the options and the log is checked before the replay renders
    options.ValidateOrThrow();
    if (options.format == DatasetFormat::kEuroc)
      CheckEurocImuOfLog(s.input, s.replay_world, options.imu);
    // the replay renders the depth with the benchmarks' sensor model (a camera's own
    // depth_noise first) or exact (--depth ground-truth)
    const bool truth = s.depth == "ground-truth";
    ReplaySummary replay;
    try {
      run_dir = ReplayLogBeside(s.input, s.replay_world, s.replay_adversity, backend,
                                truth ? ReplayDepth::kGroundTruth : ReplayDepth::kSensor,
                                options.out_dir, stop_request, &replayed, &replay);
    } catch (const ExportStopped& e) {
      return Stopped(e, s.out);
    }
    options.source_label = PathRelativeTo(input, options.out_dir);
    const RunFolder replayed_run(run_dir);
    const std::vector<std::string> names = replayed_run.CameraNames();
    const std::string camera =
        !options.camera.empty() ? options.camera : (names.size() == 1 ? names[0] : "");
    const auto model = replay.depth_models.find(camera);
    if (truth) {
      options.depth_source = "ground_truth";
      options.depth_note = "exact z-depth of the replayed run log (--depth ground-truth)";
    } else if (model != replay.depth_models.end() && !model->second.empty()) {
      options.depth_source = "sensor_model";
      options.depth_model = model->second;
      options.depth_note =
          "the replay of the run log rendered the camera's depth through this "
          "sensor model (docs/cameras.md \"RGB-D depth noise\"), the camera's "
          "own world-file depth_noise or else the benchmarks' realsense_d435";
    }
  } else {
    if (!s.replay_world.empty() || !s.replay_adversity.empty())
      throw ConfigError("", 0, s.replay_world.empty() ? "--adversity" : "--world",
                        "only for a run log (.plog) input, which is replayed first");
    if (s.backend.given()) throw BackendNotForRunFolder();
    // a run folder's depth is what its camera wrote; the model is chosen at replay
    if (s.depth_option && s.depth_option->count() > 0)
      throw ConfigError("", 0, "--depth",
                        "only for a run log (.plog) input, whose replay renders the depth with "
                        "the sensor model or exact; a run folder's depth images are exported as "
                        "its camera wrote them (world-file `depth_noise`, docs/cameras.md)");
    options.depth_source = "as_recorded";
    options.depth_note =
        "the run folder's depth images as its camera wrote them: exact unless "
        "the camera had a world-file depth_noise (see the run's world file); "
        "export the run log (.plog) for the sensor model";
  }
  const RunFolder run(run_dir);
  DatasetExportSummary summary;
  try {
    summary = ExportDataset(run, options);
  } catch (const ExportStopped& e) {
    return Stopped(e, s.out);
  }
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

int ExportCommand::RunRosbag(const std::atomic<int>* stop_request) const {
  const State& s = *state_;
  namespace fs = std::filesystem;
  const fs::path input(s.input);
  const fs::path bag(s.out);
  const bool ros2 = s.format == "rosbag2";
  const std::optional<RenderSettings::Backend> backend = s.backend.Resolve();
  if (!s.options.camera.empty() || !s.options.camera2.empty() || !s.options.imu.empty())
    throw ConfigError("", 0,
                      !s.options.camera.empty()
                          ? "--camera"
                          : (!s.options.camera2.empty() ? "--camera2" : "--imu"),
                      "a rosbag holds every camera, LiDAR and IMU of the run; expected no sensor "
                      "selection with --format " +
                          s.format);
  if (s.depth_option && s.depth_option->count() > 0)
    throw ConfigError("", 0, "--depth",
                      "not for --format " + s.format +
                          ", whose depth images are the run's as recorded; expected --format tum");
  // a build without ROS 2 says so before a run log is replayed
  if (ros2) RequireRosbag2();
  // a run log is replayed into a temporary run folder beside the bag first
  std::optional<TempFolder> replayed;
  fs::path run_dir = input;
  if (input.extension() == ".plog") {
    CheckRunLogInput(input);
    if (!ros2 && bag.extension() != ".bag")
      throw ConfigError("", 0, "--out",
                        "'" + bag.string() + "'; expected a bag file name ending in .bag");
    std::error_code ec;
    if (fs::exists(fs::symlink_status(bag, ec)))
      throw ConfigError("", 0, "--out",
                        "'" + bag.string() + "' exists; expected a new " +
                            (ros2 ? "folder" : "file") + " (never overwritten)");
    try {
      run_dir = ReplayLogBeside(s.input, s.replay_world, s.replay_adversity, backend,
                                ReplayDepth::kAsRecorded, bag, stop_request, &replayed);
    } catch (const ExportStopped& e) {
      return Stopped(e, s.out);
    }
  } else if (!s.replay_world.empty() || !s.replay_adversity.empty()) {
    throw ConfigError("", 0, s.replay_world.empty() ? "--adversity" : "--world",
                      "only for a run log (.plog) input, which is replayed first");
  } else if (s.backend.given()) {
    throw BackendNotForRunFolder();
  }
  RosbagExportSummary summary;
  try {
    summary =
        ros2 ? ExportRosbag2(run_dir, bag, stop_request) : ExportRosbag(run_dir, bag, stop_request);
  } catch (const ExportStopped& e) {
    return Stopped(e, s.out);
  }
  spdlog::info("exported {} messages on {} topics (names from {}) -> {}", summary.messages,
               summary.counts.size(), summary.world_file, s.out);
  return 0;
}

void ExportCommand::AddOptions(CLI::App* command) {
  State& s = *state_;
  s.command = command;
  s.command
      ->add_option("run", s.input,
                   "output folder of `penumbra run`, or a run log (.plog), replayed first")
      ->required();
  s.command->add_option("--world", s.replay_world,
                        "for a .plog: world-file override of the replay (replay --world), e.g. "
                        "to add depth to a camera");
  s.command->add_option("--adversity", s.replay_adversity,
                        "for a .plog: adversity preset of the replay (replay --adversity)");
  s.backend.Add(s.command, "the recorded render.backend (for a .plog input)");
  s.command->add_option("--format,-f", s.format, "dataset layout")
      ->required()
      ->check(CLI::IsMember({"tum", "euroc", "kitti", "rosbag", "rosbag2"}));
  s.command
      ->add_option("--out,-o", s.out,
                   "output folder (new or empty); rosbag: a new FILE.bag; rosbag2: a new "
                   "folder (ROS 2 bag: metadata.yaml + MCAP)")
      ->required();
  s.command->add_option("--camera", s.options.camera,
                        "camera to export (default: the run's only camera)");
  s.command->add_option("--camera2", s.options.camera2,
                        "second camera: EuRoC cam1, KITTI image_1 (a synchronised stereo pair)");
  s.command->add_option("--imu", s.options.imu, "IMU for EuRoC (default: the run's only IMU)");
  s.command->add_option("--sequence", s.options.sequence, "KITTI sequence number (two digits)");
  s.depth_option =
      s.command
          ->add_option("--depth", s.depth,
                       "for a .plog: depth images through the depth sensor model the benchmarks "
                       "use (sensor, default: the camera's own depth_noise, else realsense_d435) "
                       "or exact (ground-truth)")
          ->check(CLI::IsMember({"sensor", "ground-truth"}));
}

}  // namespace penumbra

#include "penumbra/app/run_command.h"

#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/app/backend_flag.h"
#include "penumbra/app/bridge_flags.h"
#include "penumbra/app/cli_options.h"
#include "penumbra/app/stop_signals.h"
#include "penumbra/app/viewer_commands.h"
#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/replay/world_override.h"
#include "penumbra/run/runner.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

// --start-pose ROBOT,X,Y,YAW_DEG: the robot's pose in the world file replaced (x, y, yaw)
void ApplyStartPose(const std::string& text, WorldConfig* world) {
  std::vector<std::string> parts;
  size_t pos = 0;
  while (pos <= text.size()) {
    const size_t end = std::min(text.find(',', pos), text.size());
    parts.push_back(text.substr(pos, end - pos));
    pos = end + 1;
  }
  const auto bad = [&](const std::string& why) {
    return ConfigError("", 0, "--start-pose",
                       "'" + text + "': " + why + "; expected ROBOT,X,Y,YAW_DEG (m, m, deg)");
  };
  if (parts.size() != 4) throw bad("not 4 comma-separated fields");
  double v[3];
  for (int i = 0; i < 3; ++i) {
    const std::optional<double> d = ParseDecimal(parts[i + 1]);
    if (!d) throw bad("'" + parts[i + 1] + "' is not a number");
    v[i] = *d;
  }
  for (ModelConfig& m : world->models)
    if (m.is_robot && m.name == parts[0]) {
      m.pose.xyz.x() = v[0];
      m.pose.xyz.y() = v[1];
      m.pose.rpy_deg.z() = v[2];
      return;
    }
  throw bad("the world has no robot '" + parts[0] + "'");
}

class RunCommand : public Command {
 public:
  std::string name() const override { return "run"; }
  std::string summary() const override {
    return "simulate a world file or a bare MJCF/URDF model and write outputs";
  }

  void AddOptions(CLI::App* run) override {
    verb_ = run;
    run->add_option("world", world_path_, "world file (.yaml) or model (.xml MJCF, .urdf)")
        ->required();
    run->add_option("--out,-o", options_.out_dir,
                    "output folder (default: the world's output.dir)");
    AddDecimal(
        run, "--duration", [this](double v) { duration_ = v; }, 0, true,
        "simulated seconds (overrides duration_sec)");
    run->add_flag("--realtime", options_.realtime, "pace physics to wall-clock time");
    run->add_option("--tier", tier_, "render tier")
        ->check(CLI::IsMember({"realtime", "pathtraced"}));
    backend_.Add(run);
    AddInteger(run, "--spp", &spp_, 1, 65536, "samples per pixel (pathtraced)");
    AddInteger(run, "--threads", &threads_, 0, 256, "render threads (0 = all cores)");
    AddUint64(run, "--seed", &seed_, "world seed (overrides seed)");
    run->add_flag("--quiet,-q", quiet_, "no progress output");
    AddDecimal(
        run, "--progress-interval", [this](double v) { options_.progress_interval_sec = v; }, 0,
        false,
        "pathtraced tier: the least seconds between sample-pass progress lines (with an ETA; "
        "default 1, 0 = every pass)");
    run->add_flag("--force", options_.force,
                  "the output folder may hold an earlier run's outputs: remove them first "
                  "(anything else there, and a folder a running run holds, is refused); "
                  "--record may replace an existing log");
    run->add_option("--outputs", outputs_,
                    "images of every camera, comma-separated: rgb, depth, segmentation, range, "
                    "normals, instance_segmentation, semantic_segmentation (overrides the world)");
    run->add_option("--record", options_.record_file,
                    "write a run log of every physics step to FILE.plog, a new file unless "
                    "--force (docs/run-log.md)");
    run->add_flag("--record-sensors", options_.record_sensors,
                  "the run log also holds every camera image and sensor output");
    bridge_flags_.Add(run);
    viewer_flag_.Add(run);
    run->add_option("--adversity", options_.adversity,
                    "adversity preset: none, minor, major, FILE.yaml or FILE.yaml#NAME "
                    "(worlds/adversity/presets.yaml; overrides the world's `adversity`)");
    run->add_option("--override", override_,
                    "a world-file fragment whose top-level keys replace the world's (the keys "
                    "`penumbra replay --world` takes: cameras, sensors, metrics, ...; physics "
                    "keys are refused)");
    run->add_option("--start-pose", start_pose_,
                    "ROBOT,X,Y,YAW_DEG: place the robot ROBOT at (X, Y) m in the world frame, "
                    "turned YAW_DEG about z (its z, roll and pitch stay the world file's)");
  }

  int Run(const CommandArgs& args) override {
    WorldConfig world = LoadWorldOrModel(world_path_);
    if (!override_.empty()) world = ApplyWorldOverride(world, override_);
    if (!start_pose_.empty()) ApplyStartPose(start_pose_, &world);
    if (duration_) options_.duration_sec = *duration_;
    if (seed_) world.seed = *seed_;
    if (!tier_.empty())
      world.render.tier = tier_ == "pathtraced" ? RenderSettings::Tier::kPathtraced
                                                : RenderSettings::Tier::kRealtime;
    if (spp_ > 0) world.render.samples_per_pixel = spp_;
    if (threads_ >= 0) world.render.threads = threads_;
    backend_.Apply(&world.render);
    options_.progress = !quiet_;
    options_.command_line = args.command_line;
    if (!outputs_.empty() || verb_->count("--outputs"))
      options_.outputs = ParseCameraOutputs(outputs_);
    bridge_flags_.Apply(*verb_, &options_);
    viewer_flag_.Apply(*verb_, &options_);
    const StopSignals stop_signals;
    options_.stop_request = args.stop_signal;
    RunSummary s;
    try {
      s = RunWorld(world, options_);
    } catch (const SetupInterrupted& e) {
      // a signal during the set-up (a long composition): nothing was written
      spdlog::warn("{}; no outputs written", e.what());
      return 128 + e.signal();
    }
    int64_t frames = 0;
    for (const auto& [name, n] : s.frames_per_camera) frames += n;
    spdlog::info(
        "done: {:.3f} s sim time, {} steps, {} frames in {:.2f} s wall, peak RSS {:.0f} MiB -> {}",
        s.sim_time_sec, s.physics_steps, frames, s.wall_time_sec, s.peak_rss_mib, s.out_dir);
    const int sig = args.stop_signal->load();
    if (s.interrupted && sig == 0) {
      spdlog::info(
          "stopped by a client's `stop` at {:.6g} s of sim time; outputs and run.json "
          "written",
          s.sim_time_sec);
      return 0;
    }
    if (s.interrupted) {
      spdlog::warn("interrupted by {} at {:.6g} s of sim time; outputs and run.json written",
                   sig == SIGTERM ? "SIGTERM" : "SIGINT", s.sim_time_sec);
      return 128 + sig;
    }
    return 0;
  }

 private:
  CLI::App* verb_ = nullptr;
  std::string world_path_;
  RunOptions options_;
  std::optional<double> duration_;
  std::string tier_;
  int spp_ = 0, threads_ = -1;
  std::optional<uint64_t> seed_;
  bool quiet_ = false;
  std::string outputs_;
  BackendFlag backend_;
  BridgeFlags bridge_flags_;
  ViewerFlag viewer_flag_;
  std::string override_;
  std::string start_pose_;
};

}  // namespace

std::unique_ptr<Command> MakeRunCommand() { return std::make_unique<RunCommand>(); }

}  // namespace penumbra

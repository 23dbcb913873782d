#include "penumbra/app/viewer_commands.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <algorithm>
#include <atomic>
#include <chrono>
#include <filesystem>
#include <mutex>
#include <nlohmann/json.hpp>
#include <thread>

#include "penumbra/app/backend_flag.h"
#include "penumbra/app/cli_options.h"
#include "penumbra/app/stop_signals.h"
#include "penumbra/bench/net/viewer_bench.h"
#include "penumbra/core/error.h"
#include "penumbra/viewer/viewer_bridge.h"
#include "penumbra/viewer/viewer_messages.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

void AddViewerAllowOrigin(CLI::App* verb, std::vector<std::string>* origins) {
  verb->add_option("--viewer-allow-origin", *origins,
                   "let pages of this origin (http(s)://HOST[:PORT]) use the viewer too, besides "
                   "its own page on 127.0.0.1/localhost/[::1]; repeatable (docs/viewer.md)")
      ->type_name("ORIGIN")
      ->allow_extra_args(false);  // one value per flag: a positional after it stays positional
}

void ViewerFlag::Add(CLI::App* run) {
  run->add_option("--viewer", address,
                  "serve a live viewer to browsers (docs/viewer.md) on HOST:PORT (default "
                  "127.0.0.1:8080; loopback unless told); open the URL it prints (it holds the "
                  "run's secret token)")
      ->expected(0, 1)
      ->type_name("[HOST:PORT]");
  AddViewerAllowOrigin(run, &allow_origins);
}

void ViewerFlag::Apply(const CLI::App& run, RunOptions* options) const {
  if (run.count("--viewer") == 0) {
    if (run.count("--viewer-allow-origin") > 0)
      throw ConfigError("", 0, "--viewer-allow-origin",
                        "given without --viewer; expected it with --viewer (the viewer it opens)");
    return;
  }
  ViewerOptions v;
  ParseViewerAddress(address, &v);
  v.allowed_origins = allow_origins;
  options->bridges.push_back(MakeViewerBridgeFactory(v));
}

namespace {

// the live recordings (*.plog) under `dir`, relative to it
std::vector<std::string> Recordings(const std::filesystem::path& dir) {
  namespace fs = std::filesystem;
  std::vector<std::string> out;
  std::error_code ec;
  for (fs::recursive_directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec))
    if (it->is_regular_file(ec) && it->path().extension() == ".plog")
      out.push_back(it->path().lexically_relative(dir).string());
  return out;
}

}  // namespace

int RunView(const WorldConfig& world, const ViewOptions& options,
            const std::atomic<int>* stop_request) {
  namespace fs = std::filesystem;
  ViewerOptions v;
  ParseViewerAddress(options.address, &v);
  v.allowed_origins = options.allow_origins;
  RunOptions o;
  o.realtime = true;
  o.lockstep = !options.running;
  o.progress = false;
  o.force = options.force;
  o.duration_sec = options.duration_sec;
  o.adversity = options.adversity;
  o.command_line = options.command_line;
  o.stop_request = stop_request;
  // the cameras render for the page; their files go to a folder removed at exit unless --out
  const bool temporary = options.out_dir.empty();
  o.out_dir =
      temporary ? (fs::temp_directory_path() / fmt::format("penumbra_view_{}", ::getpid())).string()
                : options.out_dir;
  if (temporary) fs::remove_all(o.out_dir);
  o.bridges.push_back(MakeViewerBridgeFactory(v));
  spdlog::info("penumbra view: {} {}; Ctrl-C ends it", world.file.empty() ? "model" : world.file,
               options.running ? "running in real time" : "paused: press play in the page");
  // the page's record button writes into the output folder: a temporary one that holds a
  // recording is kept (and named) instead of removed
  auto clean_up = [&] {
    if (!temporary) return;
    const std::vector<std::string> logs = Recordings(o.out_dir);
    if (!logs.empty()) {
      spdlog::info("penumbra view: kept {} with {} live recording(s) ({}{})", o.out_dir,
                   logs.size(), logs.front(), logs.size() > 1 ? ", ..." : "");
      return;
    }
    std::error_code ec;
    fs::remove_all(o.out_dir, ec);
  };
  try {
    const RunSummary s = RunWorld(world, o);
    spdlog::info("view ended at {:.3f} s of sim time ({} steps)", s.sim_time_sec, s.physics_steps);
  } catch (...) {
    clean_up();
    throw;
  }
  clean_up();
  return 0;
}

namespace {

class ViewCommand : public Command {
 public:
  std::string name() const override { return "view"; }
  std::string summary() const override {
    return "a world served live to browsers: real time, paused at the start (docs/viewer.md)";
  }

  void AddOptions(CLI::App* view) override {
    view->add_option("world", world_path_, "world file (.yaml) or model (.xml MJCF, .urdf)")
        ->required();
    view->add_option("--viewer", options_.address,
                     "HOST:PORT to serve on (default 127.0.0.1:8080; loopback unless told); open "
                     "the URL it prints (it holds the run's secret token)");
    AddViewerAllowOrigin(view, &options_.allow_origins);
    view->add_option("--out,-o", options_.out_dir,
                     "keep the camera outputs in this folder (default: a temporary folder, "
                     "removed at exit)");
    AddDecimal(
        view, "--duration", [this](double v) { options_.duration_sec = v; }, 0, true,
        "simulated seconds (default: the world's duration_sec)");
    view->add_option("--adversity", options_.adversity,
                     "adversity preset: none, minor, major, FILE.yaml or FILE.yaml#NAME");
    view->add_flag("--running", options_.running, "start running instead of paused");
    view->add_flag("--force", options_.force, "--out may hold an earlier run's outputs");
    backend_.Add(view);
  }

  int Run(const CommandArgs& args) override {
    const std::optional<RenderSettings::Backend> backend = backend_.Resolve();
    WorldConfig world = LoadWorldOrModel(world_path_);
    if (backend) world.render.backend = *backend;
    options_.command_line = args.command_line;
    const StopSignals stop_signals;
    return RunView(world, options_, args.stop_signal);
  }

 private:
  std::string world_path_;
  ViewOptions options_;
  BackendFlag backend_;
};

class BenchViewerCommand : public Command {
 public:
  std::string name() const override { return "bench viewer"; }
  std::string summary() const override {
    return "live viewer: frames/s delivered, input-to-photon latency, steps/s with a viewer";
  }

  void AddOptions(CLI::App* verb) override {
    verb->add_option("--world", options_.world_file, "world file (default: bundled default world)");
    AddDecimal(
        verb, "--seconds", [this](double v) { options_.seconds = v; }, 0, true,
        "simulated seconds per timed run");
    AddInteger(verb, "--rounds", &options_.rounds, 1, 100, "A/B pairs");
    AddDecimal(
        verb, "--camera-hz", [this](double v) { options_.camera_hz = v; }, 0, true,
        "rate of the streamed camera, Hz");
    AddInteger(verb, "--latency-samples", &options_.latency_samples, 0, 1000,
               "teleop commands timed at real-time pacing (0 = none)");
  }

  int Run(const CommandArgs&) override { return BenchViewer(options_); }

 private:
  BenchViewerOptions options_;
};

}  // namespace

std::unique_ptr<Command> MakeViewCommand() { return std::make_unique<ViewCommand>(); }
std::unique_ptr<Command> MakeBenchViewerCommand() { return std::make_unique<BenchViewerCommand>(); }

}  // namespace penumbra

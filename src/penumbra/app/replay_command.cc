#include "penumbra/app/replay_command.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <CLI/CLI.hpp>
#include <charconv>
#include <cmath>
#include <iostream>
#include <optional>

#include "penumbra/app/backend_flag.h"
#include "penumbra/app/stop_signals.h"
#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/replay/kinematic/replay_runner.h"
#include "penumbra/replay/resimulate.h"
#include "penumbra/run/runner.h"

namespace penumbra {

struct ReplayCommand::State {
  CLI::App* verb = nullptr;
  ReplayOptions options;
  std::string tier, outputs, resimulate;
  CLI::Option* resimulate_option = nullptr;
  std::optional<double> from_sec, to_sec;
  bool quiet = false;
  int threads = -1;
  BackendFlag backend;
};

namespace {

// a finite decimal number >= 0 (core/text_match.h; no hex, nan or inf, which CLI11's own
// conversion accepts)
std::optional<double> ParseSeconds(const std::string& s) {
  const std::optional<double> v = ParseDecimal(s);
  if (!v || *v < 0) return std::nullopt;
  return v;
}

void AddSeconds(CLI::App* app, const std::string& name, std::optional<double>* target,
                const std::string& help) {
  app->add_option_function<std::string>(
         name, [target](const std::string& s) { *target = *ParseSeconds(s); }, help)
      ->type_name("SEC")
      ->check(CLI::Validator(
          [](std::string& s) -> std::string {
            return ParseSeconds(s) ? "" : "'" + s + "' is not a finite decimal number >= 0";
          },
          "SEC >= 0", ""));
}

}  // namespace

ReplayCommand::ReplayCommand() : state_(std::make_unique<State>()) {}
ReplayCommand::~ReplayCommand() = default;

std::string ReplayCommand::name() const { return "replay"; }

std::string ReplayCommand::summary() const {
  return "render a recorded run (.plog, run --record) again under other visual conditions, or "
         "re-run its physics and check it against the log (--resimulate)";
}

void ReplayCommand::AddOptions(CLI::App* r) {
  State& s = *state_;
  s.verb = r;
  ReplayOptions& o = s.options;
  r->add_option("log", o.log_path, "run log (.plog) written by penumbra run --record")->required();
  r->add_option("--out,-o", o.out_dir,
                "output folder (required for a kinematic replay; with --resimulate: the "
                "metrics and run.json)");
  r->add_flag("--force", o.force,
              "the output folder may hold an earlier run's outputs: remove them first");
  r->add_option("--adversity", o.adversity,
                "adversity preset: none, minor, major, FILE.yaml or FILE.yaml#NAME (default: as "
                "recorded); its NPCs keep clear of the logged robot (NPCs that may touch it "
                "are refused)");
  r->add_option("--world", o.world_override,
                "world-file fragment replacing visual keys of the recorded world (cameras, "
                "lights, sky, materials, render, effects, ...; docs/replay.md)");
  r->add_option("--tier", s.tier, "render tier (default: as recorded)")
      ->check(CLI::IsMember({"realtime", "pathtraced"}));
  r->add_option("--cameras", o.cameras, "cameras to render, comma-separated (default: all)")
      ->delimiter(',');
  AddSeconds(r, "--from", &s.from_sec, "first sim time replayed, s (default: the log's start)");
  AddSeconds(r, "--to", &s.to_sec, "last sim time replayed, s (default: the log's end)");
  r->add_option("--threads", s.threads, "render threads (0 = all cores; default: as recorded)")
      ->check(CLI::Range(0, 256));
  r->add_option("--outputs", s.outputs,
                "images of every camera, comma-separated: rgb, depth, segmentation, range, "
                "normals, instance_segmentation, semantic_segmentation (default: as recorded)");
  r->add_flag("--quiet,-q", s.quiet, "no progress output");
  s.backend.Add(r, "as recorded");
  s.resimulate_option =
      r->add_option("--resimulate", s.resimulate,
                    "re-run physics from the log and check every step: `--resimulate` runs the "
                    "world's controllers again, `--resimulate ctrl` applies the logged ctrl")
          ->expected(0, 1)
          ->check(CLI::IsMember({"controllers", "ctrl"}));
}

int ReplayCommand::Run(const CommandArgs& args) {
  const StopSignals stop_signals;
  const std::vector<std::string>& command_line = args.command_line;
  const std::atomic<int>* stop_request = args.stop_signal;
  const State& s = *state_;
  CLI::App* r = s.verb;
  if (s.resimulate_option->count() > 0) {
    // physics only: the options that change what is seen do not apply
    for (const char* flag : {"--adversity", "--world", "--tier", "--cameras", "--from", "--to",
                             "--threads", "--outputs", "--backend"})
      if (r->count(flag) > 0)
        throw ConfigError("", 0, flag,
                          "does not apply to --resimulate, which re-runs the recorded physics "
                          "and renders nothing; expected it without --resimulate");
    if (r->count("--force") > 0 && s.options.out_dir.empty())
      throw ConfigError("", 0, "--force", "needs --out DIR; expected it with --out");
    ResimulateOptions o;
    o.log_path = s.options.log_path;
    o.out_dir = s.options.out_dir;
    o.force = s.options.force;
    o.command_line = command_line;
    o.mode = s.resimulate == "ctrl" ? ResimulateMode::kCtrl : ResimulateMode::kControllers;
    o.stop_request = stop_request;
    const ResimulateReport report = ResimulateLog(o);
    std::cout << report.Describe() << std::endl;
    if (report.divergence) return 3;
    if (report.interrupted && stop_request) return 128 + stop_request->load();
    // a damaged log (or one not checked to its end) is not bit-exact: a runtime failure
    if (!report.bit_exact()) return 1;
    return 0;
  }

  ReplayOptions o = s.options;
  if (o.out_dir.empty())
    throw ConfigError("", 0, "--out", "required; expected the replay's output folder");
  if (!s.tier.empty())
    o.tier = s.tier == "pathtraced" ? RenderSettings::Tier::kPathtraced
                                    : RenderSettings::Tier::kRealtime;
  if (r->count("--outputs") > 0) {
    o.outputs = ParseCameraOutputs(s.outputs);
    o.outputs_text = s.outputs;
  }
  o.from_sec = s.from_sec;
  o.to_sec = s.to_sec;
  o.threads = s.threads;
  o.backend = s.backend.Resolve();
  o.progress = !s.quiet;
  o.stop_request = stop_request;
  o.command_line = command_line;
  const ReplaySummary summary = ReplayLog(o);
  int64_t frames = 0;
  for (const auto& [name, n] : summary.frames_per_camera) frames += n;
  spdlog::info("done: steps {} to {} ({:.3f} s sim time), {} frames in {:.2f} s wall -> {}",
               summary.first_step, summary.last_step, summary.sim_time_sec, frames,
               summary.wall_time_sec, summary.out_dir);
  if (summary.interrupted) {
    spdlog::warn("interrupted at {:.6g} s of sim time; outputs and run.json written",
                 summary.sim_time_sec);
    return stop_request ? 128 + stop_request->load() : 130;
  }
  return 0;
}

}  // namespace penumbra

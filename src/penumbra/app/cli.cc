#include "penumbra/app/cli.h"

#include <fmt/format.h>
#include <signal.h>
#include <spdlog/sinks/stdout_color_sinks.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <atomic>
#include <charconv>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <limits>
#include <optional>

#include "penumbra/app/backend_flag.h"
#include "penumbra/bench/bench.h"
#include "penumbra/bench/bench_bridge.h"
#include "penumbra/bench/bench_record.h"
#include "penumbra/bench/bench_ros.h"
#include "penumbra/app/benchmark_command.h"
#include "penumbra/app/bridge_flags.h"
#include "penumbra/app/contact_sheet.h"
#include "penumbra/app/decompose_command.h"
#include "penumbra/app/eval_command.h"
#include "penumbra/app/export_command.h"
#include "penumbra/app/heightfield_tool.h"
#include "penumbra/app/npc_map_command.h"
#include "penumbra/app/replay_command.h"
#include "penumbra/run/runner.h"
#include "penumbra/bench/sensor_bench.h"
#include "penumbra/app/vdb_tool.h"
#include "penumbra/app/viewer_commands.h"
#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/renderer.h"
#include "penumbra/replay/world_override.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

// a world file (.yaml/.yml) or a bare model (.xml MJCF, .urdf)
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

WorldConfig LoadWorldOrModel(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".xml" || ext == ".urdf" || ext == ".mjcf") return WorldForBareModel(path);
  if (ext == ".yaml" || ext == ".yml") return LoadWorldFile(path);
  throw ConfigError(path, 0, "",
                    "unknown file type '" + ext +
                        "'; expected a world file (.yaml, .yml) or a model (.xml MJCF, .urdf)");
}

std::vector<std::string> Args(int argc, char** argv) { return std::vector<std::string>(argv, argv + argc); }

// strict command-line numbers: plain decimal only. CLI11's own conversion accepts hex
// (0x10), octal and binary prefixes and nan/inf, and clamps out-of-range integers.

// an unsigned decimal integer: digits only (a leading '+' is allowed)
std::optional<uint64_t> ParseUnsigned(std::string_view s) {
  if (!s.empty() && s.front() == '+') s.remove_prefix(1);
  if (s.empty()) return std::nullopt;
  for (char c : s)
    if (c < '0' || c > '9') return std::nullopt;
  uint64_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

// a decimal integer that fits int64: [+-]digits
std::optional<int64_t> ParseInteger(std::string_view s) {
  std::string_view digits = s;
  if (!digits.empty() && (digits.front() == '+' || digits.front() == '-')) digits.remove_prefix(1);
  if (!ParseUnsigned(digits) || digits.front() == '+') return std::nullopt;
  if (s.front() == '+') s.remove_prefix(1);
  int64_t v = 0;
  const auto r = std::from_chars(s.data(), s.data() + s.size(), v);
  if (r.ec != std::errc() || r.ptr != s.data() + s.size()) return std::nullopt;
  return v;
}

// integer option in [lo, hi]
template <typename T>
CLI::Option* AddInteger(CLI::App* app, const std::string& name, T* target, int64_t lo, int64_t hi,
                        const std::string& help) {
  const std::string range = fmt::format("an integer in [{}, {}]", lo, hi);
  return app
      ->add_option_function<std::string>(
          name, [target](const std::string& s) { *target = static_cast<T>(*ParseInteger(s)); },
          help)
      ->type_name("INT")
      ->check(CLI::Validator(
          [lo, hi, range](std::string& s) -> std::string {
            const std::optional<int64_t> v = ParseInteger(s);
            if (!v || *v < lo || *v > hi) return "'" + s + "' is not " + range;
            return "";
          },
          range, ""));
}

// any uint64 (seeds): 0 .. 18446744073709551615, recorded exactly
CLI::Option* AddUint64(CLI::App* app, const std::string& name, std::optional<uint64_t>* target,
                       const std::string& help) {
  return app
      ->add_option_function<std::string>(
          name, [target](const std::string& s) { *target = *ParseUnsigned(s); }, help)
      ->type_name("UINT64")
      ->check(CLI::Validator(
          [](std::string& s) -> std::string {
            if (!s.empty() && s.front() == '-')
              return "'" + s + "' is negative; expected an integer in [0, 2^64 - 1]";
            if (!ParseUnsigned(s))
              return "'" + s + "' is not a decimal integer in [0, 2^64 - 1] (18446744073709551615)";
            return "";
          },
          "UINT64", ""));
}

// decimal number option: > lo (lo_open) or >= lo
CLI::Option* AddDecimal(CLI::App* app, const std::string& name, std::function<void(double)> set,
                        double lo, bool lo_open, const std::string& help) {
  const std::string range = fmt::format("a finite decimal number {} {}", lo_open ? ">" : ">=", lo);
  return app
      ->add_option_function<std::string>(
          name, [set](const std::string& s) { set(*ParseDecimal(s)); }, help)
      ->type_name("NUM")
      ->check(CLI::Validator(
          [lo, lo_open, range](std::string& s) -> std::string {
            const std::optional<double> v = ParseDecimal(s);
            if (!v) return "'" + s + "' is not " + range;
            if (lo_open ? !(*v > lo) : !(*v >= lo))
              return "'" + s + "' is out of range; expected " + range;
            return "";
          },
          range, ""));
}

// SIGINT / SIGTERM during `penumbra run`: the first asks the run to stop at the next physics
// step boundary (RunOptions::stop_request), the second exits at once. async-signal-safe:
// a lock-free atomic, write(2) and _exit(2) only.
std::atomic<int> g_stop_signal{0};
static_assert(std::atomic<int>::is_always_lock_free);

constexpr char kRunStopMessage[] =
    "\npenumbra: stopping at the next physics step and writing the outputs "
    "(signal again to exit at once)\n";
constexpr char kExportStopMessage[] =
    "\npenumbra: stopping the export and removing its partial output "
    "(signal again to exit at once)\n";
// the message of the first signal (set before the handler is installed)
const char* g_stop_message = kRunStopMessage;

extern "C" void OnStopSignal(int sig) {
  int expected = 0;
  if (!g_stop_signal.compare_exchange_strong(expected, sig)) _exit(128 + sig);
  const ssize_t ignored = write(STDERR_FILENO, g_stop_message, strlen(g_stop_message));
  (void)ignored;
}

// installs OnStopSignal for SIGINT and SIGTERM while it lives
class StopSignals {
 public:
  explicit StopSignals(const char* message = kRunStopMessage) {
    g_stop_message = message;
    struct sigaction sa = {};
    sa.sa_handler = OnStopSignal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
  }

 private:
  struct sigaction old_int_ = {}, old_term_ = {};
};

// an empty value ("") given to an option that takes one, e.g. `--out ""`: refused instead of
// falling back to the default (options whose value is optional, `--zmq`, are skipped: CLI11
// records their bare form as "" too). walks the subcommands that were parsed.
void RefuseEmptyValues(const CLI::App& app) {
  for (const CLI::Option* o : app.get_options()) {
    if (o->count() == 0 || o->get_expected_min() < 1) continue;
    for (const std::string& v : o->results()) {
      if (!v.empty()) continue;
      const std::string name = o->get_name();
      throw ConfigError(
          "", 0, name,
          "an empty value; expected a non-empty " +
              std::string(o->nonpositional() ? "value (leave " + name + " out for its default)"
                                             : "argument"));
    }
  }
  for (const CLI::App* sub : app.get_subcommands()) RefuseEmptyValues(*sub);
}

// errors and logs go to stderr; stdout carries only what was asked for (--help, --version)
void LogToStderr() {
  auto logger =
      std::make_shared<spdlog::logger>("", std::make_shared<spdlog::sinks::stderr_color_sink_mt>());
  spdlog::set_default_logger(std::move(logger));
}

}  // namespace

int RunCli(int argc, char** argv) {
  LogToStderr();
  CLI::App app{"penumbra: robotics simulator with MuJoCo physics and a physically based ray tracer"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string(PENUMBRA_VERSION));

  // penumbra run
  CLI::App* run = app.add_subcommand("run", "simulate a world file or a bare MJCF/URDF model and write outputs");
  std::string world_path;
  RunOptions run_options;
  std::optional<double> duration;
  std::string tier;
  int spp = 0, threads = -1;
  std::optional<uint64_t> seed;
  bool quiet = false;
  std::string outputs;
  run->add_option("world", world_path, "world file (.yaml) or model (.xml MJCF, .urdf)")->required();
  run->add_option("--out,-o", run_options.out_dir, "output folder (default: the world's output.dir)");
  AddDecimal(
      run, "--duration", [&](double v) { duration = v; }, 0, true,
      "simulated seconds (overrides duration_sec)");
  run->add_flag("--realtime", run_options.realtime, "pace physics to wall-clock time");
  run->add_option("--tier", tier, "render tier")->check(CLI::IsMember({"realtime", "pathtraced"}));
  BackendFlag run_backend;
  run_backend.Add(run);
  AddInteger(run, "--spp", &spp, 1, 65536, "samples per pixel (pathtraced)");
  AddInteger(run, "--threads", &threads, 0, 256, "render threads (0 = all cores)");
  AddUint64(run, "--seed", &seed, "world seed (overrides seed)");
  run->add_flag("--quiet,-q", quiet, "no progress output");
  AddDecimal(
      run, "--progress-interval", [&](double v) { run_options.progress_interval_sec = v; }, 0,
      false,
      "pathtraced tier: the least seconds between sample-pass progress lines (with an ETA; "
      "default 1, 0 = every pass)");
  run->add_flag("--force", run_options.force,
                "the output folder may hold an earlier run's outputs: remove them first "
                "(anything else there is refused)");
  run->add_option("--outputs", outputs,
                  "images of every camera, comma-separated: rgb, depth, segmentation, range, "
                  "normals, instance_segmentation, semantic_segmentation (overrides the world)");
  run->add_option("--record", run_options.record_file,
                  "write a run log of every physics step to FILE.plog (docs/run-log.md)");
  run->add_flag("--record-sensors", run_options.record_sensors,
                "the run log also holds every camera image and sensor output");
  BridgeFlags bridge_flags;
  bridge_flags.Add(run);
  ViewerFlag viewer_flag;
  viewer_flag.Add(run);
  run->add_option("--adversity", run_options.adversity,
                  "adversity preset: none, minor, major, FILE.yaml or FILE.yaml#NAME "
                  "(worlds/adversity/presets.yaml; overrides the world's `adversity`)");
  std::string run_override;
  run->add_option("--override", run_override,
                  "a world-file fragment whose top-level keys replace the world's (the keys "
                  "`penumbra replay --world` takes: cameras, sensors, metrics, ...; physics "
                  "keys are refused)");
  std::string start_pose;
  run->add_option("--start-pose", start_pose,
                  "ROBOT,X,Y,YAW_DEG: place the robot ROBOT at (X, Y) m in the world frame, "
                  "turned YAW_DEG about z (its z, roll and pitch stay the world file's)");

  // penumbra bench render|physics
  CLI::App* bench = app.add_subcommand("bench", "throughput benchmarks (not tests)");
  bench->require_subcommand(1);
  CLI::App* bench_render = bench->add_subcommand("render", "frames/s and Mrays/s at 640x480 and 800x800");
  RenderBenchOptions render_bench;
  bench_render->add_option("--world", render_bench.world_file, "world file (default: bundled default world)");
  AddInteger(bench_render, "--frames", &render_bench.frames, 1, 100000,
             "timed frames per resolution");
  AddInteger(bench_render, "--threads", &render_bench.threads, 0, 256,
             "render threads (0 = all cores)");
  bench_render->add_option("--tier", render_bench.tier, "render tier")->check(CLI::IsMember({"realtime", "pathtraced"}));
  BackendFlag bench_render_backend;
  bench_render_backend.Add(bench_render);
  AddInteger(bench_render, "--batch", &render_bench.batch, 1, 65535,
             "batch rendering: N cameras per launch on the CUDA backend (depth+seg; "
             "docs/gpu.md)");
  std::string bench_size;
  bench_render->add_option("--size", bench_size, "WxH of each camera in --batch (default 128x128)")
      ->check(CLI::Validator(
          [](std::string& v) -> std::string {
            const size_t x = v.find('x');
            const std::optional<uint64_t> w =
                x == std::string::npos ? std::nullopt : ParseUnsigned(v.substr(0, x));
            const std::optional<uint64_t> h =
                x == std::string::npos ? std::nullopt : ParseUnsigned(v.substr(x + 1));
            if (!w || !h || *w < 1 || *h < 1 || *w > 16384 || *h > 16384)
              return "'" + v + "' is not WxH with W and H in [1, 16384], e.g. 128x128";
            return "";
          },
          "WxH", ""));
  AddInteger(bench_render, "--sessions", &render_bench.sessions, 1, 64,
             "--batch: spread the cameras over this many sessions of the world (default 1)");
  bool no_adversity = false;
  bench_render->add_flag("--no-adversity", no_adversity, "skip the none/minor/major preset lines");
  bench_render
      ->add_option("--ablate", render_bench.ablate,
                   "switch parts of the CPU renderer off to time what they cost: mirror, "
                   "mirror-sparse, sky-volume, texture-filter, shadows, sun-occluder, "
                   "film (docs/performance.md)")
      ->delimiter(',');
  bench_render->add_flag("--only-640x480", render_bench.only_640x480,
                         "time only 640x480 (skip 800x800)");
  // penumbra contact-sheet / make-vdb (app/contact_sheet.h, app/vdb_tool.h)
  // penumbra heightfield (app/heightfield_tool.h)
  CLI::App* hfield = app.add_subcommand("heightfield", "a world's static geometry sampled from above into a MuJoCo hfield model");
  HeightFieldOptions hfield_options;
  hfield->add_option("world", hfield_options.world_file, "world file")->required();
  hfield->add_option("--model", hfield_options.model, "sample only this model's geoms (default: every static geom)");
  AddDecimal(
      hfield, "--cell", [&](double v) { hfield_options.cell_m = v; }, 0, true,
      "sample spacing, m (default 0.1)");
  std::vector<double> hfield_extent;
  hfield->add_option("--extent", hfield_extent, "plan rectangle x0,y0,x1,y1 in m (default: the geometry's bounds)")
      ->delimiter(',')
      ->expected(4);
  hfield->add_option("--out,-o", hfield_options.out_dir, "output folder (default .)");
  hfield->add_option("--name", hfield_options.name, "file stem (default: the model's name, or terrain)");
  CLI::App* sheet = app.add_subcommand("contact-sheet", "one instant of a world under adversity presets, side by side, as a PNG");
  ContactSheetOptions sheet_options;
  sheet->add_option("--world", sheet_options.worlds, "world file, one row each; repeat for more rows (default: bundled default world)");
  sheet->add_option("--presets", sheet_options.presets, "presets, left to right")->delimiter(',');
  AddDecimal(
      sheet, "--time", [&](double v) { sheet_options.time_sec = v; }, 0, false,
      "sim time of the frames, s");
  AddInteger(sheet, "--width", &sheet_options.width, 16, 4096, "frame width");
  AddInteger(sheet, "--height", &sheet_options.height, 16, 4096, "frame height");
  sheet->add_option("--out,-o", sheet_options.out, "output PNG (default docs/effects.png)");
  AddInteger(sheet, "--threads", &sheet_options.threads, 0, 256, "render threads (0 = all cores)");
  BackendFlag sheet_backend;
  sheet_backend.Add(sheet, "each world's render.backend");
  // penumbra npc-map (app/npc_map_command.h)
  CLI::App* npc_map = app.add_subcommand("npc-map", "the walkable map of a world's NPCs (people, vehicles, areas, lanes) as a PNG");
  NpcMapOptions npc_map_options;
  npc_map->add_option("world", npc_map_options.world_file, "world file")->required();
  npc_map->add_option("--out,-o", npc_map_options.out, "output PNG (default npc_map.png)");
  npc_map->add_option("--adversity", npc_map_options.adversity, "adversity preset whose crowd to place (default: the world's own)");
  AddInteger(npc_map, "--pixels", &npc_map_options.pixels_per_cell, 1, 16, "pixels per 0.1 m cell (default 4)");
  CLI::App* make_vdb = app.add_subcommand("make-vdb", "write a procedural smoke cloud as an OpenVDB file (float grid 'density')");
  std::string vdb_path;
  SmokeVdbOptions vdb_options;
  std::optional<uint64_t> vdb_seed;
  make_vdb->add_option("file", vdb_path, "output .vdb file")->required();
  AddUint64(make_vdb, "--seed", &vdb_seed, "blob layout seed");
  AddDecimal(
      make_vdb, "--voxel", [&](double v) { vdb_options.voxel_m = v; }, 0, true, "voxel size, m");
  AddDecimal(
      make_vdb, "--radius", [&](double v) { vdb_options.radius_m = v; }, 0, true,
      "cloud radius, m");
  AddInteger(make_vdb, "--blobs", &vdb_options.blobs, 1, 64, "Gaussian puffs");
  CLI::App* bench_physics = bench->add_subcommand("physics", "Penumbra physics steps/s vs a bare mj_step loop");
  PhysicsBenchOptions physics_bench;
  bench_physics->add_option("--world", physics_bench.world_file, "world file (default: bundled default world)");
  bench_physics->add_option("--model", physics_bench.model_file, "bare MJCF model instead of a world");
  AddDecimal(
      bench_physics, "--seconds", [&](double v) { physics_bench.sim_seconds = v; }, 0, true,
      "simulated seconds per side");
  bool no_controllers = false;
  bench_physics->add_flag("--no-controllers", no_controllers, "skip the controller-cost table of the bundled robot worlds");
  const std::unique_ptr<BenchRecordCommand> bench_record = AddBenchRecordCommand(*bench);
  const std::unique_ptr<BenchBridgeCommand> bench_bridge = AddBenchBridgeCommand(*bench);
  const std::unique_ptr<BenchRosCommand> bench_ros = AddBenchRosCommand(*bench);
  // penumbra decompose / penumbra bench decompose (app/decompose_command.h, docs/collision.md)
  const std::unique_ptr<DecomposeCommands> decompose = AddDecomposeCommands(app, *bench);
  // penumbra bench viewer / penumbra view (app/viewer_commands.h, docs/viewer.md)
  CLI::App* bench_viewer = bench->add_subcommand(
      "viewer", "live viewer: frames/s delivered, input-to-photon latency, steps/s with a viewer");
  BenchViewerOptions viewer_bench;
  bench_viewer->add_option("--world", viewer_bench.world_file,
                           "world file (default: bundled default world)");
  AddDecimal(
      bench_viewer, "--seconds", [&](double v) { viewer_bench.seconds = v; }, 0, true,
      "simulated seconds per timed run");
  AddInteger(bench_viewer, "--rounds", &viewer_bench.rounds, 1, 100, "A/B pairs");
  AddDecimal(
      bench_viewer, "--camera-hz", [&](double v) { viewer_bench.camera_hz = v; }, 0, true,
      "rate of the streamed camera, Hz");
  AddInteger(bench_viewer, "--latency-samples", &viewer_bench.latency_samples, 0, 1000,
             "teleop commands timed at real-time pacing (0 = none)");
  CLI::App* view = app.add_subcommand(
      "view", "a world served live to browsers: real time, paused at the start (docs/viewer.md)");
  std::string view_world;
  ViewOptions view_options;
  view->add_option("world", view_world, "world file (.yaml) or model (.xml MJCF, .urdf)")
      ->required();
  view->add_option("--viewer", view_options.address,
                   "HOST:PORT to serve on (default 127.0.0.1:8080; loopback unless told); open "
                   "the URL it prints (it holds the run's secret token)");
  AddViewerAllowOrigin(view, &view_options.allow_origins);
  view->add_option("--out,-o", view_options.out_dir,
                   "keep the camera outputs in this folder (default: a temporary folder, removed "
                   "at exit)");
  AddDecimal(
      view, "--duration", [&](double v) { view_options.duration_sec = v; }, 0, true,
      "simulated seconds (default: the world's duration_sec)");
  view->add_option("--adversity", view_options.adversity,
                   "adversity preset: none, minor, major, FILE.yaml or FILE.yaml#NAME");
  view->add_flag("--running", view_options.running, "start running instead of paused");
  view->add_flag("--force", view_options.force, "--out may hold an earlier run's outputs");
  BackendFlag view_backend;
  view_backend.Add(view);
  CLI::App* bench_sensors = bench->add_subcommand("sensors", "LiDAR rays/s and ms/scan, IMU/MuJoCo sensor overhead");
  SensorBenchOptions sensor_bench;
  bench_sensors->add_option("--world", sensor_bench.world_file, "world file (default: bundled default world)");
  AddInteger(bench_sensors, "--scans", &sensor_bench.scans, 1, 100000,
             "timed scans per LiDAR preset");
  AddDecimal(
      bench_sensors, "--seconds", [&](double v) { sensor_bench.seconds = v; }, 0, true,
      "simulated seconds for the sensor overhead");

  // penumbra eval ate|rpe (app/eval_command.h)
  const EvalCommand eval = AddEvalCommand(app);
  // penumbra export (app/export_command.h)
  const ExportCommand export_command = AddExportCommand(app);
  // penumbra replay (app/replay_command.h)
  const ReplayCommand replay = AddReplayCommand(app);
  // penumbra benchmark / slam (app/benchmark_command.h)
  const BenchmarkCommands benchmark_commands(app);

  // usage errors exit 2 with CLI11's message on stderr; --help and --version print to stdout
  // and exit 0
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e, std::cout, std::cerr);
    return code == 0 ? 0 : 2;
  }
  if (vdb_seed) vdb_options.seed = *vdb_seed;

  try {
    RefuseEmptyValues(app);
    if (*run) {
      WorldConfig world = LoadWorldOrModel(world_path);
      if (!run_override.empty()) world = ApplyWorldOverride(world, run_override);
      if (!start_pose.empty()) ApplyStartPose(start_pose, &world);
      if (duration) run_options.duration_sec = *duration;
      if (seed) world.seed = *seed;
      if (!tier.empty())
        world.render.tier = tier == "pathtraced" ? RenderSettings::Tier::kPathtraced : RenderSettings::Tier::kRealtime;
      if (spp > 0) world.render.samples_per_pixel = spp;
      if (threads >= 0) world.render.threads = threads;
      run_backend.Apply(&world.render);
      run_options.progress = !quiet;
      run_options.command_line = Args(argc, argv);
      if (!outputs.empty() || run->count("--outputs"))
        run_options.outputs = ParseCameraOutputs(outputs);
      bridge_flags.Apply(*run, &run_options);
      viewer_flag.Apply(*run, &run_options);
      g_stop_signal.store(0);
      run_options.stop_request = &g_stop_signal;
      const StopSignals stop_signals;
      const RunSummary s = RunWorld(world, run_options);
      int64_t frames = 0;
      for (const auto& [name, n] : s.frames_per_camera) frames += n;
      spdlog::info("done: {:.3f} s sim time, {} steps, {} frames in {:.2f} s wall, peak RSS {:.0f} MiB -> {}",
                   s.sim_time_sec, s.physics_steps, frames, s.wall_time_sec, s.peak_rss_mib, s.out_dir);
      if (s.interrupted && g_stop_signal.load() == 0) {
        spdlog::info(
            "stopped by a client's `stop` at {:.6g} s of sim time; outputs and run.json "
            "written",
            s.sim_time_sec);
        return 0;
      }
      if (s.interrupted) {
        const int sig = g_stop_signal.load();
        spdlog::warn("interrupted by {} at {:.6g} s of sim time; outputs and run.json written",
                     sig == SIGTERM ? "SIGTERM" : "SIGINT", s.sim_time_sec);
        return 128 + sig;
      }
      return 0;
    }
    if (replay.Selected()) {
      g_stop_signal.store(0);
      const StopSignals stop_signals;
      return replay.Run(Args(argc, argv), &g_stop_signal);
    }
    if (benchmark_commands.Selected()) {
      g_stop_signal.store(0);
      const StopSignals stop_signals;
      return benchmark_commands.Run(&g_stop_signal);
    }
    if (*bench_render) {
      render_bench.adversity = !no_adversity;
      render_bench.backend = bench_render_backend.Resolve();
      if (!bench_size.empty() || bench_render->count("--sessions") > 0) {
        if (render_bench.batch == 0)
          throw ConfigError("", 0, bench_size.empty() ? "--sessions" : "--size",
                            "applies to --batch only; expected it with --batch N");
      }
      if (!bench_size.empty()) {
        const size_t x = bench_size.find('x');
        render_bench.batch_width = static_cast<int>(*ParseUnsigned(bench_size.substr(0, x)));
        render_bench.batch_height = static_cast<int>(*ParseUnsigned(bench_size.substr(x + 1)));
      }
      return BenchRender(render_bench);
    }
    if (*sheet) {
      sheet_options.backend = sheet_backend.Resolve();
      return MakeContactSheet(sheet_options);
    }
    if (*npc_map) return WriteNpcMap(npc_map_options);
    if (*hfield) {
      if (!hfield_extent.empty())
        hfield_options.extent = {hfield_extent[0], hfield_extent[1], hfield_extent[2],
                                 hfield_extent[3]};
      return RunHeightField(hfield_options);
    }
    if (export_command.selected()) {
      g_stop_signal.store(0);
      const StopSignals stop_signals(kExportStopMessage);
      return export_command.Run(&g_stop_signal);
    }
    if (*make_vdb) {
      MakeSmokeVdb(vdb_path, vdb_options);
      return 0;
    }
    if (*bench_sensors) return BenchSensors(sensor_bench);
    if (eval.Selected()) return eval.Run();
    if (*bench_record->app) return bench_record->Run();
    if (*bench_bridge->app) return bench_bridge->Run();
    if (*bench_ros->app) return bench_ros->Run();
    if (*decompose->bench) return decompose->RunBench();
    if (*decompose->decompose) return decompose->RunDecompose();
    if (*bench_viewer) return BenchViewer(viewer_bench);
    if (*view) {
      const std::optional<RenderSettings::Backend> backend = view_backend.Resolve();
      WorldConfig world = LoadWorldOrModel(view_world);
      if (backend) world.render.backend = *backend;
      view_options.command_line = Args(argc, argv);
      g_stop_signal.store(0);
      const StopSignals stop_signals;
      return RunView(world, view_options, &g_stop_signal);
    }
    if (*bench_physics) {
      physics_bench.controllers = !no_controllers;
      return BenchPhysics(physics_bench);
    }
  } catch (const ConfigError& e) {
    spdlog::error("{}", e.what());
    return 2;
  } catch (const std::bad_alloc&) {
    spdlog::error(
        "out of memory; expected smaller images, fewer cameras or LiDAR columns "
        "(docs/world-file.md \"Input limits\")");
    return 1;
  } catch (const std::exception& e) {
    // bounded: a message may quote input (a 100 KB name in a path)
    spdlog::error("{}", SanitizeForMessage(e.what(), 2048));
    return 1;
  }
  return 0;
}

}  // namespace penumbra

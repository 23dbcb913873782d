#include "penumbra/bench/bench.h"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <ctime>
#include <filesystem>
#include <string>

#include "penumbra/bench/effects_bench.h"
#include "penumbra/core/bench_machine.h"
#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/controller_cost_benchmark.h"
#include "penumbra/physics/physics_benchmark.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/backends/render_ablation_switch.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/camera_pose.h"
#include "penumbra/session/session.h"
#include "penumbra/world/default_world.h"
#include "penumbra/world/world_config.h"
#if defined(PENUMBRA_WITH_CUDA)
#include "penumbra/render/cuda/cuda_batch_bench.h"
#include "penumbra/render/cuda/cuda_batch_kernels.h"
#endif

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;

// where the physics benchmarks keep the composed model they load (a temporary folder).
std::string BenchComposedPath() {
  const auto dir =
      std::filesystem::temp_directory_path() / fmt::format("penumbra_bench_{}", ::getpid());
  std::filesystem::create_directories(dir);
  return (dir / "composed.xml").string();
}

// `bench render --batch N`: N cameras over options.sessions sessions of `world` in one launch
// (render/cuda/cuda_batch_bench.h), beside the CPU backend rendering the same views
int BenchRenderBatch(const WorldConfig& world, const RenderBenchOptions& options) {
  if (ResolveBackend(world.render.backend) != RenderSettings::Backend::kCuda)
    throw ConfigError("", 0, "--batch",
                      "batch rendering runs on the CUDA backend; expected --backend cuda (or "
                      "auto on a machine with a CUDA device; docs/gpu.md)");
#if defined(PENUMBRA_WITH_CUDA)
  std::vector<std::unique_ptr<Session>> sessions;
  std::vector<cuda::BatchBenchWorld> worlds;
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  for (int s = 0; s < options.sessions; ++s) {
    sessions.push_back(std::make_unique<Session>(world, so));
    Simulation& sim = sessions.back()->sim();
    while (sim.time() < 1.0) sim.Step();
    const SceneDescription& scene = sessions.back()->scene();
    if (scene.cameras.empty())
      throw ConfigError(world.file, 0, "cameras", "bench render needs a camera");
    cuda::BatchBenchWorld w;
    w.scene = &scene;
    w.settings = world.render;
    w.snapshot = sim.Snapshot();
    const CameraSpec& cam = scene.cameras.front();
    w.view.X_WO = CameraPoseInWorld(cam, w.snapshot);
    w.view.intrinsics = cam.intrinsics;
    w.view.near_m = cam.near_m;
    worlds.push_back(w);
  }
  // the CPU backend on all cores (or --threads), one renderer: the sessions are the same world
  RenderSettings cpu_settings = world.render;
  cpu_settings.backend = RenderSettings::Backend::kEmbree;
  cpu_settings.threads = options.threads;
  const std::unique_ptr<Renderer> cpu = MakeRenderer(sessions.front()->scene(), cpu_settings);
  for (cuda::BatchBenchWorld& w : worlds) w.cpu = cpu.get();
  const CudaDeviceStatus dev = ProbeCudaDevice();
  fmt::print("penumbra bench render --batch {}: world {}, {} session(s), device {}\n",
             options.batch, world.file, options.sessions, dev.name);
  // depth + segmentation, then (realtime tier) rgb + depth
  cuda::BatchOutputs truth, rgb;
  rgb.segmentation = false;
  rgb.rgb = true;
  std::vector<cuda::BatchOutputs> sets = {truth};
  if (world.render.tier == RenderSettings::Tier::kRealtime)
    sets.push_back(rgb);
  else
    fmt::print("rgb batches: the realtime tier only (this world renders pathtraced)\n");
  const int counts[] = {options.batch};
  const std::string name = world.file.substr(world.file.find_last_of('/') + 1);
  for (const cuda::BatchOutputs& outputs : sets) {
    const std::vector<cuda::BatchBenchRow> rows =
        cuda::RunBatchBench(worlds, options.batch_width, options.batch_height, counts,
                            options.frames, outputs, StaticMapsQueryFactory());
    fmt::print("{}", cuda::FormatBatchBench(name, options.batch_width, options.batch_height,
                                            outputs, rows));
  }
  return 0;
#else
  throw ConfigError("", 0, "--batch",
                    "this penumbra was built without the CUDA backend (no nvcc at build time); "
                    "expected a build with CUDA (docs/gpu.md)");
#endif
}

// CPU time of every thread of this process, s: on a loaded machine it varies far less than the
// wall-clock time (the bench prints both).
double ProcessCpuSeconds() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

}  // namespace

const char* TargetVerdict(double measured, double target) {
  return measured >= target ? "met" : "NOT met";
}

void PrintRealtimeFpsTarget(const std::string& subject, double target_fps, double measured_fps,
                            const std::string& tier) {
  if (tier == "realtime") {
    // the verdict reads the rate as printed (0.1 frames/s), so 29.96 shows as 30.0 and is met
    const double shown_fps = std::stod(fmt::format("{:.1f}", measured_fps));
    fmt::print("{}: {}>= {:g} frames/s at 640x480 realtime: {} ({:.1f} frames/s here)\n",
               BenchTargetLabel(), subject, target_fps,
               BenchTargetVerdict(shown_fps >= target_fps, ThisMachine()), shown_fps);
  } else {
    fmt::print("{}: {}>= {:g} frames/s at 640x480 realtime: not applicable (tier {})\n",
               BenchTargetLabel(), subject, target_fps, tier);
  }
}

const std::vector<std::string>& AblationNames() {
  static const std::vector<std::string> names = {
      "mirror", "mirror-sparse", "sky-volume", "texture-filter", "shadows", "sun-occluder", "film"};
  return names;
}

void ApplyAblation(const std::vector<std::string>& names, RenderAblation* ablation) {
  bool* const fields[] = {&ablation->mirror,     &ablation->mirror_sparse,
                          &ablation->sky_volume, &ablation->texture_filter,
                          &ablation->shadows,    &ablation->sun_occluder,
                          &ablation->film};
  for (const std::string& name : names) {
    const auto& known = AblationNames();
    const auto it = std::find(known.begin(), known.end(), name);
    if (it == known.end())
      throw ConfigError(
          "", 0, "--ablate",
          fmt::format("unknown part '{}'; expected one of: {}", name, fmt::join(known, ", ")));
    *fields[it - known.begin()] = false;
  }
}

int BenchRender(const RenderBenchOptions& options) {
  WorldConfig world =
      LoadWorldFile(options.world_file.empty() ? DefaultWorldPath() : options.world_file);
  world.render.seed = world.seed;
  world.render.threads = options.threads;
  world.render.tier = options.tier == "pathtraced" ? RenderSettings::Tier::kPathtraced
                                                   : RenderSettings::Tier::kRealtime;
  if (options.backend) world.render.backend = *options.backend;
  if (options.batch > 0) return BenchRenderBatch(world, options);
  RenderAblation ablation;
  ApplyAblation(options.ablate, &ablation);
  Session session(world);  // session/session.h
  Simulation& sim = session.sim();
  const SceneDescription& scene = session.scene();
  if (scene.cameras.empty())
    throw ConfigError(world.file, 0, "cameras", "bench render needs a camera");
  const CameraSpec& cam = scene.cameras.front();
  Renderer* const renderer = session.renderer();
  if (!options.ablate.empty() && !SetRenderAblation(renderer, ablation))
    throw ConfigError(world.file, 0, "--ablate", "needs the cpu backend (--backend cpu)");
  const double fovy_deg = cam.intrinsics.fovy_deg();

  // let the robot get going so the frames show a moving world
  const int steps_per_frame =
      std::max(1, static_cast<int>(std::lround(1.0 / 30.0 / sim.timestep())));
  while (sim.time() < 1.0) sim.Step();

  fmt::print("penumbra bench render: world {}\n", world.file);
  fmt::print("camera '{}', tier {}, {} render threads requested (0 = all cores), {} timed frames\n",
             cam.name, options.tier, options.threads, options.frames);
  if (!options.ablate.empty())
    fmt::print("ablated (switched off): {}\n", fmt::join(options.ablate, ", "));
  if (!options.presets.empty()) {
    BenchRenderAdversity(options);  // bench/effects_bench.h: only the presets named
    return 0;
  }
  double fps_640x480 = 0;
  for (auto [w, h] : {std::pair{640, 480}, std::pair{800, 800}}) {
    if (options.only_640x480 && w != 640) continue;
    CameraView view;
    view.intrinsics = CameraIntrinsics::FromFovy(w, h, fovy_deg);
    view.outputs[ImageKind::kRgb] = true;
    view.outputs[ImageKind::kDepth] = true;
    view.outputs[ImageKind::kSegmentation] = false;
    view.camera_index = 0;
    view.near_m = cam.near_m;
    RenderedFrame frame;
    double seconds = 0, cpu_seconds = 0;
    int64_t rays = 0;
    for (int i = 0; i < options.warmup_frames + options.frames; ++i) {
      for (int s = 0; s < steps_per_frame; ++s) sim.Step();
      const WorldSnapshot snap = sim.Snapshot(Simulation::SnapshotContent::kPoses);
      view.X_WO = CameraPoseInWorld(cam, snap);
      view.frame_index = i;
      const auto t0 = Clock::now();
      const double c0 = ProcessCpuSeconds();
      renderer->Render(snap, view, &frame);
      const double dt = std::chrono::duration<double>(Clock::now() - t0).count();
      const double dc = ProcessCpuSeconds() - c0;
      if (i >= options.warmup_frames) {
        seconds += dt;
        cpu_seconds += dc;
        rays += frame.rays;
      }
    }
    fmt::print(
        "{}x{} rgb+depth {}: {:.1f} frames/s, {:.2f} ms/frame, {:.1f} Mrays/s, {:.2f} "
        "cpu-ms/frame, {} rays/frame\n",
        w, h, options.tier, options.frames / seconds, 1e3 * seconds / options.frames,
        rays / seconds * 1e-6, 1e3 * cpu_seconds / options.frames, rays / options.frames);
    if (w == 640) fps_640x480 = options.frames / seconds;
  }
  // the target is the realtime tier's; a pathtraced run says so instead of a verdict
  PrintRealtimeFpsTarget("", kRenderTargetFps, fps_640x480, options.tier);
  if (options.adversity) BenchRenderAdversity(options);  // bench/effects_bench.h
  return 0;
}

// "penumbra bench physics" steps of one model both ways, with its verdict line
void PrintPhysicsThroughput(const std::string& label, const std::string& model, double seconds) {
  const PhysicsBenchResult r = BenchmarkPhysics(model, seconds);
  fmt::print("{}\n", label);
  fmt::print("  {} steps of {:.1f} s sim time each way, interleaved in blocks of 250\n", r.steps,
             seconds);
  fmt::print("  penumbra Simulation::Step + 30 Hz pose snapshots: {:.0f} steps/s\n",
             r.penumbra_steps_per_sec);
  fmt::print("  penumbra Simulation::Step alone: {:.0f} steps/s (ratio {:.3f})\n",
             r.step_only_steps_per_sec, r.step_only_ratio);
  fmt::print("  bare mj_step loop: {:.0f} steps/s\n", r.bare_steps_per_sec);
  fmt::print("  ratio: {:.3f} (target >= {:.2f}: {})\n", r.ratio, kPhysicsThroughputTarget,
             TargetVerdict(r.ratio, kPhysicsThroughputTarget));
}

// shell-quoted for popen
std::string ShellQuoted(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

// runs this executable as a memory child and returns its "vm_hwm_kib" line's value
int64_t MemoryChildKiB(const std::string& mode, const std::string& model, double seconds) {
  const std::string exe = std::filesystem::read_symlink("/proc/self/exe").string();
  const std::string cmd = ShellQuoted(exe) + " bench physics --memory-child " + mode + " --model " +
                          ShellQuoted(model) +
                          fmt::format(" --seconds {} --no-controllers", seconds);
  FILE* p = ::popen(cmd.c_str(), "r");
  if (p == nullptr) throw Error("bench physics: cannot run " + cmd);
  std::string out;
  char buf[4096];
  while (std::fgets(buf, sizeof(buf), p)) out += buf;
  const int status = ::pclose(p);
  const size_t at = out.rfind("vm_hwm_kib ");
  if (status != 0 || at == std::string::npos)
    throw Error("bench physics: the memory child '" + mode + "' failed (" + cmd + "):\n" + out);
  return std::stoll(out.substr(at + 11));
}

// the memory child's work: see PhysicsBenchOptions::memory_child
int RunMemoryChild(const PhysicsBenchOptions& options) {
  const std::string& mode = options.memory_child;
  if (mode == "bare") {
    RunBareMujocoLoop(options.model_file, options.sim_seconds);
  } else if (mode == "penumbra") {
    // a bare model's run without cameras: the session (composition, physics, scene), stepped
    // with a pose snapshot at 30 Hz of sim time as the run loop takes them
    const WorldConfig world = WorldForBareModel(options.model_file);
    SessionOptions session_options;
    session_options.composed_xml_path = BenchComposedPath();
    session_options.build_renderer = false;
    Session session(world, session_options);
    Simulation& sim = session.sim();
    const int64_t total = std::max<int64_t>(1, std::llround(options.sim_seconds / sim.timestep()));
    WorldSnapshot snapshot;
    int64_t next_frame = 0;
    for (int64_t i = 0; i < total; ++i) {
      sim.Step();
      if (sim.time() + 1e-6 * sim.timestep() >= next_frame / 30.0) {
        sim.Snapshot(&snapshot, Simulation::SnapshotContent::kPoses);
        ++next_frame;
      }
    }
  } else if (mode != "idle") {
    throw ConfigError("", 0, "--memory-child",
                      "got '" + mode + "'; expected idle, bare or penumbra");
  }
  fmt::print("vm_hwm_kib {}\n", PeakResidentKiB());
  return 0;
}

int BenchPhysics(const PhysicsBenchOptions& options) {
  if (!options.memory_child.empty()) return RunMemoryChild(options);
  fmt::print("penumbra bench physics on {}\n", ThisMachine().Describe());
  if (!options.model_file.empty()) {
    // both ways first: the model must load in MuJoCo alone
    PrintPhysicsThroughput(options.model_file + " (bare model)", options.model_file,
                           options.sim_seconds);
  }
  if (options.model_file.empty() || !options.world_file.empty()) {
    WorldConfig world =
        LoadWorldFile(options.world_file.empty() ? DefaultWorldPath() : options.world_file);
    SessionOptions session_options;
    session_options.composed_xml_path = BenchComposedPath();
    session_options.add_controllers = false;
    session_options.build_renderer = false;
    const Session session(world, session_options);  // writes the composed model
    PrintPhysicsThroughput(world.file + " (composed, no controllers)",
                           session_options.composed_xml_path, options.sim_seconds);
  }
  if (!options.model_file.empty()) {
    // peak memory, each in a fresh process of this executable (the same libraries on all
    // three), interleaved twice; the smaller of each pair
    const std::string& model = options.model_file;
    const double s = options.sim_seconds;
    int64_t idle = 0, bare = 0, pen = 0;
    for (int round = 0; round < 2; ++round) {
      const int64_t i = MemoryChildKiB("idle", model, s);
      const int64_t b = MemoryChildKiB("bare", model, s);
      const int64_t p = MemoryChildKiB("penumbra", model, s);
      idle = round == 0 ? i : std::min(idle, i);
      bare = round == 0 ? b : std::min(bare, b);
      pen = round == 0 ? p : std::min(pen, p);
    }
    const double mib = 1.0 / 1024;
    const double above_bare = static_cast<double>(bare - idle),
                 above_pen = static_cast<double>(pen - idle);
    const double ratio = above_bare > 0 ? above_pen / above_bare : 0;
    fmt::print("peak resident memory (VmHWM) of {} s of {}, fresh processes of this executable:\n",
               s, model);
    fmt::print("  libraries only (no model):         {:7.1f} MiB\n", idle * mib);
    fmt::print(
        "  bare mj_step loop (MuJoCo alone):  {:7.1f} MiB ({:.1f} MiB above the libraries)\n",
        bare * mib, above_bare * mib);
    fmt::print(
        "  penumbra session, no cameras:      {:7.1f} MiB ({:.1f} MiB above the libraries)\n",
        pen * mib, above_pen * mib);
    fmt::print(
        "  ratio above the libraries: {:.2f} (target <= {:.1f}: {}); whole processes: {:.2f}\n",
        ratio, kPhysicsMemoryTarget, ratio > 0 && ratio <= kPhysicsMemoryTarget ? "met" : "NOT met",
        bare > 0 ? static_cast<double>(pen) / bare : 0.0);
  }

  // controller cost on every bundled world with controllers
  if (options.controllers) {
    fmt::print(
        "\ncontroller cost: steps/s with the world's controllers vs the same episode\n"
        "replayed from its recorded ctrl without them (thread CPU time; target >= 0.9)\n");
    const std::filesystem::path worlds = std::filesystem::path(DefaultWorldPath()).parent_path();
    for (const char* name :
         {"default", "rover", "quadruped", "quadruped_arm", "quadrotor", "arm"}) {
      const std::filesystem::path file = worlds / (std::string(name) + ".yaml");
      if (!std::filesystem::exists(file)) continue;
      const WorldConfig world = LoadWorldFile(file.string());
      SessionOptions session_options;
      session_options.composed_xml_path = BenchComposedPath();
      session_options.build_renderer = false;
      const std::string& composed_path = session_options.composed_xml_path;
      double timestep = 0;
      {
        const Session probe(world, session_options);  // writes the composed model
        if (probe.sim().num_controllers() == 0) continue;
        timestep = probe.sim().timestep();
      }
      const int64_t steps =
          std::max<int64_t>(1, std::llround(options.controller_seconds / timestep));
      const ControllerCostResult c = BenchmarkControllerCost(
          composed_path, [&](Simulation& sim) { AddWorldControllers(world, &sim); }, steps);
      std::string types;
      for (const ModelConfig& m : world.models)
        if (m.is_robot && !m.controller.type.empty())
          types += (types.empty() ? "" : ", ") + m.controller.type;
      fmt::print(
          "  {:<14} {:<20} {:>9.0f} vs {:>9.0f} steps/s  ratio {:.3f} ({}){}\n", name, types,
          c.controlled_steps_per_sec, c.replay_steps_per_sec, c.ratio, TargetVerdict(c.ratio, 0.9),
          c.replay_identical
              ? ""
              : "  (replay diverges from the controlled run: controller slower than physics rate)");
    }
  }
  return 0;
}

}  // namespace penumbra

#include "penumbra/app/cli.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <filesystem>

#include "penumbra/app/bench.h"
#include "penumbra/app/contact_sheet.h"
#include "penumbra/app/vdb_tool.h"
#include "penumbra/app/sensor_bench.h"
#include "penumbra/app/runner.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/renderer.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

// a world file (.yaml/.yml) or a bare model (.xml MJCF, .urdf)
WorldConfig LoadWorldOrModel(const std::string& path) {
  const std::string ext = std::filesystem::path(path).extension().string();
  if (ext == ".xml" || ext == ".urdf" || ext == ".mjcf") return WorldForBareModel(path);
  if (ext == ".yaml" || ext == ".yml") return LoadWorldFile(path);
  throw ConfigError(path, 0, "",
                    "unknown file type '" + ext +
                        "'; expected a world file (.yaml, .yml) or a model (.xml MJCF, .urdf)");
}

std::vector<std::string> Args(int argc, char** argv) { return std::vector<std::string>(argv, argv + argc); }

}  // namespace

int RunCli(int argc, char** argv) {
  CLI::App app{"penumbra: robotics simulator with MuJoCo physics and a physically based ray tracer"};
  app.require_subcommand(1);
  app.set_version_flag("--version", std::string(PENUMBRA_VERSION));

  // penumbra run
  CLI::App* run = app.add_subcommand("run", "simulate a world file or a bare MJCF/URDF model and write outputs");
  std::string world_path;
  RunOptions run_options;
  double duration = -1;
  std::string tier;
  int spp = 0, threads = -1;
  int64_t seed = -1;
  bool quiet = false;
  run->add_option("world", world_path, "world file (.yaml) or model (.xml MJCF, .urdf)")->required();
  run->add_option("--out,-o", run_options.out_dir, "output folder (default: the world's output.dir)");
  run->add_option("--duration", duration, "simulated seconds (overrides duration_sec)")->check(CLI::PositiveNumber);
  run->add_flag("--realtime", run_options.realtime, "pace physics to wall-clock time");
  run->add_option("--tier", tier, "render tier")->check(CLI::IsMember({"realtime", "pathtraced"}));
  run->add_option("--spp", spp, "samples per pixel (pathtraced)")->check(CLI::Range(1, 65536));
  run->add_option("--threads", threads, "render threads (0 = all cores)")->check(CLI::Range(0, 256));
  run->add_option("--seed", seed, "world seed (overrides seed)")->check(CLI::NonNegativeNumber);
  run->add_flag("--quiet,-q", quiet, "no progress output");
  run->add_option("--adversity", run_options.adversity,
                  "adversity preset: none, minor, major, FILE.yaml or FILE.yaml#NAME "
                  "(worlds/adversity/presets.yaml; overrides the world's `adversity`)");

  // penumbra bench render|physics
  CLI::App* bench = app.add_subcommand("bench", "throughput benchmarks (not tests)");
  bench->require_subcommand(1);
  CLI::App* bench_render = bench->add_subcommand("render", "frames/s and Mrays/s at 640x480 and 800x800");
  RenderBenchOptions render_bench;
  bench_render->add_option("--world", render_bench.world_file, "world file (default: bundled default world)");
  bench_render->add_option("--frames", render_bench.frames, "timed frames per resolution")->check(CLI::Range(1, 100000));
  bench_render->add_option("--threads", render_bench.threads, "render threads (0 = all cores)")->check(CLI::Range(0, 256));
  bench_render->add_option("--tier", render_bench.tier, "render tier")->check(CLI::IsMember({"realtime", "pathtraced"}));
  bool no_adversity = false;
  bench_render->add_flag("--no-adversity", no_adversity, "skip the none/minor/major preset lines");
  // penumbra contact-sheet / make-vdb (app/contact_sheet.h, app/vdb_tool.h)
  CLI::App* sheet = app.add_subcommand("contact-sheet", "one instant of a world under adversity presets, side by side, as a PNG");
  ContactSheetOptions sheet_options;
  sheet->add_option("--world", sheet_options.world_file, "world file (default: bundled default world)");
  sheet->add_option("--presets", sheet_options.presets, "presets, left to right")->delimiter(',');
  sheet->add_option("--time", sheet_options.time_sec, "sim time of the frames, s")->check(CLI::NonNegativeNumber);
  sheet->add_option("--width", sheet_options.width, "frame width")->check(CLI::Range(16, 4096));
  sheet->add_option("--height", sheet_options.height, "frame height")->check(CLI::Range(16, 4096));
  sheet->add_option("--out,-o", sheet_options.out, "output PNG (default docs/effects.png)");
  sheet->add_option("--threads", sheet_options.threads, "render threads (0 = all cores)")->check(CLI::Range(0, 256));
  CLI::App* make_vdb = app.add_subcommand("make-vdb", "write a procedural smoke cloud as an OpenVDB file (float grid 'density')");
  std::string vdb_path;
  SmokeVdbOptions vdb_options;
  make_vdb->add_option("file", vdb_path, "output .vdb file")->required();
  make_vdb->add_option("--seed", vdb_options.seed, "blob layout seed");
  make_vdb->add_option("--voxel", vdb_options.voxel_m, "voxel size, m");
  make_vdb->add_option("--radius", vdb_options.radius_m, "cloud radius, m");
  make_vdb->add_option("--blobs", vdb_options.blobs, "Gaussian puffs");
  CLI::App* bench_physics = bench->add_subcommand("physics", "Penumbra physics steps/s vs a bare mj_step loop");
  PhysicsBenchOptions physics_bench;
  bench_physics->add_option("--world", physics_bench.world_file, "world file (default: bundled default world)");
  bench_physics->add_option("--model", physics_bench.model_file, "bare MJCF model instead of a world");
  bench_physics->add_option("--seconds", physics_bench.sim_seconds, "simulated seconds per side")->check(CLI::PositiveNumber);
  bool no_controllers = false;
  bench_physics->add_flag("--no-controllers", no_controllers, "skip the controller-cost table of the bundled robot worlds");
  CLI::App* bench_sensors = bench->add_subcommand("sensors", "LiDAR rays/s and ms/scan, IMU/MuJoCo sensor overhead");
  SensorBenchOptions sensor_bench;
  bench_sensors->add_option("--world", sensor_bench.world_file, "world file (default: bundled default world)");
  bench_sensors->add_option("--scans", sensor_bench.scans, "timed scans per LiDAR preset")->check(CLI::Range(1, 100000));
  bench_sensors->add_option("--seconds", sensor_bench.seconds, "simulated seconds for the sensor overhead")->check(CLI::PositiveNumber);

  CLI11_PARSE(app, argc, argv);

  try {
    if (*run) {
      WorldConfig world = LoadWorldOrModel(world_path);
      if (duration > 0) run_options.duration_sec = duration;
      if (seed >= 0) world.seed = static_cast<uint64_t>(seed);
      if (!tier.empty())
        world.render.tier = tier == "pathtraced" ? RenderSettings::Tier::kPathtraced : RenderSettings::Tier::kRealtime;
      if (spp > 0) world.render.samples_per_pixel = spp;
      if (threads >= 0) world.render.threads = threads;
      run_options.progress = !quiet;
      run_options.command_line = Args(argc, argv);
      const RunSummary s = RunWorld(world, run_options);
      int64_t frames = 0;
      for (const auto& [name, n] : s.frames_per_camera) frames += n;
      spdlog::info("done: {:.3f} s sim time, {} steps, {} frames in {:.2f} s wall, peak RSS {:.0f} MiB -> {}",
                   s.sim_time_sec, s.physics_steps, frames, s.wall_time_sec, s.peak_rss_mib, s.out_dir);
      return 0;
    }
    if (*bench_render) {
      render_bench.adversity = !no_adversity;
      return BenchRender(render_bench);
    }
    if (*sheet) return MakeContactSheet(sheet_options);
    if (*make_vdb) {
      MakeSmokeVdb(vdb_path, vdb_options);
      return 0;
    }
    if (*bench_sensors) return BenchSensors(sensor_bench);
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
    spdlog::error("{}", e.what());
    return 1;
  }
  return 0;
}

}  // namespace penumbra

#include "penumbra/app/benchmark_command.h"

#include <spdlog/spdlog.h>
#include <unistd.h>

#include <CLI/CLI.hpp>
#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>

#include "penumbra/app/backend_flag.h"
#include "penumbra/app/stop_signals.h"
#include "penumbra/campaign/benchmark_runner.h"
#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/eval/trajectory.h"
#include "penumbra/run/runner.h"
#include "penumbra/slam/rgbd_odometry.h"
#include "penumbra/world/world_config.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra {
namespace fs = std::filesystem;

// the options of `benchmark` and `slam`, filled by CLI11 while parsing
struct BenchmarkVerbState {
  CLI::App* benchmark = nullptr;
  CLI::App* slam = nullptr;
  std::string spec, out;
  int workers = 0, job = -1;
  bool slurm = false, force = false, quiet = false;
  BackendFlag backend;  // --backend: every job's replay or run
  std::string method, dataset, trajectory, intrinsics, camera_info, camera;
  double min_depth_m = 0.2, max_depth_m = 6.0;
};

namespace {

std::string SelfExecutable() {
  std::error_code ec;
  const fs::path p = fs::read_symlink("/proc/self/exe", ec);
  if (ec) throw Error("cannot find this executable (/proc/self/exe): " + ec.message());
  return p.string();
}

// the route of a world recorded with no cameras (only the motion matters; replays add the
// benchmark camera); it stops at the next physics step once *stop_request is set
void RecordRoute(const BenchmarkWorld& w, const std::string& plog,
                 const std::atomic<int>* stop_request) {
  WorldConfig world = LoadWorldFile(w.file);
  world.cameras.clear();
  world.mjcf_cameras.enabled = false;
  world.sensors.clear();
  RunOptions run;
  run.out_dir = plog + ".run";
  run.force = true;
  run.record_file = plog;
  run.progress = false;
  run.stop_request = stop_request;
  if (w.duration_sec > 0) run.duration_sec = w.duration_sec;
  fs::remove_all(run.out_dir);
  RunWorld(world, run);
  fs::remove_all(run.out_dir);
}

PinholeIntrinsics ParseIntrinsics(const std::string& text) {
  std::vector<double> v;
  size_t pos = 0;
  while (pos <= text.size()) {
    const size_t end = std::min(text.find(',', pos), text.size());
    const std::optional<double> d = ParseDecimal(text.substr(pos, end - pos));
    if (!d)
      throw ConfigError("", 0, "--intrinsics",
                        "'" + text + "' is not 4 comma-separated numbers fx,fy,cx,cy");
    v.push_back(*d);
    pos = end + 1;
  }
  if (v.size() != 4)
    throw ConfigError("", 0, "--intrinsics",
                      "'" + text + "' is not 4 comma-separated numbers fx,fy,cx,cy");
  PinholeIntrinsics k{v[0], v[1], v[2], v[3]};
  k.ValidateOrThrow();
  return k;
}

class BenchmarkCommand : public Command {
 public:
  std::string name() const override { return "benchmark"; }
  std::string summary() const override {
    return "SLAM benchmark: routes replayed under adversity conditions, methods run and evaluated "
           "(docs/benchmarks.md)";
  }

  void AddOptions(CLI::App* benchmark) override {
    BenchmarkVerbState& s = s_;
    s.benchmark = benchmark;
    s.benchmark->add_option("spec", s.spec, "benchmark spec (.yaml)")->required();
    s.benchmark->add_option("--out,-o", s.out, "output folder (results.csv, report.md, ...)")
        ->required();
    s.benchmark
        ->add_option("--workers", s.workers,
                     "local worker processes (default: the spec's `workers`)")
        ->check(CLI::Range(1, 256));
    s.benchmark->add_flag("--slurm", s.slurm,
                          "submit the jobs as a Slurm job array and wait for them");
    s.benchmark->add_flag("--force", s.force,
                          "remove an earlier benchmark's outputs from --out first");
    s.benchmark->add_flag("--quiet,-q", s.quiet, "no progress output");
    s.benchmark
        ->add_option("--job", s.job,
                     "run only job K (the worker side; used by local workers and Slurm)")
        ->check(CLI::Range(0, 1000000));
    s.backend.Add(s.benchmark, "each world's render.backend");
  }

  int Run(const CommandArgs& args) override {
    const StopSignals stop_signals;
    const std::atomic<int>* stop_request = args.stop_signal;
    const BenchmarkVerbState& s = s_;
    s.backend.Resolve();  // cuda without a device: refused before anything runs
    if (s.job >= 0) {
      if (s.slurm)
        throw ConfigError("", 0, "--job", "not with --slurm (a worker runs one job here)");
      return RunBenchmarkWorker(s.spec, s.out, s.job, SelfExecutable(), stop_request,
                                s.backend.text());
    }
    BenchmarkOptions o;
    o.spec_path = s.spec;
    o.out_dir = s.out;
    o.penumbra_binary = SelfExecutable();
    o.workers = s.workers;
    o.slurm = s.slurm;
    o.force = s.force;
    o.backend = s.backend.text();
    o.progress = !s.quiet;
    o.record = RecordRoute;
    o.stop_request = stop_request;
    return RunBenchmark(o);
  }

 private:
  BenchmarkVerbState s_;
};

class SlamCommand : public Command {
 public:
  std::string name() const override { return "slam"; }
  std::string summary() const override {
    return "run a bundled RGB-D odometry method over a TUM RGB-D folder";
  }

  void AddOptions(CLI::App* slam) override {
    BenchmarkVerbState& s = s_;
    s.slam = slam;
    s.slam
        ->add_option("method", s.method, "opencv_rgbd | opencv_icp | opencv_rgbd_icp | open3d_rgbd")
        ->required();
    s.slam->add_option("dataset", s.dataset, "TUM RGB-D folder (penumbra export --format tum)")
        ->required();
    s.slam
        ->add_option("out", s.trajectory,
                     "output trajectory file (TUM: timestamp tx ty tz qx qy qz qw)")
        ->required();
    s.slam->add_option("--intrinsics", s.intrinsics, "fx,fy,cx,cy in pixels");
    s.slam->add_option("--camera-info", s.camera_info,
                       "a run's camera_info.json (instead of --intrinsics)");
    s.slam->add_option("--camera", s.camera, "the camera in --camera-info (default: its only one)");
    s.slam->add_option("--min-depth", s.min_depth_m, "depth below is ignored, m")
        ->check(CLI::Range(0.0, 100.0));
    s.slam->add_option("--max-depth", s.max_depth_m, "depth above is ignored, m")
        ->check(CLI::Range(0.01, 100.0));
    s.slam->add_flag("--quiet,-q", s.quiet, "no progress output");
  }

  int Run(const CommandArgs&) override {
    const StopSignals stop_signals;
    const BenchmarkVerbState& s = s_;
    if (s.intrinsics.empty() == s.camera_info.empty())
      throw ConfigError("", 0, "--intrinsics",
                        "expected exactly one of --intrinsics fx,fy,cx,cy and --camera-info FILE");
    RgbdOdometryOptions options;
    options.intrinsics = s.intrinsics.empty() ? ReadCameraInfoIntrinsics(s.camera_info, s.camera)
                                              : ParseIntrinsics(s.intrinsics);
    options.min_depth_m = s.min_depth_m;
    options.max_depth_m = s.max_depth_m;
    if (!s.quiet)
      options.progress = [](int64_t done, int64_t all) {
        if (done % 50 == 0 || done == all) spdlog::info("slam: {}/{} frames", done, all);
      };
    if (s.method == "open3d_rgbd") {
      // the Open3D method is its own executable beside this one (tools/slam_open3d.cc)
      const std::string helper =
          (fs::path(SelfExecutable()).parent_path() / "penumbra-slam-open3d").string();
      const PinholeIntrinsics& k = options.intrinsics;
      const std::vector<std::string> args = {helper,
                                             s.dataset,
                                             s.trajectory,
                                             FormatNumber(k.fx),
                                             FormatNumber(k.fy),
                                             FormatNumber(k.cx),
                                             FormatNumber(k.cy),
                                             FormatNumber(options.min_depth_m),
                                             FormatNumber(options.max_depth_m)};
      std::vector<char*> argv;
      for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
      argv.push_back(nullptr);
      // one OpenMP thread unless the caller chose otherwise: the benchmark runs its jobs side by
      // side, and libgomp's spinning threads, more of them than cores, starve each other.
      setenv("OMP_NUM_THREADS", "1", 0);
      execv(helper.c_str(), argv.data());
      throw Error("cannot run " + helper + " (built with penumbra): " + std::strerror(errno));
    }
    const std::vector<RgbdFrameFiles> frames = ReadTumRgbdSequence(s.dataset);
    const RgbdOdometryResult r = RunRgbdOdometry(s.method, frames, options);
    if (r.trajectory.size() < 2) {
      spdlog::error(
          "slam: {} tracked no frame after the first ({} frames, {} lost); no trajectory written",
          s.method, r.frames, r.lost);
      return 3;
    }
    std::ofstream out(s.trajectory, std::ios::binary | std::ios::trunc);
    out << FormatTumTrajectory(r.trajectory);
    if (!out.flush()) throw Error("cannot write " + s.trajectory);
    spdlog::info("slam: {} over {} frames: {} tracked, {} lost -> {}", s.method, r.frames,
                 r.trajectory.size(), r.lost, s.trajectory);
    return 0;
  }

 private:
  BenchmarkVerbState s_;
};

}  // namespace

std::unique_ptr<Command> MakeBenchmarkCommand() { return std::make_unique<BenchmarkCommand>(); }
std::unique_ptr<Command> MakeSlamCommand() { return std::make_unique<SlamCommand>(); }

}  // namespace penumbra

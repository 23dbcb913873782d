#include "penumbra/bench/sensors/sensor_bench.h"

#include <fmt/format.h>
#include <time.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>

#include "penumbra/core/bench_machine.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/sensors/camera_imager.h"
#include "penumbra/sensors/lidar_scanner.h"
#include "penumbra/session/session.h"
#include "penumbra/sinks/sensor_sink.h"
#include "penumbra/world/default_world.h"

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;

double ThreadCpuSec() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec + 1e-9 * ts.tv_nsec;
}

double Since(Clock::time_point t0) {
  return std::chrono::duration<double>(Clock::now() - t0).count();
}

// the world loaded for physics and sensors only (no renderer)
std::unique_ptr<Session> LoadWithSensors(const WorldConfig& world) {
  SessionOptions options;
  options.build_renderer = false;
  return std::make_unique<Session>(world, options);
}

// the first robot's root body (the mount for the benchmark's sensors), or world
std::string MountBody(const Simulation& sim, const WorldConfig& world) {
  const ModelInfo& info = sim.model_info();
  for (const ModelConfig& m : world.models) {
    if (!m.is_robot) continue;
    for (size_t b = 1; b < info.body_names.size(); ++b)
      if (info.body_parent[b] == 0 && info.body_names[b].rfind(m.name + "/", 0) == 0)
        return info.body_names[b];
  }
  return "world";
}

}  // namespace

void BenchCameraNoiseOptions(const WorldConfig& world, const SceneDescription& scene) {
  (void)world;
  (void)scene;
  // a fixed box-room scene (sensors/camera_noise_bench.cc), so the numbers compare across worlds
  fmt::print("\ncamera frames/s per noise option (320 x 240 realtime, box room):\n");
  for (const auto& [option, fps] : CameraNoiseBench(20))
    fmt::print("  {:<22} {:8.1f}\n", option, fps);
}

int BenchSensors(const SensorBenchOptions& options) {
  WorldConfig world =
      LoadWorldFile(options.world_file.empty() ? DefaultWorldPath() : options.world_file);
  world.sensors.clear();
  // a first load to find the robot's root body
  std::string mount;
  {
    const std::unique_ptr<Session> probe = LoadWithSensors(world);
    mount = MountBody(probe->sim(), world);
  }
  SensorConfig imu;
  imu.name = "bench_imu";
  imu.params = ImuSensorParams{};  // the consumer_mems preset
  imu.body = mount;
  imu.rate_hz = 200;
  SensorConfig mj;
  mj.name = "bench_mujoco";
  mj.params = MujocoSensorParams{};
  mj.rate_hz = 100;
  SensorConfig gt;
  gt.name = "bench_ground_truth";
  gt.params = GroundTruthSensorParams{};
  gt.rate_hz = 100;
  world.sensors = {imu, mj, gt};
  const std::unique_ptr<Session> session = LoadWithSensors(world);
  Simulation& sim = session->sim();
  const SceneDescription& scene = session->scene();
  fmt::print(
      "penumbra bench sensors: world {}, mount body '{}', timestep {:.4g} s, {} MuJoCo "
      "sensors\n",
      world.file, mount, sim.timestep(), sim.sensor_info().size());

  // snapshots every 0.1 s while the robot moves (the scans' start and end poses)
  std::vector<WorldSnapshot> snaps;
  const int64_t steps_per_scan = std::max<int64_t>(1, std::llround(0.1 / sim.timestep()));
  for (int k = 0; k <= options.scans; ++k) {
    snaps.push_back(sim.Snapshot());
    for (int64_t i = 0; i < steps_per_scan; ++i) sim.Step();
  }
  int mount_body = 0;
  for (size_t b = 0; b < sim.model_info().body_names.size(); ++b)
    if (sim.model_info().body_names[b] == mount) mount_body = static_cast<int>(b);
  const Pose X_BS = PoseFromXyzRpyDeg({0.1, 0, 0.12}, {0, 0, 0});

  const std::unique_ptr<RayQuery> query = MakeRayQuery(scene, world.render.backend);
  RayQuery& rs = *query;
  fmt::print(
      "\nLiDAR (single thread, Embree packets of 16, motion-interpolated pose, scene posed per "
      "scan, {} scans each after one untimed warm-up scan; {}: OS1-64 < 10 ms/scan = 10 % of "
      "one core at 10 Hz)\n",
      options.scans, BenchTargetLabel());
  fmt::print("{:<16} {:>7} {:>12} {:>10} {:>8} {:>8} {:>12} {:>8}\n", "preset", "rays",
             "wall mean ms", "median ms", "max ms", "cpu ms", "cpu Mrays/s", "points");
  // homogeneous fog of meteorological optical range 30 m (sigma_t = ln 20 / MOR)
  auto fog = std::make_shared<EffectsFrame>();
  HomogeneousMedium medium;
  medium.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(std::log(20.0) / 30.0));
  fog->homogeneous_media.push_back(medium);
  for (const char* row :
       {"ouster_os1_64", "velodyne_vlp16", "ouster_os1_128", "livox_mid40", "os1_64 fog 30m"}) {
    const bool foggy = std::string(row) == "os1_64 fog 30m";
    const char* preset = foggy ? "ouster_os1_64" : row;
    LidarConfig cfg;
    cfg.pattern = MakeLidarPattern(preset);
    LidarScanner scanner(cfg, 1);
    std::vector<double> wall;
    double cpu = 0;
    int64_t points = 0;
    LidarScan scan;
    // one untimed scan first: Embree builds its BVHs lazily on the first trace, and the
    // first preset row would otherwise pay for it
    {
      const Pose X0 = snaps[0].X_WB[mount_body] * X_BS;
      rs.Update(snaps[0]);
      scanner.Scan(
          rs, foggy ? fog.get() : nullptr, [&](double) { return X0; }, 0, &scan);
    }
    for (int k = 0; k < options.scans; ++k) {
      const WorldSnapshot& a = snaps[k];
      const WorldSnapshot& b = snaps[k + 1];
      const Pose X0 = a.X_WB[mount_body] * X_BS, X1 = b.X_WB[mount_body] * X_BS;
      const double span = b.time_sec - a.time_sec;
      const auto t0 = Clock::now();
      const double c0 = ThreadCpuSec();
      rs.Update(a);
      scanner.Scan(
          rs, foggy ? fog.get() : nullptr,
          [&](double t) { return InterpolatePose(X0, X1, std::min(1.0, t / span)); }, k, &scan);
      cpu += ThreadCpuSec() - c0;
      wall.push_back(Since(t0));
      points += static_cast<int64_t>(scan.points.size());
    }
    std::vector<double> sorted = wall;
    std::sort(sorted.begin(), sorted.end());
    double mean = 0;
    for (double w : wall) mean += w / wall.size();
    fmt::print("{:<16} {:>7} {:>12.2f} {:>10.2f} {:>8.2f} {:>8.2f} {:>12.2f} {:>8}\n", row,
               scan.rays, 1e3 * mean, 1e3 * sorted[sorted.size() / 2], 1e3 * sorted.back(),
               1e3 * cpu / options.scans, scan.rays / (cpu / options.scans) * 1e-6,
               points / options.scans);
  }

  // IMU / MuJoCo sensors / ground truth: physics with and without the sensor sink, through the
  // run's pipeline (pipeline/sim_loop.h); the wall time includes writing the sensor files
  const auto run = [&](bool with_sensors, double* snapshot_us) {
    const std::unique_ptr<Session> loaded = LoadWithSensors(world);
    Simulation& s = loaded->sim();
    const std::string dir =
        (std::filesystem::temp_directory_path() / "penumbra_bench_sensors").string();
    // times the snapshots the sensors ask for (Simulation::Snapshot, kFull)
    class TimedSource : public PhysicsSource {
     public:
      using PhysicsSource::PhysicsSource;
      std::shared_ptr<const WorldSnapshot> Snapshot(SnapshotContent content) override {
        const auto ts = std::chrono::steady_clock::now();
        auto snap = PhysicsSource::Snapshot(content);
        sec += Since(ts);
        ++taken;
        return snap;
      }
      double sec = 0;
      int64_t taken = 0;
    } source(&s);
    std::unique_ptr<SensorSink> sink;
    if (with_sensors) sink = std::make_unique<SensorSink>(world, s, scene, dir);
    SimLoopOptions loop_options;
    loop_options.end_time_sec = options.seconds;
    SimLoop loop(&source, loop_options);
    if (sink) loop.AddSink(sink.get());
    const auto t0 = Clock::now();
    const LoopFinish finish = loop.Run();
    const double wall = Since(t0);
    if (finish.error) std::rethrow_exception(finish.error);
    if (snapshot_us) *snapshot_us = source.taken ? 1e6 * source.sec / source.taken : 0;
    std::filesystem::remove_all(dir);
    return wall;
  };
  double snap_us = 0;
  const double plain = run(false, nullptr);
  const double with = run(true, &snap_us);
  fmt::print(
      "\nIMU 200 Hz + MuJoCo sensors 100 Hz + ground truth 100 Hz over {:.1f} s of sim time\n",
      options.seconds);
  fmt::print("  physics alone          {:8.3f} s wall ({:.0f} steps/s)\n", plain,
             options.seconds / sim.timestep() / plain);
  fmt::print("  physics + sensors      {:8.3f} s wall (+{:.1f} %)\n", with,
             100 * (with - plain) / plain);
  fmt::print(
      "  per sensor snapshot    {:8.1f} us (Simulation::Snapshot: mj_forward on a scratch "
      "copy, poses, twists, contacts)\n",
      snap_us);
  fmt::print("  sensor overhead        {:8.2f} ms per simulated second\n",
             1e3 * (with - plain) / options.seconds);

  BenchCameraNoiseOptions(world, scene);
  return 0;
}

}  // namespace penumbra

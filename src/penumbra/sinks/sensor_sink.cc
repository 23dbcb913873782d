#include "penumbra/sinks/sensor_sink.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>
#include <time.h>

#include <chrono>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <optional>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/core/rng.h"
#include "penumbra/output/sensor_writers.h"
#include "penumbra/pipeline/sink_worker.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/scene/sim_time.h"
#include "penumbra/sensors/imu_model.h"
#include "penumbra/sensors/lidar_scanner.h"
#include "penumbra/sensors/mujoco_sensors.h"
#include "penumbra/sensors/sensor_noise.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

double ThreadCpuSec() {
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

ConfigError SensorError(const SensorConfig& s, const std::string& key, const std::string& what) {
  return ConfigError(s.file, s.line, s.key + (key.empty() ? "" : "." + key),
                     "sensor '" + s.name + "': " + what);
}

// a sensor frame fixed to a body: X_WS = X_WB[body] * X_BS
struct Mount {
  int body = 0;
  Pose X_BS = Pose::Identity();
  Pose X_WS(const WorldSnapshot& s) const { return s.X_WB.at(body) * X_BS; }
};

Mount ResolveMount(const SensorConfig& s, const ModelInfo& info) {
  Mount m;
  if (!s.site.empty()) {
    int site = -1;
    for (size_t i = 0; i < info.site_names.size(); ++i)
      if (info.site_names[i] == s.site) site = static_cast<int>(i);
    if (site < 0)
      throw SensorError(
          s, "site",
          "no site named '" + s.site + "' in the composed model; expected \"<model>/<site>\"");
    m.body = info.site_body[site];
    m.X_BS = info.site_X_BS[site] * s.X_AS();
    return m;
  }
  const std::string body = s.body.empty() ? "world" : s.body;
  if (body == "world") {
    m.body = 0;
  } else {
    m.body = -1;
    for (size_t i = 0; i < info.body_names.size(); ++i)
      if (info.body_names[i] == body) m.body = static_cast<int>(i);
    if (m.body < 0)
      throw SensorError(s, "body",
                        "no body named '" + body +
                            "' in the composed model; expected \"<model>/<body>\" "
                            "or world");
  }
  m.X_BS = s.X_AS();
  return m;
}

// the rigid part a mounted frame moves with: from its body, up through the bodies welded to
// their parent (no joint of their own), to the first body with a joint or the world.
// returns that body and the frame's pose in it (X_RS = X_RB * X_BS).
std::pair<int, Pose> RigidMount(const ModelInfo& info, int body, const Pose& X_BS) {
  Pose X_RS = X_BS;
  if (info.body_X_PB.size() != info.body_names.size()) return {body, X_RS};
  while (body > 0) {
    bool has_joint = false;
    for (const JointInfo& j : info.joints) has_joint = has_joint || j.body == body;
    if (has_joint) break;
    X_RS = info.body_X_PB[body] * X_RS;
    body = info.body_parent[body] < 0 ? 0 : info.body_parent[body];
  }
  return {body, X_RS};
}

nlohmann::ordered_json PoseJson(const Pose& X) {
  Eigen::Quaterniond q(X.linear());
  if (q.w() < 0) q.coeffs() = -q.coeffs();
  const Eigen::Vector3d& p = X.translation();
  return {{"xyz", {p.x(), p.y(), p.z()}}, {"qwxyz", {q.w(), q.x(), q.y(), q.z()}}};
}

std::string BodyName(const ModelInfo& info, int body) {
  return body == 0 ? std::string("world") : info.body_names.at(body);
}

nlohmann::ordered_json MountJson(const ModelInfo& info, int body, const Pose& X_BS) {
  const auto [root, X_RS] = RigidMount(info, body, X_BS);
  nlohmann::ordered_json j;
  j["body"] = BodyName(info, body);
  j["X_BS"] = PoseJson(X_BS);
  j["rigid_body"] = BodyName(info, root);
  j["X_RS"] = PoseJson(X_RS);
  return j;
}

// a sample of `sensor` for SensorSink's on_sample
SensorSample MakeSample(const std::string& sensor, SensorKind kind, int64_t index, int64_t step,
                        double time_sec) {
  SensorSample s;
  s.sensor = sensor;
  s.kind = kind;
  s.index = index;
  s.step = step;
  s.time_sec = time_sec;
  return s;
}

}  // namespace

struct SensorSink::Impl {
  struct Lidar {
    const SensorConfig* cfg = nullptr;
    std::unique_ptr<LidarScanner> scanner;
    Mount mount;
    LidarScanWriter out;
    bool pending = false;
    SensorFiring start_firing;
    int64_t start_noise_index = 0;  // the scan's index within its episode (noise key)
    std::shared_ptr<const WorldSnapshot> start;
    std::shared_ptr<const EffectsFrame> start_effects;  // seen at the scan's start
    int64_t written = 0;
  };
  struct Imu {
    const SensorConfig* cfg = nullptr;
    std::unique_ptr<ImuNoiseModel> noise;
    ImuNoiseConfig noise_config;
    double period_sec = 0;
    uint64_t stream = 0;
    int episode = 0;     // the episode `noise` belongs to
    int64_t next_k = 0;  // the next sample index within it (from episode 1 on)
    SensorDescription accel, gyro;
    Mount mount;
    ImuCsvWriter out;
    ImuTruthCsvWriter truth_out;
    int64_t written = 0;
  };
  struct Mujoco {
    const SensorConfig* cfg = nullptr;
    std::unique_ptr<MujocoSensorSet> set;
    double stddev = 0;
    uint64_t stream = 0;
    MujocoSensorCsvWriter out;
    std::vector<double> values;
    std::shared_ptr<const std::vector<std::string>> columns;  // made on the first sample
    int64_t written = 0;
  };
  struct GroundTruth {
    const SensorConfig* cfg = nullptr;
    std::vector<int> bodies;
    bool contacts = true;
    GroundTruthCsvWriter out;
    int64_t written = 0;
  };
  // what each schedule id stands for: the sensor's type and its index in that type's list
  struct Entry {
    SensorKind kind = SensorKind::kLidar;
    int index = 0;
    double rate_hz = 0, latency_sec = 0;  // as given to the schedule
    int64_t next_output = 0;              // the output index of its next sample
    int64_t base = 0;  // output index = base + index within the episode; -1 = not set yet
  };

  std::vector<SensorConfig> configs;
  const SceneDescription* scene = nullptr;
  SensorEffectsAt effects_at;
  // the schedule of the current episode, on its clock (steps since the episode start)
  std::optional<SensorSchedule> schedule;
  std::vector<Entry> entries;
  const Simulation* sim = nullptr;
  double timestep_sec = 0;
  // the episode (Simulation::controller_episode_start: the last `reset`), counted from 0
  int episode = 0;
  int64_t episode_start = 0;
  std::vector<Lidar> lidars;
  std::vector<Imu> imus;
  std::vector<Mujoco> mujocos;
  std::vector<GroundTruth> truths;
  std::vector<std::string> body_names;
  std::unique_ptr<RayQuery> ray_scene;
  SensorOutputCallback on_output;
  SensorSampleCallback on_sample;
  // loop thread
  std::vector<SensorFiring> due;   // output indices and sim times
  std::vector<int64_t> due_noise;  // per entry of `due`: its index within the episode
  int64_t due_step = -1;
  double effects_sec = 0;
  // sink thread
  int processed_episode = 0;  // the episode of the last snapshot processed
  std::map<std::string, double> busy;
  // busy seconds of a sensor type (its name), or of a part of it ("<name>_<part>")
  double& Busy(SensorKind kind, std::string_view part = {}) {
    std::string key(SensorKindName(kind));
    if (!part.empty()) key += "_" + std::string(part);
    return busy[key];
  }
  SinkWorker worker{8};

  // the sensors `due` read `snap`; on the sink thread, in step order. `scan_effects`: per
  // entry of `due`, the effects a LiDAR starting a scan sees (null otherwise).
  void Process(const std::shared_ptr<const WorldSnapshot>& snap,
               const std::vector<SensorFiring>& due, const std::vector<int64_t>& due_noise,
               int due_episode,
               const std::vector<std::shared_ptr<const EffectsFrame>>& scan_effects);

  // a new episode starts at step `start` and the loop is at `step`: every schedule restarts
  // on the episode's clock (the samples due before `step` pass), output indices go on
  void StartEpisode(int64_t start, int64_t step) {
    ++episode;
    episode_start = start;
    schedule.emplace(timestep_sec);
    for (size_t i = 0; i < entries.size(); ++i) {
      schedule->Add(configs[i].name, entries[i].rate_hz, entries[i].latency_sec);
      entries[i].base = -1;
    }
    schedule->StartAt(step - start);
  }

  void TraceScan(Lidar& l, const WorldSnapshot& end) {
    const auto t0 = Clock::now();
    const double c0 = ThreadCpuSec();
    const WorldSnapshot& start = *l.start;
    ray_scene->Update(start);
    const Pose X0 = l.mount.X_WS(start), X1 = l.mount.X_WS(end);
    const double span = end.time_sec - start.time_sec;
    const SensorPoseAt pose = [&](double t) {
      return span > 0 ? InterpolatePose(X0, X1, std::min(1.0, t / span)) : X0;
    };
    auto scan_ptr = std::make_shared<LidarScan>();
    LidarScan& scan = *scan_ptr;
    l.scanner->Scan(*ray_scene, l.start_effects.get(), pose, l.start_noise_index, &scan);
    std::string pcd = l.out.Write(l.start_firing, scan);
    if (on_output) on_output(l.cfg->name, "points.pcd", start.step, start.time_sec, std::move(pcd));
    if (on_sample) {
      SensorSample sample = MakeSample(l.cfg->name, SensorKind::kLidar, l.start_firing.index,
                                       start.step, start.time_sec);
      sample.scan = std::move(scan_ptr);
      on_sample(sample);
    }
    ++l.written;
    Busy(SensorKind::kLidar) += std::chrono::duration<double>(Clock::now() - t0).count();
    Busy(SensorKind::kLidar, "cpu") += ThreadCpuSec() - c0;
  }
};

SensorSink::SensorSink(const WorldConfig& world, const Simulation& sim,
                       const SceneDescription& scene, const std::string& out_dir,
                       SensorEffectsAt effects_at)
    : impl_(std::make_unique<Impl>()) {
  Impl& s = *impl_;
  s.configs = world.sensors;
  s.scene = &scene;
  s.effects_at = std::move(effects_at);
  s.sim = &sim;
  s.timestep_sec = sim.timestep();
  const ModelInfo& info = sim.model_info();
  s.body_names = info.body_names;
  const fs::path out(out_dir);
  // rig.json: where every camera, IMU and LiDAR is mounted (dataset export needs the static
  // extrinsics between them)
  nlohmann::ordered_json rig;
  rig["frames"] =
      "X_BS: sensor frame S in its body B; X_RS: S in the rigid body R it moves with (B or the "
      "first ancestor of B with a joint, or the world); xyz in m, unit quaternion qwxyz; "
      "cameras: S = the OpenCV optical frame (x right, y down, z forward); MJCF cameras are "
      "not listed";
  rig["cameras"] = nlohmann::ordered_json::object();
  for (const CameraSpec& c : scene.cameras)
    if (c.mjcf_camera < 0) rig["cameras"][c.name] = MountJson(info, c.body, c.X_BO);
  rig["imus"] = nlohmann::ordered_json::object();
  rig["lidars"] = nlohmann::ordered_json::object();
  s.schedule.emplace(sim.timestep());
  const double physics_rate = s.schedule->physics_rate_hz();
  for (const SensorConfig& c : s.configs) {
    const uint64_t stream = SensorStreamSeed(world.seed, c.name);
    const SensorTypeInfo& type = Info(c.kind());
    double rate = c.rate_hz.value_or(type.default_rate_hz);
    // a rate above the physics rate fires once per step (sensors/sensor_schedule.h)
    if (rate > physics_rate && !type.rate_from_model) {
      spdlog::warn(
          "{}:{}: {}.rate_hz: sensor '{}' at {:.6g} Hz is faster than the physics "
          "rate ({:.6g} Hz); it records one sample per physics step",
          c.file, c.line, c.key, c.name, rate, physics_rate);
      rate = physics_rate;
    }
    // the models of the registry's types (sensors/sensor_types.h)
    if (const LidarSensorParams* p = c.get<LidarSensorParams>()) {
      Impl::Lidar l;
      l.cfg = &c;
      l.mount = ResolveMount(c, info);
      LidarConfig lc;
      try {
        lc = p->MakeConfig(c.rate_hz.value_or(0));
        l.scanner = std::make_unique<LidarScanner>(lc, stream);
      } catch (const ConfigError&) {
        throw;
      } catch (const Error& e) {
        throw SensorError(c, "preset", e.what());
      }
      rate = lc.pattern.rate_hz;
      l.out = LidarScanWriter(out, c.name);
      rig["lidars"][c.name] = MountJson(info, l.mount.body, l.mount.X_BS);
      s.entries.push_back({SensorKind::kLidar, static_cast<int>(s.lidars.size())});
      s.lidars.push_back(std::move(l));
    } else if (const ImuSensorParams* p = c.get<ImuSensorParams>()) {
      Impl::Imu m;
      m.cfg = &c;
      const auto [acc, gyr] = ImuSensorNames(c.name);
      const int ia = FindSensor(sim.sensor_info(), acc);
      const int ig = FindSensor(sim.sensor_info(), gyr);
      if (ia < 0 || ig < 0)
        throw SensorError(c, "",
                          "the composed model has no accelerometer/gyro '" + acc +
                              "' (AddImuSensors was not applied)");
      m.accel = sim.sensor_info()[ia];
      m.gyro = sim.sensor_info()[ig];
      const ImuNoiseConfig nc = p->MakeNoise();
      m.noise = std::make_unique<ImuNoiseModel>(nc, 1.0 / rate, stream);
      m.noise_config = nc;
      m.period_sec = 1.0 / rate;
      m.stream = stream;
      m.mount = ResolveMount(c, info);
      m.out = ImuCsvWriter(out, c.name);
      m.truth_out = ImuTruthCsvWriter(out, c.name);
      nlohmann::ordered_json j = MountJson(info, m.mount.body, m.mount.X_BS);
      j["rate_hz"] = rate;
      j["gyroscope_noise_density"] = nc.gyro_noise_density;
      j["gyroscope_random_walk"] = nc.gyro_random_walk;
      j["accelerometer_noise_density"] = nc.accel_noise_density;
      j["accelerometer_random_walk"] = nc.accel_random_walk;
      rig["imus"][c.name] = j;
      s.entries.push_back({SensorKind::kImu, static_cast<int>(s.imus.size())});
      s.imus.push_back(std::move(m));
    } else if (const MujocoSensorParams* p = c.get<MujocoSensorParams>()) {
      Impl::Mujoco m;
      m.cfg = &c;
      try {
        m.set = std::make_unique<MujocoSensorSet>(sim.sensor_info(), p->sensors);
      } catch (const Error& e) {
        throw SensorError(c, "sensors", e.what());
      }
      m.stddev = p->stddev;
      m.stream = stream;
      m.out = MujocoSensorCsvWriter(out, c.name, m.set->ColumnNames());
      s.entries.push_back({SensorKind::kMujoco, static_cast<int>(s.mujocos.size())});
      s.mujocos.push_back(std::move(m));
    } else if (const GroundTruthSensorParams* p = c.get<GroundTruthSensorParams>()) {
      Impl::GroundTruth g;
      g.cfg = &c;
      if (p->bodies.empty()) {
        for (size_t b = 1; b < info.body_names.size(); ++b)
          if (!info.body_names[b].empty()) g.bodies.push_back(static_cast<int>(b));
      } else {
        for (const std::string& n : p->bodies) {
          int found = -1;
          for (size_t b = 0; b < info.body_names.size(); ++b)
            if (info.body_names[b] == n) found = static_cast<int>(b);
          if (found < 0)
            throw SensorError(c, "bodies", "no body named '" + n + "' in the composed model");
          g.bodies.push_back(found);
        }
      }
      g.contacts = p->contacts;
      g.out = GroundTruthCsvWriter(out, c.name, g.bodies, info.body_names, g.contacts);
      s.entries.push_back({SensorKind::kGroundTruth, static_cast<int>(s.truths.size())});
      s.truths.push_back(std::move(g));
    }
    try {
      s.schedule->Add(c.name, rate, c.latency_sec);
    } catch (const Error& e) {
      throw SensorError(c, "rate_hz", e.what());
    }
    s.entries.back().rate_hz = rate;
    s.entries.back().latency_sec = c.latency_sec;
  }
  if (!s.lidars.empty()) s.ray_scene = MakeRayQuery(scene, world.render.backend);
  WriteFileAtomic(out / "rig.json", rig.dump(2) + "\n");
}

SensorSink::~SensorSink() { impl_->worker.Finish(); }

bool SensorSink::empty() const { return impl_->configs.empty(); }

void SensorSink::set_on_output(SensorOutputCallback on_output) {
  impl_->on_output = std::move(on_output);
}

void SensorSink::set_on_sample(SensorSampleCallback on_sample) {
  impl_->on_sample = std::move(on_sample);
}

void SensorSink::Drain() { impl_->worker.Drain(); }

void SensorSink::OnStart(const LoopStart& start) {
  impl_->schedule->StartAt(start.step);  // a loop from a later step (a replay): same indices
  impl_->worker.Start(start.report_error);
}

SnapshotContent SensorSink::Wants(int64_t step, double) {
  Impl& s = *impl_;
  s.due.clear();
  s.due_noise.clear();
  const int64_t start = s.sim->controller_episode_start();
  if (start != s.episode_start) s.StartEpisode(start, step);
  s.schedule->Due(step - s.episode_start, &s.due);
  for (SensorFiring& f : s.due) {
    Impl::Entry& e = s.entries[f.sensor];
    s.due_noise.push_back(f.index);
    if (s.episode > 0) {
      // sample k of the episode: noise keyed by k, the output index and times of the run
      if (e.base < 0) e.base = e.next_output - f.index;
      f.index += e.base;
      f.nominal_time_sec += SimTimeOfStep(s.episode_start, s.timestep_sec);
      f.capture_time_sec = SimTimeOfStep(step, s.timestep_sec);
      f.delivery_time_sec = f.capture_time_sec + e.latency_sec;
    }
    e.next_output = f.index + 1;
  }
  s.due_step = s.due.empty() ? -1 : step;
  return s.due.empty() ? SnapshotContent::kNone : SnapshotContent::kFull;
}

void SensorSink::OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) {
  Impl& s = *impl_;
  if (s.due_step < 0 || snapshot->step != s.due_step) return;
  s.due_step = -1;
  // the effects a LiDAR sees over a scan are those at its start, for its start position
  std::vector<std::shared_ptr<const EffectsFrame>> scan_effects(s.due.size());
  if (s.effects_at) {
    const auto t0 = Clock::now();
    for (size_t i = 0; i < s.due.size(); ++i) {
      const Impl::Entry e = s.entries[s.due[i].sensor];
      if (e.kind != SensorKind::kLidar) continue;
      const Pose X0 = s.lidars[e.index].mount.X_WS(*snapshot);
      scan_effects[i] = s.effects_at(*snapshot, X0.translation());
    }
    s.effects_sec += std::chrono::duration<double>(Clock::now() - t0).count();
  }
  s.worker.Post([&s, snapshot, due = s.due, due_noise = s.due_noise, episode = s.episode,
                 scan_effects = std::move(scan_effects)] {
    s.Process(snapshot, due, due_noise, episode, scan_effects);
  });
}

void SensorSink::Impl::Process(
    const std::shared_ptr<const WorldSnapshot>& snap_ptr, const std::vector<SensorFiring>& due,
    const std::vector<int64_t>& due_noise, int due_episode,
    const std::vector<std::shared_ptr<const EffectsFrame>>& scan_effects) {
  Impl& s = *this;
  const WorldSnapshot& snap = *snap_ptr;
  if (due_episode != s.processed_episode) {
    // a scan still open when its episode ends is not written (as at the end of a run)
    for (Lidar& l : s.lidars) {
      l.pending = false;
      l.start.reset();
      l.start_effects.reset();
    }
    s.processed_episode = due_episode;
  }
  for (size_t i = 0; i < due.size(); ++i) {
    const SensorFiring& f = due[i];
    const Impl::Entry e = s.entries[f.sensor];
    const auto t0 = Clock::now();
    if (e.kind == SensorKind::kLidar) {
      Impl::Lidar& l = s.lidars[e.index];
      if (l.pending) s.TraceScan(l, snap);
      l.pending = true;
      l.start_firing = f;
      l.start_noise_index = due_noise[i];
      l.start = snap_ptr;
      l.start_effects = scan_effects[i];
      continue;
    }
    if (e.kind == SensorKind::kImu) {
      Impl::Imu& m = s.imus[e.index];
      const int64_t k = due_noise[i];
      if (m.episode != due_episode) {
        // a new episode: the bias from the start of the stream, as in the first episode
        m.noise = std::make_unique<ImuNoiseModel>(m.noise_config, m.period_sec, m.stream);
        m.episode = due_episode;
        m.next_k = 0;
      }
      // the samples of the episode that passed before its first step still move the bias
      if (m.episode > 0)
        for (; m.next_k < k; ++m.next_k) m.noise->Apply(m.next_k, ImuSample{});
      m.next_k = k + 1;
      const auto a = MujocoSensorValues(snap, m.accel);
      const auto w = MujocoSensorValues(snap, m.gyro);
      ImuSample truth;
      truth.accel_m_s2 = {a[0], a[1], a[2]};
      truth.gyro_rad_s = {w[0], w[1], w[2]};
      // the true state: pose and velocity of the IMU frame, and the biases this sample gets
      ImuTruth state;
      state.X_WS = m.mount.X_WS(snap);
      const Eigen::Matrix<double, 6, 1> V = m.mount.body < static_cast<int>(snap.V_WB.size())
                                                ? snap.V_WB[m.mount.body]
                                                : Eigen::Matrix<double, 6, 1>::Zero();
      const Eigen::Vector3d p_BS_W =
          state.X_WS.translation() - snap.X_WB.at(m.mount.body).translation();
      state.v_WS = V.tail<3>() + V.head<3>().cross(p_BS_W);
      state.gyro_bias = m.noise->gyro_bias();
      state.accel_bias = m.noise->accel_bias();
      const ImuSample measured = m.noise->Apply(k, truth);
      std::string row = m.out.Write(f, measured);
      m.truth_out.Write(f, state);
      if (s.on_sample) {
        SensorSample sample =
            MakeSample(m.cfg->name, SensorKind::kImu, f.index, snap.step, snap.time_sec);
        sample.values = {measured.accel_m_s2.x(), measured.accel_m_s2.y(), measured.accel_m_s2.z(),
                         measured.gyro_rad_s.x(), measured.gyro_rad_s.y(), measured.gyro_rad_s.z()};
        s.on_sample(sample);
      }
      if (s.on_output)
        s.on_output(m.cfg->name, "imu.csv", snap.step, snap.time_sec, std::move(row));
      ++m.written;
      s.Busy(SensorKind::kImu) += std::chrono::duration<double>(Clock::now() - t0).count();
    } else if (e.kind == SensorKind::kMujoco) {
      Impl::Mujoco& m = s.mujocos[e.index];
      m.values.clear();
      m.set->Read(snap, &m.values);
      Rng rng(HashKeys(m.stream, static_cast<uint64_t>(due_noise[i])));
      if (m.stddev > 0)
        for (double& v : m.values) v += m.stddev * StandardNormal(&rng);
      std::string row = m.out.Write(f, m.values);
      if (s.on_sample) {
        if (!m.columns)
          m.columns = std::make_shared<const std::vector<std::string>>(m.set->ColumnNames());
        SensorSample sample =
            MakeSample(m.cfg->name, SensorKind::kMujoco, f.index, snap.step, snap.time_sec);
        sample.values = m.values;
        sample.columns = m.columns;
        s.on_sample(sample);
      }
      if (s.on_output)
        s.on_output(m.cfg->name, "sensor.csv", snap.step, snap.time_sec, std::move(row));
      ++m.written;
      s.Busy(SensorKind::kMujoco) += std::chrono::duration<double>(Clock::now() - t0).count();
    } else {
      Impl::GroundTruth& g = s.truths[e.index];
      g.out.Write(f.index, snap);
      ++g.written;
      s.Busy(SensorKind::kGroundTruth) += std::chrono::duration<double>(Clock::now() - t0).count();
    }
  }
}

void SensorSink::OnFinish(const LoopFinish&) {
  Impl& s = *impl_;
  s.worker.Finish();
  s.Busy(SensorKind::kLidar, "effects") += s.effects_sec;
  if (!s.lidars.empty()) s.Busy(SensorKind::kLidar) += s.effects_sec;
  // every file is closed (and its error, if any, seen); the first error is rethrown
  std::exception_ptr first;
  auto close = [&](auto& writer) {
    try {
      writer.Close();
    } catch (...) {
      if (!first) first = std::current_exception();
    }
  };
  for (auto& l : s.lidars) close(l.out);
  for (auto& m : s.imus) {
    close(m.out);
    close(m.truth_out);
  }
  for (auto& m : s.mujocos) close(m.out);
  for (auto& g : s.truths) close(g.out);
  if (first) std::rethrow_exception(first);
}

std::map<std::string, int64_t> SensorSink::samples() const {
  std::map<std::string, int64_t> out;
  for (const auto& l : impl_->lidars) out[l.cfg->name] = l.written;
  for (const auto& m : impl_->imus) out[m.cfg->name] = m.written;
  for (const auto& m : impl_->mujocos) out[m.cfg->name] = m.written;
  for (const auto& g : impl_->truths) out[g.cfg->name] = g.written;
  return out;
}

std::map<std::string, double> SensorSink::busy_sec() const { return impl_->busy; }

}  // namespace penumbra

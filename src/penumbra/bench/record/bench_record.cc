#include "penumbra/bench/record/bench_record.h"

#include <fmt/format.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <ctime>
#include <filesystem>
#include <vector>

#include "penumbra/core/build_info.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/output/recorder_sink.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/session/session.h"
#include "penumbra/world/default_world.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;

struct Round {
  double steps_per_sec = 0;    // wall clock
  double cpu_us_per_step = 0;  // CPU time of the whole process (loop + writer threads)
  int64_t steps = 0;
  uint64_t log_bytes = 0;
};

double RecordProcessCpuSec() {
  timespec ts{};
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &ts);
  return static_cast<double>(ts.tv_sec) + 1e-9 * static_cast<double>(ts.tv_nsec);
}

// one run of `seconds` of the world from its start through the pipeline, with a recorder
// writing to `log_path` ("" = none). the session (compose, compile) is set up untimed.
Round RunRound(const WorldConfig& world, double seconds, const std::string& log_path,
               int zstd_level) {
  SessionOptions so;
  so.build_renderer = false;
  Session session(world, so);
  PhysicsSource physics(&session.sim());
  SimLoopOptions lo;
  lo.end_time_sec = seconds;
  SimLoop loop(&physics, lo);
  std::unique_ptr<RecorderSink> recorder;
  if (!log_path.empty()) {
    RunLogWriterOptions wo;
    wo.zstd_level = zstd_level;
    recorder = std::make_unique<RecorderSink>(
        log_path, MakeRunLogHeader(session, PENUMBRA_VERSION, "penumbra bench record"), wo);
    loop.AddSink(recorder.get());
  }
  const auto t0 = Clock::now();
  const double cpu0 = RecordProcessCpuSec();
  const LoopFinish f = loop.Run();
  const double cpu = RecordProcessCpuSec() - cpu0;
  const double wall = std::chrono::duration<double>(Clock::now() - t0).count();
  if (f.error) std::rethrow_exception(f.error);
  Round r;
  r.steps = physics.step();
  r.steps_per_sec = static_cast<double>(r.steps) / std::max(wall, 1e-9);
  r.cpu_us_per_step = 1e6 * cpu / static_cast<double>(std::max<int64_t>(r.steps, 1));
  if (recorder) r.log_bytes = recorder->stats().file_bytes;
  return r;
}

double RecordMedian(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int BenchRecord(const BenchRecordOptions& options) {
  WorldConfig world =
      LoadWorldFile(options.world_file.empty() ? DefaultWorldPath() : options.world_file);
  world.render.seed = world.seed;
  namespace fs = std::filesystem;
  const fs::path dir =
      options.log_dir.empty()
          ? fs::temp_directory_path() / fmt::format("penumbra_bench_record_{}", ::getpid())
          : fs::path(options.log_dir);
  fs::create_directories(dir);
  const std::string log = (dir / "bench.plog").string();

  fmt::print("bench record: {} ({} rounds of {:.3g} s sim time, recording off then on)\n",
             world.file, options.rounds, options.round_seconds);
  std::vector<double> off, on, cpu_off, cpu_on;
  for (int i = 0; i < options.rounds; ++i) {
    const Round a = RunRound(world, options.round_seconds, "", options.zstd_level);
    const Round b = RunRound(world, options.round_seconds, log, options.zstd_level);
    off.push_back(a.steps_per_sec);
    on.push_back(b.steps_per_sec);
    cpu_off.push_back(a.cpu_us_per_step);
    cpu_on.push_back(b.cpu_us_per_step);
    fmt::print(
        "  round {}: off {:7.0f} steps/s ({:6.1f} us CPU/step)   on {:7.0f} steps/s ({:6.1f} us "
        "CPU/step)   ratio {:.3f}\n",
        i + 1, a.steps_per_sec, a.cpu_us_per_step, b.steps_per_sec, b.cpu_us_per_step,
        b.steps_per_sec / a.steps_per_sec);
  }
  const double m_off = RecordMedian(off), m_on = RecordMedian(on);
  fmt::print("median: off {:.0f} steps/s, on {:.0f} steps/s, ratio {:.3f} (target >= 0.9)\n", m_off,
             m_on, m_on / m_off);
  // the CPU time of the process (loop and writer threads): the ratio a single free core
  // would see, independent of other load on the machine
  const double c_off = RecordMedian(cpu_off), c_on = RecordMedian(cpu_on);
  fmt::print("median CPU: off {:.1f} us/step, on {:.1f} us/step (+{:.1f} us), CPU ratio {:.3f}\n",
             c_off, c_on, c_on - c_off, c_off / c_on);

  // the size of a log of size_seconds, read back to check it is whole
  const Round s = RunRound(world, options.size_seconds, log, options.zstd_level);
  const RunLogReader reader = RunLogReader::Open(log);
  const double mb = static_cast<double>(s.log_bytes) / 1e6;
  fmt::print(
      "log of {:.3g} s: {} steps, {} chunks, {:.2f} MB ({:.1f} bytes/step; target for 60 s: "
      "< 50 MB)\n",
      options.size_seconds, reader.num_steps(), reader.chunks().size(), mb,
      static_cast<double>(s.log_bytes) / std::max<int64_t>(reader.num_steps(), 1));
  std::error_code ec;
  fs::remove(log, ec);
  if (options.log_dir.empty()) fs::remove(dir, ec);
  return 0;
}

}  // namespace penumbra

#pragma once
// how much penumbra's stepping (controllers, warning and divergence checks,
// snapshots) costs on top of MuJoCo itself.

#include <cstdint>
#include <string>

namespace penumbra {

/// steps per wall-clock second of Simulation::Step and of a bare mj_step loop.
struct PhysicsBenchResult {
  /// Simulation::Step + a pose snapshot (SnapshotContent::kPoses) every 1/30 s of sim time
  double penumbra_steps_per_sec = 0;
  double step_only_steps_per_sec = 0;  ///< Simulation::Step alone (a second Simulation)
  double bare_steps_per_sec = 0;       ///< mj_step on a separately loaded copy of the model
  double ratio = 0;                    ///< penumbra / bare (1 = no overhead)
  double step_only_ratio = 0;          ///< step only / bare
  int64_t steps = 0;                   ///< steps each side ran
};

/// runs `sim_seconds` of simulated time of the model at `mjcf_path` three ways (Simulation::Step
/// with snapshots, Simulation::Step alone, bare mj_step), after an untimed warm-up block,
/// interleaved in blocks of 250 steps (rotating which side goes first) so machine noise hits
/// all alike.
/// no controllers are attached; pose snapshots are taken at 30 Hz of sim time, as the runner
/// takes them for cameras (a world's sensors add full snapshots at their own rates).
/// wall-clock time is measured with std::chrono::steady_clock (it never feeds the simulation).
/// @throws ConfigError for a bad model or sim_seconds <= 0; PhysicsError if it diverges.
PhysicsBenchResult BenchmarkPhysics(const std::string& mjcf_path, double sim_seconds);

/// the bare side of the memory comparison (`penumbra bench physics --model`): loads
/// `mjcf_path` with MuJoCo alone (mj_loadXML, one mjData) and runs `sim_seconds` of mj_step,
/// nothing else. returns the steps run.
/// @throws ConfigError for a bad model or sim_seconds <= 0.
int64_t RunBareMujocoLoop(const std::string& mjcf_path, double sim_seconds);

/// this process's peak resident memory (/proc/self/status VmHWM), KiB; 0 where unreadable. a
/// process started by exec has its own peak (unlike getrusage's ru_maxrss, which keeps the
/// peak of the process it was forked from).
int64_t PeakResidentKiB();

}  // namespace penumbra

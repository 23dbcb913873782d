#pragma once
// `penumbra replay FILE.plog --resimulate`: the recorded run simulated again from its recorded
// world (replay/recorded_world.h, set up as `run` sets it up) and checked against the log at
// EVERY step: step count, time and every vector of the state table (scene/sim_state.h
// kStateFields; controller_next_update only with controllers), compared bit for bit (the
// logged step 0 against the initial state too). it reports
// "bit-exact (N steps)" only when every logged step was read from a CRC-valid chunk and compared
// and the log ended with its end chunk; else the first divergent step, field and index with both
// values, or the damage (the chunk and its steps) that left the rest of the log unverified.
//
// modes:
//   kControllers  the world's controllers run again and compute ctrl (the default). commands a
//                 bridge carried out (ZeroMQ, ROS, the viewer: "command" events, docs/run-log.md)
//                 are not re-injected, so a log that holds "command" events is refused in this
//                 mode, naming the first.
//   kCtrl         no controllers: before each step the ctrl the log holds after that step is
//                 applied (what the controllers wrote), so physics alone is checked. commands
//                 that only steer controllers or set ctrl are covered by the logged ctrl; a log
//                 with a command that changes the state itself (set_mocap, reset) is refused.
// it runs as a pipeline (docs/architecture.md): PhysicsSource -> SimLoop -> a checking sink
// that compares every step's snapshot with the log (the first divergence ends the loop) and,
// with an output folder (ResimulateOptions::out_dir), the world's `metrics:` sink with every
// quantity (metrics/metrics_sink.h MetricsMode::kDynamics) and run.json (its "replay" object
// has mode "resimulate" and the verdict). without an output folder nothing is written.
//
// MuJoCo computes a step from exactly the state the log holds (scene/sim_state.h SimState),
// so a run is bit-exact as long as the model, the world, the MuJoCo version and the binary's
// floating point are those of the recording (changed model files are warned about). a format 1
// log (MuJoCo 2.2.2) holds no history, eq_active, plugin_state or plastic: those are not
// compared.

#include <atomic>
#include <cstdint>
#include <optional>
#include <string>
#include <vector>

namespace penumbra {

/// how a resimulation computes ctrl.
enum class ResimulateMode {
  kControllers,  ///< the world's controllers run again
  kCtrl,         ///< the logged ctrl is applied, controllers off
};

/// settings of a resimulation.
struct ResimulateOptions {
  std::string log_path;
  ResimulateMode mode = ResimulateMode::kControllers;
  /// a stop request (SIGINT): checking stops at the next step; the report says how far it got.
  const std::atomic<int>* stop_request = nullptr;
  /// the output folder of the metrics and run.json ("" = write nothing); prepared as `run`
  /// prepares its own (output/output_folder.h: empty or new, or `force`).
  std::string out_dir;
  bool force = false;
  /// argv, for run.json.
  std::vector<std::string> command_line;
};

/// the first difference between the log and the resimulation.
struct Divergence {
  int64_t step = 0;     ///< logged step where it differs
  double time_sec = 0;  ///< its time, s
  std::string field;    ///< "qpos", "qvel", ..., "step", "time_sec", "size of qpos"
  int64_t index = 0;    ///< entry of the field (0 for scalars)
  std::string what;     ///< what the entry belongs to, e.g. "joint 'go1/FR_calf'" ("" if none)
  double logged = 0, simulated = 0;  ///< both values
};

/// how a resimulation went.
struct ResimulateReport {
  int64_t steps_checked = 0;  ///< logged steps compared (step 0 included)
  int64_t last_step = 0;      ///< the last logged step compared
  std::optional<Divergence> divergence;
  bool interrupted = false;           ///< stopped by the stop request before the log's end
  std::vector<std::string> warnings;  ///< damaged log, changed assets
  /// the reader's description of damage (a CRC mismatch, a cut chunk, no end chunk: "log ends
  /// at chunk N (step S): ..."); the steps after it were not checked. nullopt for a whole log.
  std::optional<std::string> damage;
  /// step records the log holds in its CRC-valid chunks (all of them are compared unless the
  /// check stops early).
  int64_t steps_logged = 0;
  /// the whole log was checked and matched: no divergence, no damage, not interrupted and
  /// every logged step compared.
  bool bit_exact() const;
  /// "bit-exact (N steps)" (only when bit_exact()); "diverged at step S (t = T s): FIELD[I]
  /// (WHAT): logged L, simulated M" with 17 significant digits; "stopped after N steps
  /// (bit-exact so far)"; "damaged log, not verified past step S: DAMAGE (N steps before it
  /// bit-exact)"; "not verified: N of M logged steps checked".
  std::string Describe() const;
};

/// resimulates the log (see the file header).
/// a damaged log is not thrown: it is checked up to its damage and the report says so
/// (ResimulateReport::damage, bit_exact() false).
/// @throws RunLogError for a file that is not a readable run log; ConfigError naming the log
///         when it holds command events in kControllers mode or set_mocap / reset command
///         events in kCtrl mode (naming the first), when its model does not match
///         the recorded world's (state sizes), its first step is not 0 or it skips a step;
///         ConfigError("--out") for an output folder PrepareOutputFolder refuses, and the
///         metrics sink's for a bad `metrics:` (located in the recorded world); PhysicsError
///         when the simulation fails where the recording did not; Error if an output cannot
///         be written.
ResimulateReport ResimulateLog(const ResimulateOptions& options);

}  // namespace penumbra

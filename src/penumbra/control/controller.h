#pragma once
// the pluggable controller interface. a controller reads the state through a
// ControlInput and writes its actuators' entries of ctrl. the Simulation owns its
// controllers and calls them on simulated time at their rate (see rate_hz()).
//
// life cycle:
//   1. construction (usually by control/controller_factory from a world file):
//      parameters are parsed and range-checked; errors are ConfigErrors.
//   2. Initialize(model), called by Simulation::AddController at load: every name in
//      RequiredNames() is resolved; if any is missing, ONE ConfigError lists all of
//      them, so a bad world file fails before the first step, not at run time.
//   3. Compute(input, ctrl) at each control update.
//   4. Reset(), called by Simulation::ResetControllers (the `reset` command): back to the
//      state right after Initialize, so the next episode runs as the first one did. the
//      controllers' OnInitialize end with their Reset(): the initial state is written once.

#include <span>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/control/control_input.h"
#include "penumbra/control/model_info.h"

namespace penumbra {

/// where a controller was configured, for error messages.
struct ControllerContext {
  std::string file;  ///< world file ("" when built in code)
  int line = 0;      ///< line of the controller block, 0 if unknown
  std::string key;   ///< key path of the block, e.g. "robots[rover].controller"
};

/// a name a controller needs in the compiled model.
struct NameRequirement {
  ModelObject kind = ModelObject::kBody;
  std::string name;  ///< full (prefixed) model name, e.g. "rover/chassis"
  std::string key;   ///< config key it came from, e.g. "base_body" ("" if none)
};

/// base class of every controller. not thread-safe; called from the physics thread.
class Controller {
 public:
  explicit Controller(ControllerContext context) : context_(std::move(context)) {}
  virtual ~Controller() = default;
  Controller(const Controller&) = delete;
  Controller& operator=(const Controller&) = delete;

  /// controller type as written in world files, e.g. "waypoint_follower".
  virtual std::string type() const = 0;
  /// update rate on simulated time (Hz); 0 = every physics step. update k runs at the
  /// first physics step whose time is at least k / rate_hz; ctrl holds in between.
  virtual double rate_hz() const = 0;
  /// every model name the controller needs, with the config key each came from.
  virtual std::vector<NameRequirement> RequiredNames() const = 0;

  /// resolves RequiredNames() against `model` and passes the ids to OnInitialize.
  /// @throws ConfigError (file, line and key from context()) listing every missing
  ///         name with its kind and config key, and some names that do exist.
  void Initialize(const ModelInfo& model);

  /// one control update: reads `input`, writes this controller's actuators in `ctrl`
  /// ((nu) MuJoCo ctrl vector; entries of other actuators must be left alone).
  /// must write finite values (the simulation throws PhysicsError otherwise).
  virtual void Compute(const ControlInput& input, std::span<double> ctrl) = 0;

  /// returns the controller to its state right after Initialize: everything it learned or
  /// integrated at its updates (gait phase origin, references, integrators, filters, histories,
  /// last action, start pose, script position) and every programmatic command (twists,
  /// waypoints, queued commands) is forgotten; configuration and resolved model ids stay.
  /// called by Simulation::ResetControllers from the thread that steps the simulation.
  virtual void Reset() = 0;

  /// names of the values AppendTrackingError reports, each ending in its unit (e.g.
  /// "cross_track_m", "vx_error_m_s"), for the world file's `tracking_error` metric
  /// (world/metrics_config.h). empty (the default): the controller reports no tracking error.
  virtual std::vector<std::string> tracking_error_labels() const { return {}; }
  /// appends one value per tracking_error_labels() entry to `out`: the tracking error at the
  /// last control update (NaN before the first one). the default appends nothing.
  virtual void AppendTrackingError(std::vector<double>* out) const {}

  /// where the controller was configured.
  const ControllerContext& context() const { return context_; }
  /// "type (key)" for messages, e.g. "waypoint_follower (robots[rover].controller)".
  std::string label() const;

  /// the warnings the controller raised since the last call (e.g. trot_gait's check of the
  /// leg joints' signs at Initialize and of the start pose at its first update), emptied;
  /// the simulation logs them (Simulation::TakeWarnings, prefixed with label()).
  std::vector<std::string> TakeWarnings() { return std::exchange(warnings_, {}); }

 protected:
  /// records a warning for TakeWarnings (one sentence, no trailing newline).
  void Warn(std::string text) { warnings_.push_back(std::move(text)); }

  /// called by Initialize with ids[i] = model index of RequiredNames()[i] (all valid).
  virtual void OnInitialize(const ModelInfo& model, const std::vector<int>& ids) = 0;

 private:
  ControllerContext context_;
  std::vector<std::string> warnings_;
};

}  // namespace penumbra

#pragma once
// what controllers cost: physics steps/s of a model stepped with its controllers
// against the same episode replayed from the recorded ctrl with no controller.

#include <cstdint>
#include <functional>
#include <string>

#include "penumbra/physics/simulation.h"

namespace penumbra {

/// result of BenchmarkControllerCost.
struct ControllerCostResult {
  double controlled_steps_per_sec = 0;  ///< Simulation::Step with the controllers attached
  double replay_steps_per_sec = 0;      ///< same ctrl sequence written before each plain Step
  double ratio = 0;                     ///< controlled / replay (1 = controllers are free)
  int64_t steps = 0;                    ///< steps each side ran per episode
  bool replay_identical = false;        ///< the replay reproduced the controlled qpos bit for bit
};

/// records `steps` steps of the model at `mjcf_path` with `add_controllers` applied, then
/// times `episodes` episodes of each side on thread CPU time (alternating which goes first,
/// so machine load hits both alike). the replay writes the recorded ctrl of step k before
/// step k; it matches the controlled run exactly only when every controller updates at
/// every step (a controller running slower than the physics rate changes ctrl between
/// mj_step1 and mj_step2 of its update steps), which replay_identical reports.
/// @throws ConfigError for a bad model or arguments; PhysicsError if it diverges.
ControllerCostResult BenchmarkControllerCost(const std::string& mjcf_path,
                                             const std::function<void(Simulation&)>& add_controllers,
                                             int64_t steps, int episodes = 3);

}  // namespace penumbra

#pragma once
// the crowd of a run (docs/npcs.md): a CrowdSim (effects/crowd_sim.h) advanced from the
// agents' mocap drivers on the physics thread. the crowd steps at its own dt (0.05 s) on sim
// time; each step reads the robots' root poses from the simulation (a robot without a free
// joint stands at its world-file pose), and the agents' poses between two crowd steps are
// interpolated (position linearly, heading along the shorter arc; the crowd is stepped as soon
// as the time asked for passes its own, so the poses are continuous in time). every CrowdDecision
// goes to the decision sink (a run log's "npc" events, run/runner.cc).

#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/effects/crowd_sim.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

class Simulation;

/// a robot the crowd watches: where its root's pose is in qpos, or a fixed pose.
struct CrowdRobotSource {
  std::string name;
  int qpos_adr = -1;  ///< first qpos index of the root free joint; -1 = fixed at `fixed`
  Eigen::Vector2d fixed_W{0, 0};
  double fixed_yaw = 0;
  double radius_m = 0.45;  ///< plan-view disc about the root, m
};

/// the robots among `models` (ModelConfig::is_robot) in `sim`: each one's first free joint, with
/// a disc radius from its geoms' plan extent at the start about its root (primitive geoms;
/// [0.2, 1.5] m; 0.45 m when it has none).
std::vector<CrowdRobotSource> CrowdRobotsOf(const std::vector<ModelConfig>& models,
                                            const Simulation& sim);

/// the running crowd.
class CrowdRunner {
 public:
  /// @param crowd      the crowd (its time 0 is `start_sec` of sim time)
  /// @param sim        the simulation whose robots it reads (outlives the runner)
  /// @param robots     the robots (CrowdRobotsOf)
  CrowdRunner(std::unique_ptr<CrowdSim> crowd, const Simulation* sim,
              std::vector<CrowdRobotSource> robots, double floor_z, double start_sec = 0);

  /// X_WA of agent i at sim time t: advances the crowd to t first (t never goes back; an
  /// earlier t gets the current poses).
  Pose X_WA(size_t i, double time_sec);

  /// receives each decision (time, JSON payload with agent, what, goal, plan_points).
  void set_decision_sink(std::function<void(double, const std::string&)> sink);
  const CrowdSim& crowd() const { return *crowd_; }
  /// agent i in or out of the crowd (CrowdSim::SetActive), from the next crowd step.
  void SetActive(size_t i, bool active) { crowd_->SetActive(i, active); }

 private:
  void AdvanceTo(double time_sec);
  std::vector<CrowdRobot> Robots();

  std::unique_ptr<CrowdSim> crowd_;
  const Simulation* sim_;
  std::vector<CrowdRobotSource> sources_;
  std::vector<Eigen::Vector2d> last_robot_W_;
  double floor_z_;
  double start_sec_;
  std::vector<CrowdAgentState> previous_;
  std::mutex sink_mu_;
  std::function<void(double, const std::string&)> sink_;
};

}  // namespace penumbra

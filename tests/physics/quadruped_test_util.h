#pragma once
// shared helpers of the quadruped tests: scenes around the bundled quadruped models, the
// trot_gait configs of the bundled robots, and a probe that records what the acceptance
// criteria need (trunk contact, trajectory).

#include <Eigen/Geometry>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/control/trot_gait.h"
#include "penumbra/physics/simulation.h"

namespace penumbra::quadruped_test {

inline const std::string kModelsDir = PENUMBRA_SOURCE_DIR "/worlds/models";

/// the ground the robot stands on.
enum class Ground { kFlat, kRamp };

/// MJCF text: `robot` ("quadruped" or "quadruped_arm") on a flat floor or the ramp course,
/// plus a test-only actuator "push" that applies a force of ctrl newtons along the trunk's
/// y axis at its origin (site imu), for push-recovery tests. names are unprefixed.
inline std::string SceneXml(const std::string& robot, Ground ground) {
  std::string xml = "<mujoco model=\"" + robot + "_test\">\n";
  if (ground == Ground::kRamp) {
    xml += "  <include file=\"ramp.xml\"/>\n";
  } else {
    xml += "  <worldbody><geom name=\"floor\" type=\"plane\" size=\"0 0 0.05\"/></worldbody>\n";
  }
  xml += "  <include file=\"" + robot + ".xml\"/>\n";
  xml +=
      "  <actuator><general name=\"push\" site=\"imu\" gear=\"0 1 0 0 0 0\" ctrllimited=\"true\" "
      "ctrlrange=\"-2000 2000\"/></actuator>\n";
  xml += "</mujoco>\n";
  return xml;
}

/// the legs block of a trot_gait config for the bundled models (joint, actuator and foot
/// site names as in worlds/models/quadruped*.xml).
inline std::string LegsYaml() {
  std::string s = "legs:\n";
  for (const char* leg : {"FR", "FL", "RR", "RL"}) {
    const std::string l = leg;
    s += "  " + l + ": {hip: " + l + "_hip, thigh: " + l + "_thigh, calf: " + l +
         "_calf, foot: " + l + "_foot, signs: [1, 1, 1]}\n";
  }
  return s;
}

/// records, at every physics step, the trunk's contact force (touch sensor trunk_touch),
/// the base pose and the time.
class Probe final : public Controller {
 public:
  Probe() : Controller(ControllerContext{"", 0, "probe"}) {}
  std::string type() const override { return "probe"; }
  double rate_hz() const override { return 0; }
  std::vector<NameRequirement> RequiredNames() const override {
    return {{ModelObject::kSensor, "trunk_touch", ""}, {ModelObject::kBody, "trunk", ""}};
  }
  void Compute(const ControlInput& in, std::span<double>) override {
    const double touch = in.sensordata()[touch_adr_];
    max_trunk_touch_n = std::max(max_trunk_touch_n, touch);
    if (touch > 0 && first_trunk_touch_sec < 0) first_trunk_touch_sec = in.time_sec();
    const Pose X = in.X_WB(trunk_);
    min_up_z = std::min(min_up_z, X.linear()(2, 2));
  }

  double max_trunk_touch_n = 0;  ///< largest trunk contact force seen (N)
  double first_trunk_touch_sec = -1;
  double min_up_z = 1;  ///< smallest z component of the trunk's z axis (1 = upright)

 protected:
  void OnInitialize(const ModelInfo& m, const std::vector<int>& ids) override {
    touch_adr_ = m.sensors[ids[0]].adr;
    trunk_ = ids[1];
  }

 private:
  int touch_adr_ = 0;
  int trunk_ = 0;
};

/// a loaded scene with a trot_gait controller and a probe.
struct Rig {
  Simulation sim;
  TrotGait* gait = nullptr;
  Probe* probe = nullptr;
  int trunk = -1;
  int push = -1;  ///< index of the push actuator in ctrl
};

/// loads `robot` on `ground` with a trot_gait built through the factory from `config_yaml`.
inline Rig MakeRig(const std::string& robot, Ground ground, const std::string& config_yaml) {
  Rig rig{Simulation::LoadFromString(SceneXml(robot, ground), std::nullopt, kModelsDir)};
  ControllerConfig cfg;
  cfg.type = "trot_gait";
  cfg.line = 1;
  cfg.params_yaml = config_yaml;
  std::unique_ptr<Controller> c = MakeController(cfg, "", "test.yaml");
  rig.gait = dynamic_cast<TrotGait*>(c.get());
  rig.sim.AddController(std::move(c));
  auto probe = std::make_unique<Probe>();
  rig.probe = probe.get();
  rig.sim.AddController(std::move(probe));
  rig.trunk = rig.sim.scene().FindBody("trunk");
  rig.push = rig.sim.model_info().Find(ModelObject::kActuator, "push");
  return rig;
}

/// yaw of the trunk (rad) from a pose.
inline double Yaw(const Pose& X) { return std::atan2(X.linear()(1, 0), X.linear()(0, 0)); }

}  // namespace penumbra::quadruped_test

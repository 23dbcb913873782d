#pragma once
// shared helpers of the quadruped tests: scenes around the bundled quadruped models, the
// trot_gait configs of the bundled robots, and a probe that records what the acceptance
// criteria need (trunk contact, trajectory).

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/config/yaml_document.h"
#include "penumbra/control/controller.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/control/quadruped_leg_kinematics.h"
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
  void Reset() override {}  // records over the whole run
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

/// compares, at every step, the trot_gait leg model (analytic FK and Jacobian of
/// control/quadruped_leg_kinematics.h with the geometry TrotGait read from the model) with
/// MuJoCo's kinematics: foot positions (calf body pose and foot offset) and MuJoCo's
/// translational Jacobian of the foot point (columns of the leg's three joints).
class LegModelCheck final : public Controller {
 public:
  explicit LegModelCheck(const TrotGait* gait) : Controller(ControllerContext{}), gait_(gait) {}
  std::string type() const override { return "leg_model_check"; }
  double rate_hz() const override { return 0; }
  std::vector<NameRequirement> RequiredNames() const override {
    std::vector<NameRequirement> r = {{ModelObject::kBody, "trunk", ""}};
    for (const char* leg : {"FR", "FL", "RR", "RL"})
      for (const char* j : {"_hip", "_thigh", "_calf"})
        r.push_back({ModelObject::kJoint, std::string(leg) + j, ""});
    return r;
  }
  void Reset() override {}  // records over the whole run
  void Compute(const ControlInput& in, std::span<double>) override {
    const Pose X_WT = in.X_WB(trunk_);
    for (int i = 0; i < 4; ++i) {
      Eigen::Vector3d q;
      for (int j = 0; j < 3; ++j) q[j] = in.qpos()[joints_[i][j].qpos_adr];
      const LegGeometry& g = gait_->leg_geometry()[i];
      const Eigen::Vector3d foot_W = X_WT * (gait_->hip_offsets()[i] + LegForwardKinematics(g, q));
      const Eigen::Vector3d foot_mj =
          in.X_WB(joints_[i][2].body) * Eigen::Vector3d(0, 0, -g.calf_m);
      max_position_error_m = std::max(max_position_error_m, (foot_W - foot_mj).norm());
      in.Jacobian(joints_[i][2].body, foot_mj, &jac_);
      const Eigen::Matrix3d J = X_WT.linear() * LegJacobian(g, q);
      for (int j = 0; j < 3; ++j)
        max_jacobian_error = std::max(
            max_jacobian_error, (jac_.block<3, 1>(3, joints_[i][j].dof_adr) - J.col(j)).norm());
    }
    ++checks;
  }

  double max_position_error_m = 0;  ///< largest foot position difference (m)
  double max_jacobian_error = 0;    ///< largest Jacobian column difference (m/rad)
  int checks = 0;

 protected:
  void OnInitialize(const ModelInfo& m, const std::vector<int>& ids) override {
    trunk_ = ids[0];
    for (int i = 0; i < 4; ++i)
      for (int j = 0; j < 3; ++j) joints_[i][j] = m.joints[ids[1 + 3 * i + j]];
  }

 private:
  const TrotGait* gait_;
  int trunk_ = 0;
  std::array<std::array<JointInfo, 3>, 4> joints_;
  Eigen::Matrix<double, 6, Eigen::Dynamic> jac_;
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
  cfg.params = ParseYaml(config_yaml);
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

/// X_W_trunk: the trunk's pose at the simulation's current state.
inline Pose Trunk(const Rig& rig) {
  WorldSnapshot snap;
  rig.sim.Snapshot(&snap);
  return snap.X_WB[rig.trunk];
}

/// steps the rig's simulation until its time reaches t_sec.
inline void RunUntil(Rig* rig, double t_sec) {
  while (rig->sim.time() < t_sec - 1e-9) rig->sim.Step();
}

/// yaw of the trunk (rad) from a pose.
inline double Yaw(const Pose& X) { return std::atan2(X.linear()(1, 0), X.linear()(0, 0)); }

/// steps `a` and `b` together for `steps` steps; fails at the first step where their qpos or
/// qvel differ in any bit.
inline ::testing::AssertionResult StepInLockstep(Simulation& a, Simulation& b, int steps) {
  for (int i = 0; i < steps; ++i) {
    a.Step();
    b.Step();
    const auto qa = a.qpos(), qb = b.qpos();
    const auto va = a.qvel(), vb = b.qvel();
    if (!std::equal(qa.begin(), qa.end(), qb.begin()))
      return ::testing::AssertionFailure() << "qpos differs at step " << i;
    if (!std::equal(va.begin(), va.end(), vb.begin()))
      return ::testing::AssertionFailure() << "qvel differs at step " << i;
  }
  return ::testing::AssertionSuccess();
}

}  // namespace penumbra::quadruped_test

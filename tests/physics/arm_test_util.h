#pragma once
// helpers shared by the arm tests: the bundled table scene, controller blocks as a world
// file would write them, forward kinematics of sampled configurations through MuJoCo,
// and joint-limit checks on the live simulation.

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/config/yaml_document.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/core/pose.h"
#include "penumbra/core/rng.h"
#include "penumbra/physics/simulation.h"

namespace penumbra::arm_test {

inline const std::string kSceneXml = PENUMBRA_SOURCE_DIR "/worlds/models/table_scene.xml";
inline const std::string kArmXml = PENUMBRA_SOURCE_DIR "/worlds/models/arm.xml";

inline const std::vector<std::string> kJoints = {"joint1", "joint2", "joint3", "joint4",
                                                 "joint5", "joint6", "joint7"};

// the servo part of a controller block for the Panda-class arm (robot-local names):
// Franka's joint impedance example gains, the datasheet speed limits.
inline std::string ServoBlock(bool gravity_compensation = true) {
  return std::string(
             "joints: [joint1, joint2, joint3, joint4, joint5, joint6, joint7]\n"
             "actuators: [actuator1, actuator2, actuator3, actuator4, actuator5, actuator6, "
             "actuator7]\n"
             "output: torque\n"
             "kp: [600, 600, 600, 600, 250, 150, 50]\n"
             "kd: [50, 50, 50, 50, 30, 25, 15]\n"
             "max_velocity: [2.175, 2.175, 2.175, 2.175, 2.61, 2.61, 2.61]\n") +
         "gravity_compensation: " + (gravity_compensation ? "true" : "false") + "\n";
}

inline ControllerConfig Block(const std::string& type, const std::string& body, int line = 7) {
  ControllerConfig cfg;
  cfg.type = type;
  cfg.line = line;
  cfg.params = ParseYaml("type: " + type + "\n" + body);
  return cfg;
}

// the model's joint ranges and qpos addresses of the arm joints (unprefixed names)
struct ArmJoints {
  std::vector<int> qpos_adr;
  std::vector<double> lo, hi;
};

inline ArmJoints FindArmJoints(const ModelInfo& m, const std::string& prefix = "") {
  ArmJoints a;
  for (const auto& name : kJoints) {
    const int j = m.Find(ModelObject::kJoint, prefix + name);
    EXPECT_GE(j, 0) << name;
    if (j < 0) continue;
    a.qpos_adr.push_back(m.joints[j].qpos_adr);
    a.lo.push_back(m.joints[j].range[0]);
    a.hi.push_back(m.joints[j].range[1]);
  }
  return a;
}

// largest violation (rad) of any arm joint's range in `qpos` (0 = within limits)
inline double LimitViolation(const ArmJoints& a, std::span<const double> qpos) {
  double worst = 0;
  for (size_t i = 0; i < a.qpos_adr.size(); ++i) {
    const double q = qpos[a.qpos_adr[i]];
    worst = std::max({worst, a.lo[i] - q, q - a.hi[i]});
  }
  return worst;
}

// X_W_ee from a snapshot: the site's body pose times the site offset
inline Pose SitePose(const Simulation& sim, const WorldSnapshot& snap, const std::string& site) {
  const ModelInfo& m = sim.model_info();
  const int s = m.Find(ModelObject::kSite, site);
  EXPECT_GE(s, 0) << site;
  return snap.X_WB[m.site_body[s]] * m.site_X_BS[s];
}

// angle (rad) of R_a^T R_b
inline double AngleBetween(const Eigen::Matrix3d& Ra, const Eigen::Matrix3d& Rb) {
  return Eigen::AngleAxisd(Ra.transpose() * Rb).angle();
}

// a MuJoCo model + data for forward kinematics of arbitrary configurations
class Kinematics {
 public:
  explicit Kinematics(const std::string& path) {
    char err[1000] = "";
    m_ = mj_loadXML(path.c_str(), nullptr, err, sizeof(err));
    if (!m_) throw std::runtime_error(err);
    d_ = mj_makeData(m_);
    for (const auto& name : kJoints) {
      const int j = mj_name2id(m_, mjOBJ_JOINT, name.c_str());
      joints_.push_back(j);
    }
    ee_ = mj_name2id(m_, mjOBJ_SITE, "ee");
    link0_ = mj_name2id(m_, mjOBJ_BODY, "link0");
  }
  ~Kinematics() {
    mj_deleteData(d_);
    mj_deleteModel(m_);
  }
  Kinematics(const Kinematics&) = delete;
  Kinematics& operator=(const Kinematics&) = delete;

  double lo(int i) const { return m_->jnt_range[2 * joints_[i]]; }
  double hi(int i) const { return m_->jnt_range[2 * joints_[i] + 1]; }

  // sets the arm joints (other qpos at qpos0) and runs mj_forward.
  void Set(const std::vector<double>& q) {
    mju_copy(d_->qpos, m_->qpos0, m_->nq);
    for (size_t i = 0; i < q.size(); ++i) d_->qpos[m_->jnt_qposadr[joints_[i]]] = q[i];
    mj_forward(m_, d_);
  }
  // X_link0_ee for the configuration of the last Set
  Pose EePose() const {
    const Pose X_W0 = PoseFromPosQuat(d_->xpos + 3 * link0_, d_->xquat + 4 * link0_);
    Pose X_Wee = Pose::Identity();
    X_Wee.linear() =
        Eigen::Map<const Eigen::Matrix<double, 3, 3, Eigen::RowMajor>>(d_->site_xmat + 9 * ee_);
    X_Wee.translation() = Eigen::Vector3d(d_->site_xpos[3 * ee_], d_->site_xpos[3 * ee_ + 1],
                                          d_->site_xpos[3 * ee_ + 2]);
    return X_W0.inverse() * X_Wee;
  }
  // number of contacts of the last Set that involve a body of the arm (link1 .. fingers)
  int ArmContacts() const {
    int n = 0;
    for (int c = 0; c < d_->ncon; ++c) {
      const int b1 = m_->geom_bodyid[d_->contact[c].geom1];
      const int b2 = m_->geom_bodyid[d_->contact[c].geom2];
      if (IsArm(b1) || IsArm(b2)) ++n;
    }
    return n;
  }

 private:
  bool IsArm(int body) const {
    // every body whose root chain passes through link0, except link0 itself (fixed)
    if (body == link0_) return false;
    for (int b = body; b > 0; b = m_->body_parentid[b])
      if (b == link0_) return true;
    return false;
  }
  mjModel* m_ = nullptr;
  mjData* d_ = nullptr;
  std::vector<int> joints_;
  int ee_ = -1, link0_ = -1;
};

}  // namespace penumbra::arm_test

#include "penumbra/session/crowd_runner.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>

#include "penumbra/physics/simulation.h"
#include "penumbra/session/geom_extents.h"

namespace penumbra {

std::vector<CrowdRobotSource> CrowdRobotsOf(const std::vector<ModelConfig>& models,
                                            const Simulation& sim) {
  std::vector<CrowdRobotSource> out;
  const ModelInfo& info = sim.model_info();
  const SceneDescription& scene = sim.scene();
  const std::vector<Pose> X_WB = sim.Snapshot(Simulation::SnapshotContent::kPoses).X_WB;
  for (const ModelConfig& m : models) {
    if (!m.is_robot) continue;
    CrowdRobotSource r;
    r.name = m.name;
    const Pose X = m.pose.ToPose();
    r.fixed_W = X.translation().head<2>();
    r.fixed_yaw = std::atan2(X.linear()(1, 0), X.linear()(0, 0));
    const std::string prefix = m.name + "/";
    for (const JointInfo& j : info.joints)
      if (j.type == JointInfo::Type::kFree && j.name.rfind(prefix, 0) == 0) {
        r.qpos_adr = j.qpos_adr;
        break;
      }
    // disc radius: the plan extent of its primitive geoms about the start position
    double radius = 0;
    for (const Geom& g : scene.geoms) {
      if (g.body < 0 || g.body >= static_cast<int>(scene.bodies.size()) ||
          g.body >= static_cast<int>(X_WB.size()) ||
          scene.bodies[g.body].name.rfind(prefix, 0) != 0)
        continue;
      const std::optional<Eigen::Vector3d> e = PrimitiveHalfExtents(g);
      if (!e) continue;
      const Pose X_WG = X_WB[g.body] * g.X_BG;
      const Eigen::Vector3d ew = X_WG.linear().cwiseAbs() * *e;
      const Eigen::Vector2d c = X_WG.translation().head<2>() - r.fixed_W;
      radius = std::max(radius, (c.cwiseAbs() + ew.head<2>()).norm());
    }
    if (radius > 0) r.radius_m = std::clamp(radius, 0.2, 1.5);
    out.push_back(r);
  }
  return out;
}

CrowdRunner::CrowdRunner(std::unique_ptr<CrowdSim> crowd, const Simulation* sim,
                         std::vector<CrowdRobotSource> robots, double floor_z, double start_sec)
    : crowd_(std::move(crowd)),
      sim_(sim),
      sources_(std::move(robots)),
      floor_z_(floor_z),
      start_sec_(start_sec),
      previous_(crowd_->states()) {}

void CrowdRunner::set_decision_sink(std::function<void(double, const std::string&)> sink) {
  std::lock_guard<std::mutex> lock(sink_mu_);
  sink_ = std::move(sink);
}

std::vector<CrowdRobot> CrowdRunner::Robots() {
  std::vector<CrowdRobot> out;
  const std::span<const double> q = sim_ ? sim_->qpos() : std::span<const double>();
  const bool first = last_robot_W_.empty();
  for (size_t i = 0; i < sources_.size(); ++i) {
    const CrowdRobotSource& s = sources_[i];
    CrowdRobot r;
    r.radius_m = s.radius_m;
    r.position_W = s.fixed_W;
    r.yaw = s.fixed_yaw;
    if (s.qpos_adr >= 0 && s.qpos_adr + 7 <= static_cast<int>(q.size())) {
      r.position_W = Eigen::Vector2d(q[s.qpos_adr], q[s.qpos_adr + 1]);
      const Eigen::Quaterniond quat(q[s.qpos_adr + 3], q[s.qpos_adr + 4], q[s.qpos_adr + 5],
                                    q[s.qpos_adr + 6]);
      const Eigen::Vector3d x = quat.normalized() * Eigen::Vector3d::UnitX();
      r.yaw = std::atan2(x.y(), x.x());
    }
    if (!first) r.velocity_W = (r.position_W - last_robot_W_[i]) / crowd_->dt();
    out.push_back(r);
  }
  last_robot_W_.clear();
  for (const CrowdRobot& r : out) last_robot_W_.push_back(r.position_W);
  return out;
}

void CrowdRunner::AdvanceTo(double time_sec) {
  const double local = time_sec - start_sec_;
  // the crowd stays a step ahead of the time asked for, so that X_WA interpolates within
  // [t1 - dt, t1] and never holds a pose (stepping at the middle of the interval instead made
  // the roots stand still for half of each crowd step and then jump half a step ahead)
  while (crowd_->time_sec() < local) {
    previous_ = crowd_->states();
    crowd_->Step(Robots());
    std::vector<CrowdDecision> decisions = crowd_->TakeDecisions();
    std::lock_guard<std::mutex> lock(sink_mu_);
    if (!sink_) continue;
    for (const CrowdDecision& d : decisions) {
      nlohmann::json j;
      j["agent"] = crowd_->agents()[d.agent].name;
      j["what"] = d.what;
      j["goal"] = {d.goal_W.x(), d.goal_W.y()};
      j["plan_points"] = d.plan_points;
      sink_(start_sec_ + d.time_sec, j.dump());
    }
  }
}

Pose CrowdRunner::X_WA(size_t i, double time_sec) {
  AdvanceTo(time_sec);
  // between the last two crowd steps
  const double t1 = crowd_->time_sec(), t0 = t1 - crowd_->dt();
  const double s = std::clamp((time_sec - start_sec_ - t0) / crowd_->dt(), 0.0, 1.0);
  const CrowdAgentState& a = previous_[i];
  const CrowdAgentState& b = crowd_->states()[i];
  const Eigen::Vector2d p = a.position_W + s * (b.position_W - a.position_W);
  const double yaw = a.yaw + s * std::remainder(b.yaw - a.yaw, 2 * M_PI);
  Pose X = Pose::Identity();
  X.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  X.translation() = Eigen::Vector3d(p.x(), p.y(), floor_z_);
  return X;
}

}  // namespace penumbra

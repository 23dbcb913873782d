#include "penumbra/metrics/fall_detector.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <cmath>
#include <nlohmann/json.hpp>
#include <numbers>
#include <utility>

#include "penumbra/control/model_info.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {

double BaseTiltDeg(const Eigen::Quaterniond& q_WB) {
  // z axis of the body in world coordinates, its z component: R_22 = (w^2 - x^2 - y^2 + z^2)
  // / |q|^2
  const double n2 = q_WB.squaredNorm();
  if (!(n2 > 0)) return 0;
  const double r22 =
      (q_WB.w() * q_WB.w() - q_WB.x() * q_WB.x() - q_WB.y() * q_WB.y() + q_WB.z() * q_WB.z()) / n2;
  return std::acos(std::clamp(r22, -1.0, 1.0)) * 180.0 / std::numbers::pi;
}

FallDetector::FallDetector(std::string robot, std::string body, FallRule rule) : rule_(rule) {
  result_.robot = std::move(robot);
  result_.body = std::move(body);
}

bool FallDetector::Update(double time_sec, double tilt_deg) {
  if (tilt_deg > result_.max_tilt_deg) {
    result_.max_tilt_deg = tilt_deg;
    result_.max_tilt_time_sec = time_sec;
  }
  if (!(tilt_deg > rule_.tilt_threshold_deg)) {
    above_since_ = std::numeric_limits<double>::quiet_NaN();
    return false;
  }
  if (std::isnan(above_since_)) above_since_ = time_sec;
  if (result_.fell || time_sec - above_since_ < rule_.min_duration_sec) return false;
  result_.fell = true;
  result_.fall_time_sec = above_since_;
  return true;
}

bool StartCheck::Update(double time_sec, double tilt_deg, double base_z_m) {
  if (done_) return false;
  if (!started_) {
    started_ = true;
    t0_ = time_sec;
    tilt0_ = tilt_deg;
    z0_ = base_z_m;
  }
  if (time_sec - t0_ > rule_.window_sec) {
    done_ = true;
    stumbled_ = max_drop_m_ > rule_.drop_m || max_tilt_change_ > rule_.tilt_change_deg;
    return stumbled_;
  }
  max_drop_m_ = std::max(max_drop_m_, z0_ - base_z_m);
  max_tilt_change_ = std::max(max_tilt_change_, std::abs(tilt_deg - tilt0_));
  return false;
}

std::vector<FallTarget> FallTargets(const WorldConfig& world, const Simulation& sim) {
  std::vector<FallTarget> out;
  const std::vector<JointInfo>& joints = sim.model_info().joints;
  const std::vector<Body>& bodies = sim.scene().bodies;
  for (const ModelConfig& m : world.models) {
    if (!m.is_robot) continue;
    const std::string prefix = m.name + "/";
    for (const JointInfo& j : joints) {
      if (j.type != JointInfo::Type::kFree || j.body <= 0 ||
          j.body >= static_cast<int>(bodies.size()))
        continue;
      if (bodies[j.body].name.rfind(prefix, 0) != 0) continue;
      out.push_back({m.name, bodies[j.body].name, j.qpos_adr + 3, !m.initial_keyframe.empty()});
      break;
    }
  }
  return out;
}

FallSink::FallSink(std::vector<FallTarget> targets, FallRule rule)
    : targets_(std::move(targets)), rule_(rule) {
  for (const FallTarget& t : targets_) detectors_.emplace_back(t.robot, t.body, rule_);
  starts_.resize(targets_.size());
}

SnapshotContent FallSink::Wants(int64_t step, double time_sec) { return SnapshotContent::kState; }

void FallSink::OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) {
  const std::vector<double>& qpos = snapshot->qpos;
  for (size_t i = 0; i < targets_.size(); ++i) {
    const int a = targets_[i].quat_adr;
    if (a < 0 || static_cast<size_t>(a) + 4 > qpos.size()) continue;
    const Eigen::Quaterniond q(qpos[a], qpos[a + 1], qpos[a + 2], qpos[a + 3]);
    const double tilt = BaseTiltDeg(q);
    StartCheck& start = starts_[i];
    if (start.Update(snapshot->time_sec, tilt, qpos[a - 1])) {
      spdlog::warn(
          "robot '{}' stumbled from its initial pose in its first {:g} s: its base {} dropped "
          "{:.3f} m and tilted {:.1f} deg{}",
          targets_[i].robot, start.rule().window_sec, targets_[i].body, start.max_drop_m(),
          start.max_tilt_change_deg(),
          targets_[i].has_initial_keyframe
              ? " (from the world file's initial_keyframe: is it a standing pose its "
                "actuators hold?)"
              : " (it starts in its model's reference pose qpos0, often not a standing one: "
                "set the robot's initial_keyframe to a standing <key> of its MJCF, or give it a "
                "controller that holds it)");
    }
    FallDetector& d = detectors_[i];
    if (d.Update(snapshot->time_sec, tilt)) {
      const RobotFall& r = d.result();
      spdlog::warn(
          "robot '{}' fell at {:.3f} s: its base {} tilted more than {:g} deg from upright for "
          "{:g} s (max tilt {:.1f} deg so far); run.json \"falls\"",
          r.robot, r.fall_time_sec, r.body, rule_.tilt_threshold_deg, rule_.min_duration_sec,
          r.max_tilt_deg);
    }
  }
}

std::vector<RobotFall> FallSink::Results() const {
  std::vector<RobotFall> out;
  for (const FallDetector& d : detectors_) out.push_back(d.result());
  return out;
}

std::string FallSink::SummaryJson() const {
  nlohmann::ordered_json j;
  j["rule"] = fmt::format("base tilt from upright > {:g} deg for >= {:g} s",
                          rule_.tilt_threshold_deg, rule_.min_duration_sec);
  j["tilt_threshold_deg"] = rule_.tilt_threshold_deg;
  j["min_duration_sec"] = rule_.min_duration_sec;
  nlohmann::ordered_json robots = nlohmann::ordered_json::object();
  for (const FallDetector& d : detectors_) {
    const RobotFall& r = d.result();
    nlohmann::ordered_json e;
    e["base_body"] = r.body;
    e["fell"] = r.fell;
    e["fall_time_sec"] = r.fell ? nlohmann::ordered_json(r.fall_time_sec) : nullptr;
    e["max_tilt_deg"] = r.max_tilt_deg;
    e["max_tilt_time_sec"] = r.max_tilt_time_sec;
    const StartCheck& start = starts_[&d - detectors_.data()];
    e["start_drop_m"] = start.max_drop_m();
    e["start_tilt_change_deg"] = start.max_tilt_change_deg();
    e["stumbled_at_start"] = start.stumbled();
    robots[r.robot] = e;
  }
  j["robots"] = robots;
  return j.dump();
}

std::unique_ptr<FallSink> MakeFallSink(const WorldConfig& world, const Simulation& sim) {
  std::vector<FallTarget> targets = FallTargets(world, sim);
  if (targets.empty()) return nullptr;
  return std::make_unique<FallSink>(std::move(targets));
}

}  // namespace penumbra

#include "penumbra/effects/agent_animation.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

double Yaw(const Pose& X) {
  const Eigen::Vector3d x = X.linear().col(0);
  return std::atan2(x.y(), x.x());
}

double WrapPi(double a) { return std::remainder(a, 2.0 * M_PI); }

}  // namespace

std::vector<AgentWheel> AgentWheels(AgentKind kind) {
  switch (kind) {
    case AgentKind::kPerson:
      return {};
    case AgentKind::kForklift:
      return {{"wheel_fl", {0.55, 0.49, 0.25}, 0.25, 0.14, 0},
              {"wheel_fr", {0.55, -0.49, 0.25}, 0.25, 0.14, 0},
              {"wheel_rl", {-0.55, 0.49, 0.25}, 0.25, 0.14, -1},
              {"wheel_rr", {-0.55, -0.49, 0.25}, 0.25, 0.14, -1}};
    case AgentKind::kCart:
      return {{"wheel_fl", {0.4, 0.29, 0.1}, 0.1, 0.04, 1},
              {"wheel_fr", {0.4, -0.29, 0.1}, 0.1, 0.04, 1},
              {"wheel_rl", {-0.4, 0.29, 0.1}, 0.1, 0.04, 0},
              {"wheel_rr", {-0.4, -0.29, 0.1}, 0.1, 0.04, 0}};
  }
  return {};
}

double AgentWheelbase(AgentKind kind) {
  // the body's own axles: the crowd's bicycle model (effects/crowd_sim.h KindModel) and the
  // wheels' steering read this one number
  double front = 0, rear = 0;
  for (const AgentWheel& w : AgentWheels(kind)) {
    front = std::max(front, w.centre.x());
    rear = std::min(rear, w.centre.x());
  }
  return front - rear;
}

std::vector<std::string> AgentPartNames(AgentKind kind) {
  std::vector<std::string> names;
  if (kind == AgentKind::kPerson) {
    for (int i = 0; i < kWalkerSegmentCount; ++i)
      names.push_back(WalkerSegmentName(static_cast<WalkerSegment>(i)));
  } else {
    for (const AgentWheel& w : AgentWheels(kind)) names.push_back(w.name);
  }
  return names;
}

Pose AgentWheelPose(const AgentWheel& wheel, double spin, double steer) {
  return Pose(Eigen::Translation3d(wheel.centre)) *
         Pose(Eigen::AngleAxisd(steer, Eigen::Vector3d::UnitZ())) *
         Pose(Eigen::AngleAxisd(spin, Eigen::Vector3d::UnitY()));
}

AgentMotionClock::AgentMotionClock(std::function<Pose(double)> X_WA, double hip_height_m)
    : X_WA_(std::move(X_WA)), hip_height_m_(hip_height_m) {
  if (!X_WA_) throw Error("AgentMotionClock: empty pose function");
  X_k_ = X_WA_(0.0);
}

void AgentMotionClock::Advance() {
  const double dt = kAnimationGridSec;
  const Pose next = X_WA_(static_cast<double>(k_ + 1) * dt);
  const Eigen::Vector2d d = (next.translation() - X_k_.translation()).head<2>();
  const double yaw0 = Yaw(X_k_), yaw1 = Yaw(next);
  const Eigen::Vector2d heading(std::cos(yaw0), std::sin(yaw0));
  const double raw_speed = d.norm() / dt;
  const double raw_yaw_rate = WrapPi(yaw1 - yaw0) / dt;
  // exponential smoothing on the grid (exact for a piecewise-constant input)
  const double a = 1.0 - std::exp(-dt / kAnimationSmoothingSec);
  s_.distance_m += d.dot(heading) >= 0 ? d.norm() : -d.norm();
  s_.speed_m_s += a * (raw_speed - s_.speed_m_s);
  s_.yaw_rate += a * (raw_yaw_rate - s_.yaw_rate);
  if (hip_height_m_ > 0) s_.gait_cycles += WalkerStrideFrequency(s_.speed_m_s, hip_height_m_) * dt;
  s_.raw_speed_m_s = raw_speed;
  ++k_;
  X_k_ = next;
}

AgentMotionState AgentMotionClock::At(double time_sec) {
  const double t = std::max(0.0, time_sec);
  const int64_t k = static_cast<int64_t>(std::floor(t / kAnimationGridSec));
  if (k < k_) {
    k_ = 0;
    s_ = AgentMotionState{};
    X_k_ = X_WA_(0.0);
  }
  while (k_ < k) Advance();
  // within a grid step: the cached state plus the partial step at the same rates
  AgentMotionState out = s_;
  const double frac = t - static_cast<double>(k_) * kAnimationGridSec;
  if (frac > 0) {
    const Pose X = X_WA_(t);
    const Eigen::Vector2d d = (X.translation() - X_k_.translation()).head<2>();
    const double yaw0 = Yaw(X_k_);
    const Eigen::Vector2d heading(std::cos(yaw0), std::sin(yaw0));
    out.distance_m += d.dot(heading) >= 0 ? d.norm() : -d.norm();
    if (hip_height_m_ > 0)
      out.gait_cycles += WalkerStrideFrequency(s_.speed_m_s, hip_height_m_) * frac;
  }
  out.time_sec = t;
  return out;
}

AgentAnimator::AgentAnimator(AgentKind kind, double height_m, std::function<Pose(double)> X_WA)
    : kind_(kind),
      skeleton_(WalkerSkeleton::FromHeight(kind == AgentKind::kPerson ? height_m : 1.75)),
      wheels_(AgentWheels(kind)),
      clock_(std::move(X_WA), kind == AgentKind::kPerson ? skeleton_.hip_height_m : 0.0) {}

WalkerJointAngles AgentAnimator::Angles(double time_sec) {
  if (kind_ != AgentKind::kPerson) return {};
  const AgentMotionState m = clock_.At(time_sec);
  return WalkerGaitAngles(skeleton_, m.gait_cycles, m.speed_m_s);
}

double AgentAnimator::WheelSpin(double time_sec, const AgentWheel& wheel) {
  return clock_.At(time_sec).distance_m / wheel.radius_m;
}

double AgentAnimator::SteerAngle(double time_sec, const AgentWheel& wheel) {
  if (wheel.steer == 0) return 0;
  const AgentMotionState m = clock_.At(time_sec);
  const double L = AgentWheelbase(kind_);
  // bicycle model: tan(delta) = L omega / v; near standstill the turn rate alone decides
  const double delta = std::atan2(L * m.yaw_rate, std::max(m.speed_m_s, 1e-3));
  return wheel.steer * std::clamp(delta, -kMaxSteerRad, kMaxSteerRad);
}

const std::vector<Pose>& AgentAnimator::Poses(double time_sec) {
  if (time_sec == cached_t_ && !poses_.empty()) return poses_;
  const Pose X_WA = clock_.X_WA(time_sec);
  poses_.clear();
  if (kind_ == AgentKind::kPerson) {
    const WalkerPose p = WalkerForwardKinematics(skeleton_, Angles(time_sec));
    poses_.push_back(X_WA * p.X_AR);
    for (const Pose& X_AS : p.X_AS) poses_.push_back(X_WA * X_AS);
  } else {
    poses_.push_back(X_WA);
    for (const AgentWheel& w : wheels_)
      poses_.push_back(X_WA * AgentWheelPose(w, WheelSpin(time_sec, w), SteerAngle(time_sec, w)));
  }
  cached_t_ = time_sec;
  return poses_;
}

}  // namespace penumbra

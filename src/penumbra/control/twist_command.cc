#include "penumbra/control/twist_command.h"

#include <cmath>
#include <limits>

#include "penumbra/config/config_value.h"
#include "penumbra/control/param_limits.h"
#include "penumbra/control/pure_pursuit.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {}  // namespace

TwistScriptParams TwistScriptParams::Parse(ControllerParams& p) {
  TwistScriptParams s;
  // commands: a list of {t, vx, vy, yaw_rate}, t strictly increasing
  if (const ConfigValue* cmds = p.Raw("commands")) {
    if (!cmds->IsSequence())
      p.Fail("commands", "got " + DescribeParamNode(*cmds) +
                             "; expected a list of {t, vx, vy, yaw_rate} with increasing t");
    for (size_t i = 0; i < cmds->size(); ++i) {
      const std::string key = "commands[" + std::to_string(i) + "]";
      const ConfigValue c = (*cmds)[i];
      if (!c.IsMap())
        p.Fail(key, "got " + DescribeParamNode(c) + "; expected {t, vx, vy, yaw_rate}");
      for (const auto& kv : c.pairs()) {
        const std::string k = kv.first.Scalar();
        if (k != "t" && k != "vx" && k != "vy" && k != "yaw_rate")
          p.Fail(key + "." + k, "unknown key; expected only t, vx, vy, yaw_rate");
      }
      if (!c["t"]) p.Fail(key + ".t", "missing; expected a time >= 0 (s)");
      TimedTrotCommand tc;
      tc.t_sec = ParamNumberAt(p, c["t"], key + ".t", 0, kMaxParamTimeSec, "s");
      if (!s.commands.empty() && tc.t_sec <= s.commands.back().t_sec)
        p.Fail(key + ".t", "got " + c["t"].Scalar() + "; expected a time > the previous entry's");
      if (c["vx"])
        tc.command.vx =
            ParamNumberAt(p, c["vx"], key + ".vx", -kMaxParamSpeedMS, kMaxParamSpeedMS, "m/s");
      if (c["vy"])
        tc.command.vy =
            ParamNumberAt(p, c["vy"], key + ".vy", -kMaxParamSpeedMS, kMaxParamSpeedMS, "m/s");
      if (c["yaw_rate"])
        tc.command.yaw_rate =
            ParamNumberAt(p, c["yaw_rate"], key + ".yaw_rate", -kMaxParamAngularSpeedRadS,
                          kMaxParamAngularSpeedRadS, "rad/s");
      s.commands.push_back(tc);
    }
  }
  // waypoint mode: the route keys only make sense with waypoints
  if (p.Has("waypoints")) {
    s.waypoints = p.Points2("waypoints", 1);
    s.loop = p.Bool("loop", true);
    s.speed_m_s = p.Number("speed_m_s", 0.5, 0, kMaxParamSpeedMS, true);
    s.max_yaw_rate_deg_s = p.Number("max_yaw_rate_deg_s", 60, 0, kMaxParamAngularSpeedDegS, true);
    s.tolerance_m = p.Number("tolerance_m", 0.15, 0, kMaxParamPositionM, true);
  } else {
    for (const char* k : {"loop", "speed_m_s", "max_yaw_rate_deg_s", "tolerance_m"})
      if (p.Has(k))
        p.Fail(k,
               "only valid in waypoint mode; expected also `waypoints: [[x, y], ...]` "
               "(world frame, m)");
  }
  return s;
}

TwistCommandSource::TwistCommandSource(TwistScriptParams params) : params_(std::move(params)) {
  if (!params_.waypoints.empty())
    route_.emplace(params_.waypoints, params_.loop, params_.tolerance_m);
}

TrotCommand TwistCommandSource::Scripted(double t) const {
  TrotCommand cmd;
  for (const auto& tc : params_.commands) {
    if (tc.t_sec > t + 1e-9) break;
    cmd = tc.command;
  }
  return cmd;
}

TrotCommand TwistCommandSource::Update(double t, const Pose& X_WB) {
  if (override_) return *override_;
  if (route_) route_->Advance(X_WB.translation().head<2>());
  if (route_ && !route_->finished()) {
    const UnicycleCommand u = PurePursuit(
        X_WB, route_->target(), {params_.speed_m_s, params_.max_yaw_rate_deg_s * M_PI / 180.0});
    return TrotCommand{u.v_m_s, 0.0, u.yaw_rate};
  }
  return Scripted(t);
}

void TwistCommandSource::SetWaypoints(std::vector<Eigen::Vector2d> waypoints, bool loop,
                                      const std::string& label) {
  if (waypoints.empty()) throw Error(label + ": empty waypoint list; expected at least 1");
  for (const auto& w : waypoints)
    if (!w.allFinite()) throw Error(label + ": non-finite waypoint coordinate");
  route_.emplace(std::move(waypoints), loop, params_.tolerance_m);
  override_.reset();
}

void TwistCommandSource::Reset() {
  if (route_) route_->Reset();
}

}  // namespace penumbra

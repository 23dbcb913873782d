#include "penumbra/effects/types/flashlight.h"

#include "penumbra/core/error.h"
#include "penumbra/effects/effect_config.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

class FlashlightInstance : public EffectInstance {
 public:
  FlashlightInstance(const EffectConfig& e, int body)
      : e_(e), fl_(e.Get<FlashlightParams>()), body_(body) {}

  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    const double t = ctx.time_sec, w = ctx.weight;
    if (w <= 0) return;
    const FlashlightParams& fl = fl_;
    Eigen::Vector3d pos, dir;
    if (body_ >= 0) {
      const std::vector<Pose>* X_WB = ctx.X_WB;
      if (!X_WB || static_cast<int>(X_WB->size()) <= body_) {
        throw Error("effects: flashlight '" + e_.name + "' is attached to body " + fl.attach +
                    " but Evaluate got no pose for it (X_WB has " +
                    std::to_string(X_WB ? X_WB->size() : 0) + " entries)");
      }
      const Pose& X = (*X_WB)[body_];
      pos = X * fl.position_B;
      dir = X.linear() * fl.direction_B.normalized();
    } else {
      const auto& wp = fl.waypoints;
      if (t <= wp.front().t_sec) {
        pos = wp.front().position_W;
        dir = wp.front().direction_W;
      } else if (t >= wp.back().t_sec) {
        pos = wp.back().position_W;
        dir = wp.back().direction_W;
      } else {
        size_t s = 0;
        while (wp[s + 1].t_sec < t) ++s;
        const double f = (t - wp[s].t_sec) / (wp[s + 1].t_sec - wp[s].t_sec);
        pos = (1 - f) * wp[s].position_W + f * wp[s + 1].position_W;
        dir = (1 - f) * wp[s].direction_W.normalized() + f * wp[s + 1].direction_W.normalized();
        if (dir.norm() < 1e-9) dir = wp[s + 1].direction_W;
      }
    }
    Light l;
    l.name = e_.name;
    l.type = Light::Type::kSpot;
    l.body = 0;
    l.position_B = pos;
    l.direction_B = dir.normalized();
    l.color = fl.color.cast<float>() / static_cast<float>(fl.color.maxCoeff());
    l.intensity = static_cast<float>(fl.intensity_cd * w);
    l.spot_inner_deg = static_cast<float>(fl.inner_angle_deg);
    l.spot_outer_deg = static_cast<float>(fl.outer_angle_deg);
    l.radius_m = static_cast<float>(fl.radius_m);
    frame->extra_lights.push_back(l);
  }

 private:
  const EffectConfig& e_;
  const FlashlightParams& fl_;
  int body_;  // attached body index, or -1
};

}  // namespace

std::vector<std::string_view> FlashlightParams::Keys() {
  return {"waypoints",       "attach",          "position", "direction", "intensity_cd",
          "inner_angle_deg", "outer_angle_deg", "color",    "radius_m"};
}

void FlashlightParams::Read(const EffectParamReader& r) {
  if (r.Has("waypoints")) {
    for (const auto& w : r.List("waypoints")) {
      w->ExpectKeys({"t_sec", "position", "direction"});
      FlashlightWaypoint wp;
      wp.t_sec = w->Double("t_sec");
      wp.position_W = w->Vector3("position");
      w->Vec("direction", &wp.direction_W);
      waypoints.push_back(wp);
    }
  }
  r.Str("attach", &attach);
  r.Vec("position", &position_B);
  r.Vec("direction", &direction_B);
  r.Num("intensity_cd", &intensity_cd);
  r.Num("inner_angle_deg", &inner_angle_deg);
  r.Num("outer_angle_deg", &outer_angle_deg);
  r.Vec("color", &color);
  r.Num("radius_m", &radius_m);
}

void FlashlightParams::Validate(const EffectConfig&, EffectChecker* c) const {
  using R = EffectRange;
  using N = EffectChecker;
  if (attach.empty()) {
    if (waypoints.empty()) {
      c->Fail("waypoints",
              "no waypoints and no attach body; expected a list of {t_sec, position, "
              "direction} or attach: <body name>");
    }
    for (size_t i = 0; i < waypoints.size(); ++i) {
      const std::string k = "waypoints[" + std::to_string(i) + "]";
      c->In(k + ".t_sec", waypoints[i].t_sec, R::Closed(0, kMaxDurationSec));
      if (c->ok() && i > 0 && !(waypoints[i].t_sec > waypoints[i - 1].t_sec)) {
        c->Fail(k + ".t_sec", N::Num(waypoints[i].t_sec) +
                                  " is out of range; expected t_sec increasing along the list");
      }
      c->In3(k + ".position", waypoints[i].position_W, R::Closed(-kMaxPositionM, kMaxPositionM));
      c->In3(k + ".direction", waypoints[i].direction_W,
             R::Closed(-kMaxDirectionComponent, kMaxDirectionComponent));
      if (c->ok() && waypoints[i].direction_W.norm() < 1e-9) {
        c->Fail(k + ".direction", "zero vector; expected a non-zero direction");
      }
    }
  } else {
    c->In3("position", position_B, R::Closed(-kMaxPositionM, kMaxPositionM));
    c->In3("direction", direction_B, R::Closed(-kMaxDirectionComponent, kMaxDirectionComponent));
    if (c->ok() && direction_B.norm() < 1e-9) {
      c->Fail("direction", "zero vector; expected a non-zero direction");
    }
  }
  c->In("intensity_cd", intensity_cd, R::OpenClosed(0, kMaxIntensityCd));
  c->In("inner_angle_deg", inner_angle_deg, R::Open(0, 90));
  c->In("outer_angle_deg", outer_angle_deg, R::Open(0, 90));
  if (c->ok() && inner_angle_deg > outer_angle_deg) {
    c->Fail("inner_angle_deg", N::Num(inner_angle_deg) +
                                   " is out of range; expected <= outer_angle_deg (" +
                                   N::Num(outer_angle_deg) + ")");
  }
  c->In3("color", color, R::Closed(0, 1));
  if (c->ok() && color.maxCoeff() <= 0) {
    c->Fail("color", "black; expected a colour with a component > 0");
  }
  c->In("radius_m", radius_m, R::Closed(0, kMaxLightRadiusM));
}

std::unique_ptr<EffectInstance> FlashlightParams::Bind(const EffectConfig& e,
                                                       const EffectBindContext& ctx) const {
  int body = -1;
  if (!attach.empty()) {
    body = ctx.scene.FindBody(attach);
    if (body < 0) {
      throw ConfigError("", 0, ctx.key_prefix + ".attach",
                        ctx.who + "no body named '" + attach +
                            "'; expected a body name of the composed model (\"<model>/<body>\")");
    }
  }
  return std::make_unique<FlashlightInstance>(e, body);
}

}  // namespace penumbra

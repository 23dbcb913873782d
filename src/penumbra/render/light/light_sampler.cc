#include "penumbra/render/light/light_sampler.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/light/light_math.h"

namespace penumbra {
namespace {

// the pose-independent part of a light.
PosedLight Unposed(const Light& l) {
  PosedLight p;
  p.type = l.type;
  p.intensity_rgb = l.color.cwiseMax(0.0f) * l.intensity;
  const float outer = std::clamp(l.spot_outer_deg, 0.0f, 180.0f);
  const float inner = std::clamp(l.spot_inner_deg, 0.0f, outer);
  p.cos_outer = static_cast<float>(std::cos(outer * std::numbers::pi / 180.0));
  p.cos_inner = static_cast<float>(std::cos(inner * std::numbers::pi / 180.0));
  p.radius_m = std::max(l.radius_m, 0.0f);
  p.cos_angular_radius = static_cast<float>(
      std::cos(std::clamp(l.angular_radius_deg, 0.0f, 90.0f) * std::numbers::pi / 180.0));
  p.cast_shadow = l.cast_shadow;
  return p;
}

}  // namespace

LightSampler::LightSampler(const SceneDescription& scene)
    : num_bodies_(static_cast<int>(scene.bodies.size())) {
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    if (!l.active || !(l.intensity > 0) || !(l.color.maxCoeff() > 0)) continue;
    sources_.push_back(l);
    scene_index_.push_back(static_cast<int>(i));
    lights_.push_back(Unposed(l));
    base_intensity_rgb_.push_back(lights_.back().intensity_rgb);
  }
  SyncPods();
}

void LightSampler::Update(const WorldSnapshot& snapshot, const EffectsFrame* effects) {
  const EffectsFrame* fx = effects;
  lights_.resize(sources_.size());
  for (size_t i = 0; i < sources_.size(); ++i) {
    lights_[i].intensity_rgb = base_intensity_rgb_[i];
    if (fx == nullptr || fx->light_intensity_scale.empty()) continue;
    const int k = scene_index_[i];
    if (k >= static_cast<int>(fx->light_intensity_scale.size())) continue;
    const float s = fx->light_intensity_scale[k];
    if (!(s >= 0) || !std::isfinite(s))
      throw ConfigError("", 0, "effects.light_intensity_scale[" + std::to_string(k) + "]",
                        "expected a finite value >= 0");
    lights_[i].intensity_rgb = base_intensity_rgb_[i] * s;
  }
  if (fx != nullptr) {
    for (const Light& l : fx->extra_lights) {
      if (!l.active || !(l.intensity > 0) || !(l.color.maxCoeff() > 0)) continue;
      PosedLight p = Unposed(l);
      Eigen::Vector3d pos = l.position_B, dir = l.direction_B;
      if (l.body > 0 && l.body < static_cast<int>(snapshot.X_WB.size())) {
        pos = snapshot.X_WB[l.body] * l.position_B;
        dir = snapshot.X_WB[l.body].linear() * l.direction_B;
      }
      const double n = dir.norm();
      p.position_W = pos.cast<float>();
      p.direction_W = n > 0 ? Eigen::Vector3f((dir / n).cast<float>()) : Eigen::Vector3f(0, 0, -1);
      lights_.push_back(p);
    }
  }
  for (size_t i = 0; i < sources_.size(); ++i) {
    const Light& l = sources_[i];
    PosedLight& p = lights_[i];
    Eigen::Vector3d pos, dir;
    if (l.mjcf_light >= 0) {
      if (l.mjcf_light >= static_cast<int>(snapshot.light_position_W.size()) ||
          l.mjcf_light >= static_cast<int>(snapshot.light_direction_W.size()))
        throw Error("LightSampler: light '" + l.name + "' is MJCF light " +
                    std::to_string(l.mjcf_light) + " but the snapshot has " +
                    std::to_string(snapshot.light_position_W.size()) + " lights");
      pos = snapshot.light_position_W[l.mjcf_light];
      dir = snapshot.light_direction_W[l.mjcf_light];
    } else {
      if (l.body < 0 || l.body >= static_cast<int>(snapshot.X_WB.size()))
        throw Error("LightSampler: light '" + l.name + "' is attached to body " +
                    std::to_string(l.body) + " but the snapshot has " +
                    std::to_string(snapshot.X_WB.size()) + " bodies");
      const Pose& X_WB = snapshot.X_WB[l.body];
      pos = X_WB * l.position_B;
      dir = X_WB.linear() * l.direction_B;
    }
    const double n = dir.norm();
    p.position_W = pos.cast<float>();
    p.direction_W = n > 0 ? Eigen::Vector3f((dir / n).cast<float>()) : Eigen::Vector3f(0, 0, -1);
  }
  SyncPods();
}

bool LightSampler::Sample(int i, const Eigen::Vector3f& p_W, float u1, float u2,
                          LightSample* s) const {
  // the shared SampleLight (render/light/light_math.h) with Eigen's normalisation of the cone
  // direction, which this scalar form has always used.
  const LightPod& l = pods_[i];
  s->cast_shadow = l.cast_shadow != 0;
  Float3 wi, E;
  float distance = 0;
  bool valid = false;
  SampleLight<float, Float3, bool, true>(l, Float3{p_W.x(), p_W.y(), p_W.z()}, u1, u2, &wi,
                                         &distance, &E, &valid);
  if (!valid) return false;
  s->wi = Eigen::Vector3f(wi.x, wi.y, wi.z);
  s->distance = distance;
  s->E = Eigen::Vector3f(E.x, E.y, E.z);
  return true;
}

void LightSampler::SampleLanes(int i, const Vec3Lanes& p_W, const Lanes& u1, const Lanes& u2,
                               LightSampleLanes* s) const {
  SampleLight<Lanes, Vec3Lanes, LaneMask>(pods_[i], p_W, u1, u2, &s->wi, &s->distance, &s->E,
                                          &s->valid);
}

void LightSampler::SyncPods() {
  pods_.resize(lights_.size());
  for (size_t i = 0; i < lights_.size(); ++i) {
    const PosedLight& l = lights_[i];
    LightPod& p = pods_[i];
    p.kind = l.type == Light::Type::kDirectional ? LightKind::kDirectional
             : l.type == Light::Type::kSpot      ? LightKind::kSpot
                                                 : LightKind::kPoint;
    p.position_W = {l.position_W.x(), l.position_W.y(), l.position_W.z()};
    p.direction_W = {l.direction_W.x(), l.direction_W.y(), l.direction_W.z()};
    p.intensity_rgb = {l.intensity_rgb.x(), l.intensity_rgb.y(), l.intensity_rgb.z()};
    p.cos_inner = l.cos_inner;
    p.cos_outer = l.cos_outer;
    p.radius_m = l.radius_m;
    p.cos_angular_radius = l.cos_angular_radius;
    p.cast_shadow = l.cast_shadow ? 1 : 0;
  }
}

}  // namespace penumbra

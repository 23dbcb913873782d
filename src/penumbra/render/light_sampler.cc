#include "penumbra/render/light_sampler.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/light_math.h"

namespace penumbra {
namespace {

// cubic smoothstep from e0 (0) to e1 (1); a hard step where e0 == e1.
inline float SmoothStep(float e0, float e1, float x) {
  if (e1 <= e0) return x >= e0 ? 1.0f : 0.0f;
  const float t = std::clamp((x - e0) / (e1 - e0), 0.0f, 1.0f);
  return t * t * (3.0f - 2.0f * t);
}

// tangent t and bitangent bt completing unit w to an orthonormal basis (Duff et al., "Building
// an orthonormal basis, revisited", JCGT 2017).
inline void ConeBasis(const Eigen::Vector3f& w, Eigen::Vector3f* t, Eigen::Vector3f* bt) {
  const float sign = w.z() >= 0 ? 1.0f : -1.0f;
  const float a = -1.0f / (sign + w.z());
  const float b = w.x() * w.y() * a;
  *t = Eigen::Vector3f(1.0f + sign * w.x() * w.x() * a, sign * b, -sign * w.x());
  *bt = Eigen::Vector3f(b, sign + w.y() * w.y() * a, -w.y());
}

// unit direction sampled uniformly in the cone of half-angle acos(cos_max) around unit axis
// w (Pharr, Jakob, Humphreys, "Physically Based Rendering", 4th ed., sec. A.5.4).
inline Eigen::Vector3f SampleCone(const Eigen::Vector3f& w, float cos_max, float u1, float u2) {
  const float cos_t = 1.0f - u1 * (1.0f - cos_max);
  const float sin_t = std::sqrt(std::max(0.0f, 1.0f - cos_t * cos_t));
  float sp, cp;
  SinCos2Pi(u2, &sp, &cp);
  Eigen::Vector3f t, bt;
  ConeBasis(w, &t, &bt);
  return (sin_t * cp * t + sin_t * sp * bt + cos_t * w).normalized();
}

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
  const PosedLight& l = lights_[i];
  s->cast_shadow = l.cast_shadow;
  if (l.type == Light::Type::kDirectional) {
    const Eigen::Vector3f to_light = -l.direction_W;
    s->wi =
        l.cos_angular_radius < 1.0f ? SampleCone(to_light, l.cos_angular_radius, u1, u2) : to_light;
    s->distance = std::numeric_limits<float>::infinity();
    s->E = l.intensity_rgb;
    return true;
  }
  const Eigen::Vector3f to_light = l.position_W - p_W;
  const float d2 = to_light.squaredNorm();
  const float d = std::sqrt(d2);
  if (!(d > l.radius_m)) return false;  // inside the emitter (or at a point light)
  float atten = 1.0f;
  if (l.type == Light::Type::kSpot) {
    const float cos_axis = -to_light.dot(l.direction_W) / d;
    atten = SmoothStep(l.cos_outer, l.cos_inner, cos_axis);
    if (atten <= 0) return false;
  }
  s->E = l.intensity_rgb * (atten / d2);
  const Eigen::Vector3f w = to_light * (1.0f / d);
  if (l.radius_m > 0) {
    // uniform direction in the cone the sphere subtends, ending on its near surface: for a
    // sphere of uniform radiance I / (pi r^2) each direction carries the full I / d^2.
    const float sin2 = (l.radius_m * l.radius_m) / d2;
    const float cos_max = std::sqrt(std::max(0.0f, 1.0f - sin2));
    s->wi = SampleCone(w, cos_max, u1, u2);
    // distance to the sphere along wi: the nearer root of |p + t wi - c|^2 = r^2.
    const float b = s->wi.dot(to_light);
    const float disc = std::max(0.0f, b * b - (d2 - l.radius_m * l.radius_m));
    s->distance = std::max(b - std::sqrt(disc), 0.0f);
  } else {
    s->wi = w;
    s->distance = d;
  }
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

#include "penumbra/render/light_sampler.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr double kPi = 3.14159265358979323846;

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

// SampleCone for every lane (same arithmetic).
inline Vec3Lanes SampleConeLanes(const Vec3Lanes& w, const Lanes& cos_max, const Lanes& u1,
                                 const Lanes& u2) {
  const Lanes cos_t = 1.0f - u1 * (1.0f - cos_max);
  const Lanes sin_t = (1.0f - cos_t * cos_t).max(0.0f).sqrt();
  Lanes sp, cp;
  SinCos2Pi(u2, &sp, &cp);
  Lanes sign;
  for (int k = 0; k < kLanes; ++k) sign[k] = w.z[k] >= 0 ? 1.0f : -1.0f;
  const Lanes a = -1.0f / (sign + w.z);
  const Lanes b = w.x * w.y * a;
  const Vec3Lanes t{1.0f + sign * w.x * w.x * a, sign * b, -sign * w.x};
  const Vec3Lanes bt{b, sign + w.y * w.y * a, -w.y};
  const Lanes sc = sin_t * cp, ss = sin_t * sp;
  Vec3Lanes d{sc * t.x + ss * bt.x + cos_t * w.x, sc * t.y + ss * bt.y + cos_t * w.y,
              sc * t.z + ss * bt.z + cos_t * w.z};
  const Lanes inv = 1.0f / d.Dot(d).sqrt();
  return d * inv;
}

// SampleConeLanes around one axis w shared by every lane (the sun): the basis is computed once,
// with the same arithmetic, so the directions equal those of SampleConeLanes.
inline Vec3Lanes SampleConeLanes(const Eigen::Vector3f& w, float cos_max, const Lanes& u1,
                                 const Lanes& u2) {
  const Lanes cos_t = 1.0f - u1 * (1.0f - cos_max);
  const Lanes sin_t = (1.0f - cos_t * cos_t).max(0.0f).sqrt();
  Lanes sp, cp;
  SinCos2Pi(u2, &sp, &cp);
  Eigen::Vector3f t, bt;
  ConeBasis(w, &t, &bt);
  const Lanes sc = sin_t * cp, ss = sin_t * sp;
  Vec3Lanes d{sc * t.x() + ss * bt.x() + cos_t * w.x(), sc * t.y() + ss * bt.y() + cos_t * w.y(),
              sc * t.z() + ss * bt.z() + cos_t * w.z()};
  const Lanes inv = 1.0f / d.Dot(d).sqrt();
  return d * inv;
}

// the pose-independent part of a light.
PosedLight Unposed(const Light& l) {
  PosedLight p;
  p.type = l.type;
  p.intensity_rgb = l.color.cwiseMax(0.0f) * l.intensity;
  const float outer = std::clamp(l.spot_outer_deg, 0.0f, 180.0f);
  const float inner = std::clamp(l.spot_inner_deg, 0.0f, outer);
  p.cos_outer = static_cast<float>(std::cos(outer * kPi / 180.0));
  p.cos_inner = static_cast<float>(std::cos(inner * kPi / 180.0));
  p.radius_m = std::max(l.radius_m, 0.0f);
  p.cos_angular_radius =
      static_cast<float>(std::cos(std::clamp(l.angular_radius_deg, 0.0f, 90.0f) * kPi / 180.0));
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
  const PosedLight& l = lights_[i];
  if (l.type == Light::Type::kDirectional) {
    const Eigen::Vector3f to_light = -l.direction_W;
    if (l.cos_angular_radius < 1.0f) {
      s->wi = SampleConeLanes(to_light, l.cos_angular_radius, u1, u2);
    } else {
      s->wi = {Lanes::Constant(to_light.x()), Lanes::Constant(to_light.y()),
               Lanes::Constant(to_light.z())};
    }
    s->distance = Lanes::Constant(std::numeric_limits<float>::infinity());
    s->E = {Lanes::Constant(l.intensity_rgb.x()), Lanes::Constant(l.intensity_rgb.y()),
            Lanes::Constant(l.intensity_rgb.z())};
    s->valid = LaneMask::Constant(true);
    return;
  }
  const Vec3Lanes to_light{l.position_W.x() - p_W.x, l.position_W.y() - p_W.y,
                           l.position_W.z() - p_W.z};
  const Lanes d2 = to_light.Dot(to_light);
  const Lanes d = d2.sqrt();
  s->valid = GreaterThan(d, l.radius_m);
  Lanes atten = Lanes::Ones();
  if (l.type == Light::Type::kSpot) {
    const Lanes cos_axis = -(to_light.x * l.direction_W.x() + to_light.y * l.direction_W.y() +
                             to_light.z * l.direction_W.z()) /
                           d;
    if (l.cos_inner <= l.cos_outer) {
      for (int k = 0; k < kLanes; ++k) atten[k] = cos_axis[k] >= l.cos_outer ? 1.0f : 0.0f;
    } else {
      const Lanes t = ((cos_axis - l.cos_outer) / (l.cos_inner - l.cos_outer)).max(0.0f).min(1.0f);
      atten = t * t * (3.0f - 2.0f * t);
    }
    s->valid = s->valid && GreaterThan(atten, 0.0f);
  }
  const Lanes scale = atten / d2;
  s->E = {l.intensity_rgb.x() * scale, l.intensity_rgb.y() * scale, l.intensity_rgb.z() * scale};
  const Lanes inv_d = 1.0f / d;
  const Vec3Lanes w = to_light * inv_d;
  if (l.radius_m > 0) {
    const Lanes sin2 = (l.radius_m * l.radius_m) / d2;
    const Lanes cos_max = (1.0f - sin2).max(0.0f).sqrt();
    s->wi = SampleConeLanes(w, cos_max, u1, u2);
    const Lanes b = s->wi.Dot(to_light);
    const Lanes disc = (b * b - (d2 - l.radius_m * l.radius_m)).max(0.0f);
    s->distance = (b - disc.sqrt()).max(0.0f);
  } else {
    s->wi = w;
    s->distance = d;
  }
}

}  // namespace penumbra

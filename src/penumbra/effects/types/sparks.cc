#include "penumbra/effects/types/sparks.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/rng.h"
#include "penumbra/effects/blackbody.h"
#include "penumbra/effects/effect_config.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

constexpr double kSparksPi = 3.14159265358979323846;

class SparksInstance : public EffectInstance {
 public:
  SparksInstance(const EffectConfig& e, uint64_t key, const Eigen::Vector3d& origin)
      : e_(e), sp_(e.Get<SparksParams>()), key_(key), origin_(origin) {}

  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    const SparksParams& sp = sp_;
    const double t = ctx.time_sec;
    ParticleSet set;
    set.kind = ParticleKind::kSpark;
    const Eigen::Vector3d c = BlackbodyLinearSrgb(sp.temperature_k);
    const double lum =
        sp.luminance_cd_m2 > 0 ? sp.luminance_cd_m2 : BlackbodyLuminance(sp.temperature_k);
    set.color = c.cast<float>();
    set.emission = (c * (lum / LinearSrgbLuminance(c))).cast<float>();
    const int64_t kmin = std::max<int64_t>(
        0, static_cast<int64_t>(std::ceil((t - sp.lifetime_sec) * sp.rate_per_s)));
    const int64_t kmax = static_cast<int64_t>(std::floor(t * sp.rate_per_s));
    const double cos_max = std::cos(sp.spread_deg * kSparksPi / 180.0);
    for (int64_t k = kmin; k <= kmax; ++k) {
      const double born = k / sp.rate_per_s;
      const double tau = t - born;
      if (tau < 0 || tau > sp.lifetime_sec) continue;
      const double wb = e_.Weight(born);
      Rng rng(HashKeys(key_, 3, static_cast<uint64_t>(k)));
      const double u_keep = rng.UniformD();
      const double cos_t = 1.0 - rng.UniformD() * (1.0 - cos_max);
      const double phi = 2 * kSparksPi * rng.UniformD();
      const double speed = sp.speed_m_s * (0.5 + 0.5 * rng.UniformD());
      if (u_keep >= wb) continue;
      const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
      const Eigen::Vector3d v0 =
          speed * Eigen::Vector3d(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t);
      const Eigen::Vector3d a(0, 0, -sp.gravity_m_s2);
      set.position_W.push_back((origin_ + v0 * tau + 0.5 * a * tau * tau).cast<float>());
      set.velocity_W.push_back((v0 + a * tau).cast<float>());
      set.radius_m.push_back(static_cast<float>(sp.radius_m * (1.0 - tau / sp.lifetime_sec)));
    }
    if (!set.position_W.empty()) frame->particles.push_back(std::move(set));
  }

 private:
  const EffectConfig& e_;
  const SparksParams& sp_;
  uint64_t key_;
  Eigen::Vector3d origin_;
};

}  // namespace

std::vector<std::string_view> SparksParams::Keys() {
  return {"fire",         "position",     "rate_per_s", "speed_m_s",     "spread_deg",
          "lifetime_sec", "gravity_m_s2", "radius_m",   "temperature_k", "luminance_cd_m2"};
}

void SparksParams::Read(const EffectParamReader& r) {
  r.Str("fire", &fire);
  r.Vec("position", &position_W);
  r.Num("rate_per_s", &rate_per_s);
  r.Num("speed_m_s", &speed_m_s);
  r.Num("spread_deg", &spread_deg);
  r.Num("lifetime_sec", &lifetime_sec);
  r.Num("gravity_m_s2", &gravity_m_s2);
  r.Num("radius_m", &radius_m);
  r.Num("temperature_k", &temperature_k);
  r.Num("luminance_cd_m2", &luminance_cd_m2);
}

void SparksParams::Validate(const EffectConfig&, EffectChecker* c) const {
  using R = EffectRange;
  c->In3("position", position_W, R::Closed(-kMaxPositionM, kMaxPositionM));
  c->In("rate_per_s", rate_per_s, R::OpenClosed(0, 1e5));
  c->In("speed_m_s", speed_m_s, R::Closed(0, 100));
  c->In("spread_deg", spread_deg, R::Closed(0, 90));
  c->In("lifetime_sec", lifetime_sec, R::OpenClosed(0, 60));
  c->In("gravity_m_s2", gravity_m_s2, R::Closed(-100, 100));
  c->In("radius_m", radius_m, R::OpenClosed(0, 0.1));
  c->In("temperature_k", temperature_k, R::Closed(800, 4000));
  c->In("luminance_cd_m2", luminance_cd_m2, R::Closed(0, kMaxLuminanceCdM2));
  if (c->ok() && rate_per_s * lifetime_sec > 1e6) {
    c->Fail("rate_per_s", EffectChecker::Num(rate_per_s) + " x lifetime_sec " +
                              EffectChecker::Num(lifetime_sec) +
                              " is too many live sparks; expected rate x lifetime <= 1e6");
  }
}

std::unique_ptr<EffectInstance> SparksParams::Bind(const EffectConfig& e,
                                                   const EffectBindContext& ctx) const {
  // on a fire: its first emitter
  Eigen::Vector3d origin = position_W;
  for (const EffectConfig& o : ctx.effects) {
    if (const FireParams* f = o.GetIf<FireParams>(); f && o.name == fire) {
      origin = f->fluid.emitters.front().position_W;
    }
  }
  return std::make_unique<SparksInstance>(e, ctx.key, origin);
}

std::optional<EffectProblem> SparksParams::CheckReferences(
    const std::vector<EffectConfig>& effects) const {
  if (fire.empty()) return std::nullopt;
  for (const EffectConfig& o : effects)
    if (o.name == fire && o.Is<FireParams>()) return std::nullopt;
  return EffectProblem{
      "fire", "no fire effect '" + fire + "'; expected the name of a fire effect of this world"};
}

}  // namespace penumbra

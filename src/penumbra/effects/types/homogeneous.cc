#include "penumbra/effects/types/homogeneous.h"

#include <cmath>

#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/types/dust.h"
#include "penumbra/effects/types/fog.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {

double ExtinctionSpec::SigmaT() const {
  if (sigma_t_per_m) return *sigma_t_per_m;
  if (mor_m) return -std::log(0.05) / *mor_m;
  return 0;
}

void ReadExtinction(const EffectParamReader& r, ExtinctionSpec* e) {
  if (r.Has("sigma_t_per_m")) e->sigma_t_per_m = r.Double("sigma_t_per_m");
  if (r.Has("mor_m")) e->mor_m = r.Double("mor_m");
}

void CheckExtinction(const ExtinctionSpec& e, EffectChecker* c) {
  if (e.sigma_t_per_m && e.mor_m) {
    c->Fail("mor_m", "both sigma_t_per_m and mor_m are set; expected exactly one");
  } else if (!e.sigma_t_per_m && !e.mor_m) {
    c->Fail("mor_m",
            "neither sigma_t_per_m nor mor_m is set; expected exactly one (extinction 1/m or "
            "meteorological optical range m)");
  } else if (e.sigma_t_per_m) {
    c->In("sigma_t_per_m", *e.sigma_t_per_m, EffectRange::OpenClosed(0, 1e3));
  } else {
    c->In("mor_m", *e.mor_m, EffectRange::Closed(1e-3, kMaxPositionM));
  }
}

HomogeneousMedium MakeHomogeneousMedium(double sigma_t_per_m, const Eigen::Vector3d& albedo,
                                        double g, double height_falloff_per_m, double base_height_m,
                                        const std::optional<BoxRegion>& region, double layer_top_m,
                                        double w) {
  HomogeneousMedium m;
  m.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(sigma_t_per_m * w));
  m.albedo = albedo.cast<float>();
  m.g = static_cast<float>(g);
  m.height_falloff_per_m = static_cast<float>(height_falloff_per_m);
  m.base_height_m = static_cast<float>(base_height_m);
  m.region = region;
  if (!region) m.layer_top_m = static_cast<float>(layer_top_m);
  return m;
}

double DefaultLayerTopM(const SceneDescription& scene) {
  return scene.center_W.z() + scene.extent_m;
}

namespace {

template <typename P>
class HomogeneousMediumInstance : public EffectInstance {
 public:
  HomogeneousMediumInstance(const EffectConfig& e, double layer_top_m)
      : e_(e), p_(e.Get<P>()), layer_top_m_(layer_top_m) {}
  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    if (ctx.weight <= 0) return;
    frame->homogeneous_media.push_back(
        MakeHomogeneousMedium(p_.extinction.SigmaT(), p_.*P::kAlbedo, p_.g, p_.height_falloff_per_m,
                              p_.base_height_m, e_.region, layer_top_m_, ctx.weight));
  }

 private:
  const EffectConfig& e_;
  const P& p_;
  double layer_top_m_;
};

}  // namespace

template <typename P>
std::vector<std::string_view> HomogeneousMediumType<P>::Keys() {
  return {"sigma_t_per_m",        "mor_m",         P::kAlbedoKey, "g",
          "height_falloff_per_m", "base_height_m", "layer_top_m"};
}

template <typename P>
void HomogeneousMediumType<P>::Read(const EffectParamReader& r) {
  P& p = static_cast<P&>(*this);
  ReadExtinction(r, &p.extinction);
  r.Vec(P::kAlbedoKey, &(p.*P::kAlbedo));
  r.Num("g", &p.g);
  r.Num("height_falloff_per_m", &p.height_falloff_per_m);
  r.Num("base_height_m", &p.base_height_m);
  if (r.Has("layer_top_m")) p.layer_top_m = r.Double("layer_top_m");
}

template <typename P>
void HomogeneousMediumType<P>::Validate(const EffectConfig&, EffectChecker* c) const {
  const P& p = static_cast<const P&>(*this);
  CheckExtinction(p.extinction, c);
  c->In3(std::string(P::kAlbedoKey), p.*P::kAlbedo, EffectRange::Closed(0, 1));
  c->Phase("g", p.g);
  c->In("height_falloff_per_m", p.height_falloff_per_m, EffectRange::Closed(0, 1e3));
  c->In("base_height_m", p.base_height_m, EffectRange::Closed(-kMaxPositionM, kMaxPositionM));
  if (p.layer_top_m)
    c->In("layer_top_m", *p.layer_top_m, EffectRange::Closed(-kMaxPositionM, kMaxPositionM));
}

template <typename P>
std::unique_ptr<EffectInstance> HomogeneousMediumType<P>::Bind(const EffectConfig& e,
                                                               const EffectBindContext& ctx) const {
  const P& p = static_cast<const P&>(*this);
  return std::make_unique<HomogeneousMediumInstance<P>>(
      e, p.layer_top_m ? *p.layer_top_m : DefaultLayerTopM(ctx.scene));
}

template struct HomogeneousMediumType<FogParams>;
template struct HomogeneousMediumType<DustParams>;

}  // namespace penumbra

#include "penumbra/effects/types/fog.h"

#include "penumbra/effects/effect_config.h"

namespace penumbra {
namespace {

class FogInstance : public EffectInstance {
 public:
  explicit FogInstance(const EffectConfig& e) : e_(e), p_(e.Get<FogParams>()) {}
  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    if (ctx.weight <= 0) return;
    frame->homogeneous_media.push_back(
        MakeHomogeneousMedium(p_.extinction.SigmaT(), p_.albedo, p_.g, p_.height_falloff_per_m,
                              p_.base_height_m, e_.region, ctx.weight));
  }

 private:
  const EffectConfig& e_;
  const FogParams& p_;
};

}  // namespace

std::vector<std::string_view> FogParams::Keys() {
  return {"sigma_t_per_m", "mor_m", "albedo", "g", "height_falloff_per_m", "base_height_m"};
}

void FogParams::Read(const EffectParamReader& r) {
  ReadExtinction(r, &extinction);
  r.Vec("albedo", &albedo);
  r.Num("g", &g);
  r.Num("height_falloff_per_m", &height_falloff_per_m);
  r.Num("base_height_m", &base_height_m);
}

void FogParams::Validate(const EffectConfig&, EffectChecker* c) const {
  CheckExtinction(extinction, c);
  c->In3("albedo", albedo, EffectRange::Closed(0, 1));
  c->Phase("g", g);
  c->In("height_falloff_per_m", height_falloff_per_m, EffectRange::AtLeast(0));
  c->In("base_height_m", base_height_m, EffectRange::Finite());
}

std::unique_ptr<EffectInstance> FogParams::Bind(const EffectConfig& e,
                                                const EffectBindContext&) const {
  return std::make_unique<FogInstance>(e);
}

}  // namespace penumbra

#pragma once
// the instance shared by the rain and snow effect types: a particle table drawn on first
// use and placed around the viewer at each evaluation.

#include <functional>
#include <memory>
#include <optional>

#include "penumbra/effects/effect_type.h"
#include "penumbra/effects/precipitation.h"

namespace penumbra {

/// particles of `table()` (built once, on the first evaluation with weight > 0) placed
/// around ctx.viewer_W, thinned to the weight and clipped to the effect's region.
class PrecipitationInstance : public EffectInstance {
 public:
  /// @param region the effect's region, or null (must outlive the instance)
  PrecipitationInstance(std::function<PrecipitationTable()> build_table, const BoxRegion* region)
      : build_table_(std::move(build_table)), region_(region) {}

  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    if (ctx.weight <= 0) return;
    if (!table_) table_ = build_table_();
    frame->particles.push_back(
        PlaceParticles(*table_, ctx.time_sec, ctx.viewer_W, ctx.weight, region_, ctx.pool()));
  }

 private:
  std::function<PrecipitationTable()> build_table_;
  const BoxRegion* region_;
  std::optional<PrecipitationTable> table_;
};

}  // namespace penumbra

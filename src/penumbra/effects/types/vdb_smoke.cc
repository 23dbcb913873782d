#include "penumbra/effects/types/vdb_smoke.h"

#include <filesystem>

#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/vdb_loader.h"

namespace penumbra {
namespace {

class VdbSmokeInstance : public EffectInstance {
 public:
  explicit VdbSmokeInstance(GridMedium grid) : grid_(std::move(grid)) {}
  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    if (ctx.weight <= 0) return;
    GridMedium g = grid_;
    g.sigma_t_per_m *= static_cast<float>(ctx.weight);
    frame->grid_media.push_back(std::move(g));
  }

 private:
  GridMedium grid_;
};

}  // namespace

std::vector<std::string_view> VdbSmokeParams::Keys() {
  return {"file", "grid", "max_resolution", "density_scale_per_m", "albedo", "g"};
}

void VdbSmokeParams::Read(const EffectParamReader& r) {
  r.Str("file", &file);
  if (!file.empty()) file = r.ResolvePath(file);
  r.Str("grid", &grid);
  r.Int("max_resolution", &max_resolution);
  r.Num("density_scale_per_m", &density_scale_per_m);
  r.Vec("albedo", &albedo);
  r.Num("g", &g);
}

void VdbSmokeParams::Validate(const EffectConfig&, EffectChecker* c) const {
  using R = EffectRange;
  if (file.empty()) c->Fail("file", "no file; expected the path of a .vdb file");
  // checked at load so the error names the world file's line (the grid is read later)
  if (std::error_code ec; !std::filesystem::is_regular_file(file, ec))
    c->Fail("file", "file not found: " + file +
                        " (relative paths resolve against the world file's "
                        "folder); expected an existing .vdb file");
  if (grid.empty()) c->Fail("grid", "empty grid name; expected e.g. density");
  c->In("max_resolution", max_resolution, R::Closed(4, 512));
  c->In("density_scale_per_m", density_scale_per_m, R::OpenClosed(0, 1e3));
  c->In3("albedo", albedo, R::Closed(0, 1));
  c->Phase("g", g);
}

std::unique_ptr<EffectInstance> VdbSmokeParams::Bind(const EffectConfig& e,
                                                     const EffectBindContext& ctx) const {
  return std::make_unique<VdbSmokeInstance>(
      LoadVdbDensity(*this, e.region, ctx.key_prefix, e.name));
}

}  // namespace penumbra

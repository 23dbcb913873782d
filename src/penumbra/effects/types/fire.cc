#include "penumbra/effects/types/fire.h"

#include "penumbra/effects/blackbody.h"
#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/grid_fluid.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

class FireInstance : public EffectInstance {
 public:
  FireInstance(const EffectConfig& e, uint64_t key)
      : e_(e),
        fp_(e.Get<FireParams>()),
        fluid_(fp_.fluid, *e.region, Eigen::Vector3d::Zero(), key) {}

  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    const FireParams& fp = fp_;
    fluid_.AdvanceTo(ctx.time_sec, [this](double ts) { return e_.Weight(ts); });
    const GridFluid& f = fluid_;
    if (f.MaxDensity() <= 0) return;
    GridMedium g = RegionGridMedium(*e_.region, f.nx(), f.ny(), f.nz());
    const size_t n = static_cast<size_t>(f.nx()) * f.ny() * f.nz();
    auto emission = std::make_shared<std::vector<float>>(3 * n, 0.0f);
    const double dv = f.voxel_size().prod();
    double power_y = 0;  // sum of j_Y dV, cd
    Eigen::Vector3d centroid = Eigen::Vector3d::Zero();
    Eigen::Vector3d rgb_sum = Eigen::Vector3d::Zero();
    for (int k = 0; k < f.nz(); ++k)
      for (int j = 0; j < f.ny(); ++j)
        for (int i = 0; i < f.nx(); ++i) {
          const double T = f.temperature_k(i, j, k);
          const double rho = f.density(i, j, k);
          if (T < fp.min_emission_temperature_k || rho <= 0) continue;
          const Eigen::Vector3d c = BlackbodyTable::Color(T).cast<double>();
          const double y = LinearSrgbLuminance(c);
          if (y <= 0) continue;
          const double jy = fp.absorption_per_m * rho * BlackbodyTable::Luminance(T);
          const Eigen::Vector3d j_rgb = c * (jy / y);
          const size_t idx = (static_cast<size_t>(k) * f.ny() + j) * f.nx() + i;
          for (int a = 0; a < 3; ++a) (*emission)[3 * idx + a] = static_cast<float>(j_rgb[a]);
          power_y += jy * dv;
          centroid += jy * dv * f.VoxelCentre(i, j, k);
          rgb_sum += j_rgb * dv;
        }
    g.density = std::make_shared<std::vector<float>>(f.DensityGrid());
    g.max_density = f.MaxDensity();
    g.emission = std::move(emission);
    g.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(fp.density_scale_per_m));
    g.albedo = fp.albedo.cast<float>();
    g.g = 0.0f;
    frame->grid_media.push_back(std::move(g));
    if (fp.glow_light && power_y > 0) {
      Light l;
      l.name = e_.name + "/glow";
      l.type = Light::Type::kPoint;
      l.body = 0;
      l.position_B = centroid / power_y;
      l.color = (rgb_sum / rgb_sum.maxCoeff()).cast<float>();
      // the light's luminance-weighted intensity: I = sum j_Y dV; rescale for the tint
      l.intensity = static_cast<float>(power_y / LinearSrgbLuminance(l.color.cast<double>()));
      l.radius_m = static_cast<float>(fp.glow_light_radius_m);
      l.cast_shadow = true;
      frame->extra_lights.push_back(l);
    }
  }

 private:
  const EffectConfig& e_;
  const FireParams& fp_;
  GridFluid fluid_;
};

}  // namespace

std::vector<std::string_view> FireParams::Keys() {
  std::vector<std::string_view> k = {
      "density_scale_per_m",        "absorption_per_m", "albedo",
      "min_emission_temperature_k", "glow_light",       "glow_light_radius_m"};
  for (std::string_view f : FluidParams::Keys()) k.push_back(f);
  return k;
}

void FireParams::Read(const EffectParamReader& r) {
  fluid.Read(r);
  r.Num("density_scale_per_m", &density_scale_per_m);
  r.Num("absorption_per_m", &absorption_per_m);
  r.Vec("albedo", &albedo);
  r.Num("min_emission_temperature_k", &min_emission_temperature_k);
  r.Bool("glow_light", &glow_light);
  r.Num("glow_light_radius_m", &glow_light_radius_m);
}

void FireParams::Validate(const EffectConfig& e, EffectChecker* c) const {
  using R = EffectRange;
  if (!e.region)
    c->Fail("region", "fire needs a region; expected region: {min: [x, y, z], max: [x, y, z]}");
  fluid.Validate(e.region, c);
  c->In("density_scale_per_m", density_scale_per_m, R::OpenClosed(0, 1e3));
  c->In("absorption_per_m", absorption_per_m, R::OpenClosed(0, 1e3));
  c->In3("albedo", albedo, R::Closed(0, 1));
  c->In("min_emission_temperature_k", min_emission_temperature_k, R::Closed(300, 4000));
  c->In("glow_light_radius_m", glow_light_radius_m, R::Closed(0, kMaxLightRadiusM));
}

std::unique_ptr<EffectInstance> FireParams::Bind(const EffectConfig& e,
                                                 const EffectBindContext& ctx) const {
  return std::make_unique<FireInstance>(e, ctx.key);
}

}  // namespace penumbra

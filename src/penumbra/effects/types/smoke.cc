#include "penumbra/effects/types/smoke.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/rng.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/effects/effect_config.h"
#include "penumbra/effects/grid_fluid.h"
#include "penumbra/effects/value_noise.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

class SmokeInstance : public EffectInstance {
 public:
  SmokeInstance(const EffectConfig& e, uint64_t key) : e_(e), s_(e.Get<SmokeParams>()), key_(key) {
    if (s_.mode == SmokeParams::Mode::kPlume) {
      fluid_ = std::make_unique<GridFluid>(s_.fluid, *e.region, s_.wind_m_s, key);
    }
  }

  void Evaluate(const EffectEvalContext& ctx, EffectsFrame* frame) override {
    const double t = ctx.time_sec;
    const double w = ctx.weight;
    const SmokeParams& s = s_;
    const BoxRegion& region = *e_.region;
    GridMedium g;
    if (s.mode == SmokeParams::Mode::kPlume) {
      fluid_->AdvanceTo(t, [this](double ts) { return e_.Weight(ts); });
      const GridFluid& f = *fluid_;
      if (f.MaxDensity() <= 0) return;
      g = RegionGridMedium(region, f.nx(), f.ny(), f.nz());
      g.density = std::make_shared<std::vector<float>>(f.DensityGrid());
      g.max_density = f.MaxDensity();
    } else {
      if (w <= 0) return;
      const Eigen::Vector3d ext = region.max_W - region.min_W;
      const double cell = ext.maxCoeff() / s.noise_resolution;
      const int nx = std::max(1, static_cast<int>(std::lround(ext.x() / cell)));
      const int ny = std::max(1, static_cast<int>(std::lround(ext.y() / cell)));
      const int nz = std::max(1, static_cast<int>(std::lround(ext.z() / cell)));
      g = RegionGridMedium(region, nx, ny, nz);
      auto density = std::make_shared<std::vector<float>>(static_cast<size_t>(nx) * ny * nz);
      // two noise slices blended over the evolution time: the shape changes smoothly
      const double ev = s.evolution_per_s * t;
      const double slice = std::floor(ev);
      const double blend = ev - slice;
      const uint64_t k0 = HashKeys(key_, static_cast<uint64_t>(static_cast<int64_t>(slice)));
      const uint64_t k1 = HashKeys(key_, static_cast<uint64_t>(static_cast<int64_t>(slice) + 1));
      const double threshold = 1.0 - s.coverage;
      // rows of voxels in parallel, each with its own samplers (their memo of the lattice
      // cell does not change the values).
      std::vector<float> row_max(static_cast<size_t>(ny) * nz, 0.0f);
      auto row = [&](int64_t r) {
        const int j = static_cast<int>(r % ny), k = static_cast<int>(r / ny);
        Fbm3Sampler fbm0(k0, s.octaves), fbm1(k1, s.octaves);  // = Fbm3(k0 / k1, q, octaves)
        float mx = 0;
        for (int i = 0; i < nx; ++i) {
          const Eigen::Vector3d p =
              region.min_W + Eigen::Vector3d((i + 0.5) * ext.x() / nx, (j + 0.5) * ext.y() / ny,
                                             (k + 0.5) * ext.z() / nz);
          const Eigen::Vector3d q = (p - s.wind_m_s * t) / s.noise_scale_m;
          const double n = (1 - blend) * fbm0(q) + blend * fbm1(q);
          const double d =
              s.coverage > 0 ? std::max(0.0, n - threshold) / std::max(s.coverage, 1e-6) * w : 0;
          (*density)[(static_cast<size_t>(k) * ny + j) * nx + i] = static_cast<float>(d);
          mx = std::max(mx, static_cast<float>(d));
        }
        row_max[r] = mx;
      };
      ParallelForOrSerial(ctx.pool(), static_cast<int64_t>(row_max.size()), row);
      float max_d = 0;
      for (float m : row_max) max_d = std::max(max_d, m);
      if (max_d <= 0) return;
      g.density = std::move(density);
      g.max_density = max_d;
    }
    g.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(s.density_scale_per_m));
    g.albedo = s.albedo.cast<float>();
    g.g = static_cast<float>(s.g);
    frame->grid_media.push_back(std::move(g));
  }

 private:
  const EffectConfig& e_;
  const SmokeParams& s_;
  uint64_t key_;
  std::unique_ptr<GridFluid> fluid_;  // plume mode
};

}  // namespace

std::vector<std::string_view> SmokeParams::Keys() {
  std::vector<std::string_view> k = {"mode",     "density_scale_per_m", "albedo",        "g",
                                     "wind_m_s", "noise_resolution",    "noise_scale_m", "octaves",
                                     "coverage", "evolution_per_s"};
  for (std::string_view f : FluidParams::Keys()) k.push_back(f);
  return k;
}

void SmokeParams::Read(const EffectParamReader& r) {
  if (r.Has("mode")) {
    mode = r.Enum("mode", {"noise", "plume"}) == "noise" ? Mode::kNoise : Mode::kPlume;
  }
  r.Num("density_scale_per_m", &density_scale_per_m);
  r.Vec("albedo", &albedo);
  r.Num("g", &g);
  r.Vec("wind_m_s", &wind_m_s);
  r.Int("noise_resolution", &noise_resolution);
  r.Num("noise_scale_m", &noise_scale_m);
  r.Int("octaves", &octaves);
  r.Num("coverage", &coverage);
  r.Num("evolution_per_s", &evolution_per_s);
  fluid.Read(r);
}

void SmokeParams::Validate(const EffectConfig& e, EffectChecker* c) const {
  using R = EffectRange;
  if (!e.region)
    c->Fail("region", "smoke needs a region; expected region: {min: [x, y, z], max: [x, y, z]}");
  c->In("density_scale_per_m", density_scale_per_m, R::OpenClosed(0, 1e3));
  c->In3("albedo", albedo, R::Closed(0, 1));
  c->Phase("g", g);
  c->In3("wind_m_s", wind_m_s, R::Closed(-100, 100));
  if (mode == Mode::kNoise) {
    c->In("noise_resolution", noise_resolution, R::Closed(8, 256));
    c->In("noise_scale_m", noise_scale_m, R::OpenClosed(0, kMaxGeomSizeM));
    c->In("octaves", octaves, R::Closed(1, 8));
    c->In("coverage", coverage, R::Closed(0, 1));
    c->In("evolution_per_s", evolution_per_s, R::Closed(0, FluidParams::kMaxFluidRatePerS));
  } else {
    fluid.Validate(e.region, c);
  }
}

std::unique_ptr<EffectInstance> SmokeParams::Bind(const EffectConfig& e,
                                                  const EffectBindContext& ctx) const {
  return std::make_unique<SmokeInstance>(e, ctx.key);
}

std::optional<double> SmokeParams::FluidDtSec() const {
  if (mode == Mode::kPlume) return fluid.dt_sec;
  return std::nullopt;
}

}  // namespace penumbra

#include "penumbra/effects/effects_engine.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/effects/blackbody.h"
#include "penumbra/effects/grid_fluid.h"
#include "penumbra/effects/light_events.h"
#include "penumbra/effects/precipitation.h"
#include "penumbra/effects/sun.h"
#include "penumbra/effects/value_noise.h"
#include "penumbra/effects/vdb_loader.h"

namespace penumbra {

namespace {

constexpr double kPi = 3.14159265358979323846;

// FNV-1a of the effect name: random streams stay put when effects are reordered.
uint64_t NameHash(const std::string& s) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (unsigned char c : s) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  return h;
}

HomogeneousMedium MakeHomogeneous(double sigma_t, const Eigen::Vector3d& albedo, double g,
                                  double falloff, double base, const EffectConfig& e, double w) {
  HomogeneousMedium m;
  m.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(sigma_t * w));
  m.albedo = albedo.cast<float>();
  m.g = static_cast<float>(g);
  m.height_falloff_per_m = static_cast<float>(falloff);
  m.base_height_m = static_cast<float>(base);
  m.region = e.region;
  return m;
}

// GridMedium on an axis-aligned region with the voxel layout of GridFluid.
GridMedium RegionGrid(const BoxRegion& r, int nx, int ny, int nz) {
  GridMedium g;
  g.X_WG = Pose::Identity();
  g.X_WG.translation() = 0.5 * (r.min_W + r.max_W);
  g.half_extents_m = 0.5 * (r.max_W - r.min_W);
  g.nx = nx;
  g.ny = ny;
  g.nz = nz;
  return g;
}

}  // namespace

/// per-effect state bound to the scene.
class EffectRuntime {
 public:
  EffectConfig config;
  size_t index = 0;
  uint64_t key = 0;
  std::unique_ptr<GridFluid> fluid;    // smoke plume, fire
  std::optional<GridMedium> vdb;       // vdb_smoke
  std::vector<int> lights;             // light_event targets
  int body = -1;                       // attached flashlight
  const EffectConfig* rain = nullptr;  // wetness
  Eigen::Vector3d spark_origin{0, 0, 0};
  std::optional<PrecipitationTable> precipitation;  // rain, snow: drawn on first use

  // advances the fluid to floor(t / dt) steps (restarting when t went backwards).
  void AdvanceFluid(double t) {
    const double dt =
        config.type == EffectType::kFire ? config.fire.fluid.dt_sec : config.smoke.fluid.dt_sec;
    const int target = static_cast<int>(std::floor(t / dt + 1e-9));
    if (target < fluid->steps()) fluid->Reset();
    while (fluid->steps() < target) fluid->Step(config.Weight(fluid->steps() * dt));
  }
};

EffectsEngine::EffectsEngine(const std::vector<EffectConfig>& effects, uint64_t seed,
                             const SceneDescription& scene)
    : num_scene_lights_(scene.lights.size()) {
  ValidateEffectsOrThrow(effects);
  for (size_t i = 0; i < effects.size(); ++i) {
    auto rt = std::make_unique<EffectRuntime>();
    rt->config = effects[i];
    rt->index = i;
    rt->key = HashKeys(seed, NameHash(effects[i].name), static_cast<uint64_t>(effects[i].type));
    const EffectConfig& e = rt->config;
    const std::string prefix = "effects[" + std::to_string(i) + "]";
    const std::string who = "effect '" + e.name + "' (" + EffectTypeName(e.type) + "): ";
    switch (e.type) {
      case EffectType::kSmoke:
        if (e.smoke.mode == SmokeParams::Mode::kPlume) {
          rt->fluid =
              std::make_unique<GridFluid>(e.smoke.fluid, *e.region, e.smoke.wind_m_s, rt->key);
        }
        break;
      case EffectType::kFire:
        rt->fluid =
            std::make_unique<GridFluid>(e.fire.fluid, *e.region, Eigen::Vector3d::Zero(), rt->key);
        break;
      case EffectType::kVdbSmoke:
        rt->vdb = LoadVdbDensity(e.vdb_smoke, e.region, prefix, e.name);
        break;
      case EffectType::kLightEvent: {
        std::string names;
        for (size_t l = 0; l < scene.lights.size(); ++l) {
          if (e.light_event.light == "*" || scene.lights[l].name == e.light_event.light) {
            rt->lights.push_back(static_cast<int>(l));
          }
          names += (names.empty() ? "" : ", ") + scene.lights[l].name;
        }
        if (rt->lights.empty() && e.light_event.light != "*") {
          throw ConfigError("", 0, prefix + ".light",
                            who + "no scene light named '" + e.light_event.light +
                                "' (lights: " + (names.empty() ? "none" : names) +
                                "); expected a light name of the scene or \"*\"");
        }
        any_light_event_ = true;
        break;
      }
      case EffectType::kFlashlight:
        if (!e.flashlight.attach.empty()) {
          rt->body = scene.FindBody(e.flashlight.attach);
          if (rt->body < 0) {
            throw ConfigError(
                "", 0, prefix + ".attach",
                who + "no body named '" + e.flashlight.attach +
                    "'; expected a body name of the composed model (\"<model>/<body>\")");
          }
        }
        break;
      case EffectType::kSun:
        any_sun_ = true;
        break;
      case EffectType::kSparks:
        rt->spark_origin = e.sparks.position_W;
        for (const EffectConfig& o : effects) {
          if (o.type == EffectType::kFire && o.name == e.sparks.fire) {
            rt->spark_origin = o.fire.fluid.emitters.front().position_W;
          }
        }
        break;
      default:
        break;
    }
    runtimes_.push_back(std::move(rt));
  }
  for (size_t l = 0; l < scene.lights.size(); ++l) {
    if (scene.lights[l].type == Light::Type::kDirectional) {
      directional_lights_.emplace_back(static_cast<int>(l), scene.lights[l]);
    }
  }
  // wetness refers to its rain by pointer into the runtimes (stable: unique_ptr)
  for (auto& rt : runtimes_) {
    if (rt->config.type != EffectType::kWetness) continue;
    for (auto& o : runtimes_) {
      if (o->config.type == EffectType::kRain &&
          (rt->config.wetness.rain.empty() || o->config.name == rt->config.wetness.rain)) {
        rt->rain = &o->config;
        break;
      }
    }
  }
}

EffectsEngine::~EffectsEngine() = default;

ThreadPool* EffectsEngine::Pool() {
  if (!pool_) pool_ = std::make_unique<ThreadPool>(0);
  return pool_.get();
}

std::shared_ptr<const EffectsFrame> EffectsEngine::Evaluate(double t,
                                                            const Eigen::Vector3d& viewer_W,
                                                            const std::vector<Pose>* X_WB) {
  auto frame = std::make_shared<EffectsFrame>();
  frame->time_sec = t;
  if (any_light_event_ || any_sun_) frame->light_intensity_scale.assign(num_scene_lights_, 1.0f);

  for (auto& rt_ptr : runtimes_) {
    EffectRuntime& rt = *rt_ptr;
    const EffectConfig& e = rt.config;
    const double w = e.Weight(t);
    switch (e.type) {
      case EffectType::kFog:
        if (w > 0) {
          frame->homogeneous_media.push_back(
              MakeHomogeneous(e.fog.extinction.SigmaT(), e.fog.albedo, e.fog.g,
                              e.fog.height_falloff_per_m, e.fog.base_height_m, e, w));
        }
        break;
      case EffectType::kDust:
        if (w > 0) {
          frame->homogeneous_media.push_back(
              MakeHomogeneous(e.dust.extinction.SigmaT(), e.dust.color, e.dust.g,
                              e.dust.height_falloff_per_m, e.dust.base_height_m, e, w));
        }
        break;
      case EffectType::kSmoke: {
        const SmokeParams& s = e.smoke;
        GridMedium g;
        if (s.mode == SmokeParams::Mode::kPlume) {
          rt.AdvanceFluid(t);
          const GridFluid& f = *rt.fluid;
          if (f.MaxDensity() <= 0) break;
          g = RegionGrid(*e.region, f.nx(), f.ny(), f.nz());
          g.density = std::make_shared<std::vector<float>>(f.DensityGrid());
          g.max_density = f.MaxDensity();
        } else {
          if (w <= 0) break;
          const Eigen::Vector3d ext = e.region->max_W - e.region->min_W;
          const double cell = ext.maxCoeff() / s.noise_resolution;
          const int nx = std::max(1, static_cast<int>(std::lround(ext.x() / cell)));
          const int ny = std::max(1, static_cast<int>(std::lround(ext.y() / cell)));
          const int nz = std::max(1, static_cast<int>(std::lround(ext.z() / cell)));
          g = RegionGrid(*e.region, nx, ny, nz);
          auto density = std::make_shared<std::vector<float>>(static_cast<size_t>(nx) * ny * nz);
          // two noise slices blended over the evolution time: the shape changes smoothly
          const double ev = s.evolution_per_s * t;
          const double slice = std::floor(ev);
          const double blend = ev - slice;
          const uint64_t k0 = HashKeys(rt.key, static_cast<uint64_t>(static_cast<int64_t>(slice)));
          const uint64_t k1 =
              HashKeys(rt.key, static_cast<uint64_t>(static_cast<int64_t>(slice) + 1));
          const double threshold = 1.0 - s.coverage;
          // rows of voxels in parallel, each with its own samplers (their memo of the lattice
          // cell does not change the values).
          std::vector<float> row_max(static_cast<size_t>(ny) * nz, 0.0f);
          auto row = [&](int64_t r) {
            const int j = static_cast<int>(r % ny), k = static_cast<int>(r / ny);
            Fbm3Sampler fbm0(k0, s.octaves), fbm1(k1, s.octaves);  // = Fbm3(k0 / k1, q, octaves)
            float mx = 0;
            for (int i = 0; i < nx; ++i) {
              const Eigen::Vector3d p = e.region->min_W + Eigen::Vector3d((i + 0.5) * ext.x() / nx,
                                                                          (j + 0.5) * ext.y() / ny,
                                                                          (k + 0.5) * ext.z() / nz);
              const Eigen::Vector3d q = (p - s.wind_m_s * t) / s.noise_scale_m;
              const double n = (1 - blend) * fbm0(q) + blend * fbm1(q);
              const double d = s.coverage > 0
                                   ? std::max(0.0, n - threshold) / std::max(s.coverage, 1e-6) * w
                                   : 0;
              (*density)[(static_cast<size_t>(k) * ny + j) * nx + i] = static_cast<float>(d);
              mx = std::max(mx, static_cast<float>(d));
            }
            row_max[r] = mx;
          };
          ParallelForOrSerial(Pool(), static_cast<int64_t>(row_max.size()), row);
          float max_d = 0;
          for (float m : row_max) max_d = std::max(max_d, m);
          if (max_d <= 0) break;
          g.density = std::move(density);
          g.max_density = max_d;
        }
        g.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(s.density_scale_per_m));
        g.albedo = s.albedo.cast<float>();
        g.g = static_cast<float>(s.g);
        frame->grid_media.push_back(std::move(g));
        break;
      }
      case EffectType::kVdbSmoke:
        if (w > 0) {
          GridMedium g = *rt.vdb;
          g.sigma_t_per_m *= static_cast<float>(w);
          frame->grid_media.push_back(std::move(g));
        }
        break;
      case EffectType::kFire: {
        const FireParams& fp = e.fire;
        rt.AdvanceFluid(t);
        const GridFluid& f = *rt.fluid;
        if (f.MaxDensity() <= 0) break;
        GridMedium g = RegionGrid(*e.region, f.nx(), f.ny(), f.nz());
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
          l.name = e.name + "/glow";
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
        break;
      }
      case EffectType::kRain:
      case EffectType::kSnow:
        if (w > 0) {
          if (!rt.precipitation) {
            rt.precipitation = e.type == EffectType::kRain ? BuildRainTable(e.rain, rt.key, 1)
                                                           : BuildSnowTable(e.snow, rt.key, 2);
          }
          frame->particles.push_back(PlaceParticles(*rt.precipitation, t, viewer_W, w,
                                                    e.region ? &*e.region : nullptr, Pool()));
        }
        break;
      case EffectType::kSparks: {
        const SparksParams& sp = e.sparks;
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
        const double cos_max = std::cos(sp.spread_deg * kPi / 180.0);
        for (int64_t k = kmin; k <= kmax; ++k) {
          const double born = k / sp.rate_per_s;
          const double tau = t - born;
          if (tau < 0 || tau > sp.lifetime_sec) continue;
          const double wb = e.Weight(born);
          Rng rng(HashKeys(rt.key, 3, static_cast<uint64_t>(k)));
          const double u_keep = rng.UniformD();
          const double cos_t = 1.0 - rng.UniformD() * (1.0 - cos_max);
          const double phi = 2 * kPi * rng.UniformD();
          const double speed = sp.speed_m_s * (0.5 + 0.5 * rng.UniformD());
          if (u_keep >= wb) continue;
          const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
          const Eigen::Vector3d v0 =
              speed * Eigen::Vector3d(sin_t * std::cos(phi), sin_t * std::sin(phi), cos_t);
          const Eigen::Vector3d a(0, 0, -sp.gravity_m_s2);
          set.position_W.push_back(
              (rt.spark_origin + v0 * tau + 0.5 * a * tau * tau).cast<float>());
          set.velocity_W.push_back((v0 + a * tau).cast<float>());
          set.radius_m.push_back(static_cast<float>(sp.radius_m * (1.0 - tau / sp.lifetime_sec)));
        }
        if (!set.position_W.empty()) frame->particles.push_back(std::move(set));
        break;
      }
      case EffectType::kLightEvent: {
        const float s = static_cast<float>(LightEventScale(e, t, rt.key));
        for (int l : rt.lights) frame->light_intensity_scale[l] *= s;
        break;
      }
      case EffectType::kFlashlight: {
        if (w <= 0) break;
        const FlashlightParams& fl = e.flashlight;
        Eigen::Vector3d pos, dir;
        if (rt.body >= 0) {
          if (!X_WB || static_cast<int>(X_WB->size()) <= rt.body) {
            throw Error("effects: flashlight '" + e.name + "' is attached to body " + fl.attach +
                        " but Evaluate got no pose for it (X_WB has " +
                        std::to_string(X_WB ? X_WB->size() : 0) + " entries)");
          }
          const Pose& X = (*X_WB)[rt.body];
          pos = X * fl.position_B;
          dir = X.linear() * fl.direction_B.normalized();
        } else {
          const auto& wp = fl.waypoints;
          if (t <= wp.front().t_sec) {
            pos = wp.front().position_W;
            dir = wp.front().direction_W;
          } else if (t >= wp.back().t_sec) {
            pos = wp.back().position_W;
            dir = wp.back().direction_W;
          } else {
            size_t s = 0;
            while (wp[s + 1].t_sec < t) ++s;
            const double f = (t - wp[s].t_sec) / (wp[s + 1].t_sec - wp[s].t_sec);
            pos = (1 - f) * wp[s].position_W + f * wp[s + 1].position_W;
            dir = (1 - f) * wp[s].direction_W.normalized() + f * wp[s + 1].direction_W.normalized();
            if (dir.norm() < 1e-9) dir = wp[s + 1].direction_W;
          }
        }
        Light l;
        l.name = e.name;
        l.type = Light::Type::kSpot;
        l.body = 0;
        l.position_B = pos;
        l.direction_B = dir.normalized();
        l.color = fl.color.cast<float>() / static_cast<float>(fl.color.maxCoeff());
        l.intensity = static_cast<float>(fl.intensity_cd * w);
        l.spot_inner_deg = static_cast<float>(fl.inner_angle_deg);
        l.spot_outer_deg = static_cast<float>(fl.outer_angle_deg);
        l.radius_m = static_cast<float>(fl.radius_m);
        frame->extra_lights.push_back(l);
        break;
      }
      case EffectType::kSun: {
        if (w <= 0) break;
        const SunParams& sp = e.sun;
        const double jd =
            JulianDay(sp.year, sp.month, sp.day, sp.time_utc_h) + sp.time_scale * t / 86400.0;
        const SunPosition pos = ComputeSunPosition(jd, sp.latitude_deg, sp.longitude_deg);
        frame->sun_direction_W = SunDirectionEnu(pos);
        frame->sky_luminance_scale *=
            static_cast<float>(TwilightSkyScale(pos.geometric_elevation_deg));
        // the scene's suns follow: same light, new direction, air-mass attenuated
        const double direct = DirectSunAttenuation(pos.elevation_deg);
        for (const auto& [index, light] : directional_lights_) {
          frame->light_intensity_scale[index] = 0.0f;
          if (direct <= 0) continue;
          Light sun = light;
          sun.body = 0;
          sun.mjcf_light = -1;
          sun.direction_B = -*frame->sun_direction_W;
          sun.intensity = static_cast<float>(light.intensity * direct);
          frame->extra_lights.push_back(sun);
        }
        break;
      }
      case EffectType::kWetness: {
        if (w <= 0 || !rt.rain) break;
        const WetnessParams& wp = e.wetness;
        const double a = rt.rain->start_sec, b = rt.rain->stop_sec;
        double wet = 0;
        if (t >= a && t <= b) {
          wet = 1 - std::exp(-(t - a) / wp.wetting_time_sec);
        } else if (t > b) {
          wet = (1 - std::exp(-(b - a) / wp.wetting_time_sec)) *
                std::exp(-(t - b) / wp.drying_time_sec);
        }
        frame->surface_wetness =
            std::max(frame->surface_wetness, static_cast<float>(wp.max_wetness * wet));
        break;
      }
    }
  }
  return frame;
}

}  // namespace penumbra

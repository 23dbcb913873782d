#include "penumbra/effects/precipitation.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/rng.h"

namespace penumbra {

namespace {

constexpr double kPi = 3.14159265358979323846;

// x wrapped into [lo, lo + len)
double Wrap(double x, double lo, double len) {
  const double r = x - lo;
  double m = r - len * std::floor(r / len);
  if (m >= len) m = 0;  // rounding at the upper edge
  return lo + m;
}

bool Inside(const BoxRegion* region, const Eigen::Vector3d& p) {
  if (!region) return true;
  return (p.array() >= region->min_W.array()).all() && (p.array() <= region->max_W.array()).all();
}

}  // namespace

double MarshallPalmerLambda(double rate_mm_h) { return 4.1 * std::pow(rate_mm_h, -0.21); }

double RainNumberDensity(double rate_mm_h, double d_min_mm, double d_max_mm) {
  const double lam = MarshallPalmerLambda(rate_mm_h);
  return kMarshallPalmerN0 / lam * (std::exp(-lam * d_min_mm) - std::exp(-lam * d_max_mm));
}

double RainTerminalVelocity(double d_mm) {
  return std::max(0.0, 9.65 - 10.3 * std::exp(-0.6 * d_mm));
}

double SnowFallSpeed(double d_mm) { return 0.81 * std::pow(d_mm, 0.16); }

double SnowNumberDensity(const SnowParams& p) {
  // water mass flux, kg m^-2 s^-1: R mm/h of liquid water (1000 kg/m^3)
  const double flux = p.rate_mm_h * 1e-3 * 1000.0 / 3600.0;
  const double d_m = p.flake_diameter_mm * 1e-3;
  const double mass = p.flake_density_kg_m3 * kPi * d_m * d_m * d_m / 6.0;
  return flux / (mass * SnowFallSpeed(p.flake_diameter_mm));
}

Eigen::Vector3d EffectiveHalfExtents(const Eigen::Vector3d& half, double density_per_m3,
                                     int max_particles) {
  const double volume = 8.0 * half.prod();
  const double count = density_per_m3 * volume;
  if (count <= max_particles) return half;
  return half * std::cbrt(max_particles / count);
}

PrecipitationTable BuildRainTable(const RainParams& p, uint64_t seed, uint64_t effect_key) {
  PrecipitationTable tab;
  tab.kind = ParticleKind::kRain;
  tab.color = p.color.cast<float>();
  tab.sheltered = p.sheltered;
  const double n = RainNumberDensity(p.rate_mm_h, p.min_diameter_mm, p.max_diameter_mm);
  tab.half = EffectiveHalfExtents(p.box_half_extents_m, n, p.max_particles);
  const Eigen::Vector3d size = 2.0 * tab.half;
  const size_t count = static_cast<size_t>(std::llround(n * 8.0 * tab.half.prod()));
  const double lam = MarshallPalmerLambda(p.rate_mm_h);
  const double cdf_span = 1.0 - std::exp(-lam * (p.max_diameter_mm - p.min_diameter_mm));
  tab.q0.resize(count);
  tab.velocity.resize(count);
  tab.radius_m.resize(count);
  tab.keep.resize(count);
  for (size_t i = 0; i < count; ++i) {
    Rng rng(HashKeys(seed, effect_key, static_cast<uint64_t>(i)));
    tab.keep[i] = static_cast<float>(rng.UniformD());
    // diameter from the truncated exponential by inverting its CDF
    const double d_mm = p.min_diameter_mm - std::log(1.0 - rng.UniformD() * cdf_span) / lam;
    tab.q0[i] = Eigen::Vector3d(rng.UniformD() * size.x(), rng.UniformD() * size.y(),
                                rng.UniformD() * size.z());
    tab.velocity[i] = Eigen::Vector3d(p.wind_m_s.x(), p.wind_m_s.y(), -RainTerminalVelocity(d_mm));
    tab.radius_m[i] = static_cast<float>(0.5e-3 * d_mm);
  }
  return tab;
}

PrecipitationTable BuildSnowTable(const SnowParams& p, uint64_t seed, uint64_t effect_key) {
  PrecipitationTable tab;
  tab.kind = ParticleKind::kSnow;
  tab.color = p.color.cast<float>();
  tab.sheltered = p.sheltered;
  const double n = SnowNumberDensity(p);
  tab.half = EffectiveHalfExtents(p.box_half_extents_m, n, p.max_particles);
  const Eigen::Vector3d size = 2.0 * tab.half;
  const size_t count = static_cast<size_t>(std::llround(n * 8.0 * tab.half.prod()));
  tab.drift_amplitude_m_s =
      Eigen::Vector3d(p.turbulence_m_s, p.turbulence_m_s, 0.3 * p.turbulence_m_s);
  tab.q0.resize(count);
  tab.velocity.resize(count);
  tab.radius_m.resize(count);
  tab.keep.resize(count);
  tab.omega.resize(count);
  tab.phase.resize(count);
  for (size_t i = 0; i < count; ++i) {
    Rng rng(HashKeys(seed, effect_key, static_cast<uint64_t>(i)));
    tab.keep[i] = static_cast<float>(rng.UniformD());
    const double d_mm = p.flake_diameter_mm * (0.7 + 0.6 * rng.UniformD());
    tab.q0[i] = Eigen::Vector3d(rng.UniformD() * size.x(), rng.UniformD() * size.y(),
                                rng.UniformD() * size.z());
    tab.omega[i] = 2 * kPi * p.drift_frequency_hz * (0.5 + rng.UniformD());
    tab.phase[i] = Eigen::Vector3d(2 * kPi * rng.UniformD(), 2 * kPi * rng.UniformD(),
                                   2 * kPi * rng.UniformD());
    tab.velocity[i] = Eigen::Vector3d(p.wind_m_s.x(), p.wind_m_s.y(), -SnowFallSpeed(d_mm));
    tab.radius_m[i] = static_cast<float>(0.5e-3 * d_mm);
  }
  return tab;
}

ParticleSet PlaceParticles(const PrecipitationTable& tab, double t, const Eigen::Vector3d& viewer_W,
                           double weight, const BoxRegion* region, ThreadPool* pool) {
  ParticleSet set;
  set.kind = tab.kind;
  set.color = tab.color;
  set.sheltered = tab.sheltered;
  const Eigen::Vector3d size = 2.0 * tab.half;
  const Eigen::Vector3d lo = viewer_W - tab.half;
  const bool drift = !tab.omega.empty();
  const size_t count = tab.q0.size();
  // chunks of the table in parallel, each into its own arrays, then joined in table order.
  constexpr size_t kChunk = 16384;
  const size_t chunks = (count + kChunk - 1) / kChunk;
  std::vector<ParticleSet> part(chunks);
  auto chunk = [&](int64_t c) {
    const size_t i0 = static_cast<size_t>(c) * kChunk, i1 = std::min(count, i0 + kChunk);
    ParticleSet& out = part[c];
    const size_t expect =
        static_cast<size_t>(std::min(1.0, std::max(0.0, weight)) * (i1 - i0)) + 16;
    out.position_W.reserve(expect);
    out.velocity_W.reserve(expect);
    out.radius_m.reserve(expect);
    for (size_t i = i0; i < i1; ++i) {
      if (tab.keep[i] >= weight) continue;
      Eigen::Vector3d q = tab.q0[i] + tab.velocity[i] * t;
      Eigen::Vector3d v = tab.velocity[i];
      if (drift) {
        const double w = tab.omega[i];
        for (int a = 0; a < 3; ++a) {
          const double amp = tab.drift_amplitude_m_s[a];
          const double ph = tab.phase[i][a];
          // integral of amp sin(w s + ph) ds over [0, t]
          q[a] += amp / w * (std::cos(ph) - std::cos(w * t + ph));
          v[a] += amp * std::sin(w * t + ph);
        }
      }
      const Eigen::Vector3d pos(Wrap(q.x(), lo.x(), size.x()), Wrap(q.y(), lo.y(), size.y()),
                                Wrap(q.z(), lo.z(), size.z()));
      if (!Inside(region, pos)) continue;
      out.position_W.push_back(pos.cast<float>());
      out.velocity_W.push_back(v.cast<float>());
      out.radius_m.push_back(tab.radius_m[i]);
    }
  };
  ParallelForOrSerial(pool, static_cast<int64_t>(chunks), chunk);
  size_t total = 0;
  for (const ParticleSet& p : part) total += p.position_W.size();
  set.position_W.reserve(total);
  set.velocity_W.reserve(total);
  set.radius_m.reserve(total);
  for (const ParticleSet& p : part) {
    set.position_W.insert(set.position_W.end(), p.position_W.begin(), p.position_W.end());
    set.velocity_W.insert(set.velocity_W.end(), p.velocity_W.begin(), p.velocity_W.end());
    set.radius_m.insert(set.radius_m.end(), p.radius_m.begin(), p.radius_m.end());
  }
  return set;
}

ParticleSet SampleRain(const RainParams& p, double t, const Eigen::Vector3d& viewer_W,
                       double weight, const BoxRegion* region, uint64_t seed, uint64_t effect_key) {
  return PlaceParticles(BuildRainTable(p, seed, effect_key), t, viewer_W, weight, region);
}

ParticleSet SampleSnow(const SnowParams& p, double t, const Eigen::Vector3d& viewer_W,
                       double weight, const BoxRegion* region, uint64_t seed, uint64_t effect_key) {
  return PlaceParticles(BuildSnowTable(p, seed, effect_key), t, viewer_W, weight, region);
}

}  // namespace penumbra

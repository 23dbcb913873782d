#include "penumbra/effects/precipitation.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/rng.h"

namespace penumbra {

namespace {

constexpr double kPi = 3.14159265358979323846;

// x wrapped into [lo, lo + len)
double Wrap(double x, double lo, double len) {
  double r = std::fmod(x - lo, len);
  if (r < 0) r += len;
  return lo + r;
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

ParticleSet SampleRain(const RainParams& p, double t, const Eigen::Vector3d& viewer_W,
                       double weight, const BoxRegion* region, uint64_t seed, uint64_t effect_key) {
  ParticleSet set;
  set.kind = ParticleKind::kRain;
  set.color = p.color.cast<float>();
  const double n = RainNumberDensity(p.rate_mm_h, p.min_diameter_mm, p.max_diameter_mm);
  const Eigen::Vector3d half = EffectiveHalfExtents(p.box_half_extents_m, n, p.max_particles);
  const Eigen::Vector3d size = 2.0 * half;
  const Eigen::Vector3d lo = viewer_W - half;
  const long long count = std::llround(n * 8.0 * half.prod());
  const double lam = MarshallPalmerLambda(p.rate_mm_h);
  const double cdf_span = 1.0 - std::exp(-lam * (p.max_diameter_mm - p.min_diameter_mm));
  set.position_W.reserve(count);
  set.velocity_W.reserve(count);
  set.radius_m.reserve(count);
  for (long long i = 0; i < count; ++i) {
    Rng rng(HashKeys(seed, effect_key, static_cast<uint64_t>(i)));
    const double u_keep = rng.UniformD();
    // diameter from the truncated exponential by inverting its CDF
    const double u_d = rng.UniformD();
    const double d_mm = p.min_diameter_mm - std::log(1.0 - u_d * cdf_span) / lam;
    const Eigen::Vector3d q0(rng.UniformD() * size.x(), rng.UniformD() * size.y(),
                             rng.UniformD() * size.z());
    if (u_keep >= weight) continue;
    const Eigen::Vector3d v(p.wind_m_s.x(), p.wind_m_s.y(), -RainTerminalVelocity(d_mm));
    const Eigen::Vector3d q = q0 + v * t;
    const Eigen::Vector3d pos(Wrap(q.x(), lo.x(), size.x()), Wrap(q.y(), lo.y(), size.y()),
                              Wrap(q.z(), lo.z(), size.z()));
    if (!Inside(region, pos)) continue;
    set.position_W.push_back(pos.cast<float>());
    set.velocity_W.push_back(v.cast<float>());
    set.radius_m.push_back(static_cast<float>(0.5e-3 * d_mm));
  }
  return set;
}

ParticleSet SampleSnow(const SnowParams& p, double t, const Eigen::Vector3d& viewer_W,
                       double weight, const BoxRegion* region, uint64_t seed, uint64_t effect_key) {
  ParticleSet set;
  set.kind = ParticleKind::kSnow;
  set.color = p.color.cast<float>();
  const double n = SnowNumberDensity(p);
  const Eigen::Vector3d half = EffectiveHalfExtents(p.box_half_extents_m, n, p.max_particles);
  const Eigen::Vector3d size = 2.0 * half;
  const Eigen::Vector3d lo = viewer_W - half;
  const long long count = std::llround(n * 8.0 * half.prod());
  for (long long i = 0; i < count; ++i) {
    Rng rng(HashKeys(seed, effect_key, static_cast<uint64_t>(i)));
    const double u_keep = rng.UniformD();
    const double d_mm = p.flake_diameter_mm * (0.7 + 0.6 * rng.UniformD());
    const Eigen::Vector3d q0(rng.UniformD() * size.x(), rng.UniformD() * size.y(),
                             rng.UniformD() * size.z());
    const double f = p.drift_frequency_hz * (0.5 + rng.UniformD());
    const Eigen::Vector3d phase(2 * kPi * rng.UniformD(), 2 * kPi * rng.UniformD(),
                                2 * kPi * rng.UniformD());
    if (u_keep >= weight) continue;
    const double w = 2 * kPi * f;
    const Eigen::Vector3d amp(p.turbulence_m_s, p.turbulence_m_s, 0.3 * p.turbulence_m_s);
    const Eigen::Vector3d mean_v(p.wind_m_s.x(), p.wind_m_s.y(), -SnowFallSpeed(d_mm));
    Eigen::Vector3d drift, v;
    for (int a = 0; a < 3; ++a) {
      // integral of amp sin(w s + phase) ds over [0, t]
      drift[a] = amp[a] / w * (std::cos(phase[a]) - std::cos(w * t + phase[a]));
      v[a] = mean_v[a] + amp[a] * std::sin(w * t + phase[a]);
    }
    const Eigen::Vector3d q = q0 + mean_v * t + drift;
    const Eigen::Vector3d pos(Wrap(q.x(), lo.x(), size.x()), Wrap(q.y(), lo.y(), size.y()),
                              Wrap(q.z(), lo.z(), size.z()));
    if (!Inside(region, pos)) continue;
    set.position_W.push_back(pos.cast<float>());
    set.velocity_W.push_back(v.cast<float>());
    set.radius_m.push_back(static_cast<float>(0.5e-3 * d_mm));
  }
  return set;
}

}  // namespace penumbra

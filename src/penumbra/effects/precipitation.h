#pragma once
// rain and snow particles around a viewer (models and citations in types/rain.h and
// types/snow.h, RainParams / SnowParams).
//
// sampling: particle i of an effect draws its size, its position in a periodic cell and its
// drift phases from Rng(HashKeys(seed, effect key, i)). the cell (the box around the
// viewer, size 2 x half extents) tiles space periodically; a particle's world position at
// time t is its start position + displacement(t), wrapped into the box centred on the
// viewer. the number density is therefore the same at every time and viewer position, and
// a particle keeps its identity while it falls (no popping) unless it wraps around.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "penumbra/core/thread_pool.h"
#include "penumbra/effects/types/rain.h"
#include "penumbra/effects/types/snow.h"
#include "penumbra/scene/effects_frame.h"

namespace penumbra {

/// Marshall-Palmer slope Lambda = 4.1 R^-0.21, 1/mm, for R in mm/h (> 0).
double MarshallPalmerLambda(double rate_mm_h);

/// Marshall-Palmer intercept N0 = 8000 m^-3 mm^-1.
constexpr double kMarshallPalmerN0 = 8000.0;

/// number of drops per m^3 with diameter in [d_min_mm, d_max_mm]:
/// integral of N0 exp(-Lambda D) dD = N0 / Lambda (exp(-Lambda d_min) - exp(-Lambda d_max)).
double RainNumberDensity(double rate_mm_h, double d_min_mm, double d_max_mm);

/// terminal fall speed of a raindrop of diameter d_mm, m/s: Atlas et al. 1973 fit to Gunn &
/// Kinzer 1949, v = max(0, 9.65 - 10.3 exp(-0.6 D)).
double RainTerminalVelocity(double d_mm);

/// fall speed of a snow aggregate of diameter d_mm, m/s: Locatelli & Hobbs 1974,
/// v = 0.81 D^0.16.
double SnowFallSpeed(double d_mm);

/// snowflakes per m^3 for a water-equivalent rate and nominal flake size (SnowParams).
double SnowNumberDensity(const SnowParams& p);

/// box half extents actually used: `half` shrunk uniformly so that density x volume stays
/// <= max_particles.
Eigen::Vector3d EffectiveHalfExtents(const Eigen::Vector3d& half, double density_per_m3,
                                     int max_particles);

/// the fixed per-particle draws of a rain or snow effect (sizes, places in the periodic
/// cell, velocities, drift), drawn once; PlaceParticles() moves them to a time and viewer.
struct PrecipitationTable {
  ParticleKind kind = ParticleKind::kRain;
  Eigen::Vector3d half{1, 1, 1};          ///< half extents of the periodic box, m
  std::vector<Eigen::Vector3d> q0;        ///< (N) place in the cell [0, 2 half)^3 at t = 0
  std::vector<Eigen::Vector3d> velocity;  ///< (N) mean velocity, m/s
  std::vector<float> radius_m;            ///< (N)
  std::vector<float> keep;                ///< (N) uniform draw for thinning by the weight
  // snow drift: amplitude per axis, angular frequency and phases per flake
  Eigen::Vector3d drift_amplitude_m_s{0, 0, 0};
  std::vector<double> omega;           ///< (N) rad/s, empty for rain
  std::vector<Eigen::Vector3d> phase;  ///< (N) rad
  Eigen::Vector3f color{1, 1, 1};
  bool sheltered = true;  ///< ParticleSet::sheltered of the placed particles
};

/// the drops of a rain effect (see SampleRain).
PrecipitationTable BuildRainTable(const RainParams& p, uint64_t seed, uint64_t effect_key);
/// the flakes of a snow effect (see SampleSnow).
PrecipitationTable BuildSnowTable(const SnowParams& p, uint64_t seed, uint64_t effect_key);
/// the particles of a table at time t around viewer_W, thinned to `weight` and clipped to
/// `region` (may be null), in table order; chunks of the table are placed over `pool` (may be
/// null; the result does not depend on it).
ParticleSet PlaceParticles(const PrecipitationTable& table, double t,
                           const Eigen::Vector3d& viewer_W, double weight, const BoxRegion* region,
                           ThreadPool* pool = nullptr);

/// rain drops at time t (sim seconds) around viewer_W. `weight` in [0, 1] thins the drops
/// (drop i is kept when its own uniform draw is < weight); `region` (may be null) keeps only
/// drops inside it. radius = D / 2, velocity = (wind_x, wind_y, -v(D)).
ParticleSet SampleRain(const RainParams& p, double t, const Eigen::Vector3d& viewer_W,
                       double weight, const BoxRegion* region, uint64_t seed, uint64_t effect_key);

/// snowflakes at time t (see SnowParams for the drift model).
ParticleSet SampleSnow(const SnowParams& p, double t, const Eigen::Vector3d& viewer_W,
                       double weight, const BoxRegion* region, uint64_t seed, uint64_t effect_key);

}  // namespace penumbra

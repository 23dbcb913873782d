#pragma once
// deterministic value noise (Perlin, "An image synthesizer", SIGGRAPH 1985, lattice value
// variant): uniform random values at integer lattice points from core/rng.h hashed by
// (key, lattice index), blended with the quintic fade 6t^5 - 15t^4 + 10t^3. pure functions
// of their arguments: no state, thread-safe.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

namespace penumbra {

/// uniform value in [0, 1) at an integer lattice point.
double LatticeValue(uint64_t key, int64_t i, int64_t j = 0, int64_t k = 0);

/// smooth 1D noise in [0, 1] with unit lattice spacing.
double ValueNoise1(uint64_t key, double x);

/// smooth 3D noise in [0, 1] with unit lattice spacing.
double ValueNoise3(uint64_t key, const Eigen::Vector3d& p);

/// fractal sum of `octaves` ValueNoise3 octaves (frequency x2, amplitude x0.5 per octave),
/// normalised to [0, 1].
double Fbm3(uint64_t key, const Eigen::Vector3d& p, int octaves);

/// Fbm3 for a sequence of nearby points (a voxel grid row by row): equal to Fbm3(key, p,
/// octaves) bit for bit, but each octave keeps the eight lattice values of the last cell it
/// used, so consecutive points in the same lattice cell do not hash them again. one object per
/// thread (it has state).
class Fbm3Sampler {
 public:
  Fbm3Sampler(uint64_t key, int octaves);
  /// Fbm3(key, p, octaves).
  double operator()(const Eigen::Vector3d& p);

 private:
  struct Octave {
    uint64_t key = 0;
    bool valid = false;
    int64_t i = 0, j = 0, k = 0;
    double v[2][2][2] = {};  // [dz][dy][dx]
  };
  std::vector<Octave> octaves_;
};

}  // namespace penumbra

#include "penumbra/effects/value_noise.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/rng.h"

namespace penumbra {

namespace {

double Fade(double t) { return t * t * t * (t * (t * 6 - 15) + 10); }

}  // namespace

double LatticeValue(uint64_t key, int64_t i, int64_t j, int64_t k) {
  // one linear combination of the lattice index with odd 64-bit constants, then two rounds
  // of the SplitMix64 finaliser keyed by `key`
  const uint64_t lin = static_cast<uint64_t>(i) * 0x9e3779b97f4a7c15ULL +
                       static_cast<uint64_t>(j) * 0xc2b2ae3d27d4eb4fULL +
                       static_cast<uint64_t>(k) * 0x165667b19e3779f9ULL;
  const uint64_t h = Mix64(key ^ Mix64(lin));
  return static_cast<double>(h >> 11) * 0x1.0p-53;
}

double ValueNoise1(uint64_t key, double x) {
  const double fl = std::floor(x);
  const int64_t i = static_cast<int64_t>(fl);
  const double f = Fade(x - fl);
  return LatticeValue(key, i) * (1 - f) + LatticeValue(key, i + 1) * f;
}

double ValueNoise3(uint64_t key, const Eigen::Vector3d& p) {
  const Eigen::Vector3d fl(std::floor(p.x()), std::floor(p.y()), std::floor(p.z()));
  const int64_t i = static_cast<int64_t>(fl.x()), j = static_cast<int64_t>(fl.y()),
                k = static_cast<int64_t>(fl.z());
  const double fx = Fade(p.x() - fl.x()), fy = Fade(p.y() - fl.y()), fz = Fade(p.z() - fl.z());
  double c[2][2];
  for (int dz = 0; dz < 2; ++dz) {
    for (int dy = 0; dy < 2; ++dy) {
      const double a = LatticeValue(key, i, j + dy, k + dz);
      const double b = LatticeValue(key, i + 1, j + dy, k + dz);
      c[dz][dy] = a + (b - a) * fx;
    }
  }
  const double y0 = c[0][0] + (c[0][1] - c[0][0]) * fy;
  const double y1 = c[1][0] + (c[1][1] - c[1][0]) * fy;
  return y0 + (y1 - y0) * fz;
}

double Fbm3(uint64_t key, const Eigen::Vector3d& p, int octaves) {
  double sum = 0, amp = 1, norm = 0, freq = 1;
  for (int o = 0; o < octaves; ++o) {
    sum += amp * ValueNoise3(HashKeys(key, static_cast<uint64_t>(o)), p * freq);
    norm += amp;
    amp *= 0.5;
    freq *= 2.0;
  }
  return sum / norm;
}

Fbm3Sampler::Fbm3Sampler(uint64_t key, int octaves) : octaves_(std::max(octaves, 0)) {
  for (int o = 0; o < octaves; ++o) octaves_[o].key = HashKeys(key, static_cast<uint64_t>(o));
}

double Fbm3Sampler::operator()(const Eigen::Vector3d& p) {
  // the arithmetic of Fbm3 and ValueNoise3, with the lattice values of the cell memoised.
  double sum = 0, amp = 1, norm = 0, freq = 1;
  for (Octave& oc : octaves_) {
    const Eigen::Vector3d x = p * freq;
    const Eigen::Vector3d fl(std::floor(x.x()), std::floor(x.y()), std::floor(x.z()));
    const int64_t i = static_cast<int64_t>(fl.x()), j = static_cast<int64_t>(fl.y()),
                  k = static_cast<int64_t>(fl.z());
    if (!oc.valid || i != oc.i || j != oc.j || k != oc.k) {
      for (int dz = 0; dz < 2; ++dz)
        for (int dy = 0; dy < 2; ++dy)
          for (int dx = 0; dx < 2; ++dx)
            oc.v[dz][dy][dx] = LatticeValue(oc.key, i + dx, j + dy, k + dz);
      oc.valid = true;
      oc.i = i, oc.j = j, oc.k = k;
    }
    const double fx = Fade(x.x() - fl.x()), fy = Fade(x.y() - fl.y()), fz = Fade(x.z() - fl.z());
    double c[2][2];
    for (int dz = 0; dz < 2; ++dz)
      for (int dy = 0; dy < 2; ++dy) {
        const double a = oc.v[dz][dy][0], b = oc.v[dz][dy][1];
        c[dz][dy] = a + (b - a) * fx;
      }
    const double y0 = c[0][0] + (c[0][1] - c[0][0]) * fy;
    const double y1 = c[1][0] + (c[1][1] - c[1][0]) * fy;
    sum += amp * (y0 + (y1 - y0) * fz);
    norm += amp;
    amp *= 0.5;
    freq *= 2.0;
  }
  return sum / norm;
}

}  // namespace penumbra

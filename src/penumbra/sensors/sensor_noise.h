#pragma once
// seeded noise streams for sensors: every sensor draws from its own counter-based stream
// keyed by (world seed, hash of the sensor name, sample index), so adding or removing one
// sensor never changes another's noise, and results never depend on thread count.

#include <cmath>
#include <cstdint>
#include <string_view>

#include "penumbra/core/rng.h"

namespace penumbra {

/// 64-bit FNV-1a hash of a sensor name (stable across platforms and runs).
constexpr uint64_t SensorNameHash(std::string_view name) {
  uint64_t h = 0xcbf29ce484222325ULL;
  for (char c : name) {
    h ^= static_cast<uint8_t>(c);
    h *= 0x100000001b3ULL;
  }
  return h;
}

/// stream id of sensor `name` under world seed `seed`; key per-sample streams on top of it
/// with HashKeys(SensorStreamSeed(seed, name), sample_index).
constexpr uint64_t SensorStreamSeed(uint64_t seed, std::string_view name) {
  return HashKeys(seed, SensorNameHash(name));
}

/// one standard normal sample N(0, 1) (Box-Muller transform on two uniforms of `rng`).
inline double StandardNormal(Rng* rng) {
  // 1 - u in (0, 1] keeps the log finite
  const double u1 = 1.0 - rng->UniformD();
  const double u2 = rng->UniformD();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(6.283185307179586 * u2);
}

}  // namespace penumbra

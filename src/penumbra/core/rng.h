#pragma once
// counter-based random numbers: every draw is a pure function of its keys, so
// results never depend on thread count, scheduling or call order.
//
// host and device (PB_HOST_DEVICE): the CUDA kernels draw the CPU's streams bit for bit.
//
// hash: the 64-bit finaliser of SplitMix64 (Steele, Lea, Flood, "Fast splittable
// pseudorandom number generators", OOPSLA 2014).

#include <cstdint>

#include "penumbra/core/host_device.h"

namespace penumbra {

namespace rng_detail {
constexpr uint64_t kGamma = 0x9e3779b97f4a7c15ULL;  // SplitMix64's golden-ratio increment
// SplitMix64's output mix of its state z.
constexpr uint64_t Finalize(uint64_t z) {
  z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
  z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
  return z ^ (z >> 31);
}
}  // namespace rng_detail

/// SplitMix64 finaliser: a bijective 64-bit mix.
constexpr uint64_t Mix64(uint64_t z) { return rng_detail::Finalize(z + rng_detail::kGamma); }

/// combines keys into one 64-bit stream id.
constexpr uint64_t HashKeys(uint64_t a, uint64_t b) { return Mix64(a ^ Mix64(b)); }
constexpr uint64_t HashKeys(uint64_t a, uint64_t b, uint64_t c) {
  return HashKeys(HashKeys(a, b), c);
}
constexpr uint64_t HashKeys(uint64_t a, uint64_t b, uint64_t c, uint64_t d) {
  return HashKeys(HashKeys(a, b, c), d);
}

/// a small deterministic stream seeded by keys, e.g. Rng(HashKeys(seed, frame, pixel, sample)).
class Rng {
 public:
  PB_HOST_DEVICE explicit constexpr Rng(uint64_t stream) : state_(stream) {}
  /// next 64 random bits.
  PB_HOST_DEVICE constexpr uint64_t NextU64() {
    state_ += kGamma;
    return Finalize(state_);
  }
  /// the n-th output (n = 0, 1, ...) of Rng(stream).NextU64() without drawing the ones before
  /// it: SplitMix64 is counter-based, its state after n + 1 draws is stream + (n + 1) gamma.
  /// branch-free, so loops over many streams vectorise.
  PB_HOST_DEVICE static constexpr uint64_t DrawAt(uint64_t stream, uint64_t n) {
    return Finalize(stream + (n + 1) * kGamma);
  }
  /// uniform float in [0, 1).
  PB_HOST_DEVICE float Uniform() { return static_cast<float>(NextU64() >> 40) * 0x1.0p-24f; }
  /// two uniform floats in [0, 1) from one 64-bit draw: *a from its top 24 bits (the value
  /// Uniform() would return for that draw), *b from the 24 bits below them.
  PB_HOST_DEVICE void Uniform2(float* a, float* b) { Uniform2Of(NextU64(), a, b); }
  /// the two floats Uniform2 makes of the 64-bit draw z (via 32-bit integers, exact for
  /// 24-bit values, so that loops over lanes vectorise).
  PB_HOST_DEVICE static constexpr void Uniform2Of(uint64_t z, float* a, float* b) {
    *a = static_cast<float>(static_cast<int32_t>(z >> 40)) * 0x1.0p-24f;
    *b = static_cast<float>(static_cast<int32_t>((z >> 16) & 0xffffffULL)) * 0x1.0p-24f;
  }
  /// uniform double in [0, 1).
  PB_HOST_DEVICE double UniformD() { return static_cast<double>(NextU64() >> 11) * 0x1.0p-53; }

 private:
  static constexpr uint64_t kGamma = rng_detail::kGamma;
  PB_HOST_DEVICE static constexpr uint64_t Finalize(uint64_t z) { return rng_detail::Finalize(z); }
  uint64_t state_;
};

}  // namespace penumbra

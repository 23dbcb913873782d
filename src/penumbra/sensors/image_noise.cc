#include "penumbra/sensors/image_noise.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "penumbra/core/error.h"

namespace penumbra {

double SampleStandardNormal(Rng* rng) {
  const double u1 = 1.0 - rng->UniformD();  // (0, 1]
  const double u2 = rng->UniformD();
  return std::sqrt(-2.0 * std::log(u1)) * std::cos(2.0 * M_PI * u2);
}

int64_t SamplePoisson(double mean, Rng* rng) {
  if (!(mean > 0)) return 0;
  if (mean < 10) {
    const double limit = std::exp(-mean);
    double p = 1.0;
    int64_t k = -1;
    do {
      ++k;
      p *= rng->UniformD();
    } while (p > limit);
    return k;
  }
  // PTRS (Hoermann 1993, algorithm PTRS with the constants of his table)
  const double slam = std::sqrt(mean);
  const double loglam = std::log(mean);
  const double b = 0.931 + 2.53 * slam;
  const double a = -0.059 + 0.02483 * b;
  const double inv_alpha = 1.1239 + 1.1328 / (b - 3.4);
  const double v_r = 0.9277 - 3.6224 / (b - 2.0);
  for (;;) {
    const double U = rng->UniformD() - 0.5;
    const double V = rng->UniformD();
    const double us = 0.5 - std::abs(U);
    const double kd = std::floor((2.0 * a / us + b) * U + mean + 0.43);
    if (us >= 0.07 && V <= v_r) return static_cast<int64_t>(kd);
    if (kd < 0 || (us < 0.013 && V > us)) continue;
    if (std::log(V) + std::log(inv_alpha) - std::log(a / (us * us) + b) <=
        -mean + kd * loglam - std::lgamma(kd + 1.0))
      return static_cast<int64_t>(kd);
  }
}

void ValidateImageNoiseOrThrow(const ImageNoiseConfig& c, const std::string& key_prefix) {
  auto positive = [&](double v, const char* name) {
    if (!(v > 0) || !std::isfinite(v))
      throw ConfigError("", 0, key_prefix + "." + name,
                        "got " + std::to_string(v) + "; expected a finite number > 0");
  };
  positive(c.full_well_e, "full_well_e");
  positive(c.iso, "iso");
  positive(c.base_iso, "base_iso");
  if (!(c.read_noise_e >= 0) || !std::isfinite(c.read_noise_e))
    throw ConfigError("", 0, key_prefix + ".read_noise_e",
                      "got " + std::to_string(c.read_noise_e) + "; expected a finite number >= 0");
  auto at_least_zero = [&](double v, const char* name, double hi) {
    if (!(v >= 0 && v <= hi))
      throw ConfigError(
          "", 0, key_prefix + "." + name,
          "got " + std::to_string(v) + "; expected a number in [0, " + std::to_string(hi) + "]");
  };
  at_least_zero(c.dark_current_e_per_s, "dark_current_e_per_s", 1e9);
  at_least_zero(c.dsnu_e, "dsnu_e", 1e6);
  at_least_zero(c.prnu, "prnu", 0.5);
  if (c.adc_bits < 1 || c.adc_bits > 16)
    throw ConfigError("", 0, key_prefix + ".adc_bits",
                      "got " + std::to_string(c.adc_bits) + "; expected an integer in [1, 16]");
}

double GainDnPerElectron(const ImageNoiseConfig& c) {
  return (std::ldexp(1.0, c.adc_bits) - 1.0) / c.full_well_e * c.iso / c.base_iso;
}

void ApplyImageNoise(const ImageF& exposed, const ImageNoiseConfig& c, uint64_t key, ImageF* dn,
                     ThreadPool* pool, double exposure_time_sec, uint64_t fixed_pattern_key) {
  if (dn->width != exposed.width || dn->height != exposed.height ||
      dn->channels != exposed.channels)
    *dn = ImageF(exposed.width, exposed.height, exposed.channels);
  const double gain = GainDnPerElectron(c);
  const double max_dn = std::ldexp(1.0, c.adc_bits) - 1.0;
  const double e_per_x = c.full_well_e * c.base_iso / c.iso;
  const size_t row = static_cast<size_t>(exposed.width) * exposed.channels;
  const double dark_e = c.dark_current_e_per_s * std::max(0.0, exposure_time_sec);
  const bool fixed_pattern = c.dsnu_e > 0 || c.prnu > 0;
  auto do_row = [&](int64_t v) {
    for (size_t i = v * row; i < (v + 1) * row; ++i) {
      const double x = std::max(0.0f, exposed.data[i]);
      double e = std::isfinite(x) ? x * e_per_x : c.full_well_e;
      if (c.enabled) {
        double offset = 0;
        if (fixed_pattern) {
          Rng fp(HashKeys(fixed_pattern_key, static_cast<uint64_t>(i)));
          e *= std::max(0.0, 1.0 + c.prnu * SampleStandardNormal(&fp));
          offset = c.dsnu_e * SampleStandardNormal(&fp);
        }
        Rng rng(HashKeys(key, static_cast<uint64_t>(i)));
        e = static_cast<double>(SamplePoisson(std::min(e + dark_e, 4.0 * c.full_well_e), &rng));
        e += offset + c.read_noise_e * SampleStandardNormal(&rng);
      }
      e = std::clamp(e, 0.0, c.full_well_e);
      dn->data[i] = static_cast<float>(std::min(max_dn, std::round(e * gain)));
    }
  };
  ParallelForOrSerial(pool, exposed.height, do_row);
}

}  // namespace penumbra

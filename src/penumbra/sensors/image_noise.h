#pragma once
// image sensor noise: the photon transfer model of sensors/camera_sensor_config.h
// (ImageNoiseConfig; EMVA Standard 1288 release 3.1, sec. 2): Poisson shot noise of the
// photo-electrons, Gaussian read noise, full-well clipping, ISO gain and ADC quantisation.
// every pixel and channel draws from Rng(HashKeys(key, pixel, channel)), so results are a
// pure function of (key, image) and never depend on thread count.

#include <cstdint>
#include <string>

#include "penumbra/core/image.h"
#include "penumbra/core/rng.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/sensors/camera_sensor_config.h"

namespace penumbra {

/// a Poisson(mean) sample (mean >= 0): Knuth's multiplication method below mean 10, the
/// transformed rejection method PTRS of Hoermann ("The transformed rejection method for
/// generating Poisson random variables", Insurance: Mathematics and Economics 12, 1993) above.
int64_t SamplePoisson(double mean, Rng* rng);

/// a standard normal sample (Box-Muller).
double SampleStandardNormal(Rng* rng);

/// checks ranges (see ImageNoiseConfig). @throws ConfigError with key `key_prefix`.<field>.
void ValidateImageNoiseOrThrow(const ImageNoiseConfig& c, const std::string& key_prefix);

/// ADC gain in DN per electron: (2^adc_bits - 1) / full_well_e * iso / base_iso.
double GainDnPerElectron(const ImageNoiseConfig& c);

/// applies the sensor model to `exposed` ((H x W x C) float, linear exposed values, 1 = full
/// well at base ISO) and writes `dn` ((H x W x C) float holding integer DN in
/// [0, 2^adc_bits - 1]). `key` seeds the noise (e.g. HashKeys(seed, camera, frame)).
/// with c.enabled == false only the gain and quantisation are applied.
/// rows are spread over `pool` when given (results do not depend on it).
void ApplyImageNoise(const ImageF& exposed, const ImageNoiseConfig& c, uint64_t key, ImageF* dn,
                     ThreadPool* pool = nullptr);

}  // namespace penumbra

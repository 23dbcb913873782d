#pragma once
// image sensor noise: the photon transfer model of sensors/camera_sensor_config.h
// (ImageNoiseConfig; EMVA Standard 1288 release 3.1, sec. 2): Poisson shot noise of the
// photo-electrons and of the dark current, Gaussian read noise, fixed pattern noise (PRNU gain
// and DSNU offset per pixel), full-well clipping, ISO gain and ADC quantisation. every pixel
// and channel draws its temporal noise from Rng(HashKeys(key, index)) and its fixed pattern
// from Rng(HashKeys(fixed_pattern_key, index)), so results are a pure function of (keys, image)
// and never depend on thread count; the fixed pattern is the same in every frame of a camera.

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
/// [0, 2^adc_bits - 1]). `key` seeds the temporal noise (e.g. HashKeys(seed, camera, frame)),
/// `fixed_pattern_key` the per-pixel PRNU and DSNU (e.g. HashKeys(seed, camera)); the dark
/// current accumulates over `exposure_time_sec`. per pixel, in electrons:
///   e = Poisson(x e_per_x (1 + prnu n1) + dark_current T) + dsnu n2 + read_noise n3
/// with n1, n2 fixed and n3 temporal standard normals, then clipped to [0, full_well] and
/// converted to DN. with c.enabled == false only the gain and quantisation are applied.
/// rows are spread over `pool` when given (results do not depend on it).
void ApplyImageNoise(const ImageF& exposed, const ImageNoiseConfig& c, uint64_t key, ImageF* dn,
                     ThreadPool* pool = nullptr, double exposure_time_sec = 0,
                     uint64_t fixed_pattern_key = 0);

}  // namespace penumbra

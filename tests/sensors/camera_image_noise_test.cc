#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/sensors/image_noise.h"

namespace penumbra {
namespace {

struct Moments {
  double mean = 0, var = 0;
};

Moments Measure(const ImageF& img) {
  double s = 0, s2 = 0;
  for (float v : img.data) s += v;
  const double m = s / img.data.size();
  for (float v : img.data) s2 += (v - m) * (v - m);
  return {m, s2 / (img.data.size() - 1)};
}

TEST(CameraImageNoiseTest, VarianceFollowsPhotonTransferCurve) {
  ImageNoiseConfig c;
  c.enabled = true;
  c.full_well_e = 10000;
  c.read_noise_e = 5;
  c.iso = 400;
  c.adc_bits = 12;
  const double gain = GainDnPerElectron(c);
  EXPECT_NEAR(gain, 4095.0 / 10000 * 4, 1e-12);
  // signals well above the read noise: the model clips electrons at 0 (no black-level
  // pedestal), which biases pixels within a few read-noise sigmas of black
  for (double x : {0.02, 0.1, 0.3, 0.6}) {
    const ImageF flat(200, 200, 3, static_cast<float>(x));
    ImageF dn;
    ApplyImageNoise(flat, c, HashKeys(7, 1, 2), &dn);
    const Moments m = Measure(dn);
    // var(DN) = gain * mean(DN) + (gain * read_e)^2 + 1/12 (uniform quantisation error)
    const double expected =
        gain * m.mean + gain * gain * c.read_noise_e * c.read_noise_e + 1.0 / 12;
    std::printf("x %.3f mean %.2f DN (expected %.2f) var %.3f expected %.3f (%.2f%%)\n", x, m.mean,
                x * 4095, m.var, expected, 100 * (m.var / expected - 1));
    EXPECT_NEAR(m.mean, x * 4095, 0.005 * x * 4095 + 0.5);
    EXPECT_NEAR(m.var, expected, 0.05 * expected);
  }
}

TEST(CameraImageNoiseTest, PoissonSamplerHasPoissonMoments) {
  for (double mean : {0.5, 3.0, 9.9, 10.0, 37.0, 1234.5}) {
    double s = 0, s2 = 0;
    const int n = 200000;
    for (int i = 0; i < n; ++i) {
      Rng rng(HashKeys(11, i));
      const double k = static_cast<double>(SamplePoisson(mean, &rng));
      s += k;
      s2 += k * k;
    }
    const double m = s / n, var = s2 / n - m * m;
    EXPECT_NEAR(m, mean, 4 * std::sqrt(mean / n)) << mean;
    EXPECT_NEAR(var, mean, 0.02 * mean + 4 * mean * std::sqrt(2.0 / n)) << mean;
  }
}

TEST(CameraImageNoiseTest, SeededAndDeterministic) {
  ImageNoiseConfig c;
  c.enabled = true;
  const ImageF flat(32, 32, 3, 0.3f);
  ImageF a, b, d;
  ApplyImageNoise(flat, c, 5, &a);
  ApplyImageNoise(flat, c, 5, &b);
  ApplyImageNoise(flat, c, 6, &d);
  EXPECT_EQ(a.data, b.data);
  EXPECT_NE(a.data, d.data);
}

TEST(CameraImageNoiseTest, DisabledNoiseOnlyQuantises) {
  ImageNoiseConfig c;
  c.adc_bits = 8;
  const ImageF flat(4, 4, 3, 0.25f);
  ImageF dn;
  ApplyImageNoise(flat, c, 1, &dn);
  for (float v : dn.data) EXPECT_EQ(v, 64.0f);  // round(0.25 * 255)
}

TEST(CameraImageNoiseTest, BadSettingsNameTheKey) {
  ImageNoiseConfig c;
  c.full_well_e = 0;
  try {
    ValidateImageNoiseOrThrow(c, "cameras[front].noise");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "cameras[front].noise.full_well_e");
  }
  c = ImageNoiseConfig();
  c.adc_bits = 20;
  EXPECT_THROW(ValidateImageNoiseOrThrow(c, "x"), ConfigError);
}

}  // namespace
}  // namespace penumbra

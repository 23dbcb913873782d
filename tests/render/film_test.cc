// exposure, tone mapping and sRGB encoding.

#include "penumbra/render/film.h"

#include <gtest/gtest.h>

#include <cmath>

namespace penumbra {
namespace {

ImageF Uniform(int w, int h, float value) {
  ImageF img(w, h, 3, value);
  return img;
}

RenderSettings Manual(double ev100, RenderSettings::ToneMap tm = RenderSettings::ToneMap::kLinear) {
  RenderSettings s;
  s.auto_exposure = false;
  s.ev100 = ev100;
  s.tone_map = tm;
  return s;
}

TEST(FilmTest, ExposureFromEv100) {
  EXPECT_DOUBLE_EQ(ExposureFromEv100(0), 1.0 / 1.2);
  EXPECT_DOUBLE_EQ(ExposureFromEv100(1), 0.5 / 1.2);
  EXPECT_DOUBLE_EQ(ExposureFromEv100(-2), 4.0 / 1.2);
}

TEST(FilmTest, SrgbOetfMatchesTheStandard) {
  EXPECT_FLOAT_EQ(SrgbOetf(0), 0);
  EXPECT_FLOAT_EQ(SrgbOetf(1), 1);
  EXPECT_NEAR(SrgbOetf(0.0031308f), 0.04045f, 1e-6);
  EXPECT_NEAR(SrgbOetf(0.5f), 0.735357f, 1e-5);
  EXPECT_NEAR(SrgbOetf(0.18f), 0.461356f, 1e-5);
  EXPECT_FLOAT_EQ(SrgbOetf(2.0f), 1.0f);
}

TEST(FilmTest, AcesCurve) {
  EXPECT_EQ(AcesFilmic(0), 0);
  float prev = 0;
  for (float x = 0.01f; x < 100; x *= 1.3f) {
    const float y = AcesFilmic(x);
    EXPECT_GE(y, prev);
    EXPECT_LE(y, 1.0f);
    prev = y;
  }
  EXPECT_FLOAT_EQ(AcesFilmic(1e6f), 1.0f);
  // Narkowicz's fit at 0.18: 0.18 (2.51 0.18 + 0.03) / (0.18 (2.43 0.18 + 0.59) + 0.14).
  EXPECT_NEAR(AcesFilmic(0.18f), 0.18 * (2.51 * 0.18 + 0.03) / (0.18 * (2.43 * 0.18 + 0.59) + 0.14),
              1e-6);
}

TEST(FilmTest, DevelopEncodesWithinOneCodeOfExactRounding) {
  // manual EV100 = log2(1 / 1.2): exposure 1, so the pixel value is the radiance itself.
  const Film film(Manual(std::log2(1.0 / 1.2)));
  ImageF ramp(1001, 1, 3);
  for (int u = 0; u < 1001; ++u)
    for (int c = 0; c < 3; ++c) ramp.at(u, 0)[c] = u / 1000.0f;
  ImageU8 rgb;
  film.Develop(ramp, std::log2(1.0 / 1.2), nullptr, &rgb);
  int exact = 0;
  for (int u = 0; u < 1001; ++u) {
    const int expected = static_cast<int>(std::lround(255.0 * SrgbOetf(u / 1000.0f)));
    EXPECT_LE(std::abs(rgb.at(u, 0)[0] - expected), 1) << u;
    exact += rgb.at(u, 0)[0] == expected;
  }
  EXPECT_GT(exact, 990);
  EXPECT_EQ(rgb.at(0, 0)[0], 0);
  EXPECT_EQ(rgb.at(1000, 0)[0], 255);
}

TEST(FilmTest, AutoExposureMapsTheLogAverageToMiddleGrey) {
  for (float L : {0.05f, 3.0f, 2000.0f}) {
    RenderSettings s;
    s.auto_exposure = true;
    s.tone_map = RenderSettings::ToneMap::kLinear;
    const Film film(s);
    const ImageF img = Uniform(40, 30, L);
    EXPECT_NEAR(film.LogAverageLuminance(img, nullptr), L, 1e-4 * L);
    const double ev = film.Ev100(img, nullptr);
    EXPECT_NEAR(ev, std::log2(L / (0.18 * 1.2)), 1e-6);
    ImageU8 rgb;
    film.Develop(img, ev, nullptr, &rgb);
    EXPECT_EQ(rgb.at(5, 5)[1], static_cast<int>(std::lround(255 * SrgbOetf(0.18f))));  // 118
  }
  // compensation +1 stop brightens: EV100 one lower.
  RenderSettings s;
  s.exposure_compensation_ev = 1;
  const ImageF img = Uniform(8, 8, 10.0f);
  EXPECT_NEAR(Film(s).Ev100(img, nullptr), std::log2(10.0 / 0.216) - 1, 1e-9);
  // manual mode ignores the image.
  EXPECT_DOUBLE_EQ(Film(Manual(7.5)).Ev100(img, nullptr), 7.5);
}

TEST(FilmTest, ThreadCountDoesNotChangeTheResult) {
  ImageF img(97, 53, 3);
  for (size_t i = 0; i < img.data.size(); ++i)
    img.data[i] = static_cast<float>((i * 7919) % 1000) * 0.37f;
  RenderSettings s;
  s.tone_map = RenderSettings::ToneMap::kFilmic;
  const Film film(s);
  ThreadPool pool(2);
  EXPECT_EQ(film.Ev100(img, nullptr), film.Ev100(img, &pool));
  ImageU8 a, b;
  film.Develop(img, film.Ev100(img, nullptr), nullptr, &a);
  film.Develop(img, film.Ev100(img, &pool), &pool, &b);
  EXPECT_EQ(a.data, b.data);
}

TEST(FilmTest, BlackImageHasFiniteExposure) {
  const Film film(RenderSettings{});
  const ImageF black = Uniform(4, 4, 0.0f);
  const double ev = film.Ev100(black, nullptr);
  EXPECT_TRUE(std::isfinite(ev));
  EXPECT_NEAR(film.LogAverageLuminance(black, nullptr), kMinLuminance, 1e-12);
}

}  // namespace
}  // namespace penumbra

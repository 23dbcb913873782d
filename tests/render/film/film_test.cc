// exposure, tone mapping and sRGB encoding.

#include "penumbra/render/film/film.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include "penumbra/core/srgb.h"

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

// film_math.h's FrameExposure (the CUDA backend's auto exposure, on the host and in its
// exposure kernel) gives the bits of the formula written out: the rows added in row order, the
// exp of their mean, log2 against the key (Film::Ev100FromLogAverage), the float exposure times
// each gain; for auto and manual exposure, with and without compensation.
TEST(FilmTest, FrameExposureIsTheFilmsEv100BitForBit) {
  const int W = 640, H = 480;
  const int64_t pixels = static_cast<int64_t>(W) * H;
  std::vector<double> rows(H);
  for (int v = 0; v < H; ++v)
    rows[v] = W * (-2.5 + 3.0 * std::sin(0.37 * v) + 0.001 * v);  // ln L of W pixels
  const float gains[3] = {1.25f, 1.0f, 0.8125f};
  for (int k = 0; k < 4; ++k) {
    RenderSettings s;
    s.auto_exposure = k < 3;
    s.exposure_compensation_ev = k == 1 ? 1.3 : k == 3 ? -0.7 : 0;
    s.ev100 = 7.25;
    if (k == 2) rows.assign(H, std::log(kMinLuminance) * W);  // a black frame
    const Film film(s);
    double total = 0;
    for (double r : rows) total += r;
    const double log_average = std::exp(total / static_cast<double>(pixels));
    const double want_ev = (s.auto_exposure ? std::log2(log_average / (0.18 * 1.2)) : s.ev100) -
                           s.exposure_compensation_ev;
    const float e = static_cast<float>(1.0 / (1.2 * std::exp2(want_ev)));
    float got[3];
    const double ev =
        FrameExposure(film.exposure_pod(), rows.data(), H, pixels, kMinLuminance, gains, got);
    EXPECT_EQ(ev, want_ev) << k;
    EXPECT_EQ(film.Ev100FromLogAverage(log_average), want_ev) << k;
    for (int c = 0; c < 3; ++c) EXPECT_EQ(got[c], e * gains[c]) << k << " " << c;
  }
  // no pixels: the minimum luminance
  EXPECT_EQ(LogAverageFromRowSums(rows.data(), 0, 0, kMinLuminance), kMinLuminance);
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
    const int expected = static_cast<int>(std::lround(255.0 * LinearToSrgb(u / 1000.0f)));
    EXPECT_LE(std::abs(rgb.at(u, 0)[0] - expected), 1) << u;
    exact += rgb.at(u, 0)[0] == expected;
  }
  EXPECT_GT(exact, 990);
  EXPECT_EQ(rgb.at(0, 0)[0], 0);
  EXPECT_EQ(rgb.at(1000, 0)[0], 255);
}

// HSV hue (degrees) of an 8-bit RGB pixel.
double HueDeg(const uint8_t* p) {
  const double r = p[0], g = p[1], b = p[2];
  const double mx = std::max({r, g, b}), mn = std::min({r, g, b});
  if (mx == mn) return 0;
  double h = 0;
  if (mx == r) {
    h = 60 * (g - b) / (mx - mn);
  } else if (mx == g) {
    h = 60 * (2 + (b - r) / (mx - mn));
  } else {
    h = 60 * (4 + (r - g) / (mx - mn));
  }
  return h < 0 ? h + 360 : h;
}

// a per-channel curve would turn a saturated orange yellow when over-exposed and red when
// dim. the filmic map keeps the hue of the material colour from 1/4 to 4x of the exposure at
// which the linear colour itself is the exposed value.
TEST(FilmTest, FilmicKeepsTheHueOfSaturatedColours) {
  const Film film(Manual(0, RenderSettings::ToneMap::kFilmic));
  struct Case {
    const char* name;
    float srgb[3];
  };
  for (const Case& col : {Case{"orange", {1.0f, 0.5f, 0.0f}}, Case{"blue", {0.1f, 0.3f, 1.0f}}}) {
    ImageF radiance(1, 1, 3);
    for (int c = 0; c < 3; ++c) {
      const float v = col.srgb[c];  // sRGB decode (IEC 61966-2-1)
      radiance.at(0, 0)[c] = v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
    }
    uint8_t code[3];
    for (int c = 0; c < 3; ++c) code[c] = static_cast<uint8_t>(std::lround(255 * col.srgb[c]));
    const double material_hue = HueDeg(code);
    for (double stops = -2; stops <= 2; stops += 0.5) {
      // exposure H = 2^stops: EV100 = log2(1 / (1.2 H)).
      ImageU8 rgb;
      film.Develop(radiance, std::log2(1.0 / 1.2) - stops, nullptr, &rgb);
      EXPECT_NEAR(HueDeg(rgb.at(0, 0)), material_hue, 3.0)
          << col.name << " at " << stops << " stops: " << int(rgb.at(0, 0)[0]) << " "
          << int(rgb.at(0, 0)[1]) << " " << int(rgb.at(0, 0)[2]);
    }
  }
}

TEST(FilmTest, FilmicMapsGreyThroughTheAcesCurve) {
  const Film film(Manual(std::log2(1.0 / 1.2), RenderSettings::ToneMap::kFilmic));
  ImageF ramp(200, 1, 3);
  for (int u = 0; u < 200; ++u)
    for (int c = 0; c < 3; ++c) ramp.at(u, 0)[c] = u / 20.0f;
  ImageU8 rgb;
  film.Develop(ramp, std::log2(1.0 / 1.2), nullptr, &rgb);
  for (int u = 0; u < 200; ++u) {
    const int expected = static_cast<int>(std::lround(255.0 * LinearToSrgb(AcesFilmic(u / 20.0f))));
    for (int c = 0; c < 3; ++c) EXPECT_LE(std::abs(rgb.at(u, 0)[c] - expected), 1) << u;
  }
  float x[3] = {4.0f, 1.0f, std::nanf("")}, y[3];
  HuePreservingFilmic(x, y);
  EXPECT_FLOAT_EQ(y[0], AcesFilmic(4.0f));
  EXPECT_FLOAT_EQ(y[1], AcesFilmic(4.0f) / 4);
  EXPECT_TRUE(std::isnan(y[2]));
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
    EXPECT_EQ(rgb.at(5, 5)[1], static_cast<int>(std::lround(255 * LinearToSrgb(0.18f))));  // 118
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

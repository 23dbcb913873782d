// camera white balance (render/film/white_balance.h) through Film::Develop: a neutral floor under
// the daylight sky and sun comes out neutral (auto and daylight), saturated albedos keep their
// hue and saturation through the hue-preserving tone map.

#include "penumbra/render/film/white_balance.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "penumbra/render/film/film.h"
#include "render/media_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

// a Lambertian floor of `albedo` under the default daylight sky (Preetham, turbidity 3) and a
// 100 klx white sun in the sky model's sun direction.
SceneDescription DaylightFloor(const Eigen::Vector3f& albedo) {
  SceneDescription s = EmptyScene();
  s.sky.type = Sky::Type::kDaylight;
  const int m = AddMaterial(&s, albedo, 1.0f, 0.0f, 0.0f);
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, m);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = -s.sky.sun_direction_W.normalized();
  sun.intensity = 1e5f;
  s.lights.push_back(sun);
  return s;
}

ImageF RenderDaylightFloor(const SceneDescription& s) {
  RenderSettings rs = TierSettings(RenderSettings::Tier::kRealtime);
  auto r = MakeRenderer(s, rs);
  const CameraView view = MakeView(CameraLookingDown({0, 0, 2}), 16, 16, 30, true, false, false);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), nullptr, view, &f);
  return f.radiance;
}

float SrgbToLinearForWb(uint8_t code) {
  const float v = code / 255.0f;
  return v <= 0.04045f ? v / 12.92f : std::pow((v + 0.055f) / 1.055f, 2.4f);
}

// the mean of the decoded (linear) pixels of the developed image: auto exposure, filmic tone
// map (the defaults), the given gains.
Eigen::Vector3f DevelopedMeanLinear(const ImageF& radiance, const Eigen::Vector3f& gains) {
  RenderSettings rs;  // auto exposure, filmic
  const Film film(rs);
  ImageU8 rgb;
  film.Develop(radiance, film.Ev100(radiance, nullptr), nullptr, &rgb, gains);
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (int v = 0; v < rgb.height; ++v)
    for (int u = 0; u < rgb.width; ++u)
      for (int c = 0; c < 3; ++c) sum[c] += SrgbToLinearForWb(rgb.at(u, v)[c]);
  return (sum / (rgb.width * rgb.height)).cast<float>();
}

// (max - min) / max of an rgb value.
double ChromaOf(const Eigen::Vector3f& c) { return (c.maxCoeff() - c.minCoeff()) / c.maxCoeff(); }

// hue in degrees [0, 360) and HSV saturation of a linear rgb value.
void HueSatOf(const Eigen::Vector3f& c, double* hue, double* sat) {
  const double mx = c.maxCoeff(), mn = c.minCoeff(), d = mx - mn;
  *sat = mx > 0 ? d / mx : 0;
  double h = 0;
  if (d > 0) {
    if (mx == c.x()) {
      h = 60 * std::fmod((c.y() - c.z()) / d, 6.0);
    } else if (mx == c.y()) {
      h = 60 * ((c.z() - c.x()) / d + 2);
    } else {
      h = 60 * ((c.x() - c.y()) / d + 4);
    }
  }
  *hue = h < 0 ? h + 360 : h;
}

double HueDistance(double a, double b) {
  const double d = std::abs(a - b);
  return std::min(d, 360 - d);
}

TEST(WhiteBalanceTest, PlanckianWhite) {
  // 6500 K is close to the sRGB white (D65: 6504 K, 0.003 off the Planckian locus).
  const Eigen::Vector3f d65 = PlanckianWhiteRgb(6500);
  EXPECT_LT(ChromaOf(d65), 0.06);
  const Eigen::Vector3f tungsten = PlanckianWhiteRgb(2856);  // CIE illuminant A
  EXPECT_GT(tungsten.x(), 1.5 * tungsten.z());
  const Eigen::Vector3f g = WhiteBalanceGains(tungsten);
  EXPECT_LT(ChromaOf(g.cwiseProduct(tungsten)), 1e-5);
  EXPECT_NEAR(
      0.2126 * g.x() * tungsten.x() + 0.7152 * g.y() * tungsten.y() + 0.0722 * g.z() * tungsten.z(),
      1.0, 1e-4);
  EXPECT_EQ(WhiteBalanceGains(Eigen::Vector3f(1, 0, 1)), Eigen::Vector3f::Ones());
}

TEST(WhiteBalanceTest, NeutralGreyUnderDaylightIsNeutral) {
  const SceneDescription s = DaylightFloor(Eigen::Vector3f::Constant(0.5f));
  const ImageF radiance = RenderDaylightFloor(s);
  // without white balance the sky's blue tints the grey (a colour cast).
  const double raw = ChromaOf(DevelopedMeanLinear(radiance, Eigen::Vector3f::Ones()));
  EXPECT_GT(raw, 0.02);
  for (WhiteBalance::Mode mode : {WhiteBalance::Mode::kAuto, WhiteBalance::Mode::kDaylight}) {
    WhiteBalance wb;
    wb.mode = mode;
    const Eigen::Vector3f gains = GainsForFrame(wb, DaylightWhite(s), radiance);
    const double chroma = ChromaOf(DevelopedMeanLinear(radiance, gains));
    EXPECT_LT(chroma, 0.02) << (mode == WhiteBalance::Mode::kAuto ? "auto" : "daylight")
                            << " (unbalanced " << raw << ")";
  }
}

TEST(WhiteBalanceTest, SaturatedAlbedosKeepHueAndSaturation) {
  // linear albedos: red, orange, green, blue, pink.
  const Eigen::Vector3f albedos[] = {{0.8f, 0.05f, 0.05f},
                                     {0.8f, 0.25f, 0.02f},
                                     {0.05f, 0.6f, 0.05f},
                                     {0.05f, 0.1f, 0.8f},
                                     {0.8f, 0.1f, 0.5f}};
  for (const Eigen::Vector3f& a : albedos) {
    SCOPED_TRACE(::testing::Message() << a.transpose());
    const SceneDescription s = DaylightFloor(a);
    const ImageF radiance = RenderDaylightFloor(s);
    WhiteBalance wb;  // the default: daylight
    const Eigen::Vector3f out =
        DevelopedMeanLinear(radiance, GainsForFrame(wb, DaylightWhite(s), radiance));
    double h0, s0, h1, s1;
    HueSatOf(a, &h0, &s0);
    HueSatOf(out, &h1, &s1);
    EXPECT_LT(HueDistance(h0, h1), 3.0) << h0 << " -> " << h1;
    EXPECT_NEAR(s1, s0, 0.1 * s0);
  }
}

}  // namespace
}  // namespace penumbra

// daylight by the numbers (render/sky/sky_math.h): air mass, the sun's direct-normal and the clear
// sky's diffuse illuminance against published clear-sky values, and the MJCF skybox lookup of
// SkyModel::Background.

#include "penumbra/render/sky/sky_math.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "penumbra/render/sky/sky_model.h"

namespace penumbra {
namespace {

constexpr double kDegSkyMath = 3.14159265358979323846 / 180.0;

// the IES clear-sky model (IESNA Lighting Handbook, 9th ed., ch. 8; IES RP-21): direct-normal
// illuminance 127.5 klx exp(-0.21 / sin h), diffuse horizontal 0.8 + 15.5 sin^0.5 h klx.
double IesClearDirectNormalLux(double elevation_deg) {
  return 127500.0 * std::exp(-0.21 / std::sin(elevation_deg * kDegSkyMath));
}
double IesClearDiffuseHorizontalLux(double elevation_deg) {
  return 800.0 + 15500.0 * std::sqrt(std::sin(elevation_deg * kDegSkyMath));
}

TEST(SkyMathTest, KastenYoungAirMass) {
  EXPECT_NEAR(RelativeAirMass(90), 1.0, 1e-3);
  // Kasten and Young 1989, approximation: 1.9943 at 30 deg, 5.586 at 10 deg; 38 at the horizon.
  EXPECT_NEAR(RelativeAirMass(30), 1.9942, 2e-3);
  EXPECT_NEAR(RelativeAirMass(10), 5.59, 0.03);
  EXPECT_NEAR(RelativeAirMass(0), 37.9, 0.3);
  EXPECT_EQ(SunDirectNormalIlluminance(-5, 3), 0.0f);
  EXPECT_EQ(SkyDiffuseHorizontalIlluminance(0, 3), 0.0f);
}

TEST(SkyMathTest, ClearSkyIlluminanceMatchesPublishedValues) {
  // a clear sky (turbidity 2.5): the sun within 15 %, the sky within 25 % of the IES clear sky
  // at low, middle and high sun.
  for (const double h : {20.0, 45.0, 70.0}) {
    SCOPED_TRACE(h);
    const double sun = SunDirectNormalIlluminance(static_cast<float>(h), 2.5f);
    const double sky = SkyDiffuseHorizontalIlluminance(static_cast<float>(h), 2.5f);
    EXPECT_NEAR(sun / IesClearDirectNormalLux(h), 1.0, 0.15) << sun;
    EXPECT_NEAR(sky / IesClearDiffuseHorizontalLux(h), 1.0, 0.25) << sky;
    // direct sun ~100 klx against ~10-20 klx of sky: a shadow on the ground keeps only the sky.
    const double lit = sun * std::sin(h * kDegSkyMath) + sky;
    EXPECT_GT(1.0 - sky / lit, h >= 45 ? 0.75 : 0.6);
  }
  // more haze: less sun, more sky.
  EXPECT_LT(SunDirectNormalIlluminance(45, 5), SunDirectNormalIlluminance(45, 2.5f));
  EXPECT_GT(SkyDiffuseHorizontalIlluminance(45, 5), SkyDiffuseHorizontalIlluminance(45, 2.5f));
}

TEST(SkyMathTest, ZenithScaleGivesTheDiffuseIlluminance) {
  Sky sky;
  sky.type = Sky::Type::kDaylight;
  sky.turbidity = 3;
  sky.sun_direction_W = Eigen::Vector3d(std::cos(45 * kDegSkyMath), 0, std::sin(45 * kDegSkyMath));
  const double per_zenith = SkyModel::HorizontalIlluminancePerZenithLuminance(sky);
  ASSERT_GT(per_zenith, 1.0);
  const double target = SkyDiffuseHorizontalIlluminance(45, 3);
  sky.zenith_luminance = SkyModel::PhysicalZenithLuminance(sky);
  EXPECT_NEAR(sky.zenith_luminance, target / per_zenith, 1e-3 * sky.zenith_luminance);
  const Eigen::Vector3f e = SkyModel(sky).Irradiance(Eigen::Vector3f::UnitZ());
  const double lum = 0.2126 * e.x() + 0.7152 * e.y() + 0.0722 * e.z();
  EXPECT_NEAR(lum / target, 1.0, 0.02);
}

TEST(SkyMathTest, SkyboxIsTheBackgroundAsMujocoDrawsIt) {
  // six uniform faces of distinct colours (MuJoCo order +x, -x, +y, -y, +z, -z).
  const int w = 4;
  const uint8_t colours[6][3] = {{255, 0, 0},   {0, 255, 0},   {0, 0, 255},
                                 {255, 255, 0}, {0, 255, 255}, {255, 0, 255}};
  std::vector<uint8_t> rgb;
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < w * w; ++i) rgb.insert(rgb.end(), colours[f], colours[f] + 3);
  Sky sky;
  sky.type = Sky::Type::kDaylight;
  SkyboxBackground box;
  box.image = std::make_shared<TextureImage>(w, 6 * w, 6, rgb);
  box.sun_horizontal_lux = 50000;
  const SkyModel model(sky, box);
  // a white texel is a white Lambertian surface facing up under the sky and the sun.
  const Eigen::Vector3f e_sky = model.Irradiance(Eigen::Vector3f::UnitZ());
  const float white = model.skybox_white_luminance();
  EXPECT_NEAR(white * 3.14159265f,
              0.2126f * e_sky.x() + 0.7152f * e_sky.y() + 0.0722f * e_sky.z() + 50000.0f, 50.0f);
  // the cube's +y face (MuJoCo's gradient top) is the world's zenith, -y the nadir; +x stays.
  const auto expect_face = [&](const Eigen::Vector3f& d, int face) {
    SCOPED_TRACE(::testing::Message() << d.transpose() << " -> face " << face);
    const Eigen::Vector3f b = model.Background(d);
    for (int c = 0; c < 3; ++c)
      EXPECT_NEAR(b[c], colours[face][c] > 0 ? white : 0.0f, 1e-2f * white);
  };
  expect_face({0, 0, 1}, 2);
  expect_face({0, 0, -1}, 3);
  expect_face({1, 0, 0.1f}, 0);
  expect_face({-1, 0, 0.1f}, 1);
  expect_face({0, 1, 0.1f}, 5);
  expect_face({0, -1, 0.1f}, 4);
  // light still comes from the sky: Radiance ignores the skybox.
  const SkyModel plain(sky);
  EXPECT_EQ(model.Radiance({0, 0, 1}), plain.Radiance({0, 0, 1}));
  EXPECT_EQ(plain.Background({0, 0, 1}), plain.Radiance({0, 0, 1}));
  EXPECT_EQ(plain.skybox_white_luminance(), 0.0f);
}

}  // namespace
}  // namespace penumbra

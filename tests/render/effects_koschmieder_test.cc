// Koschmieder's law in the realtime tier: a black target seen through purely scattering fog
// under a uniform sky has apparent contrast C = (L_target - L_horizon) / L_horizon =
// -exp(-sigma_t d). the realtime tier treats the sky as an isotropic in-scatter source that
// reaches every point of the fog unoccluded, which is exactly Koschmieder's setting; the
// pathtraced tier attenuates the sky through the fog (an unbounded fog hides the sky entirely),
// so the law is tested in the realtime tier only.

#include <gtest/gtest.h>

#include <cmath>

#include "render/media_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

TEST(EffectsKoschmiederTest, ContrastFallsExponentiallyWithDistance) {
  const float sigma = 0.3f;
  for (double d : {2.0, 5.0, 9.0}) {
    SceneDescription s = EmptyScene();
    s.sky.radiance = Eigen::Vector3f(1.0f, 1.2f, 1.5f);
    // a small black Lambertian target (albedo 0, no specular): 0.4 m wide at distance d.
    const int black = AddMaterial(&s, Eigen::Vector3f::Zero(), 1.0f, 0.0f, 0.0f);
    AddGeom(&s, GeomShape::kBox, {0.05, 0.2, 0.2}, Translation(d + 0.05, 0, 0), 0, black);
    EffectsFrame fx;
    fx.homogeneous_media.push_back(Fog(sigma, 1.0f, 0.0f));
    auto r = MakeRenderer(s, TierSettings(RenderSettings::Tier::kRealtime));
    // the target fills the centre pixels; the corners see the horizon.
    const double fovy = 2 * std::atan(0.6 / d) * 180 / M_PI;
    const CameraView view = MakeView(CameraLookingAlongX(), 33, 33, fovy, true, false, true);
    RenderedFrame f;
    r->Render(IdentitySnapshot(s), &fx, view, &f);
    ASSERT_NE(*f.geom_id.at(16, 16), -1);
    ASSERT_EQ(*f.geom_id.at(0, 0), -1);
    for (int c = 0; c < 3; ++c) {
      const double L_t = f.radiance.at(16, 16)[c];
      const double L_h = f.radiance.at(0, 0)[c];
      const double C = (L_t - L_h) / L_h;
      const double expected = -std::exp(-sigma * d);
      EXPECT_NEAR(C, expected, 0.03 * std::abs(expected)) << "d " << d << " channel " << c;
      if (c == 1)
        RecordProperty("contrast_d" + std::to_string(static_cast<int>(d)), std::to_string(C));
    }
    // the horizon of an unbounded fog is the in-scatter equilibrium (albedo 1: the sky).
    EXPECT_NEAR(f.radiance.at(0, 0)[1], 1.2, 0.012);
  }
}

// single scattering of a point light in a bounded fog: the realtime tier's froxel in-scatter
// against the pathtraced tier limited to one scattering event (max_bounces = 1).
TEST(EffectsKoschmiederTest, LightInScatterTiersAgree) {
  SceneDescription s = EmptyScene();
  s.extent_m = 10;
  Light l;
  l.type = Light::Type::kPoint;
  l.position_B = Eigen::Vector3d(3, 0, 2.0);  // above the view: no singular glow in it
  l.intensity = 100;
  s.lights.push_back(l);
  EffectsFrame fx;
  HomogeneousMedium fog = Fog(0.1f, 1.0f, 0.3f);
  fog.region = BoxRegion{{0.5, -4, -4}, {8, 4, 4}};
  fx.homogeneous_media.push_back(fog);
  const CameraView view = MakeView(CameraLookingAlongX(), 144, 96, 30, true, false, false);
  double mean[2];
  int k = 0;
  for (RenderSettings::Tier tier :
       {RenderSettings::Tier::kRealtime, RenderSettings::Tier::kPathtraced}) {
    RenderSettings rs = TierSettings(tier, 16);
    rs.max_bounces = 1;
    auto r = MakeRenderer(s, rs);
    RenderedFrame f;
    r->Render(IdentitySnapshot(s), &fx, view, &f);
    mean[k++] = MeanRadiance(f.radiance, 0, 144, 0, 96);
  }
  EXPECT_GT(mean[1], 0.0);
  EXPECT_NEAR(mean[0], mean[1], 0.1 * mean[1]);
  RecordProperty("realtime_over_pathtraced", std::to_string(mean[0] / mean[1]));
}

}  // namespace
}  // namespace penumbra

// fog of finite extent (HomogeneousMedium::layer_top_m): an unbounded fog is a layer below its
// top, so the sun reaching the floor is attenuated along its path inside the layer,
// exp(-sigma_t * path), instead of being removed; its shadow stays.

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/render/media/media_common.h"
#include "penumbra/render/media/media_scene.h"
#include "render/media_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

constexpr double kFogSunElevationDeg = 45;
constexpr double kFogLayerTopM = 5;
constexpr double kFogCameraHeightM = 4;

// a Lambertian floor (albedo 0.5) with a 1 m cube at the origin under a 1000 lx sun at 45 deg
// elevation in +x (its shadow falls on x in [-1.5, -0.5]), black sky.
SceneDescription FogLayerScene() {
  SceneDescription s = EmptyScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Constant(0.5f), 1.0f, 0.0f, 0.0f);
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, m);
  AddGeom(&s, GeomShape::kBox, {0.5, 0.5, 0.5}, Translation(0, 0, 0.5), 0, m);
  Light sun;
  sun.type = Light::Type::kDirectional;
  const double e = kFogSunElevationDeg * M_PI / 180;
  sun.direction_B = -Eigen::Vector3d(std::cos(e), 0, std::sin(e));
  sun.intensity = 1000;
  s.lights.push_back(sun);
  return s;
}

struct FogPatches {
  double lit = 0, shadow = 0;
  double Contrast() const { return (lit - shadow) / lit; }
};

// mean radiance of the floor at world (1.5, 0) (sunlit) and (-1, 0) (in the cube's shadow),
// seen straight down from kFogCameraHeightM.
FogPatches RenderFogPatches(const EffectsFrame* fx, RenderSettings::Tier tier) {
  const SceneDescription s = FogLayerScene();
  auto r = MakeRenderer(s, TierSettings(tier, 16));
  const int w = 64;
  const CameraView view =
      MakeView(CameraLookingDown({0, 0, kFogCameraHeightM}), w, w, 60, true, false, false);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), fx, view, &f);
  const double fpx = view.intrinsics.fy;
  auto u_of = [&](double x) {
    return static_cast<int>(std::lround(view.intrinsics.cx + fpx * x / kFogCameraHeightM));
  };
  const int v = w / 2;
  FogPatches p;
  p.lit = MeanRadiance(f.radiance, u_of(1.5) - 2, u_of(1.5) + 3, v - 2, v + 3);
  p.shadow = MeanRadiance(f.radiance, u_of(-1.0) - 2, u_of(-1.0) + 3, v - 2, v + 3);
  return p;
}

EffectsFrame FogLayerFrame(double mor_m, float top_m) {
  EffectsFrame fx;
  HomogeneousMedium m = Fog(static_cast<float>(SigmaTFromMorM(mor_m)), 0.95f, 0.8f);
  m.layer_top_m = top_m;
  fx.homogeneous_media.push_back(m);
  return fx;
}

TEST(FogLayerTest, OpticalDepthOfTheSunIsItsPathInsideTheLayer) {
  EffectsFrame fx = FogLayerFrame(200, kFogLayerTopM);
  MediaScene media;
  media.Build(&fx);
  const float sigma = static_cast<float>(SigmaTFromMorM(200));
  const double e = kFogSunElevationDeg * M_PI / 180;
  const Eigen::Vector3f to_sun(std::cos(e), 0, std::sin(e));
  const float inf = std::numeric_limits<float>::infinity();
  // from the floor: the path up to the top is top / sin(elevation).
  const Eigen::Vector3f tau = media.AnalyticOpticalDepth({1, 0, 0}, to_sun, 0, inf);
  EXPECT_NEAR(tau.y(), sigma * kFogLayerTopM / std::sin(e), 1e-4);
  // above the layer nothing; a horizontal ray inside it is unbounded.
  EXPECT_EQ(media.AnalyticOpticalDepth({0, 0, 6}, to_sun, 0, inf).y(), 0.0f);
  EXPECT_NEAR(media.AnalyticOpticalDepth({0, 0, 6}, -to_sun, 0, 10).y(),
              sigma * (10 - 1 / std::sin(e)), 1e-4);
  EXPECT_TRUE(std::isinf(media.AnalyticOpticalDepth({0, 0, 1}, {1, 0, 0}, 0, inf).y()) ||
              media.AnalyticOpticalDepth({0, 0, 1}, {1, 0, 0}, 0, inf).y() > 1e20f);
}

TEST(FogLayerTest, SunShadowStaysAndDimsAsMorFalls) {
  for (RenderSettings::Tier tier :
       {RenderSettings::Tier::kRealtime, RenderSettings::Tier::kPathtraced}) {
    SCOPED_TRACE(tier == RenderSettings::Tier::kRealtime ? "realtime" : "pathtraced");
    const FogPatches none = RenderFogPatches(nullptr, tier);
    ASSERT_GT(none.lit, 0);
    EXPECT_GT(none.Contrast(), 0.5);
    double last_lit = none.lit;
    for (double mor : {200.0, 50.0}) {
      SCOPED_TRACE(mor);
      const EffectsFrame fx = FogLayerFrame(mor, kFogLayerTopM);
      const FogPatches fog = RenderFogPatches(&fx, tier);
      // minor's 200 m fog keeps the shadow (contrast >= half of none's).
      EXPECT_GE(fog.Contrast(), 0.5 * none.Contrast());
      EXPECT_LT(fog.lit, last_lit);
      last_lit = fog.lit;
      // the sunlit floor is at least the sun attenuated along its path in the layer and the
      // camera's path (in-scatter only adds), and no brighter than without fog.
      const double sigma = SigmaTFromMorM(mor);
      const double path = kFogLayerTopM / std::sin(kFogSunElevationDeg * M_PI / 180);
      const double t = std::exp(-sigma * (path + kFogCameraHeightM));
      EXPECT_GE(fog.lit, 0.95 * t * none.lit);
      EXPECT_LE(fog.lit, none.lit);
    }
  }
}

}  // namespace
}  // namespace penumbra

// fog and particles lit by the sky the static geometry lets through (SkyIrradianceVolume::
// AmbientRadiance): a closed room under a bright sky must not fill its fog
// with sky light, while fog under the open sky keeps Koschmieder's sky in-scatter.

#include <gtest/gtest.h>

#include <cmath>

#include "render/media_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

constexpr float kSky = 2000.0f;  // cd/m^2: a bright overcast sky, far above the lamp-lit room

// a closed box room (inside x in [-1, 4], y in [-2.5, 2.5], z in [-1, 1.5]; walls 0.2 m thick,
// static) with a white wall ahead of a camera at the origin looking along +x, a black square on
// it (x = 0.5 m, the patch's face towards the camera), and a point lamp near the ceiling.
// `closed` false leaves the room open: only the target wall (and its black patch) stay.
SceneDescription Room(bool closed, float target_x) {
  SceneDescription s = EmptyScene();
  s.sky.radiance = Eigen::Vector3f::Constant(kSky);
  const int white = AddMaterial(&s, Eigen::Vector3f::Constant(0.8f));
  const int black = AddMaterial(&s, Eigen::Vector3f::Constant(0.02f));
  const int wall = AddBody(&s, "room", true);
  const double t = 0.1;
  // the target wall and the black patch on it (0.3 m square, 1 cm proud of the wall).
  AddGeom(&s, GeomShape::kBox, {t, 2.7, 1.4}, Translation(target_x + t, 0, 0.25), wall, white);
  AddGeom(&s, GeomShape::kBox, {0.005, 0.15, 0.15}, Translation(target_x - 0.005, 0.15, 0), wall,
          black);
  if (closed) {
    AddGeom(&s, GeomShape::kBox, {t, 2.7, 1.4}, Translation(-1 - t, 0, 0.25), wall, white);
    AddGeom(&s, GeomShape::kBox, {2.7, t, 1.4}, Translation(1.5, 2.5 + t, 0.25), wall, white);
    AddGeom(&s, GeomShape::kBox, {2.7, t, 1.4}, Translation(1.5, -2.5 - t, 0.25), wall, white);
    AddGeom(&s, GeomShape::kBox, {2.7, 2.7, t}, Translation(1.5, 0, 1.5 + t), wall, white);
    AddGeom(&s, GeomShape::kBox, {2.7, 2.7, t}, Translation(1.5, 0, -1 - t), wall, white);
  }
  Light l;
  l.type = Light::Type::kPoint;
  l.position_B = Eigen::Vector3d(0.2, 0, 1.2);
  l.intensity = 200;  // cd
  l.cast_shadow = true;
  s.lights.push_back(l);
  s.center_W = Eigen::Vector3d(1.5, 0, 0.25);
  s.extent_m = 4;
  return s;
}

// Michelson contrast between the black patch (image left of centre) and the white wall
// (image right of centre) at the green channel.
double PatchContrast(const RenderedFrame& f, int W, int H) {
  const double black = MeanRadiance(f.radiance, W / 2 - 6, W / 2 - 2, H / 2 - 2, H / 2 + 2);
  const double white = MeanRadiance(f.radiance, W / 2 + 6, W / 2 + 10, H / 2 - 2, H / 2 + 2);
  return (white - black) / (white + black);
}

RenderedFrame RenderRoom(const SceneDescription& s, const EffectsFrame* fx,
                         RenderSettings::Tier tier, int W, int H, int spp = 1) {
  RenderSettings rs = TierSettings(tier, spp);
  rs.ev100 = 4;
  auto r = MakeRenderer(s, rs);
  const CameraView view = MakeView(CameraLookingAlongX(), W, H, 60, true, false, true);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), fx, view, &f);
  return f;
}

// in the closed room the fog keeps the contrast that attenuation alone leaves. contrast is
// Michelson's (white - black) / (white + black) of the black patch on the white wall 0.5 m
// away; attenuation alone is the same fog with albedo 0 (a pure absorber: no in-scatter). an
// unoccluded sky of 2000 cd/m^2 would add 0.95 (1 - exp(-0.1 x 0.5)) 2000 = 93 cd/m^2 of veil
// to a lamp-lit wall of about 25 cd/m^2 (retained contrast about 0.12).
TEST(MediaOccludedSkyTest, ClosedRoomFogKeepsAttenuationContrast) {
  const int W = 64, H = 48;
  const float d = 0.5f, sigma = 2.996f / 30.0f;  // MOR 30 m (the minor preset's old fog)
  const SceneDescription s = Room(true, d);
  EffectsFrame fx, absorber;
  fx.homogeneous_media.push_back(Fog(sigma, 0.95f, 0.8f));
  absorber.homogeneous_media.push_back(Fog(sigma, 0.0f, 0.8f));
  const RenderedFrame clear = RenderRoom(s, nullptr, RenderSettings::Tier::kRealtime, W, H);
  const RenderedFrame foggy = RenderRoom(s, &fx, RenderSettings::Tier::kRealtime, W, H);
  const RenderedFrame dark = RenderRoom(s, &absorber, RenderSettings::Tier::kRealtime, W, H);
  ASSERT_EQ(*clear.geom_id.at(W / 2 - 4, H / 2), 101);  // the black patch
  ASSERT_EQ(*clear.geom_id.at(W / 2 + 8, H / 2), 100);  // the white wall
  const double c0 = PatchContrast(clear, W, H);
  ASSERT_GT(c0, 0.8);
  const double retained = PatchContrast(foggy, W, H) / c0;
  const double attenuation_only = PatchContrast(dark, W, H) / c0;
  RecordProperty("contrast_retained", std::to_string(retained));
  RecordProperty("contrast_retained_attenuation_only", std::to_string(attenuation_only));
  // the lamp's own in-scatter veils a little (about 1 % of the white wall's radiance).
  EXPECT_NEAR(retained, attenuation_only, 0.05);
  EXPECT_GT(retained, 0.9);
  // the wall's radiance falls by the fog's transmittance from the lamp (at (0.2, 0, 1.2), the
  // wall point about (0.5, -0.08, 0)) and on to the camera (and rises a little by in-scatter).
  const double w0 = MeanRadiance(clear.radiance, W / 2 + 6, W / 2 + 10, H / 2 - 2, H / 2 + 2);
  const double w1 = MeanRadiance(foggy.radiance, W / 2 + 6, W / 2 + 10, H / 2 - 2, H / 2 + 2);
  const double lamp_m = (Eigen::Vector3d(0.2, 0, 1.2) - Eigen::Vector3d(0.5, -0.08, 0)).norm();
  EXPECT_NEAR(w1 / w0, std::exp(-sigma * (d + lamp_m)), 0.03);
}

// with no lamp, a closed room in fog under a bright sky is dark in both tiers (the realtime
// tier through the sky volume, the pathtraced tier through its shadow rays).
TEST(MediaOccludedSkyTest, ClosedRoomFogGetsNoSkyLight) {
  const int W = 32, H = 24;
  SceneDescription s = Room(true, 3.5f);
  s.lights.clear();
  EffectsFrame fx;
  fx.homogeneous_media.push_back(Fog(0.3f, 0.95f, 0.8f));
  for (RenderSettings::Tier tier :
       {RenderSettings::Tier::kRealtime, RenderSettings::Tier::kPathtraced}) {
    const RenderedFrame f = RenderRoom(s, &fx, tier, W, H, 4);
    const double mean = MeanRadiance(f.radiance, 0, W, 0, H);
    // an unoccluded sky would put 0.95 (1 - exp(-0.3 x 3.5)) kSky = 1240 cd/m^2 in the fog.
    EXPECT_LT(mean, 1e-3 * kSky) << "tier " << static_cast<int>(tier);
  }
}

// the open scene (the target wall alone under the sky): the fog in front of the black patch
// carries the sky's in-scatter, albedo (1 - exp(-sigma d)) L_sky within a few per cent (the
// wall itself hides a part of the sky from the fog next to it).
TEST(MediaOccludedSkyTest, OpenSkyFogKeepsSkyInScatter) {
  const int W = 64, H = 48;
  const float d = 3.0f, sigma = 0.2f;
  SceneDescription s = Room(false, d);
  s.lights.clear();
  EffectsFrame fx;
  fx.homogeneous_media.push_back(Fog(sigma, 1.0f, 0.0f));
  const RenderedFrame f = RenderRoom(s, &fx, RenderSettings::Tier::kRealtime, W, H);
  // the patch spans about 3 pixels at 3 m: its centre pixel.
  int count = 0;
  const Eigen::Vector2d c = MaskCentroid(f.geom_id, 101, &count);
  ASSERT_GT(count, 0);
  const double L = f.radiance.at(static_cast<int>(c.x()), static_cast<int>(c.y()))[1];
  const double open = (1 - std::exp(-sigma * d)) * kSky;
  RecordProperty("open_sky_inscatter_ratio", std::to_string(L / open));
  // the wall (a plane 3 m ahead) hides up to half the sphere from the fog near it.
  EXPECT_GT(L, 0.6 * open);
  EXPECT_LT(L, 1.05 * open);
}

}  // namespace
}  // namespace penumbra

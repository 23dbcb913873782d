// precipitation falls only where the sky is open above (render/particles/shelter_map.h): rain under
// a roofed box is not drawn, rain in the open is, and sparks are not sheltered.

#include <gtest/gtest.h>

#include "penumbra/render/embree/particle_scene.h"
#include "penumbra/render/particles/shelter_map.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

std::unique_ptr<RayQuery> Query(const SceneDescription& s) {
  return MakeRayQuery(s, RenderSettings::Backend::kEmbree);
}

// a floor plane and a roofed box (walls and a roof 0.1 m thick) over x, y in [-2, 2], z in
// [0, 2.5], static; the open sky elsewhere.
SceneDescription RoofedBox() {
  SceneDescription s = EmptyScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Constant(0.5f));
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Translation(0, 0, 0), 0, m);
  AddGeom(&s, GeomShape::kBox, {2.1, 2.1, 0.05}, Translation(0, 0, 2.55), 0, m);  // roof
  AddGeom(&s, GeomShape::kBox, {0.05, 2.1, 1.3}, Translation(2.05, 0, 1.3), 0, m);
  AddGeom(&s, GeomShape::kBox, {0.05, 2.1, 1.3}, Translation(-2.05, 0, 1.3), 0, m);
  AddGeom(&s, GeomShape::kBox, {2.1, 0.05, 1.3}, Translation(0, 2.05, 1.3), 0, m);
  AddGeom(&s, GeomShape::kBox, {2.1, 0.05, 1.3}, Translation(0, -2.05, 1.3), 0, m);
  return s;
}

TEST(ParticleShelterTest, RoofShelters) {
  const SceneDescription s = RoofedBox();
  ShelterMap map(Query);
  map.Update(s, IdentitySnapshot(s), nullptr);
  ASSERT_FALSE(map.empty());
  EXPECT_NEAR(map.RoofHeight(0.3f, -0.7f), 2.6f, 1e-3f);
  EXPECT_TRUE(map.Sheltered({0.3f, -0.7f, 1.0f}));   // inside the box
  EXPECT_TRUE(map.Sheltered({-1.8f, 1.8f, 0.1f}));   // inside, next to a wall
  EXPECT_FALSE(map.Sheltered({0.3f, -0.7f, 3.0f}));  // above the roof
  EXPECT_FALSE(map.Sheltered({3.0f, 0.0f, 1.0f}));   // outside the box (open sky)
  EXPECT_FALSE(map.Sheltered({40.0f, 0.0f, 1.0f}));  // outside the map
  EXPECT_FALSE(map.Sheltered({NAN, 0.0f, 1.0f}));
  // no finite static geometry: nothing is sheltered.
  SceneDescription open = EmptyScene();
  AddGeom(&open, GeomShape::kPlane, {0, 0, 1}, Translation(0, 0, 0), 0, -1);
  ShelterMap none(Query);
  none.Update(open, IdentitySnapshot(open), nullptr);
  EXPECT_TRUE(none.empty());
  EXPECT_FALSE(none.Sheltered({0, 0, 1}));
}

// rain drops on a grid at 1 m height, inside the box (|x|, |y| < 1.8) and outside it
// (3 <= |x| <= 5), seen by a camera above the scene looking down (pathtraced: every drop in
// the frame becomes a streak).
TEST(ParticleShelterTest, RainFallsOnlyUnderTheOpenSky) {
  const SceneDescription s = RoofedBox();
  ShelterMap map(Query);
  map.Update(s, IdentitySnapshot(s), nullptr);
  EffectsFrame fx;
  ParticleSet rain;
  rain.kind = ParticleKind::kRain;
  int inside = 0, outside = 0;
  for (float x = -5; x <= 5.01f; x += 0.5f)
    for (float y = -1.5f; y <= 1.51f; y += 0.5f) {
      const bool in = std::abs(x) < 1.8f;
      const bool out = std::abs(x) >= 3.0f;
      if (!in && !out) continue;
      (in ? inside : outside) += 1;
      rain.position_W.emplace_back(x, y, 1.0f);
      rain.velocity_W.emplace_back(0, 0, -5);
      rain.radius_m.push_back(0.002f);
    }
  fx.particles.push_back(rain);
  const Camera camera(CameraLookingDown({0, 0, 30}), CameraIntrinsics::FromFovy(64, 64, 60));
  ParticleScene open, covered;
  open.Build(&fx, camera, 0.01, StreakRays::kAny, nullptr, nullptr, nullptr);
  covered.Build(&fx, camera, 0.01, StreakRays::kAny, nullptr, nullptr, &map);
  EXPECT_EQ(open.size(), inside + outside);
  EXPECT_EQ(covered.size(), outside);
  // a set that opts out (the effect's `sheltered: false`) falls indoors too.
  fx.particles[0].sheltered = false;
  ParticleScene leaking;
  leaking.Build(&fx, camera, 0.01, StreakRays::kAny, nullptr, nullptr, &map);
  EXPECT_EQ(leaking.size(), inside + outside);
  fx.particles[0].sheltered = true;
  // sparks are never sheltered.
  fx.particles[0].kind = ParticleKind::kSpark;
  ParticleScene sparks;
  sparks.Build(&fx, camera, 0.01, StreakRays::kAny, nullptr, nullptr, &map);
  EXPECT_EQ(sparks.size(), inside + outside);
}

}  // namespace
}  // namespace penumbra

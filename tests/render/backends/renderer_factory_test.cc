// the backend factory (render/backends/renderer_factory.h): RenderSettings::backend picks the
// Renderer and the RayQuery; the only backend today is Embree.

#include "penumbra/render/backends/renderer_factory.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/cpu/embree_renderer.h"
#include "penumbra/render/embree/embree_version.h"
#include "penumbra/render/embree/ray_scene.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using testing::AddGeom;
using testing::AddMaterial;
using testing::CameraLookingAlongX;
using testing::EmptyScene;
using testing::IdentitySnapshot;
using testing::MakeView;
using testing::TestSettings;
using testing::Translation;

// a lit sphere in front of a wall, seen by a camera at the origin looking along +x.
SceneDescription LitScene() {
  SceneDescription s = EmptyScene();
  s.sky.radiance = Eigen::Vector3f(50, 60, 70);
  const int grey = AddMaterial(&s, Eigen::Vector3f::Constant(0.5f));
  const int red = AddMaterial(&s, Eigen::Vector3f(0.8f, 0.1f, 0.1f));
  AddGeom(&s, GeomShape::kBox, {0.5, 5, 5}, Translation(6.5, 0, 0), 0, grey);
  AddGeom(&s, GeomShape::kSphere, {0.7, 0, 0}, Translation(3, 0.8, -0.4), 0, red);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(1, -0.5, -0.7).normalized();
  sun.intensity = 2000;
  s.lights.push_back(sun);
  return s;
}

RenderSettings BadBackend() {
  RenderSettings r = TestSettings();
  r.backend = static_cast<RenderSettings::Backend>(7);
  return r;
}

TEST(RendererFactoryTest, EmbreeBackendIsTheEmbreeRenderer) {
  const SceneDescription s = LitScene();
  RenderSettings settings = TestSettings(2);
  settings.backend = RenderSettings::Backend::kEmbree;
  std::unique_ptr<Renderer> made = MakeRenderer(s, settings);
  ASSERT_NE(dynamic_cast<EmbreeRenderer*>(made.get()), nullptr);
  // and it renders what the Embree renderer renders, bit for bit
  std::unique_ptr<Renderer> embree = MakeEmbreeRenderer(s, settings);
  const CameraView view = MakeView(CameraLookingAlongX(), 64, 48, 60);
  RenderedFrame a, b;
  made->Render(IdentitySnapshot(s), view, &a);
  embree->Render(IdentitySnapshot(s), view, &b);
  ASSERT_EQ(a.rgb.data.size(), 64u * 48u * 3u);
  EXPECT_EQ(a.rgb.data, b.rgb.data);
  EXPECT_EQ(a.depth_m.data, b.depth_m.data);
  EXPECT_EQ(a.geom_id.data, b.geom_id.data);
  int sphere_pixels = 0;
  for (int32_t id : a.geom_id.data) sphere_pixels += id == s.geoms[1].id;
  EXPECT_GT(sphere_pixels, 50);
}

TEST(RendererFactoryTest, EmbreeRayQueryIsTheRayScene) {
  const SceneDescription s = LitScene();
  std::unique_ptr<RayQuery> q = MakeRayQuery(s, RenderSettings::Backend::kEmbree);
  ASSERT_NE(dynamic_cast<RayScene*>(q.get()), nullptr);
  EXPECT_EQ(&q->scene(), &s);  // referenced, not copied
  q->Update(IdentitySnapshot(s));
  Ray r;
  r.d = Eigen::Vector3f::UnitX();
  SurfaceHit hit;
  bool did_hit = false;
  q->Intersect({&r, 1}, {&hit, 1}, {&did_hit, 1});
  ASSERT_TRUE(did_hit);
  EXPECT_NEAR(hit.t, 6.0f, 1e-5f);  // the wall's -x face; the sphere is off the x axis
  EXPECT_EQ(hit.geom, 0);
}

TEST(RendererFactoryTest, EmbreeVersionForManifests) {
  const std::string v = RendererVersion(RenderSettings::Backend::kEmbree);
  EXPECT_EQ(v, EmbreeVersion());
  ASSERT_FALSE(v.empty());
  EXPECT_EQ(v[0], '3') << v;  // Embree 3
}

TEST(RendererFactoryTest, UnknownBackendIsAConfigErrorNamingTheKey) {
  const SceneDescription s = LitScene();
  const RenderSettings bad = BadBackend();
  for (int which = 0; which < 3; ++which) {
    try {
      if (which == 0) MakeRenderer(s, bad);
      if (which == 1) MakeRayQuery(s, bad.backend);
      if (which == 2) RendererVersion(bad.backend);
      ADD_FAILURE() << "no error from call " << which;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), "render.backend") << which;
      EXPECT_NE(std::string(e.what()).find("expected one of: cpu, cuda, auto"), std::string::npos)
          << e.what();
    }
  }
}

}  // namespace
}  // namespace penumbra

// spatial tendons: a capsule of the tendon's width around each segment of its
// wrap-point path, in both tiers, moved by the snapshot's tendon paths.

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/render/backends/renderer_factory.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

constexpr float kEmission = 10.0f;

// a black floor at z = 0 under a black sky without lights, and one green emissive tendon of
// width 0.05 m (drawn through the snapshot's paths).
SceneDescription TendonScene() {
  SceneDescription s = EmptyScene();
  const int floor = AddMaterial(&s, Eigen::Vector3f::Zero());
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, floor);
  const int green = AddMaterial(&s, Eigen::Vector3f::Zero());
  s.materials[green].emission = Eigen::Vector3f(0, kEmission, 0);
  Tendon t;
  t.name = "rope";
  t.id = 0;
  t.width_m = 0.05;
  t.material = green;
  s.tendons.push_back(t);
  return s;
}

// a snapshot whose tendon runs through `points` (world frame).
WorldSnapshot WithPath(const SceneDescription& s, std::vector<Eigen::Vector3d> points) {
  WorldSnapshot snap = IdentitySnapshot(s);
  snap.tendon_paths.push_back({0, std::move(points)});
  return snap;
}

// the pixel that sees world point p.
Eigen::Vector2i PixelOf(const CameraView& view, const Eigen::Vector3d& p_W) {
  const Eigen::Vector3d q = view.X_WO.inverse() * p_W;
  const CameraIntrinsics& k = view.intrinsics;
  return {static_cast<int>(std::floor(k.fx * q.x() / q.z() + k.cx)),
          static_cast<int>(std::floor(k.fy * q.y() / q.z() + k.cy))};
}

TEST(TendonRenderTest, TendonIsDrawnAtItsPathInBothTiers) {
  const SceneDescription s = TendonScene();
  // a vertical tendon from (3, 0, 0.2) over (3, 0, 0.6) to (3, 0.3, 1.0): two segments
  const std::vector<Eigen::Vector3d> path = {{3, 0, 0.2}, {3, 0, 0.6}, {3, 0.3, 1.0}};
  for (const auto tier : {RenderSettings::Tier::kRealtime, RenderSettings::Tier::kPathtraced}) {
    RenderSettings settings = TestSettings();
    settings.tier = tier;
    settings.samples_per_pixel = 16;
    settings.denoise = false;
    auto renderer = MakeRenderer(s, settings);
    const CameraView view = MakeView(CameraLookingAlongX({0, 0, 0.6}), 96, 96, 60);
    RenderedFrame f;
    renderer->Render(WithPath(s, path), view, &f);
    const bool realtime = tier == RenderSettings::Tier::kRealtime;
    const char* name = realtime ? "realtime" : "pathtraced";
    // the pathtraced tier adds the glossy reflections of the tendon in itself and the floor
    const float tol = realtime ? 1e-3f : 0.02f * kEmission;
    // the midpoints of both segments show the tendon's colour; beside it, the black floor/sky
    for (const Eigen::Vector3d& p : {Eigen::Vector3d(3, 0, 0.4), Eigen::Vector3d(3, 0.15, 0.8)}) {
      const Eigen::Vector2i px = PixelOf(view, p);
      EXPECT_NEAR(f.radiance.at(px.x(), px.y())[1], kEmission, tol)
          << name << " at " << p.transpose();
      EXPECT_EQ(f.geom_id.at(px.x(), px.y())[0], -1) << name;
      // the capsule's near side: within its radius in front of the axis at x = 3 m
      EXPECT_GE(f.depth_m.at(px.x(), px.y())[0], 3.0f - 0.05f) << name;
      EXPECT_LE(f.depth_m.at(px.x(), px.y())[0], 3.0f) << name;
    }
    const Eigen::Vector2i beside = PixelOf(view, {3, -0.4, 0.4});
    EXPECT_LT(f.radiance.at(beside.x(), beside.y())[1], tol) << name;

    // the next snapshot moves the tendon: the old midpoint is clear, the new one drawn
    renderer->Render(WithPath(s, {{3, -0.4, 0.2}, {3, -0.4, 0.6}}), view, &f);
    const Eigen::Vector2i old_px = PixelOf(view, {3, 0, 0.4});
    EXPECT_LT(f.radiance.at(old_px.x(), old_px.y())[1], tol) << name;
    EXPECT_NEAR(f.radiance.at(beside.x(), beside.y())[1], kEmission, tol) << name;

    // no paths: nothing drawn
    renderer->Render(IdentitySnapshot(s), view, &f);
    EXPECT_LT(f.radiance.at(beside.x(), beside.y())[1], tol) << name;
  }
}

TEST(TendonRenderTest, TendonCastsAShadow) {
  // a white floor lit from straight above: the tendon's shadow falls right under it
  SceneDescription s = EmptyScene();
  const int white = AddMaterial(&s, Eigen::Vector3f::Ones());
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, white);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(0, 0, -1);
  sun.intensity = 1000;
  s.lights.push_back(sun);
  const int red = AddMaterial(&s, Eigen::Vector3f(1, 0, 0));
  Tendon t;
  t.id = 0;
  t.width_m = 0.1;
  t.material = red;
  s.tendons.push_back(t);
  auto renderer = MakeRenderer(s, TestSettings());
  const CameraView view = MakeView(CameraLookingDown({0, 0, 3}), 64, 64, 60);
  RenderedFrame f;
  renderer->Render(WithPath(s, {{0.5, -1, 1}, {0.5, 1, 1}}), view, &f);
  // the floor right under the tendon (seen past it from the camera at x = 0) is in its shadow
  const Eigen::Vector2i lit = PixelOf(view, {0.2, 0, 0});
  const Eigen::Vector2i shadow = PixelOf(view, {0.5, 0, 0});
  const float lit_g = f.radiance.at(lit.x(), lit.y())[1];
  EXPECT_GT(lit_g, 0.0f);
  EXPECT_LT(f.radiance.at(shadow.x(), shadow.y())[1], 0.01f * lit_g);
  const Eigen::Vector2i top = PixelOf(view, {0.5, 0, 1.1});
  const float top_r = f.radiance.at(top.x(), top.y())[0];
  EXPECT_GT(top_r, 0.0f);
  EXPECT_LT(f.radiance.at(top.x(), top.y())[1], 1e-3f * top_r);  // the red tendon, from above
}

}  // namespace
}  // namespace penumbra

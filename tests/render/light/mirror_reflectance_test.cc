// MuJoCo's material `reflectance`: a mirror layer on planes and the +z faces
// of boxes, drawn by both tiers.

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/material/material_eval.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

constexpr float kEmission = 10.0f;

// a black floor (z = 0) with reflectance r and a red emissive box (x 2.7 .. 3.3, z 0 .. 1) on
// it, under a black sky without lights: the floor's only light is the box's mirror image.
SceneDescription MirrorFloorScene(float r) {
  SceneDescription s = EmptyScene();
  const int floor = AddMaterial(&s, Eigen::Vector3f::Zero());
  s.materials[floor].reflectance = r;
  const int red = AddMaterial(&s, Eigen::Vector3f::Zero());
  s.materials[red].emission = Eigen::Vector3f(kEmission, 0, 0);
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, floor);
  AddGeom(&s, GeomShape::kBox, {0.3, 0.5, 0.5}, Translation(3, 0, 0.5), 0, red);
  return s;
}

// mean red radiance of the 3 x 3 pixels around the pixel that sees world point p (through the
// floor's mirror when p is below it).
float RedAround(const RenderedFrame& f, const CameraView& view, const Eigen::Vector3d& p_W) {
  const Eigen::Vector3d q = view.X_WO.inverse() * p_W;
  const CameraIntrinsics& k = view.intrinsics;
  const int u = static_cast<int>(std::floor(k.fx * q.x() / q.z() + k.cx));
  const int v = static_cast<int>(std::floor(k.fy * q.y() / q.z() + k.cy));
  double sum = 0;
  for (int dv = -1; dv <= 1; ++dv)
    for (int du = -1; du <= 1; ++du) sum += f.radiance.at(u + du, v + dv)[0];
  return static_cast<float>(sum / 9);
}

TEST(MirrorReflectanceTest, ReflectiveFloorShowsTheMirroredObjectInBothTiers) {
  for (const auto tier : {RenderSettings::Tier::kRealtime, RenderSettings::Tier::kPathtraced}) {
    for (float r : {0.0f, 0.5f}) {
      const SceneDescription s = MirrorFloorScene(r);
      RenderSettings settings = TestSettings();
      settings.tier = tier;
      settings.samples_per_pixel = 64;
      settings.denoise = false;
      auto renderer = MakeRenderer(s, settings);
      const CameraView view = MakeView(CameraLookingAlongX({0, 0, 1}), 64, 48, 60);
      RenderedFrame f;
      renderer->Render(IdentitySnapshot(s), view, &f);
      const char* name = tier == RenderSettings::Tier::kRealtime ? "realtime" : "pathtraced";
      // the box itself, and its mirror image in the floor (the floor point seen there lies in
      // front of the box).
      EXPECT_NEAR(RedAround(f, view, {2.7, 0, 0.5}), kEmission, 1e-3) << name;
      const float mirrored = RedAround(f, view, {2.7, 0, -0.3});
      // the pathtraced tier picks the mirror with probability r: 9 x 64 samples.
      const float tol = tier == RenderSettings::Tier::kRealtime ? 1e-3f : 0.1f * kEmission;
      EXPECT_NEAR(mirrored, r * kEmission, tol) << name << " r " << r;
      // floor beside the box mirrors the black sky (in the pathtraced tier the black floor's
      // Fresnel rise at grazing angles still catches a little of the box).
      EXPECT_NEAR(RedAround(f, view, {2.7, 1.6, -0.3}), 0, 0.3f * tol) << name << " r " << r;
    }
  }
}

TEST(MirrorReflectanceTest, MirrorLayerOnPlanesAndBoxTopsOnlyAsMuJoCo) {
  SceneDescription s = EmptyScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Constant(0.5f));
  s.materials[m].reflectance = 0.3f;
  const int plane = AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, m);
  const int box = AddGeom(&s, GeomShape::kBox, {1, 1, 1}, Pose::Identity(), 0, m);
  const int sphere = AddGeom(&s, GeomShape::kSphere, {1, 0, 0}, Pose::Identity(), 0, m);
  const MaterialEvaluator eval(s);
  auto mirror = [&](int geom, const Eigen::Vector3f& n_G) {
    SurfaceHit h;
    h.geom = geom;
    h.material = m;
    h.n_G = n_G;
    return eval.Evaluate(h).mirror;
  };
  EXPECT_FLOAT_EQ(mirror(plane, {0, 0, 1}), 0.3f);
  EXPECT_FLOAT_EQ(mirror(box, {0, 0, 1}), 0.3f);
  EXPECT_EQ(mirror(box, {1, 0, 0}), 0.0f);
  EXPECT_EQ(mirror(box, {0, 0, -1}), 0.0f);
  EXPECT_EQ(mirror(sphere, {0, 0, 1}), 0.0f);
}

}  // namespace
}  // namespace penumbra

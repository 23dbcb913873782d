// the mirror layer's importance (render/cpu/mirror_layer.h): mirrors with
// r >= kMirrorDenseReflectance are traced per pixel as before (bit-identical), weaker ones on a
// grid of every 2nd or 4th pixel and interpolated (within r times the reflected contrast), with
// depth and segmentation unchanged.

#include "penumbra/render/cpu/mirror_layer.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "penumbra/render/backends/render_ablation_switch.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

// a grey floor (z = 0) with reflectance r, a red emissive box and a white wall behind it, lit
// by a point lamp and a grey sky.
SceneDescription MirrorLayerScene(float r) {
  SceneDescription s = EmptyScene();
  const int floor = AddMaterial(&s, Eigen::Vector3f::Constant(0.3f));
  s.materials[floor].reflectance = r;
  const int red = AddMaterial(&s, Eigen::Vector3f::Zero());
  s.materials[red].emission = Eigen::Vector3f(20, 2, 2);
  const int white = AddMaterial(&s, Eigen::Vector3f::Constant(0.8f));
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, floor);
  AddGeom(&s, GeomShape::kBox, {0.3, 0.5, 0.5}, Translation(3, 0, 0.5), 0, red);
  AddGeom(&s, GeomShape::kBox, {0.1, 3, 1.5}, Translation(5, 0, 1.5), 0, white);
  AddPointLamp(&s, {1.5, 1, 2}, 40, 0.05f);
  s.sky.type = Sky::Type::kUniform;
  s.sky.radiance = Eigen::Vector3f::Constant(2);
  return s;
}

struct MirrorLayerFrames {
  RenderedFrame sparse, full;
};

MirrorLayerFrames RenderBothWays(float r) {
  const SceneDescription s = MirrorLayerScene(r);
  RenderSettings sparse = TestSettings(2);
  sparse.backend = RenderSettings::Backend::kEmbree;
  const CameraView view = MakeView(CameraLookingAlongX({0, 0, 1}), 96, 72, 60);
  MirrorLayerFrames f;
  MakeRenderer(s, sparse)->Render(IdentitySnapshot(s), view, &f.sparse);
  auto full = MakeRenderer(s, sparse);
  RenderAblation per_pixel;
  per_pixel.mirror_sparse = false;
  EXPECT_TRUE(SetRenderAblation(full.get(), per_pixel));
  full->Render(IdentitySnapshot(s), view, &f.full);
  return f;
}

TEST(MirrorLayerTest, DenseMirrorsAreTracedPerPixelAsBefore) {
  const MirrorLayerFrames f = RenderBothWays(kMirrorDenseReflectance);
  EXPECT_EQ(f.sparse.radiance.data, f.full.radiance.data);
  EXPECT_EQ(f.sparse.rays, f.full.rays);
}

TEST(MirrorLayerTest, WeakMirrorsOnAGridWithinTheReflectedContrast) {
  // r 0.15: every 2nd pixel traced; r 0.05: every 4th.
  for (const float r : {0.15f, 0.05f}) {
    SCOPED_TRACE(r);
    const MirrorLayerFrames f = RenderBothWays(r);
    // depth and segmentation are the camera rays': byte-identical.
    EXPECT_EQ(f.sparse.depth_m.data, f.full.depth_m.data);
    EXPECT_EQ(f.sparse.geom_id.data, f.full.geom_id.data);
    // where the floor's reflection changes (the red box's mirror image), the interpolated
    // pixels differ from the traced ones by at most r times the reflected contrast (20 cd/m^2
    // of the box against the wall and sky); elsewhere by float rounding.
    const ImageF& a = f.sparse.radiance;
    const ImageF& b = f.full.radiance;
    double max_diff = 0, sum_diff = 0;
    int differing = 0, floor_pixels = 0;
    for (int v = 0; v < a.height; ++v)
      for (int u = 0; u < a.width; ++u) {
        if (f.full.geom_id.at(u, v)[0] == 100) ++floor_pixels;
        for (int c = 0; c < 3; ++c) {
          const double d = std::abs(a.at(u, v)[c] - b.at(u, v)[c]);
          max_diff = std::max(max_diff, d);
          sum_diff += d;
          differing += d > 0 ? 1 : 0;
        }
      }
    EXPECT_LE(max_diff, r * 20.0 + 1e-3);
    EXPECT_GT(differing, 0);  // the sparse layer is in use
    EXPECT_LT(sum_diff / (3.0 * a.width * a.height), 0.01 * r * 20.0);
    // each traced mirror pixel costs one reflected ray and one shadow ray (the lamp): about
    // three quarters of the floor's 2 rays per pixel are saved.
    ASSERT_GT(floor_pixels, a.width * a.height / 4);
    EXPECT_LT(f.sparse.rays, f.full.rays - floor_pixels);
  }
}

}  // namespace
}  // namespace penumbra

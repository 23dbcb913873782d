// the realtime media's shared 2x2-quad froxel lookups (RealtimeMedia::PrepareQuad) against
// every pixel's own lookups, in height fog with a light and a smoke grid over a floor and a
// wall (depth edges, sky pixels, near and far surfaces).

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "penumbra/render/camera/camera.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/media/media_realtime.h"
#include "penumbra/render/media/media_scene.h"
#include "render/media_test_util.h"

namespace penumbra::testing {
namespace {

TEST(MediaQuadTest, SharedQuadLookupsMatchPerPixelLookups) {
  SceneDescription s = EmptyScene();
  Light l;
  l.type = Light::Type::kPoint;
  l.position_B = {4, 1.5, 2.5};
  l.intensity = 200;
  s.lights.push_back(l);
  // smoke: a density ramp along x around the floor and the wall.
  EffectsFrame fx;
  HomogeneousMedium fog = Fog(0.25f, 0.9f, 0.3f);
  fog.height_falloff_per_m = 0.1f;
  fx.homogeneous_media.push_back(fog);
  fx.grid_media.push_back(RampGrid({5, 0, 1}, {3, 3, 1.5}, 24, 1.0f, 0.25f, 1.5f, 0.8f));
  const WorldSnapshot snap = IdentitySnapshot(s);
  LightSampler lights(s);
  lights.Update(snap);
  RayScene rays(s);
  rays.Update(snap);
  constexpr int W = 192, H = 144;
  const CameraView view = MakeView(CameraLookingAlongX({0, 0, 1.2}), W, H, 60.0);
  const Camera camera(view.X_WO, view.intrinsics);
  MediaScene media;
  media.Build(&fx);
  RealtimeMedia rm;
  rm.Build(media, lights, rays, camera, 1234, Eigen::Vector3f(5, 0, 1), 8.0,
           Eigen::Vector3f::Constant(0.4f), nullptr, nullptr);

  // distances: the floor z = 0, a wall x = 7 on the image's left half (world y > 0), sky.
  const float inf = std::numeric_limits<float>::infinity();
  auto distance = [&](const Eigen::Vector3f& o, const Eigen::Vector3f& d) {
    float t = inf;
    if (d.z() < 0) t = -o.z() / d.z();
    if (d.x() > 0 && d.y() > 0) t = std::min(t, (7.0f - o.x()) / d.x());
    return t;
  };
  double max_dT = 0, max_dL = 0, sum_dT = 0, sum_dL = 0, max_L = 0;
  int pixels = 0, differing = 0, sky_quads = 0, surface_quads = 0;
  for (int v0 = 0; v0 < H; v0 += 2) {
    for (int u0 = 0; u0 < W; u0 += 2) {
      Eigen::Vector3f o[4], d[4];
      float t[4];
      int hits = 0;
      for (int c = 0; c < 4; ++c) {
        const Ray r =
            camera.GenerateRay(static_cast<float>(u0 + (c & 1)), static_cast<float>(v0 + (c >> 1)));
        o[c] = r.o, d[c] = r.d.normalized();
        t[c] = distance(o[c], d[c]);
        hits += std::isfinite(t[c]) ? 1 : 0;
      }
      if (hits != 0 && hits != 4) continue;  // the renderer shares only uniform quads
      const float t_c = hits == 4 ? 0.25f * (t[0] + t[1] + t[2] + t[3]) : inf;
      (hits == 4 ? surface_quads : sky_quads) += 1;
      MediaQuad q;
      rm.PrepareQuad(u0, v0, t_c, o[0], d[0], &q);
      for (int c = 0; c < 4; ++c) {
        const int u = u0 + (c & 1), v = v0 + (c >> 1);
        // the surface, points 1 % and 3 % behind the quad's mean distance and the surface
        // (where the slices' slopes in distance matter) and, as for a particle streak, a point
        // half-way to the surface.
        const bool sky = !std::isfinite(t[c]);
        for (float te : {t[c], sky ? 1.0f : 1.01f * t_c, sky ? 2.0f : 1.03f * t[c],
                         sky ? 3.0f : 0.5f * t[c]}) {
          const MediaSegment own = rm.IntegrateView(lights, o[c], d[c], te, u, v);
          const MediaSegment shared = rm.IntegrateView(lights, o[c], d[c], te, u, v, &q);
          const double dT = (shared.T - own.T).cwiseAbs().maxCoeff();
          const double dL = (shared.L_add - own.L_add).cwiseAbs().maxCoeff();
          max_dT = std::max(max_dT, dT);
          max_dL = std::max(max_dL, dL);
          max_L = std::max(max_L, static_cast<double>(own.L_add.maxCoeff()));
          sum_dT += dT;
          sum_dL += dL;
          ++pixels;
          differing += (dT > 0 || dL > 0) ? 1 : 0;
        }
      }
    }
  }
  ASSERT_GT(surface_quads, 1000);
  ASSERT_GT(sky_quads, 100);
  ASSERT_GT(max_L, 0.0);
  // the quad values are the lookups half a pixel away (the quad's centre), in the same slices:
  // they differ from the pixel's own by a fraction of the change between neighbouring columns
  // (12 and 24 pixels apart).
  EXPECT_GT(differing, 0);  // the shared path is taken
  EXPECT_LT(max_dT, 0.01);
  EXPECT_LT(max_dL, 0.03 * max_L);
  EXPECT_LT(sum_dT / pixels, 1e-3);
  EXPECT_LT(sum_dL / pixels, 3e-3 * max_L);
  RecordProperty("max_dT", std::to_string(max_dT));
  RecordProperty("max_dL_rel", std::to_string(max_dL / max_L));
  RecordProperty("mean_dT", std::to_string(sum_dT / pixels));
  RecordProperty("mean_dL_rel", std::to_string(sum_dL / pixels / max_L));
}

}  // namespace
}  // namespace penumbra::testing

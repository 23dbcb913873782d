// the transport's Embree tracer (render/cpu/embree_tracer.h) names its hits as the BVH scene's
// own traversal names them (BvhTracer): the same instance, primitive and part, t and the
// barycentrics within float rounding, on every shape kind, static and moving, and tendons.

#include "penumbra/render/cpu/embree_tracer.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "penumbra/render/bvh/bvh_traversal.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using testing::AddGeom;
using testing::Translation;

std::vector<cuda::TraceRay> Fan(const Eigen::Vector3f& o, const Eigen::Vector3f& ahead, int w,
                                int h, float half_fov) {
  const Eigen::Vector3f z = ahead.normalized();
  const Eigen::Vector3f x = z.cross(Eigen::Vector3f::UnitZ()).normalized();
  const Eigen::Vector3f y = z.cross(x);
  std::vector<cuda::TraceRay> rays;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      const float u = (2.0f * i / (w - 1) - 1) * half_fov, v = (2.0f * j / (h - 1) - 1) * half_fov;
      const Eigen::Vector3f d = z + u * x + v * y;
      cuda::TraceRay r;
      r.o = {o.x(), o.y(), o.z()};
      r.d = {d.x(), d.y(), d.z()};
      r.tmin = 0.01f;
      r.tmax = INFINITY;
      rays.push_back(r);
    }
  return rays;
}

// Embree's hits against the BVH traversal's on `rays`: the same miss or the same instance,
// primitive and part, t within 1e-4 relative, u and v within 1e-3; returns the hits compared.
int ExpectSameNames(const RayScene& embree, const cuda::BvhScene& bvh,
                    const std::vector<cuda::TraceRay>& rays, const std::string& what) {
  SCOPED_TRACE(what);
  const EmbreeTracer tracer{embree, bvh};
  const cuda::SceneView view = bvh.view();
  const cuda::BvhTracer reference{view};
  int hits = 0, differ = 0, blocked_short = 0, clear_through = 0;
  for (const cuda::TraceRay& r : rays) {
    cuda::TraceHit a, b;
    tracer.Closest(r, &a);
    reference.Closest(r, &b);
    if ((a.instance >= 0) != (b.instance >= 0)) {
      ++differ;
      continue;
    }
    if (a.instance < 0) continue;
    ++hits;
    const bool same = a.instance == b.instance && a.prim == b.prim && a.part == b.part &&
                      std::abs(a.t - b.t) <= 1e-4f * (1 + b.t) && std::abs(a.u - b.u) <= 1e-3f &&
                      std::abs(a.v - b.v) <= 1e-3f;
    differ += same ? 0 : 1;
    // the occlusion verdicts up to just short of the hit (clear) and beyond it (blocked)
    cuda::TraceRay shorter = r;
    shorter.tmax = 0.99f * b.t;
    cuda::TraceRay through = r;
    through.tmax = 1.01f * b.t;
    blocked_short += tracer.Occluded(shorter) ? 1 : 0;
    clear_through += tracer.Occluded(through) ? 0 : 1;
  }
  EXPECT_LE(blocked_short, static_cast<int>(rays.size()) / 1000);
  EXPECT_LE(clear_through, static_cast<int>(rays.size()) / 1000);
  // a grazing ray may miss on one side of an edge and hit on the other: at most 1 in 1000
  EXPECT_LE(differ, static_cast<int>(rays.size()) / 1000);
  EXPECT_GT(tracer.traced, static_cast<int64_t>(rays.size()));
  return hits;
}

TEST(EmbreeTracer, NamesEveryShapeStaticAndMovingAsTheBvh) {
  int body = 0;
  const SceneDescription scene = testing::EveryShapeScene(&body);
  WorldSnapshot snapshot = testing::IdentitySnapshot(scene);
  RayScene embree(scene);
  cuda::BvhScene bvh(scene);
  for (double yaw : {0.4, -1.1}) {
    testing::PoseEveryShapeMover(&snapshot, body, yaw);
    embree.Update(snapshot);
    bvh.Update(snapshot);
    const std::vector<cuda::TraceRay> rays = Fan({-1, 0, 0.2f}, {1, 0, -0.05f}, 160, 120, 0.8f);
    EXPECT_GT(ExpectSameNames(embree, bvh, rays, "yaw " + std::to_string(yaw)),
              static_cast<int>(rays.size()) / 3);
  }
}

TEST(EmbreeTracer, NamesTendonCapsulesAsTheBvh) {
  SceneDescription scene = testing::EmptyScene();
  AddGeom(&scene, GeomShape::kPlane, {0, 0, 1}, Translation(0, 0, -1));
  const int body = testing::AddBody(&scene, "mover");
  AddGeom(&scene, GeomShape::kSphere, {0.2, 0, 0}, Pose::Identity(), body);
  Tendon rope;
  rope.name = "rope";
  rope.width_m = 0.04;
  rope.material = testing::AddMaterial(&scene, {0, 1, 0});
  scene.tendons.push_back(rope);
  WorldSnapshot snap = testing::IdentitySnapshot(scene);
  snap.X_WB[body] = Translation(3, 0.5, 0.1);
  // two segments and a repeated point (a sphere)
  snap.tendon_paths = {{0, {{3, -0.3, -0.8}, {3, -0.3, 0.3}, {3, 0.2, 0.6}, {3, 0.2, 0.6}}}};
  RayScene embree(scene);
  cuda::BvhScene bvh(scene);
  embree.Update(snap);
  bvh.Update(snap);
  const std::vector<cuda::TraceRay> rays = Fan({0, 0, 0}, {1, 0, 0}, 200, 200, 0.3f);
  ExpectSameNames(embree, bvh, rays, "tendons");
  // the rope is seen: hits on records of geom -1
  const EmbreeTracer tracer{embree, bvh};
  const cuda::SceneView view = bvh.view();
  int rope_hits = 0;
  for (const cuda::TraceRay& r : rays) {
    cuda::TraceHit h;
    tracer.Closest(r, &h);
    rope_hits += h.instance >= 0 && view.records[view.prims[h.prim].record].geom == -1;
  }
  EXPECT_GT(rope_hits, 100);
}

}  // namespace
}  // namespace penumbra

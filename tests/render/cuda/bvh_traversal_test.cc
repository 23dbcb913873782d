// the CUDA backend's BVH and traversal (render/cuda/bvh_*.h, PB_HOST_DEVICE code that the GPU
// kernels run too), run on the CPU against Embree's RayScene: hand-built scenes with every
// shape on static and moving bodies, and the bundled default, house and warehouse worlds
// (camera-like ray fans). the hit distance within 1e-4 relative and the geom equal on >= 99.9 %
// of the rays (triangle edges may go either way between two float triangle tests).

#include "penumbra/render/bvh/bvh_traversal.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/frame/bvh_builder.h"
#include "penumbra/render/frame/bvh_ray_query.h"
#include "penumbra/render/geometry/static_geometry.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

struct Agreement {
  int rays = 0, both_hit = 0, hit_mismatch = 0, geom_mismatch = 0, t_mismatch = 0, ties = 0;
  double worst_rel = 0;
};

// traces `rays` through both queries and counts where they disagree.
Agreement CompareQueries(const RayScene& embree, const cuda::BvhRayQuery& bvh,
                         const std::vector<Ray>& rays) {
  std::vector<SurfaceHit> he(rays.size()), hb(rays.size());
  std::unique_ptr<bool[]> de(new bool[rays.size()]), db(new bool[rays.size()]);
  embree.Intersect(rays, he, std::span<bool>(de.get(), rays.size()));
  bvh.Intersect(rays, hb, std::span<bool>(db.get(), rays.size()));
  Agreement a;
  a.rays = static_cast<int>(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) {
    if (de[i] != db[i]) {
      ++a.hit_mismatch;
      continue;
    }
    if (!de[i]) continue;
    ++a.both_hit;
    // coplanar overlapping geoms (the generated house's walls and trims) hit at the same t
    // are a tie that each BVH breaks its own way: counted apart
    if (he[i].geom != hb[i].geom)
      ++(std::abs(he[i].t - hb[i].t) <= 1e-5f * (1 + he[i].t) ? a.ties : a.geom_mismatch);
    const double rel = std::abs(he[i].t - hb[i].t) / std::max(1e-3f, std::abs(he[i].t));
    if (he[i].geom == hb[i].geom) a.worst_rel = std::max(a.worst_rel, rel);
    if (rel > 1e-4) ++a.t_mismatch;
  }
  return a;
}

// a fan of w x h pinhole rays from o looking along the world direction `ahead`.
std::vector<Ray> RayFan(const Eigen::Vector3f& o, const Eigen::Vector3f& ahead, int w, int h,
                        float half_fov = 0.8f) {
  const Eigen::Vector3f z = ahead.normalized();
  const Eigen::Vector3f x = z.cross(Eigen::Vector3f::UnitZ()).normalized();
  const Eigen::Vector3f y = z.cross(x);
  std::vector<Ray> rays;
  for (int j = 0; j < h; ++j)
    for (int i = 0; i < w; ++i) {
      Ray r;
      r.o = o;
      const float u = (2.0f * i / (w - 1) - 1) * half_fov, v = (2.0f * j / (h - 1) - 1) * half_fov;
      r.d = z + u * x + v * y;
      r.tmin = 0.01f;
      rays.push_back(r);
    }
  return rays;
}

void ExpectAgree(const Agreement& a, const std::string& what) {
  SCOPED_TRACE(what);
  EXPECT_GT(a.both_hit, a.rays / 10) << "too few hits to compare";
  EXPECT_LE(a.hit_mismatch, a.rays / 1000);
  EXPECT_LE(a.geom_mismatch, a.rays / 1000);
  EXPECT_LE(a.t_mismatch, a.rays / 1000);
  EXPECT_LT(a.worst_rel, 1e-3);
  ::testing::Test::RecordProperty("ties_" + what, a.ties);
}

TEST(CudaBvhTraversal, EveryShapeStaticAndMovingMatchesEmbree) {
  int body = 0;
  const SceneDescription scene = testing::EveryShapeScene(&body);
  WorldSnapshot snapshot = testing::IdentitySnapshot(scene);
  RayScene embree(scene);
  cuda::BvhRayQuery bvh(scene);
  // posed twice: the instance transforms follow each snapshot, nothing is rebuilt
  for (double yaw : {0.4, -1.1}) {
    testing::PoseEveryShapeMover(&snapshot, body, yaw);
    embree.Update(snapshot);
    const int64_t version = bvh.bvh().geometry_version();
    bvh.Update(snapshot);
    EXPECT_EQ(bvh.bvh().geometry_version(), version);
    const Agreement a =
        CompareQueries(embree, bvh, RayFan({-1, 0, 0.2f}, {1, 0, -0.05f}, 160, 120));
    ExpectAgree(a, "yaw " + std::to_string(yaw));
    // every kind of geom is seen
    EXPECT_GT(a.both_hit, 160 * 120 / 3);
  }
  // occlusion: a segment through the box is blocked, one beside everything is not
  Ray through;
  through.o = {2, 0.8f, 0.2f};
  through.d = {1, 0, 0};
  through.tmax = 5;
  EXPECT_TRUE(bvh.Occluded(through));
  Ray clear = through;
  clear.o = {2, 0.8f, 5};
  EXPECT_FALSE(bvh.Occluded(clear));
}

// visible spatial tendons: capsules around the snapshot's wrap-point paths, as RayScene draws
// them (geom -1, the tendon's material), beside a moving body; the tendon group's BLAS is rebuilt
// when, and only when, the paths move.
TEST(CudaBvhTraversal, TendonsMatchEmbreeAndFollowTheirPaths) {
  SceneDescription scene = testing::EmptyScene();
  testing::AddGeom(&scene, GeomShape::kPlane, {0, 0, 1}, testing::Translation(0, 0, -1));
  const int body = testing::AddBody(&scene, "mover");
  testing::AddGeom(&scene, GeomShape::kSphere, {0.2, 0, 0}, Pose::Identity(), body);
  Tendon rope;
  rope.name = "rope";
  rope.width_m = 0.04;
  rope.material = testing::AddMaterial(&scene, {0, 1, 0});
  scene.tendons.push_back(rope);
  rope.name = "cable";
  rope.width_m = 0.02;
  scene.tendons.push_back(rope);
  WorldSnapshot snap = testing::IdentitySnapshot(scene);
  snap.X_WB[body] = testing::Translation(3, 0.5, 0.1);
  // rope: two segments and a repeated point (a sphere); cable: one segment
  snap.tendon_paths = {{0, {{3, -0.3, -0.8}, {3, -0.3, 0.3}, {3, 0.2, 0.6}, {3, 0.2, 0.6}}},
                       {1, {{2.5, -0.8, 0.2}, {3.5, -0.6, 0.2}}}};
  RayScene embree(scene);
  cuda::BvhRayQuery bvh(scene);
  const auto trace = [&](const WorldSnapshot& s, const std::string& what) {
    embree.Update(s);
    bvh.Update(s);
    const std::vector<Ray> rays = RayFan({0, 0, 0}, {1, 0, 0}, 200, 200, 0.3f);
    const Agreement a = CompareQueries(embree, bvh, rays);
    ExpectAgree(a, what);
    // the tendons are seen: hits with geom -1 and the tendon's material
    std::vector<SurfaceHit> hits(rays.size());
    std::unique_ptr<bool[]> did(new bool[rays.size()]);
    bvh.Intersect(rays, hits, std::span<bool>(did.get(), rays.size()));
    int tendon_hits = 0;
    for (size_t i = 0; i < rays.size(); ++i)
      tendon_hits += did[i] && hits[i].geom == -1 && hits[i].material == rope.material;
    EXPECT_GT(tendon_hits, 100) << what;
  };
  trace(snap, "first paths");
  const int64_t version = bvh.bvh().geometry_version();
  // a new body pose alone rebuilds nothing
  snap.X_WB[body] = testing::Translation(3, 0.6, 0.1);
  bvh.Update(snap);
  EXPECT_EQ(bvh.bvh().geometry_version(), version);
  // moved paths rebuild the tendons' BLAS: the rope's old place is clear, its new one blocked
  Ray old_place;
  old_place.o = {2, -0.3f, 0};
  old_place.d = {1, 0, 0};
  old_place.tmax = 2;
  EXPECT_TRUE(bvh.Occluded(old_place));
  snap.tendon_paths[0].p_W = {{3, 0.9, -0.8}, {3, 0.9, 0.3}};
  trace(snap, "moved paths");
  EXPECT_GT(bvh.bvh().geometry_version(), version);
  EXPECT_FALSE(bvh.Occluded(old_place));
  Ray new_place = old_place;
  new_place.o = {2, 0.9f, 0};
  EXPECT_TRUE(bvh.Occluded(new_place));
  // a path of a missing tendon is refused by name
  snap.tendon_paths.push_back({7, {{0, 0, 0}, {1, 0, 0}}});
  EXPECT_THROW(bvh.Update(snap), Error);
}

TEST(CudaBvhTraversal, BuilderKeepsEveryPrimitiveOnceAndBoxesHoldChildren) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-10, 10);
  std::vector<cuda::PrimBox> boxes(5000);
  for (cuda::PrimBox& b : boxes)
    for (int a = 0; a < 3; ++a) {
      b.lo[a] = u(rng);
      b.hi[a] = b.lo[a] + 0.1f;
    }
  std::vector<cuda::BvhNode> nodes;
  std::vector<int32_t> index;
  cuda::BuildBvh(boxes, 100, &nodes, &index);
  ASSERT_EQ(index.size(), boxes.size());
  std::vector<int> seen(boxes.size(), 0);
  for (int32_t i : index) ++seen[i - 100];
  for (int s : seen) EXPECT_EQ(s, 1);
  for (const cuda::BvhNode& n : nodes) {
    if (n.count > 0) {
      EXPECT_LE(n.count, 8);
      for (int k = 0; k < n.count; ++k)
        for (int a = 0; a < 3; ++a) {
          EXPECT_LE(n.lo[a], boxes[index[n.first + k] - 100].lo[a]);
          EXPECT_GE(n.hi[a], boxes[index[n.first + k] - 100].hi[a]);
        }
    } else {
      for (int c : {n.first, n.first + 1})
        for (int a = 0; a < 3; ++a) {
          EXPECT_LE(n.lo[a], nodes[c].lo[a]);
          EXPECT_GE(n.hi[a], nodes[c].hi[a]);
        }
    }
  }
}

// the binary tree's traversal as it was before WidenBvh (one node a visit, its children's
// boxes loaded from the children; leaves index the primitives through BuildBvh's prim_index):
// the reference the widened traversal must match bit for bit. hit->prim: into prims.
bool ReferenceTraverse(const std::vector<cuda::BvhNode>& nodes,
                       const std::vector<int32_t>& prim_index,
                       const std::vector<cuda::PrimRef>& prims,
                       const std::vector<cuda::Triangle>& triangles, cuda::F3 o, cuda::F3 d,
                       float tmin, bool any_hit, cuda::TraceHit* hit) {
  const cuda::F3 inv{1.0f / d.x, 1.0f / d.y, 1.0f / d.z};
  std::vector<int> stack;
  std::vector<float> stack_t;
  bool found = false;
  int node = 0;
  if (cuda::SlabEntry(nodes[0].lo, nodes[0].hi, o, inv, tmin, hit->t) == INFINITY) return false;
  while (true) {
    const cuda::BvhNode& n = nodes[node];
    if (n.count > 0) {
      for (int k = 0; k < n.count; ++k) {
        const int pi = prim_index[n.first + k];
        float t, u = 0, v = 0;
        if (!cuda::IntersectTriangle(triangles[prims[pi].index], o, d, tmin, hit->t, &t, &u, &v))
          continue;
        hit->t = t, hit->u = u, hit->v = v, hit->part = 0, hit->prim = pi, hit->instance = 0;
        found = true;
        if (any_hit) return true;
      }
    } else {
      const int a = n.first, b = n.first + 1;
      const float ta = cuda::SlabEntry(nodes[a].lo, nodes[a].hi, o, inv, tmin, hit->t);
      const float tb = cuda::SlabEntry(nodes[b].lo, nodes[b].hi, o, inv, tmin, hit->t);
      const bool ha = ta != INFINITY, hb = tb != INFINITY;
      if (ha && hb) {
        stack.push_back(ta <= tb ? b : a);
        stack_t.push_back(ta <= tb ? tb : ta);
        node = ta <= tb ? a : b;
        continue;
      }
      if (ha || hb) {
        node = ha ? a : b;
        continue;
      }
    }
    bool next = false;
    while (!stack.empty()) {
      const int m = stack.back();
      const float t = stack_t.back();
      stack.pop_back(), stack_t.pop_back();
      if (t <= hit->t) {
        node = m;
        next = true;
        break;
      }
    }
    if (!next) break;
  }
  return found;
}

// random triangle soups (a leaf root and a deep tree): TraceClosest and TraceOccluded over the
// widened BVH with the primitives in leaf order (as BvhScene keeps them) give the same bits as
// the binary tree's traversal on random rays.
// BuildBvh over a pool makes the one-thread build's nodes and order bit for bit: 60,000 boxes
// in clusters (thin streak-like boxes, as the pathtraced tier's rain), some sharing one
// centroid (the middle split), with pools of 2, 3 and 8 threads; the nodes are appended after
// existing ones and the order indexes from prim_base as without a pool.
TEST(CudaBvhTraversal, PoolBuildIsTheOneThreadBuildBitForBit) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<cuda::PrimBox> boxes;
  for (int c = 0; c < 60; ++c) {
    const float cx = 20 * u(rng), cy = 20 * u(rng), cz = 3 * u(rng);
    for (int k = 0; k < 1000; ++k) {
      cuda::PrimBox b;
      const bool same = k % 50 == 0;  // every 50th box of a cluster at the cluster's centre
      const float x = same ? cx : cx + u(rng), y = same ? cy : cy + u(rng);
      const float z = same ? cz : cz + 2 * u(rng);
      const float r = 0.002f + 0.001f * (u(rng) + 1), len = 0.05f * (u(rng) + 1.5f);
      b.lo[0] = x - r, b.lo[1] = y - r, b.lo[2] = z - len;
      b.hi[0] = x + r, b.hi[1] = y + r, b.hi[2] = z + r;
      boxes.push_back(b);
    }
  }
  ASSERT_GE(static_cast<int>(boxes.size()), cuda::kParallelBuildMinPrims);
  const std::vector<cuda::BvhNode> prefix(3);
  std::vector<cuda::BvhNode> want_nodes = prefix;
  std::vector<int32_t> want_order = {9, 9};
  cuda::BuildBvh(boxes, 100, &want_nodes, &want_order);
  ASSERT_GT(want_nodes.size(), 10000u);
  for (int threads : {2, 3, 8}) {
    ThreadPool pool(threads);
    std::vector<cuda::BvhNode> nodes = prefix;
    std::vector<int32_t> order = {9, 9};
    cuda::BuildBvh(boxes, 100, &nodes, &order, &pool);
    ASSERT_EQ(nodes.size(), want_nodes.size()) << threads << " threads";
    EXPECT_EQ(std::memcmp(nodes.data(), want_nodes.data(), nodes.size() * sizeof(cuda::BvhNode)), 0)
        << threads << " threads";
    EXPECT_EQ(order, want_order) << threads << " threads";
  }
}

// byte-wise equality of two arrays of records without padding
template <typename T>
bool SameBytes(const std::vector<T>& a, const std::vector<T>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(T)) == 0;
}

// the same triangles, bit for bit (a Triangle's last 12 bytes are padding)
bool SameTriangles(const std::vector<cuda::Triangle>& a, const std::vector<cuda::Triangle>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], 3 * sizeof(cuda::F3)) != 0) return false;
  return true;
}

// the same analytic shapes, bit for bit (field by field: AnalyticPrim has padding)
bool SameAnalytics(const std::vector<cuda::AnalyticPrim>& a,
                   const std::vector<cuda::AnalyticPrim>& b) {
  if (a.size() != b.size()) return false;
  for (size_t i = 0; i < a.size(); ++i)
    if (a[i].kind != b[i].kind || std::memcmp(a[i].size, b[i].size, sizeof(a[i].size)) != 0 ||
        std::memcmp(a[i].R_GI, b[i].R_GI, sizeof(a[i].R_GI)) != 0 ||
        std::memcmp(a[i].p_GI, b[i].p_GI, sizeof(a[i].p_GI)) != 0)
      return false;
  return true;
}

// BvhScene over a pool (as CudaRenderer and the statics' maps build it) has the one-thread
// scene's arrays byte for byte, built and then posed by the world's snapshot (the static BLAS
// rebuilt): the outdoor world, whose static group is large enough for BuildBvh's parallel path.
TEST(CudaBvhTraversal, SceneBuiltOverAPoolIsTheOneThreadScene) {
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  Session session(LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/outdoor.yaml"), so);
  const WorldSnapshot snap = session.sim().Snapshot();
  cuda::BvhScene want(session.scene());
  want.Update(snap);
  ASSERT_GE(want.num_triangles(), cuda::kParallelBuildMinPrims);
  ThreadPool pool(4);
  cuda::BvhScene got(session.scene(), &pool);
  got.Update(snap);
  EXPECT_TRUE(SameBytes(got.nodes(), want.nodes()));
  EXPECT_TRUE(SameBytes(got.prims(), want.prims()));
  EXPECT_TRUE(SameTriangles(got.triangles(), want.triangles()));
  EXPECT_TRUE(SameAnalytics(got.analytics(), want.analytics()));
  EXPECT_TRUE(SameBytes(got.blases(), want.blases()));
  EXPECT_TRUE(SameBytes(got.instances(), want.instances()));
}

TEST(CudaBvhTraversal, WidenedNodesTraceTheSameBitsAsTheBinaryTree) {
  for (const int num_triangles : {3, 4000}) {
    std::mt19937 rng(11);
    std::uniform_real_distribution<float> u(-5, 5), e(-0.6f, 0.6f);
    std::vector<cuda::Triangle> triangles(num_triangles);
    std::vector<cuda::PrimRef> prims(num_triangles);
    std::vector<cuda::PrimBox> boxes(num_triangles);
    for (int i = 0; i < num_triangles; ++i) {
      cuda::Triangle& t = triangles[i];
      t.v0 = {u(rng), u(rng), u(rng)};
      t.e1 = {e(rng), e(rng), e(rng)};
      t.e2 = {e(rng), e(rng), e(rng)};
      prims[i].kind = 0, prims[i].index = i;
      const float x[3] = {t.v0.x, t.v0.x + t.e1.x, t.v0.x + t.e2.x};
      const float y[3] = {t.v0.y, t.v0.y + t.e1.y, t.v0.y + t.e2.y};
      const float z[3] = {t.v0.z, t.v0.z + t.e1.z, t.v0.z + t.e2.z};
      boxes[i] = {{std::min({x[0], x[1], x[2]}), std::min({y[0], y[1], y[2]}),
                   std::min({z[0], z[1], z[2]})},
                  {std::max({x[0], x[1], x[2]}), std::max({y[0], y[1], y[2]}),
                   std::max({z[0], z[1], z[2]})}};
    }
    std::vector<cuda::BvhNode> tree;
    std::vector<int32_t> prim_index;
    cuda::BuildBvh(boxes, 0, &tree, &prim_index);
    std::vector<cuda::BvhWideNode> wide;
    cuda::Blas blas;
    cuda::WidenBvh(tree, &wide, &blas);
    EXPECT_EQ(blas.root_count, num_triangles == 3 ? 3 : -1);
    cuda::Instance in;
    for (int k = 0; k < 12; ++k) in.X_WI[k] = in.X_IW[k] = (k % 5 == 0) ? 1.0f : 0.0f;
    for (int a = 0; a < 3; ++a) in.lo[a] = -100, in.hi[a] = 100;
    std::vector<cuda::PrimRef> leaf_prims;
    for (int32_t i : prim_index) leaf_prims.push_back(prims[i]);
    cuda::SceneView s;
    s.nodes = wide.data();
    s.prims = leaf_prims.data();
    s.triangles = triangles.data();
    s.blases = &blas;
    s.instances = &in;
    s.num_instances = 1;
    int hits = 0, occluded = 0;
    for (int r = 0; r < 20000; ++r) {
      cuda::TraceRay ray;
      ray.o = {1.5f * u(rng), 1.5f * u(rng), 1.5f * u(rng)};
      // towards a random triangle's corner, give or take
      const cuda::F3 c = triangles[rng() % num_triangles].v0;
      ray.d = {c.x + e(rng) - ray.o.x, c.y + e(rng) - ray.o.y, c.z + e(rng) - ray.o.z};
      if (r % 7 == 0) ray.d.x = 0;  // axis-parallel slabs
      ray.tmin = 0;
      ray.tmax = r % 2 ? INFINITY : 4.0f;
      cuda::TraceHit got, want;
      cuda::TraceClosest(s, ray, &got);
      want.t = ray.tmax;
      ReferenceTraverse(tree, prim_index, prims, triangles, ray.o, ray.d, ray.tmin, false, &want);
      ASSERT_EQ(got.instance, want.instance) << r;
      if (want.instance < 0) continue;
      ++hits;
      EXPECT_EQ(leaf_prims[got.prim].index, prims[want.prim].index) << r;
      EXPECT_EQ(std::memcmp(&got.t, &want.t, sizeof(float)), 0) << r;
      EXPECT_EQ(std::memcmp(&got.u, &want.u, sizeof(float)), 0) << r;
      EXPECT_EQ(std::memcmp(&got.v, &want.v, sizeof(float)), 0) << r;
      cuda::TraceHit any;
      any.t = ray.tmax;
      const bool blocked =
          ReferenceTraverse(tree, prim_index, prims, triangles, ray.o, ray.d, ray.tmin, true, &any);
      EXPECT_EQ(cuda::TraceOccluded(s, ray), blocked) << r;
      occluded += blocked ? 1 : 0;
    }
    EXPECT_GT(hits, 100);
    EXPECT_GT(occluded, 100);
  }
}

// the bundled worlds, posed by their own simulations at time 0, seen from their cameras'
// poses in fans of rays in four directions.
class CudaBvhWorlds : public ::testing::TestWithParam<std::string> {
 protected:
  // the bundled world GetParam() without renderer or controllers
  std::unique_ptr<Session> LoadWorld() const {
    SessionOptions so;
    so.build_renderer = false;
    so.add_controllers = false;
    return std::make_unique<Session>(
        LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/" + GetParam()), so);
  }

  // the world, Embree's RayScene and the BVH, both posed at the world's time-0 snapshot
  struct Posed {
    std::unique_ptr<Session> session;
    std::unique_ptr<RayScene> embree;
    std::unique_ptr<cuda::BvhRayQuery> bvh;
  };
  Posed LoadPosed() const {
    Posed p;
    p.session = LoadWorld();
    const WorldSnapshot snap = p.session->sim().Snapshot();
    p.embree = std::make_unique<RayScene>(p.session->scene());
    p.bvh = std::make_unique<cuda::BvhRayQuery>(p.session->scene());
    p.embree->Update(snap);
    p.bvh->Update(snap);
    return p;
  }
};

TEST_P(CudaBvhWorlds, MatchEmbreeOnBundledWorld) {
  const Posed posed = LoadPosed();
  const RayScene& embree = *posed.embree;
  const cuda::BvhRayQuery& bvh = *posed.bvh;
  ASSERT_GT(bvh.bvh().num_triangles(), 0);
  Eigen::Vector3f eye(0, 0, 1.2f);
  for (const Eigen::Vector3f& ahead :
       {Eigen::Vector3f(1, 0, -0.2f), Eigen::Vector3f(0, 1, -0.2f),
        Eigen::Vector3f(-1, 0.3f, -0.1f), Eigen::Vector3f(0.2f, -1, -0.4f)}) {
    const Agreement a = CompareQueries(embree, bvh, RayFan(eye, ahead, 96, 72));
    ExpectAgree(a, GetParam());
  }
}

// LocalBvhStack that counts the entries put at each depth (all traversals of the test).
struct DepthCountingStack : cuda::LocalBvhStack {
  static inline std::array<int64_t, cuda::kMaxBvhDepth> puts{};
  void Put(int i, const cuda::BvhPending& e) {
    ++puts[i];
    cuda::LocalBvhStack::Put(i, e);
  }
};

// a stack of kKeep entries that drops deeper ones (their subtrees skipped): what a short stack
// with nowhere to put deeper entries would do, to show the comparison below sees a wrong
// traversal.
template <int kKeep>
struct DroppingStack : cuda::LocalBvhStack {
  void Put(int i, cuda::BvhPending e) {
    if (i >= kKeep) e.t = INFINITY;
    cuda::LocalBvhStack::Put(i, e);
  }
};

bool SameHit(const cuda::TraceHit& a, const cuda::TraceHit& b) {
  return std::memcmp(&a.t, &b.t, sizeof(float)) == 0 && a.u == b.u && a.v == b.v &&
         a.prim == b.prim && a.instance == b.instance && a.part == b.part;
}

// how deep the traversal's stack gets in the bundled worlds (through a stack policy that counts
// its entries, bvh_traversal.h): camera fans from four eyes and shadow rays between their hits.
// the deepest entry must stay well inside the stack (kMaxBvhDepth; the traversal drops a child
// it cannot push), and the counts (printed) size any shorter stack: a stack of 2 entries that
// drops deeper ones changes hits, so the comparison with it can fail.
TEST_P(CudaBvhWorlds, TraversalStackStaysShallow) {
  const std::unique_ptr<Session> session = LoadWorld();
  const WorldSnapshot snap = session->sim().Snapshot();
  cuda::BvhRayQuery bvh(session->scene());
  bvh.Update(snap);
  const cuda::SceneView s = bvh.bvh().view();
  DepthCountingStack::puts.fill(0);
  int64_t rays = 0, hits = 0, occluded = 0, differ = 0, dropped_differ = 0;
  std::vector<cuda::F3> points;  // the hits, pulled back a little towards the eye
  for (const Eigen::Vector3f& eye :
       {Eigen::Vector3f(0, 0, 1.2f), Eigen::Vector3f(2, 1, 1.2f), Eigen::Vector3f(-2, -1.5f, 0.6f),
        Eigen::Vector3f(4, -3, 1.5f)})
    for (const Eigen::Vector3f& ahead :
         {Eigen::Vector3f(1, 0, -0.2f), Eigen::Vector3f(0, 1, -0.2f),
          Eigen::Vector3f(-1, 0.3f, -0.1f), Eigen::Vector3f(0.2f, -1, -0.4f)}) {
      for (const Ray& ray : RayFan(eye, ahead, 64, 48)) {
        const cuda::TraceRay r = cuda::ToTraceRay(ray);
        cuda::TraceHit local, counted, dropped;
        cuda::TraceClosest(s, r, &local);
        cuda::TraceClosest<DepthCountingStack>(s, r, &counted);
        cuda::TraceClosest<DroppingStack<2>>(s, r, &dropped);
        ++rays;
        differ += !SameHit(local, counted);
        dropped_differ += !SameHit(local, dropped);
        if (local.instance < 0) continue;
        ++hits;
        const float t = local.t * 0.99f;
        points.push_back({r.o.x + t * r.d.x, r.o.y + t * r.d.y, r.o.z + t * r.d.z});
      }
    }
  // shadow rays between hits far apart in the fans' order (some blocked, some not)
  const size_t n = points.size();
  for (size_t k = 0; k < n; ++k) {
    const cuda::F3 a = points[k], b = points[(k * 7919 + n / 3) % n];
    cuda::TraceRay sr;
    sr.o = a;
    sr.d = {b.x - a.x, b.y - a.y, b.z - a.z};
    sr.tmin = 1e-4f;
    sr.tmax = 1.0f;
    const bool blocked = cuda::TraceOccluded(s, sr);
    occluded += blocked;
    differ += cuda::TraceOccluded<DepthCountingStack>(s, sr) != blocked;
  }
  EXPECT_EQ(differ, 0);
  EXPECT_GT(dropped_differ, 0);
  EXPECT_GT(hits, rays / 2);
  EXPECT_GT(occluded, 0);
  EXPECT_LT(occluded, hits);
  int64_t puts = 0, beyond_8 = 0, beyond_16 = 0;
  int deepest = -1;
  for (int i = 0; i < cuda::kMaxBvhDepth; ++i) {
    const int64_t n = DepthCountingStack::puts[i];
    puts += n;
    if (i >= 8) beyond_8 += n;
    if (i >= 16) beyond_16 += n;
    if (n > 0) deepest = i;
  }
  std::printf(
      "%s: %lld rays (%lld hits, %lld of as many shadow rays blocked), %lld pushes, "
      "deepest entry %d, pushes at entry 8 or deeper %lld (%.4f %%), at 16 or deeper %lld; "
      "a stack of 2 changed %lld hits\n",
      GetParam().c_str(), static_cast<long long>(rays), static_cast<long long>(hits),
      static_cast<long long>(occluded), static_cast<long long>(puts), deepest,
      static_cast<long long>(beyond_8), 100.0 * beyond_8 / std::max<int64_t>(puts, 1),
      static_cast<long long>(beyond_16), static_cast<long long>(dropped_differ));
  // the bundled worlds reach entries 5 (default), 8 (house) and 9 (warehouse)
  EXPECT_LT(deepest, 16);
}

// shadow rays between the hits of camera fans from three eyes in four directions (w x h rays
// each), far apart in the fans' order.
std::vector<Ray> ShadowRaysBetweenHits(const cuda::SceneView& s, int w, int h) {
  std::vector<cuda::F3> points;  // the fans' hits, pulled back a little towards the eye
  for (const Eigen::Vector3f& eye :
       {Eigen::Vector3f(0, 0, 1.2f), Eigen::Vector3f(2, 1, 1.2f), Eigen::Vector3f(-2, -1.5f, 0.6f)})
    for (const Eigen::Vector3f& ahead :
         {Eigen::Vector3f(1, 0, -0.2f), Eigen::Vector3f(0, 1, -0.2f),
          Eigen::Vector3f(-1, 0.3f, -0.1f), Eigen::Vector3f(0.2f, -1, -0.4f)})
      for (const Ray& ray : RayFan(eye, ahead, w, h)) {
        cuda::TraceHit hit;
        const cuda::TraceRay r = cuda::ToTraceRay(ray);
        cuda::TraceClosest(s, r, &hit);
        if (hit.instance < 0) continue;
        const float t = hit.t * 0.99f;
        points.push_back({r.o.x + t * r.d.x, r.o.y + t * r.d.y, r.o.z + t * r.d.z});
      }
  std::vector<Ray> rays;
  const size_t n = points.size();
  for (size_t k = 0; k < n; ++k) {
    const cuda::F3 a = points[k], b = points[(k * 7919 + n / 3) % n];
    Ray ray;
    ray.o = {a.x, a.y, a.z};
    ray.d = {b.x - a.x, b.y - a.y, b.z - a.z};
    ray.tmin = 1e-4f;
    ray.tmax = 1.0f;
    rays.push_back(ray);
  }
  return rays;
}

// every moving body of `scene` in *snap turned 0.5 rad about z and put in front of the first
// eye, along the fans' directions 0.8 to 2 m away (where the fans and the shadow rays meet it);
// piles: instead four piles of them, each body of a pile at one pose, 1.2 m along each direction
// (equal shapes there hit rays at equal t). returns how many bodies moved.
int MoveBodiesBeforeTheFirstEye(const SceneDescription& scene, WorldSnapshot* snap, bool piles) {
  int moved = 0;
  const Eigen::Vector3d aheads[4] = {{1, 0, -0.2}, {0, 1, -0.2}, {-1, 0.3, -0.1}, {0.2, -1, -0.4}};
  for (const RayGeomGroup& g : GroupRayGeoms(scene, "test")) {
    if (g.body < 0) continue;
    Pose& X = snap->X_WB[g.body];
    if (piles) {
      X = Pose(Eigen::AngleAxisd(0.5 * (moved % 4), Eigen::Vector3d::UnitZ()));
      X.translation() = Eigen::Vector3d(0, 0, 1.2) + 1.2 * aheads[moved % 4].normalized();
    } else {
      X = Pose(X * Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()));
      X.translation() = Eigen::Vector3d(0, 0, 1.2) +
                        (0.8 + 0.3 * ((moved / 4) % 5)) * aheads[moved % 4].normalized();
    }
    ++moved;
  }
  return moved;
}

// a stack of kKeep entries whose deeper entries become empty leaves (their subtrees skipped in
// either order): shows the verdicts' comparison below sees a wrong occlusion traversal.
template <int kKeep>
struct EmptyingStack : cuda::LocalBvhStack {
  void Put(int i, cuda::BvhPending e) {
    if (i >= kKeep) e.count = 0;
    cuda::LocalBvhStack::Put(i, e);
  }
};

// occlusion in any order (TraceOccluded's default, bvh_traversal.h: the children in their
// stored order, no entry test on a pop) gives the nearer-child-first traversal's verdict on
// every shadow ray between the camera fans' hits, and agrees with Embree's rtcOccluded1 as the
// ordered one does; a stack of 1 entry that empties deeper ones changes verdicts, so the
// comparison can fail.
TEST_P(CudaBvhWorlds, OcclusionInAnyOrderGivesTheOrderedVerdicts) {
  const Posed posed = LoadPosed();
  const RayScene& embree = *posed.embree;
  const cuda::SceneView s = posed.bvh->bvh().view();
  const std::vector<Ray> rays = ShadowRaysBetweenHits(s, 48, 36);
  const size_t n = rays.size();
  ASSERT_GT(n, 1000u);
  int64_t occluded = 0, differ = 0, embree_differ = 0, embree_differ_ordered = 0, emptied = 0;
  for (const Ray& ray : rays) {
    const cuda::TraceRay sr = cuda::ToTraceRay(ray);
    const bool any = cuda::TraceOccluded<cuda::LocalBvhStack, true>(s, sr);
    const bool ordered = cuda::TraceOccluded<cuda::LocalBvhStack, false>(s, sr);
    const bool reference = embree.Occluded(ray);
    occluded += any;
    differ += any != ordered;
    embree_differ += any != reference;
    embree_differ_ordered += ordered != reference;
    emptied += cuda::TraceOccluded<EmptyingStack<1>, true>(s, sr) != any;
  }
  std::printf(
      "%s: %zu shadow rays, %lld blocked, %lld differ from Embree (ordered: %lld), "
      "a stack of 1 changed %lld\n",
      GetParam().c_str(), n, static_cast<long long>(occluded),
      static_cast<long long>(embree_differ), static_cast<long long>(embree_differ_ordered),
      static_cast<long long>(emptied));
  EXPECT_EQ(differ, 0);
  EXPECT_EQ(embree_differ, embree_differ_ordered);
  EXPECT_LE(embree_differ, static_cast<int64_t>(n / 1000));
  EXPECT_GT(occluded, 0);
  EXPECT_LT(occluded, static_cast<int64_t>(n));
  EXPECT_GT(emptied, 0);
}

// occlusion rays through the top level over the instances (SceneView::tlas, TraceOccluded's
// default) give the flat instance list's verdict on every shadow ray between the camera fans'
// hits, and agree with Embree's rtcOccluded1 as the list does; then again with every moving
// body moved and turned (BvhScene::Update rebuilds the top level). a top level left from the
// first pose (stale boxes) misses occluders that moved out of them, so the comparison can fail.
TEST_P(CudaBvhWorlds, OcclusionThroughTheTopLevelGivesTheFlatListsVerdicts) {
  Posed posed = LoadPosed();
  const cuda::BvhScene& bvh = posed.bvh->bvh();
  WorldSnapshot snap = posed.session->sim().Snapshot();
  // the top level of the first pose (host arrays), for the stale control
  const std::vector<cuda::BvhWideNode> old_nodes = bvh.tlas_nodes();
  const std::vector<int32_t> old_instances = bvh.tlas_instances();
  const cuda::Blas old_tlas = bvh.tlas();
  for (int pose = 0; pose < 2; ++pose) {
    const cuda::SceneView s = bvh.view();
    ASSERT_NE(s.tlas_instances, nullptr);
    cuda::SceneView flat = s;
    flat.tlas_instances = nullptr;  // no top level: the flat loop
    cuda::SceneView stale = s;
    stale.tlas_nodes = old_nodes.empty() ? nullptr : old_nodes.data();
    stale.tlas_instances = old_instances.data();
    stale.tlas = old_tlas;
    const std::vector<Ray> rays = ShadowRaysBetweenHits(s, 64, 48);
    ASSERT_GT(rays.size(), 20000u);
    int64_t occluded = 0, differ = 0, ordered_differ = 0, embree_differ = 0, flat_embree_differ = 0,
            stale_differ = 0;
    for (const Ray& ray : rays) {
      const cuda::TraceRay sr = cuda::ToTraceRay(ray);
      const bool tlas = cuda::TraceOccluded(s, sr);
      const bool listed = cuda::TraceOccluded(flat, sr);
      const bool reference = posed.embree->Occluded(ray);
      occluded += tlas;
      differ += tlas != listed;
      ordered_differ += cuda::TraceOccluded<cuda::LocalBvhStack, false>(s, sr) != listed;
      embree_differ += tlas != reference;
      flat_embree_differ += listed != reference;
      stale_differ += cuda::TraceOccluded(stale, sr) != listed;
    }
    std::printf(
        "%s, pose %d: %d instances, top level of %d inner nodes (deepest %d); %zu shadow rays, "
        "%lld blocked, %lld differ from Embree (flat list: %lld), the first pose's top level "
        "changed %lld\n",
        GetParam().c_str(), pose, s.num_instances, s.tlas.num_nodes, bvh.tlas_depth(), rays.size(),
        static_cast<long long>(occluded), static_cast<long long>(embree_differ),
        static_cast<long long>(flat_embree_differ), static_cast<long long>(stale_differ));
    EXPECT_EQ(differ, 0);
    EXPECT_EQ(ordered_differ, 0);
    EXPECT_EQ(embree_differ, flat_embree_differ);
    EXPECT_LE(embree_differ, static_cast<int64_t>(rays.size() / 1000));
    EXPECT_GT(occluded, 0);
    EXPECT_LT(occluded, static_cast<int64_t>(rays.size()));
    if (pose == 0) {
      EXPECT_EQ(stale_differ, 0);
    } else {
      EXPECT_GT(stale_differ, 0);
    }
    ASSERT_GT(MoveBodiesBeforeTheFirstEye(posed.session->scene(), &snap, false), 0);
    posed.embree->Update(snap);
    posed.bvh->Update(snap);
  }
}

INSTANTIATE_TEST_SUITE_P(Bundled, CudaBvhWorlds,
                         ::testing::Values("default.yaml", "house.yaml", "warehouse.yaml"));

// the top level `s.tlas` with each leaf's instances in reverse order (the arrays it points to
// kept in *nodes, *instances): a top level as valid as BuildBvh's, which visits the instances of
// a leaf the other way round, so a tie between two instances of one leaf is met in both orders.
cuda::SceneView ReversedLeaves(const cuda::SceneView& s, std::vector<cuda::BvhWideNode>* nodes,
                               std::vector<int32_t>* instances) {
  nodes->assign(s.tlas_nodes, s.tlas_nodes + s.tlas.num_nodes);
  instances->assign(s.tlas_instances, s.tlas_instances + s.num_instances);
  std::vector<std::array<int, 2>> todo = {{s.tlas.root_first, s.tlas.root_count}};
  while (!todo.empty()) {
    const auto [first, count] = todo.back();
    todo.pop_back();
    if (count >= 0) {
      std::reverse(instances->begin() + first, instances->begin() + first + count);
      continue;
    }
    const cuda::BvhWideNode& n = (*nodes)[first];
    for (int c = 0; c < 2; ++c) todo.push_back({n.first[c], n.count[c]});
  }
  cuda::SceneView r = s;
  r.tlas_nodes = nodes->empty() ? nullptr : nodes->data();
  r.tlas_instances = instances->data();
  return r;
}

// how many instances, each searched alone as the flat loop searches it (its box, its BLAS, no
// bound but the ray's), hit ray r at exactly t: 2 or more is a tie the loop decides by index.
int InstancesHittingAt(const cuda::SceneView& s, const cuda::TraceRay& r, float t) {
  int n = 0;
  for (int i = 0; i < s.num_instances; ++i) {
    cuda::SceneView one = s;
    one.instances = s.instances + i;
    one.num_instances = 1;
    one.tlas_instances = nullptr;
    cuda::TraceHit h;
    cuda::TraceClosest(one, r, &h);
    n += h.instance == 0 && std::memcmp(&h.t, &t, sizeof(float)) == 0;
  }
  return n;
}

// TraceClosest through the top level (BuildBvh's and the one with reversed leaves) against the
// flat loop (no top level), and the variants of its tie rule (ClosestTies).
struct ClosestComparison {
  int64_t rays = 0, hits = 0, ties = 0;
  int64_t differ = 0, reversed_differ = 0;         // must stay 0
  int64_t next_up_differ = 0, no_rule_differ = 0;  // either top level, the variants

  void Add(const cuda::SceneView& s, const cuda::SceneView& reversed, const cuda::TraceRay& r) {
    cuda::SceneView flat = s;
    flat.tlas_instances = nullptr;
    cuda::TraceHit want, got, rev, next_up[2], no_rule[2];
    cuda::TraceClosest(flat, r, &want);
    cuda::TraceClosest(s, r, &got);
    cuda::TraceClosest(reversed, r, &rev);
    using cuda::ClosestTies;
    cuda::TraceClosest<cuda::LocalBvhStack, ClosestTies::kNextUp>(s, r, &next_up[0]);
    cuda::TraceClosest<cuda::LocalBvhStack, ClosestTies::kNextUp>(reversed, r, &next_up[1]);
    cuda::TraceClosest<cuda::LocalBvhStack, ClosestTies::kNone>(s, r, &no_rule[0]);
    cuda::TraceClosest<cuda::LocalBvhStack, ClosestTies::kNone>(reversed, r, &no_rule[1]);
    ++rays;
    differ += !SameHit(got, want);
    reversed_differ += !SameHit(rev, want);
    next_up_differ += !SameHit(next_up[0], want) || !SameHit(next_up[1], want);
    no_rule_differ += !SameHit(no_rule[0], want) || !SameHit(no_rule[1], want);
    if (want.instance < 0) return;
    ++hits;
    ties += InstancesHittingAt(s, r, want.t) >= 2;
  }
  void Print(const std::string& what) const {
    std::printf(
        "%s: %lld rays, %lld hits, %lld ties between instances; differ from the flat loop: "
        "%lld (reversed leaves %lld), one float above the best t %lld, no tie rule %lld\n",
        what.c_str(), static_cast<long long>(rays), static_cast<long long>(hits),
        static_cast<long long>(ties), static_cast<long long>(differ),
        static_cast<long long>(reversed_differ), static_cast<long long>(next_up_differ),
        static_cast<long long>(no_rule_differ));
  }
};

// the bundled worlds (and one with agents) for the closest-hit comparison.
class CudaBvhClosestWorlds : public CudaBvhWorlds {};

// closest hits through the top level over the instances (TraceClosest's default) are the flat
// index-order loop's, every field bit for bit, on camera fans from four eyes and on segments
// between their hits; again with every moving body moved and turned (BvhScene::Update rebuilds
// the top level), and with the moving bodies piled up four by four at one pose each, where
// equal shapes (the crowd's people) and the bodies' shared planes give ties between instances;
// also through a top level whose leaves list their instances the other way round. the variants
// of the tie rule show the comparison can fail (the counts are in
// docs/journal/2026-11-26-gpu-speed.md, "Closest hits through the top level").
TEST_P(CudaBvhClosestWorlds, ClosestThroughTheTopLevelGivesTheFlatLoopsHits) {
  Posed posed = LoadPosed();
  const cuda::BvhScene& bvh = posed.bvh->bvh();
  WorldSnapshot snap = posed.session->sim().Snapshot();
  int64_t ties = 0, no_rule_differ = 0;
  for (int pose = 0; pose < 3; ++pose) {
    const cuda::SceneView s = bvh.view();
    ASSERT_NE(s.tlas_instances, nullptr);
    std::vector<cuda::BvhWideNode> nodes;
    std::vector<int32_t> instances;
    const cuda::SceneView reversed = ReversedLeaves(s, &nodes, &instances);
    ClosestComparison c;
    for (const Eigen::Vector3f& eye :
         {Eigen::Vector3f(0, 0, 1.2f), Eigen::Vector3f(2, 1, 1.2f),
          Eigen::Vector3f(-2, -1.5f, 0.6f), Eigen::Vector3f(4, -3, 1.5f)})
      for (const Eigen::Vector3f& ahead :
           {Eigen::Vector3f(1, 0, -0.2f), Eigen::Vector3f(0, 1, -0.2f),
            Eigen::Vector3f(-1, 0.3f, -0.1f), Eigen::Vector3f(0.2f, -1, -0.4f)})
        for (const Ray& ray : RayFan(eye, ahead, 48, 36)) c.Add(s, reversed, cuda::ToTraceRay(ray));
    for (const Ray& ray : ShadowRaysBetweenHits(s, 32, 24))
      c.Add(s, reversed, cuda::ToTraceRay(ray));
    c.Print(GetParam() + ", pose " + std::to_string(pose) + " (" + std::to_string(s.num_instances) +
            " instances, top level of " + std::to_string(s.tlas.num_nodes) + " inner nodes)");
    EXPECT_EQ(c.differ, 0);
    EXPECT_EQ(c.reversed_differ, 0);
    EXPECT_GT(c.hits, c.rays / 2);
    ties += c.ties;
    no_rule_differ += c.no_rule_differ;
    // pose 1: the moving bodies in front of the first eye; pose 2: piled up there
    ASSERT_GT(MoveBodiesBeforeTheFirstEye(posed.session->scene(), &snap, pose > 0), 0);
    posed.bvh->Update(snap);
  }
  // the ties are there in some worlds only; where they are, no tie rule changes hits
  std::printf("%s: %lld ties, no tie rule changed %lld hits\n", GetParam().c_str(),
              static_cast<long long>(ties), static_cast<long long>(no_rule_differ));
  if (ties > 0) {
    EXPECT_GT(no_rule_differ, 0);
  }
}

INSTANTIATE_TEST_SUITE_P(Bundled, CudaBvhClosestWorlds,
                         ::testing::Values("default.yaml", "house.yaml", "warehouse.yaml",
                                           "effects/crowd.yaml"));

// ties by construction: pairs of equal shapes (every kind) on two bodies at one pose, so two
// instances give the same bits; boxes stacked and side by side on their own bodies, sharing
// faces, with rays in the shared planes (the edges' hits of two instances a few floats apart).
// through the top level (BuildBvh's, and with its leaves reversed) every hit is the flat loop's;
// without the tie rule (ClosestTies::kNone) and with a bound one float above the best t
// (kNextUp) hits differ (the counts are in
// docs/journal/2026-11-26-gpu-speed.md, "Closest hits through the top level").
TEST(CudaBvhTraversal, ClosestThroughTheTopLevelKeepsTheLowerInstanceOnATie) {
  SceneDescription scene = testing::EmptyScene();
  using testing::AddGeom;
  using testing::Translation;
  AddGeom(&scene, GeomShape::kPlane, {5, 5, 0.1}, Translation(0, 0, 0));
  AddGeom(&scene, GeomShape::kBox, {0.2, 2, 1}, Translation(4, 0, 1));
  const struct {
    GeomShape shape;
    Eigen::Vector3d size;
  } shapes[] = {{GeomShape::kBox, {0.2, 0.15, 0.1}},        {GeomShape::kSphere, {0.15, 0, 0}},
                {GeomShape::kCapsule, {0.1, 0.15, 0}},      {GeomShape::kCylinder, {0.12, 0.1, 0}},
                {GeomShape::kEllipsoid, {0.15, 0.1, 0.12}}, {GeomShape::kBox, {0.1, 0.1, 0.1}}};
  WorldSnapshot snap;
  std::vector<Pose> poses;
  for (int k = 0; k < 6; ++k) {
    Pose X = Translation(2, -1.25 + 0.5 * k, 0.25);
    X.linear() =
        Eigen::AngleAxisd(0.3 * k, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
    for (int twin = 0; twin < 2; ++twin) {
      const int b =
          testing::AddBody(&scene, "pair" + std::to_string(k) + "_" + std::to_string(twin));
      AddGeom(&scene, shapes[k].shape, shapes[k].size, Pose::Identity(), b);
      poses.push_back(X);
    }
  }
  // three boxes of 0.25 m: two stacked (faces at z = 0.25), one beside the lower (y = 1.875)
  for (const Eigen::Vector3d& p :
       {Eigen::Vector3d(2.5, 1.75, 0.125), Eigen::Vector3d(2.5, 1.75, 0.375),
        Eigen::Vector3d(2.5, 2.0, 0.125)}) {
    const int b = testing::AddBody(&scene, "stack" + std::to_string(poses.size()));
    AddGeom(&scene, GeomShape::kBox, {0.125, 0.125, 0.125}, Pose::Identity(), b);
    poses.push_back(Translation(p.x(), p.y(), p.z()));
  }
  snap = testing::IdentitySnapshot(scene);
  for (size_t k = 0; k < poses.size(); ++k) snap.X_WB[k + 1] = poses[k];
  cuda::BvhRayQuery query(scene);
  query.Update(snap);
  const cuda::SceneView s = query.bvh().view();
  ASSERT_EQ(s.num_instances, 16);
  ASSERT_NE(s.tlas_instances, nullptr);
  ASSERT_GT(s.tlas.num_nodes, 1);
  std::vector<cuda::BvhWideNode> nodes;
  std::vector<int32_t> instances;
  const cuda::SceneView reversed = ReversedLeaves(s, &nodes, &instances);
  ClosestComparison c;
  // fans at the pairs from three eyes, and fans in the shared planes z = 0.25 and y = 1.875
  for (const Eigen::Vector3f& eye : {Eigen::Vector3f(0, 0, 0.6f), Eigen::Vector3f(1, -2, 1.2f),
                                     Eigen::Vector3f(1.2f, 2.5f, 0.9f)})
    for (const Ray& ray : RayFan(eye, Eigen::Vector3f(2, 0, 0.25f) - eye, 96, 72, 0.7f))
      c.Add(s, reversed, cuda::ToTraceRay(ray));
  for (int k = 0; k < 4000; ++k) {
    const float a = -0.9f + 1.8f * k / 3999;
    cuda::TraceRay r;
    r.tmin = 0.01f;
    r.tmax = INFINITY;
    r.o = {0.5f, 1.875f + std::sin(a), 0.25f};  // in the plane z = 0.25
    r.d = {std::cos(a), -std::sin(a) * 0.9f, 0};
    c.Add(s, reversed, r);
    r.o = {0.5f + std::sin(a), 1.875f, 0.05f + 0.4f * k / 3999};  // in the plane y = 1.875
    r.d = {std::cos(a) * 1.5f, 0, std::sin(a) * 0.1f};
    c.Add(s, reversed, r);
  }
  c.Print("pairs and stacked boxes");
  EXPECT_EQ(c.differ, 0);
  EXPECT_EQ(c.reversed_differ, 0);
  EXPECT_GT(c.ties, 1000);
  EXPECT_GT(c.no_rule_differ, 100);
}

}  // namespace
}  // namespace penumbra

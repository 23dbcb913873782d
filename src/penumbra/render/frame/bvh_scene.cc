#include "penumbra/render/frame/bvh_scene.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/geometry/analytic_shapes.h"
#include "penumbra/render/geometry/static_geometry.h"
#include "penumbra/render/geometry/triangle_shapes.h"
#include "penumbra/render/transport/primary_pixel.h"

namespace penumbra::cuda {
namespace {

// half-size (m) of the quad that stands in for an infinite MJCF plane (RayScene's
// kInfinitePlaneHalfSize, render/embree/ray_scene.h; the root may not include render/embree).
constexpr double kInfinitePlane = 1e4;

AnalyticKind KindOf(GeomShape shape) {
  switch (shape) {
    case GeomShape::kPlane:
      return AnalyticKind::kPlane;
    case GeomShape::kSphere:
      return AnalyticKind::kSphere;
    case GeomShape::kCapsule:
      return AnalyticKind::kCapsule;
    case GeomShape::kEllipsoid:
      return AnalyticKind::kEllipsoid;
    default:
      return AnalyticKind::kCylinder;
  }
}

void ToRowMajor(const Pose& X, float m[12]) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) m[4 * r + c] = static_cast<float>(X.linear()(r, c));
    m[4 * r + 3] = static_cast<float>(X.translation()(r));
  }
}

F3 F3Of(const Eigen::Vector3f& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

BvhScene::BvhScene(const SceneDescription& scene, ThreadPool* pool) : scene_(scene), pool_(pool) {
  const int num_bodies = static_cast<int>(scene.bodies.size());
  X_WB_.assign(num_bodies, Pose::Identity());
  static_poses_ = X_WB_;
  for (const RayGeomGroup& rg : GroupRayGeoms(scene, "BvhScene")) {
    groups_.emplace_back();
    groups_.back().body = rg.body;
    groups_.back().geoms = rg.geoms;
  }
  for (const Tendon& tendon : scene.tendons) ValidateRayTendon(scene, tendon, "BvhScene");
  if (!scene.tendons.empty()) {
    tendon_group_ = static_cast<int>(groups_.size());
    groups_.emplace_back();
    groups_.back().tendons = true;
  }
  BuildAll();
}

int BvhScene::AddRecord(const Record& rec, int k, const Pose& X_IG) {
  const int record = static_cast<int>(records_.size());
  records_.push_back(rec);
  record_group_.push_back(k);
  X_GI_.push_back(X_IG.inverse());
  record_first_input_.push_back(static_cast<int32_t>(prims_.size()));
  return record;
}

void BvhScene::AddGeom(int gi, const Pose& X_IG, std::vector<PrimBox>* boxes, int record) {
  const Geom& geom = scene_.geoms[gi];
  if (geom.shape == GeomShape::kBox || geom.shape == GeomShape::kMesh ||
      geom.shape == GeomShape::kHeightField) {
    const TriangleShape shape = geom.shape == GeomShape::kBox ? BoxTriangles(geom.size)
                                : geom.shape == GeomShape::kMesh
                                    ? MeshTriangles(scene_.meshes[geom.mesh])
                                    : HeightFieldTriangles(scene_.hfields[geom.hfield]);
    const Eigen::Matrix3f R = X_IG.linear().cast<float>();
    const Eigen::Vector3f p = X_IG.translation().cast<float>();
    std::vector<Eigen::Vector3f> v_I(shape.vertices.size());
    for (size_t i = 0; i < v_I.size(); ++i) v_I[i] = R * shape.vertices[i] + p;
    // vertex normals and texcoords as RayScene keeps them (render/geometry/triangle_shapes.h)
    const TriangleShadingTerms terms = ShadingTermsOf(shape, R);
    const bool normals = !terms.normals_I.empty(), uv = !shape.texcoords.empty();
    for (size_t f = 0; f < shape.faces.size(); ++f) {
      const Eigen::Vector3i& face = shape.faces[f];
      const Eigen::Vector3f &a = v_I[face[0]], &b = v_I[face[1]], &c = v_I[face[2]];
      Triangle tri{F3Of(a), F3Of(b - a), F3Of(c - a)};
      PrimRef ref;
      ref.kind = 0;
      ref.index = static_cast<int32_t>(triangles_.size());
      ref.record = record;
      if (normals || uv) {
        TriangleShading ts{};
        for (int k = 0; k < 3; ++k) {
          if (normals) ts.n[k] = F3Of(terms.normals_I[face[k]]);
          if (uv)
            ts.uv[k][0] = shape.texcoords[face[k]].x(), ts.uv[k][1] = shape.texcoords[face[k]].y();
        }
        if (uv) {
          for (int r = 0; r < 2; ++r)
            for (int col = 0; col < 3; ++col) ts.duv_dp_G[3 * r + col] = terms.duv_dp_G[f](r, col);
          ts.uv_per_m = terms.uv_per_m[f];
        }
        ts.has_normals = normals ? 1 : 0;
        ts.has_uv = uv ? 1 : 0;
        ref.shading = static_cast<int32_t>(shading_.size());
        shading_.push_back(ts);
      }
      triangles_.push_back(tri);
      prims_.push_back(ref);
      PrimBox box;
      const Eigen::Vector3f lo = a.cwiseMin(b).cwiseMin(c), hi = a.cwiseMax(b).cwiseMax(c);
      for (int k = 0; k < 3; ++k) box.lo[k] = lo[k], box.hi[k] = hi[k];
      boxes->push_back(box);
    }
    return;
  }
  const double size[3] = {geom.size.x(), geom.size.y(), geom.size.z()};
  AddAnalytic(KindOf(geom.shape), size, X_IG, "geom '" + geom.name + "'", boxes, record);
}

void BvhScene::AddAnalytic(AnalyticKind kind, const double size[3], const Pose& X_IG,
                           const std::string& what, std::vector<PrimBox>* boxes, int record) {
  AnalyticPrim a;
  a.kind = kind;
  a.size[0] = size[0], a.size[1] = size[1], a.size[2] = size[2];
  if (a.kind == AnalyticKind::kPlane) {
    a.size[0] = size[0] > 0 ? size[0] : kInfinitePlane;
    a.size[1] = size[1] > 0 ? size[1] : kInfinitePlane;
    a.size[2] = 0;
  }
  const Pose X_GI = X_IG.inverse();
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) a.R_GI[3 * r + c] = X_GI.linear()(r, c);
    a.p_GI[r] = X_GI.translation()(r);
  }
  AnalyticShape shape;
  shape.kind = a.kind;
  shape.size = {a.size[0], a.size[1], a.size[2]};
  const Eigen::Vector3d h = AnalyticHalfExtents(shape);
  if (!(h.minCoeff() >= 0) || !h.allFinite() ||
      (a.kind != AnalyticKind::kPlane && !(h.minCoeff() > 0)))
    throw Error("BvhScene: " + what + " has a non-positive size for its shape");
  // group-frame box of the rotated geom box, padded as RayScene's AnalyticBounds
  const Eigen::Vector3d c = X_IG.translation();
  const Eigen::Vector3d e = X_IG.linear().cwiseAbs() * h;
  const Eigen::Vector3d pad = 1e-6 * (Eigen::Vector3d::Ones() + c.cwiseAbs() + e);
  PrimBox box;
  for (int k = 0; k < 3; ++k) {
    box.lo[k] = static_cast<float>(c[k] - e[k] - pad[k]);
    box.hi[k] = static_cast<float>(c[k] + e[k] + pad[k]);
  }
  PrimRef ref;
  ref.kind = 1;
  ref.index = static_cast<int32_t>(analytics_.size());
  ref.record = record;
  analytics_.push_back(a);
  prims_.push_back(ref);
  boxes->push_back(box);
}

void BvhScene::BuildAll() {
  const auto start = std::chrono::steady_clock::now();
  nodes_.clear();
  // BuildBvh's primitive order of every group so far (one element per primitive)
  std::vector<int32_t> prim_index;
  prims_.clear();
  triangles_.clear();
  shading_.clear();
  analytics_.clear();
  blases_.clear();
  records_.clear();
  record_group_.clear();
  X_GI_.clear();
  record_first_input_.clear();
  prim_of_input_.clear();
  record_of_geom_.assign(scene_.geoms.size(), -1);
  for (size_t k = 0; k < groups_.size(); ++k) {
    if (static_cast<int>(k) == tendon_group_)
      tendon_start_ = {nodes_.size(), prims_.size(), analytics_.size(), records_.size(),
                       blases_.size()};
    BuildGroup(static_cast<int>(k), &prim_index);
  }
  // the triangles and analytic shapes in the primitives' order (a leaf's shapes consecutive)
  std::vector<Triangle> triangles;
  std::vector<AnalyticPrim> analytics;
  triangles.reserve(triangles_.size());
  analytics.reserve(analytics_.size());
  for (PrimRef& p : prims_) {
    if (p.kind == 0) {
      triangles.push_back(triangles_[p.index]);
      p.index = static_cast<int32_t>(triangles.size()) - 1;
    } else {
      analytics.push_back(analytics_[p.index]);
      p.index = static_cast<int32_t>(analytics.size()) - 1;
    }
  }
  triangles_ = std::move(triangles);
  analytics_ = std::move(analytics);
  ++geometry_version_;
  build_seconds_ = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  SetInstances();
}

void BvhScene::BuildGroup(int k, std::vector<int32_t>* prim_index) {
  Group& g = groups_[k];
  std::vector<PrimBox> boxes;
  const int32_t prim_base = static_cast<int32_t>(prims_.size());
  if (g.tendons) {
    AddTendons(k, &boxes);
  } else {
    for (int gi : g.geoms) {
      const Geom& geom = scene_.geoms[gi];
      const Pose X_IG = g.body < 0 ? Pose(static_poses_[geom.body] * geom.X_BG) : geom.X_BG;
      Record rec;
      rec.geom = gi;
      rec.material = geom.material;
      rec.mujoco_id = geom.id;
      rec.body = geom.body;
      rec.semantic_class = geom.semantic_class;
      const int record = AddRecord(rec, k, X_IG);
      record_of_geom_[gi] = record;
      AddGeom(gi, X_IG, &boxes, record);
    }
  }
  if (boxes.empty()) {
    g.blas = -1;
    return;
  }
  std::vector<BvhNode> tree;
  BuildBvh(boxes, prim_base, &tree, prim_index, pool_);
  // the group's primitives in its leaves' order: leaf ranges index prims_ directly (the leaves
  // index prim_index from prim_base on, as prim_index holds one element per primitive)
  std::vector<PrimRef> leaf_order;
  leaf_order.reserve(boxes.size());
  for (size_t i = prim_base; i < prims_.size(); ++i) leaf_order.push_back(prims_[(*prim_index)[i]]);
  std::copy(leaf_order.begin(), leaf_order.end(), prims_.begin() + prim_base);
  prim_of_input_.resize(prims_.size(), -1);
  for (size_t i = prim_base; i < prims_.size(); ++i)
    prim_of_input_[(*prim_index)[i]] = static_cast<int32_t>(i);
  Blas blas;
  WidenBvh(tree, &nodes_, &blas);
  g.blas = static_cast<int>(blases_.size());
  blases_.push_back(blas);
}

void BvhScene::AddTendons(int k, std::vector<PrimBox>* boxes) {
  for (const WorldSnapshot::TendonPath& path : tendon_paths_) {
    const Tendon& tendon = scene_.tendons[path.tendon];
    for (size_t i = 0; i + 1 < path.p_W.size(); ++i) {
      const Eigen::Vector3d& a = path.p_W[i];
      const Eigen::Vector3d& b = path.p_W[i + 1];
      if (!a.allFinite() || !b.allFinite()) continue;
      const double length = (b - a).norm();
      const bool capsule = length > 1e-9;
      // geom frame: origin at the segment's midpoint, z along it (RayScene's frame)
      Pose X_IG = Pose::Identity();
      if (capsule) {
        const Eigen::Vector3d z = (b - a) / length;
        const Eigen::Vector3d x = z.unitOrthogonal();
        X_IG.linear().col(0) = x;
        X_IG.linear().col(1) = z.cross(x);
        X_IG.linear().col(2) = z;
      }
      X_IG.translation() = 0.5 * (a + b);
      Record rec;
      rec.geom = -1;
      rec.material = tendon.material;
      const int record = AddRecord(rec, k, X_IG);
      const double size[3] = {tendon.width_m, 0.5 * length, 0};
      AddAnalytic(capsule ? AnalyticKind::kCapsule : AnalyticKind::kSphere, size, X_IG,
                  "a segment of tendon '" + tendon.name + "'", boxes, record);
    }
  }
}

void BvhScene::RebuildTendons() {
  const TendonStart& t = tendon_start_;
  nodes_.resize(t.nodes);
  prims_.resize(t.prims);
  analytics_.resize(t.analytics);
  records_.resize(t.records);
  record_group_.resize(t.records);
  X_GI_.resize(t.records);
  record_first_input_.resize(t.records);
  prim_of_input_.resize(t.prims);
  blases_.resize(t.blases);
  // BuildBvh appends the group's order after one element per primitive before it
  std::vector<int32_t> prim_index(t.prims, 0);
  BuildGroup(tendon_group_, &prim_index);
  // the group's capsules in its primitives' (leaf) order, as BuildAll orders every group's
  std::vector<AnalyticPrim> capsules;
  capsules.reserve(prims_.size() - t.prims);
  for (size_t i = t.prims; i < prims_.size(); ++i) {
    capsules.push_back(analytics_[prims_[i].index]);
    prims_[i].index = static_cast<int32_t>(t.analytics + capsules.size() - 1);
  }
  std::copy(capsules.begin(), capsules.end(), analytics_.begin() + t.analytics);
  ++geometry_version_;
}

void BvhScene::SetInstances() {
  instances_.clear();
  instance_of_group_.assign(groups_.size(), -1);
  for (size_t k = 0; k < groups_.size(); ++k) {
    Group& g = groups_[k];
    if (g.blas < 0) continue;
    instance_of_group_[k] = static_cast<int32_t>(instances_.size());
    g.X_WI = g.body < 0 ? Pose::Identity() : X_WB_[g.body];
    Instance in;
    in.blas = g.blas;
    in.group = static_cast<int32_t>(k);
    ToRowMajor(g.X_WI, in.X_WI);
    ToRowMajor(g.X_WI.inverse(), in.X_IW);
    // world box of the posed root box
    const Blas& root = blases_[g.blas];
    Eigen::Vector3d lo = Eigen::Vector3d::Constant(INFINITY), hi = -lo;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d corner((c & 1) ? root.hi[0] : root.lo[0],
                                   (c & 2) ? root.hi[1] : root.lo[1],
                                   (c & 4) ? root.hi[2] : root.lo[2]);
      const Eigen::Vector3d w = g.X_WI * corner;
      lo = lo.cwiseMin(w), hi = hi.cwiseMax(w);
    }
    // pad against float rounding of the transformed ray
    const Eigen::Vector3d pad =
        1e-5 * (Eigen::Vector3d::Ones() + lo.cwiseAbs().cwiseMax(hi.cwiseAbs()));
    for (int a = 0; a < 3; ++a) {
      in.lo[a] = static_cast<float>(lo[a] - pad[a]);
      in.hi[a] = static_cast<float>(hi[a] + pad[a]);
    }
    instances_.push_back(in);
  }
  BuildTlas();
}

void BvhScene::BuildTlas() {
  std::vector<PrimBox> boxes(instances_.size());
  for (size_t i = 0; i < instances_.size(); ++i)
    for (int a = 0; a < 3; ++a)
      boxes[i].lo[a] = instances_[i].lo[a], boxes[i].hi[a] = instances_[i].hi[a];
  // the same boxes give the same top level (a frame whose bodies did not move)
  if (tlas_built_ && boxes.size() == tlas_boxes_.size() &&
      (boxes.empty() ||
       std::memcmp(boxes.data(), tlas_boxes_.data(), boxes.size() * sizeof(PrimBox)) == 0))
    return;
  tlas_boxes_ = boxes;
  tlas_built_ = true;
  std::vector<BvhNode> tree;
  tlas_instances_.clear();
  BuildBvh(boxes, 0, &tree, &tlas_instances_);
  tlas_nodes_.clear();
  WidenBvh(tree, &tlas_nodes_, &tlas_);
  // the deepest inner node's depth (root 0) bounds the traversal's pending entries
  std::vector<int> depth(tree.size(), 0);
  int deepest = 0;
  for (size_t k = 0; k < tree.size(); ++k) {
    if (tree[k].count > 0 || tree.size() == 1) continue;
    deepest = std::max(deepest, depth[k]);
    depth[tree[k].first] = depth[tree[k].first + 1] = depth[k] + 1;
  }
  tlas_depth_ = deepest;
}

void BvhScene::Update(const WorldSnapshot& snapshot) {
  if (snapshot.X_WB.size() != X_WB_.size())
    throw Error("BvhScene::Update: snapshot has " + std::to_string(snapshot.X_WB.size()) +
                " body poses, scene has " + std::to_string(X_WB_.size()) + " bodies");
  X_WB_ = snapshot.X_WB;
  bool static_moved = false;
  for (int gi : groups_[0].geoms) {
    const int b = scene_.geoms[gi].body;
    if (snapshot.X_WB[b].matrix() != static_poses_[b].matrix()) static_moved = true;
  }
  bool tendons_moved = false;
  if (tendon_group_ >= 0) {
    for (const WorldSnapshot::TendonPath& path : snapshot.tendon_paths)
      if (path.tendon < 0 || path.tendon >= static_cast<int>(scene_.tendons.size()))
        throw Error("BvhScene::Update: a tendon path refers to missing tendon " +
                    std::to_string(path.tendon));
    tendons_moved = snapshot.tendon_paths.size() != tendon_paths_.size();
    for (size_t k = 0; !tendons_moved && k < tendon_paths_.size(); ++k)
      tendons_moved = snapshot.tendon_paths[k].tendon != tendon_paths_[k].tendon ||
                      snapshot.tendon_paths[k].p_W != tendon_paths_[k].p_W;
    if (tendons_moved) tendon_paths_ = snapshot.tendon_paths;
  }
  if (static_moved) {
    static_poses_ = snapshot.X_WB;
    BuildAll();
    return;
  }
  if (tendons_moved) RebuildTendons();
  SetInstances();
}

bool BvhScene::NameHit(int geom, int segment, int face, TraceHit* th) const {
  int record = -1;
  if (geom >= 0) {
    if (geom < static_cast<int>(record_of_geom_.size())) record = record_of_geom_[geom];
  } else if (tendon_group_ >= 0 && segment >= 0) {
    record = static_cast<int>(tendon_start_.records) + segment;
  }
  if (record < 0 || record >= static_cast<int>(records_.size())) return false;
  const int64_t input = static_cast<int64_t>(record_first_input_[record]) + face;
  const int64_t end = record + 1 < static_cast<int>(records_.size())
                          ? record_first_input_[record + 1]
                          : static_cast<int64_t>(prims_.size());
  if (face < 0 || input >= end) return false;
  const int32_t instance = instance_of_group_[record_group_[record]];
  if (instance < 0) return false;
  th->prim = prim_of_input_[input];
  th->instance = instance;
  return true;
}

SceneView BvhScene::view() const {
  SceneView v;
  v.nodes = nodes_.data();
  v.prims = prims_.data();
  v.triangles = triangles_.data();
  v.analytics = analytics_.data();
  v.blases = blases_.data();
  v.instances = instances_.data();
  v.num_instances = static_cast<int32_t>(instances_.size());
  // a top level deeper than the traversal's stack is left out (every instance in turn)
  if (tlas_depth_ < kMaxTlasDepth) {
    v.tlas_nodes = tlas_nodes_.empty() ? nullptr : tlas_nodes_.data();
    v.tlas_instances = tlas_instances_.data();
    v.tlas = tlas_;
  }
  v.records = records_.data();
  v.shading = shading_.empty() ? nullptr : shading_.data();
  return v;
}

void BvhScene::FinishHit(const Ray& ray, const TraceHit& th, SurfaceHit* hit) const {
  const PrimRef& pr = prims_[th.prim];
  const Record& rec = records_[pr.record];
  const Group& g = groups_[record_group_[pr.record]];
  const Pose& X_GI = X_GI_[pr.record];
  BeginSurfaceHit(ray, th.t, rec.geom, rec.material, hit);
  const Eigen::Vector3d p_W =
      ray.o.cast<double>() + static_cast<double>(th.t) * ray.d.cast<double>();
  const Eigen::Vector3d p_G = X_GI * (g.X_WI.inverse() * p_W);
  const Eigen::Matrix3d R_GW = X_GI.linear() * g.X_WI.linear().transpose();
  Eigen::Vector3d n_G;
  if (pr.kind == 1) {
    const AnalyticPrim& a = analytics_[pr.index];
    AnalyticNormalArrays(a.kind, a.size, p_G.data(), th.part, n_G.data());
  } else {
    const Triangle& t = triangles_[pr.index];
    const Eigen::Vector3d e1(t.e1.x, t.e1.y, t.e1.z), e2(t.e2.x, t.e2.y, t.e2.z);
    const Eigen::Vector3d n_I = e1.cross(e2);
    const double len = n_I.norm();
    n_G = len > 0 ? Eigen::Vector3d(X_GI.linear() * (n_I / len)) : Eigen::Vector3d::UnitZ();
  }
  hit->p_G = p_G.cast<float>();
  hit->n_G = n_G.cast<float>();
  hit->d_G = (R_GW * ray.d.cast<double>()).normalized().cast<float>();
  Eigen::Vector3f ng_W = (R_GW.transpose() * n_G).cast<float>();
  hit->front_face = ng_W.dot(ray.d) <= 0;
  if (!hit->front_face) ng_W = -ng_W;
  hit->ng_W = ng_W;
  hit->ns_W = ng_W;
  if (pr.kind != 0) return;
  // smooth shading and texcoords (render/transport/primary_pixel.h, as the GPU shades them)
  const SceneView v = view();
  Float3 ns;
  if (HitShadingNormal(v, th, hit->front_face, &ns)) hit->ns_W = Eigen::Vector3f(ns.x, ns.y, ns.z);
  float u = 0, w = 0;
  if (const TriangleShading* ts = HitTexcoords(v, th, &u, &w)) {
    hit->has_uv = true;
    hit->uv = Eigen::Vector2f(u, w);
    hit->uv_per_m = ts->uv_per_m;
    for (int r = 0; r < 2; ++r)
      for (int c = 0; c < 3; ++c) hit->duv_dp_G(r, c) = ts->duv_dp_G[3 * r + c];
  }
}

}  // namespace penumbra::cuda

#pragma once
// the CUDA backend's scene in flat arrays of plain structs, read by the same traversal code on
// the CPU (tests, BvhRayQuery) and on the GPU (CudaRayQuery, CudaRenderer): a two-level BVH as
// RayScene's Embree scenes (render/embree/ray_scene.h). bottom level: one BVH per instanced
// group (the static bodies merged in the world frame, built once and again only if a static
// body moves; each moving body in its body frame, built once); top level: the instances, their
// transforms rewritten from every snapshot (no BLAS rebuild), and a small BVH over their world
// boxes, rebuilt on the host when the boxes change (occlusion rays walk it). no Eigen and no
// standard containers here: device code reads these through raw pointers
// (render/bvh/bvh_traversal.h).

#include <cstddef>
#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/geometry/analytic_shape_math.h"

namespace penumbra::cuda {

/// a float 3-vector (no Eigen in device code).
struct F3 {
  float x = 0, y = 0, z = 0;
};

/// a node of the builder's binary BVH (BuildBvh): a box and either two children (count == 0:
/// children at `first` and `first + 1`) or a leaf of `count` primitives prim_index[first ..
/// first + count). 32 bytes, 16-aligned. the traversal reads BvhWideNode (WidenBvh) instead.
struct alignas(16) BvhNode {
  float lo[3], hi[3];
  int32_t first = 0;
  int32_t count = 0;
};

/// the traversal's node (BuildBvh's binary tree with each inner node's two children's boxes
/// and references stored in it, WidenBvh): child c's box box[c] (lo x, y, z, hi x, y, z) and
/// either a leaf (count[c] >= 0: primitives prims[first[c] .. first[c] + count[c])) or an
/// inner node (count[c] == -1: the node at first[c], relative to its BLAS's node_offset). 64
/// bytes, 64-aligned: a node visit tests both children from one cache-line load (four 16-byte
/// loads on the GPU) instead of the node's own 32 bytes and its two children's 64.
struct alignas(64) BvhWideNode {
  float box[2][6];
  int32_t first[2];
  int32_t count[2];
};
static_assert(sizeof(BvhWideNode) == 64, "BvhWideNode is one 64-byte line");

/// one triangle in its group's frame (edges from v0, as Moller-Trumbore takes them). 48 bytes,
/// 16-aligned (12 bytes of padding): the GPU loads it in three 16-byte loads (LoadTriangle).
struct alignas(16) Triangle {
  F3 v0, e1, e2;
};
static_assert(sizeof(Triangle) == 48, "Triangle is three 16-byte loads");

/// an analytic shape (render/geometry/analytic_shapes.h) and the map from its group's frame to its
/// own: p_G = R_GI p_I + p_GI (double, as RayScene).
struct AnalyticPrim {
  AnalyticKind kind = AnalyticKind::kSphere;
  double size[3] = {1, 1, 1};
  double R_GI[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< row-major
  double p_GI[3] = {0, 0, 0};
};

/// a primitive: a triangle (kind 0) or an analytic shape (kind 1), with the record (geom) it
/// belongs to and its triangle's shading attributes. 16 bytes, 16-aligned.
struct alignas(16) PrimRef {
  int32_t kind = 0;      ///< 0 = triangle, 1 = analytic
  int32_t index = 0;     ///< into triangles or analytics
  int32_t record = 0;    ///< into the scene's records
  int32_t shading = -1;  ///< triangle: into SceneView::shading; -1: none (flat, untextured)
};

/// the shading attributes of a triangle of a mesh or height field with vertex normals or
/// texture coordinates (RayScene's TriangleGeom per face, render/embree/ray_scene.cc): read for
/// the closest hit only (HitShadingNormal, HitTexcoords in primary_pixel.h), never by the
/// traversal, which reads the 48-byte Triangle alone. 96 bytes.
struct TriangleShading {
  /// the vertices' unit normals in the group frame (TriangleShadingTerms::normals_I), in the
  /// triangle's vertex order (v0, v0 + e1, v0 + e2); unused without has_normals.
  F3 n[3];
  /// the vertices' texture coordinates (u, v), as n; unused without has_uv.
  float uv[3][2];
  /// the triangle's texcoord gradient in its geom frame, row-major 2 x 3 (SurfaceHit::duv_dp_G).
  float duv_dp_G[6];
  /// texcoord units per metre of surface (SurfaceHit::uv_per_m).
  float uv_per_m;
  int32_t has_normals;  ///< 1: n holds vertex normals (smooth shading)
  int32_t has_uv;       ///< 1: uv holds texture coordinates
};
static_assert(sizeof(TriangleShading) == 96, "TriangleShading is 96 bytes");

/// a bottom-level BVH: its inner nodes at nodes[node_offset ..] (SceneView::nodes), the root's
/// box and reference (root_count >= 0: the root is a leaf of root_count primitives at
/// prims[root_first ..]; -1: the root is inner node root_first, i.e. 0).
struct Blas {
  int32_t node_offset = 0;
  int32_t num_nodes = 0;
  int32_t root_first = 0;
  int32_t root_count = 0;
  float lo[3] = {1, 1, 1}, hi[3] = {-1, -1, -1};
};

/// an instance of a BLAS posed in the world: the world-frame box of the posed BLAS (for the top
/// level), X_WI and its inverse as row-major 3x4 floats. 128 bytes, 16-aligned, laid out for
/// the traversal's loads (LoadInstanceBox, LoadInstanceInverse in bvh_traversal.h): the box with
/// the BLAS and group in the first two 16-byte words (lo x, y, z, hi x; hi y, z, blas, group),
/// then X_IW and X_WI in three 16-byte words each.
struct alignas(16) Instance {
  float lo[3], hi[3];
  int32_t blas = 0;
  int32_t group = 0;
  float X_IW[12];
  float X_WI[12];  ///< row-major [R | p]
};
static_assert(sizeof(Instance) == 128, "Instance is eight 16-byte words");
static_assert(offsetof(Instance, blas) == 24 && offsetof(Instance, X_IW) == 32 &&
                  offsetof(Instance, X_WI) == 80,
              "LoadInstanceBox and LoadInstanceInverse read Instance by these offsets");

/// what a primitive's record stands for.
struct Record {
  int32_t geom = -1;       ///< index into SceneDescription::geoms
  int32_t material = -1;   ///< index into SceneDescription::materials
  int32_t mujoco_id = -1;  ///< Geom::id
  int32_t body = -1;       ///< Geom::body
  int32_t semantic_class = 0;
};

/// the arrays of one scene (host or device pointers) as the traversal reads them.
struct SceneView {
  const BvhWideNode* nodes = nullptr;  ///< every BLAS's inner nodes (Blas::node_offset)
  /// leaf ranges index this directly: each BLAS's primitives in its leaves' order (BvhScene
  /// sorts them so, and the triangles and analytic shapes in the primitives' order), so the
  /// traversal reads a leaf's primitives and their shapes from consecutive memory.
  const PrimRef* prims = nullptr;
  const Triangle* triangles = nullptr;
  const AnalyticPrim* analytics = nullptr;
  const Blas* blases = nullptr;
  const Instance* instances = nullptr;
  int32_t num_instances = 0;
  /// the top level over the instances' world boxes (BvhScene builds it whenever the instances
  /// change: BuildBvh and WidenBvh over Instance::lo, hi): its inner nodes (tlas.node_offset 0,
  /// tlas.num_nodes of them; null when the root is a leaf) and its root. TraceClosest and
  /// TraceOccluded walk it.
  const BvhWideNode* tlas_nodes = nullptr;
  /// the top level's leaves' instances: a leaf's reference (first, count) indexes this array
  /// (num_instances entries, each an index into instances). null: no top level (TraceClosest
  /// and TraceOccluded test every instance in index order).
  const int32_t* tlas_instances = nullptr;
  Blas tlas;
  const Record* records = nullptr;           ///< by PrimRef::record
  const TriangleShading* shading = nullptr;  ///< by PrimRef::shading (closest hits only)
};

/// a ray in the traversal's form (world frame; d not necessarily unit).
struct TraceRay {
  F3 o, d;
  float tmin = 0, tmax = 0;
};

/// the closest hit of a traced ray: t, the instance and primitive, and where on it (triangle:
/// barycentrics u, v; analytic: part in `part`).
struct TraceHit {
  float t = 0;
  int32_t instance = -1;  ///< -1 = miss
  int32_t prim = -1;      ///< into prims
  float u = 0, v = 0;
  int32_t part = 0;
};

}  // namespace penumbra::cuda

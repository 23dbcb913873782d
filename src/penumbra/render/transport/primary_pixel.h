#pragma once
// the camera's pixel rays and what a hit is on the scene's plain data: the pinhole camera
// (PinholeCamera: the ray through pixel (u, v), pixel centres integers, is o + t (((u - cx)
// inv_fx) ex + ((v - cy) inv_fy) ey + ez), as Camera::GenerateRay for a camera without
// distortion or motion), a hit's geometric and shading normals and texcoords (HitNormal,
// HitShadingNormal, HitTexcoords) and one pixel's ground-truth images (TracePixelTruth), written
// once as PB_HOST_DEVICE functions: the batch kernel (render/cuda/cuda_batch_kernels.cu) runs them
// on the GPU, the host tests (tests/render/cuda/batch_layout_test.cc) on the CPU over the same
// BvhScene arrays.

#include <cmath>
#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/bvh/bvh_types.h"
#include "penumbra/render/geometry/mesh_shading_math.h"
#include "penumbra/render/shading_math.h"

namespace penumbra::cuda {

/// a pinhole camera as the primary-ray kernel takes it: world ray through pixel (u, v) (pixel
/// centres are integers) is o + t (((u - cx) inv_fx) ex + ((v - cy) inv_fy) ey + ez), as
/// Camera::GenerateRay (render/camera/camera.h) for a camera without distortion or motion.
struct PinholeCamera {
  F3 o, ex, ey, ez;
  float cx = 0, cy = 0, inv_fx = 1, inv_fy = 1;
  float near = 0;
  int width = 0, height = 0;
  /// a camera with lens distortion: (height x width x 2) undistorted normalised coordinates
  /// (x, y) of the pixel centres, used instead of ((u - cx) inv_fx, (v - cy) inv_fy); null = a
  /// pinhole. a moving camera (rolling shutter): (height x 12) per row o, ex, ey, ez, used
  /// instead of the fields above; null = one pose. both in the memory the reader runs in (host
  /// or device); render/cuda/camera_rays.h fills them.
  const float* xy = nullptr;
  const float* rows = nullptr;
};

/// the ground truth of one pixel: depth along the optical axis (m; 0 = miss), range along the
/// ray (m; 0 = miss), the MuJoCo geom id (-1 = miss or no geom), the body (instance) id (-1 =
/// miss) and the semantic class (0 = miss), as RenderedFrame's depth_m, range_m, geom_id,
/// body_id and semantic_class; with the camera's axes given (TracePixelTruth), the unit
/// surface normal facing the camera in the camera frame O (x right, y down, z forward; 0 0 0 =
/// miss), as RenderedFrame's normal_O.
struct PixelTruth {
  float depth = 0;
  float range = 0;
  int32_t geom_id = -1;
  int32_t body_id = -1;
  int32_t semantic = 0;
  F3 normal_O{0, 0, 0};
};

/// where a pixel's ground truth goes (each plane row-major, null = not wanted): depth, range
/// (float m), geom id, body id, semantic class (int32), normal_O (3 floats).
struct PixelTruthPlanes {
  float* depth = nullptr;
  int32_t* geom_id = nullptr;
  int32_t* body_id = nullptr;
  int32_t* semantic = nullptr;
  float* range = nullptr;
  float* normal_O = nullptr;
  /// writes p as pixel i of every plane that is wanted.
  PB_HOST_DEVICE void Write(const PixelTruth& p, int64_t i) const {
    if (depth) depth[i] = p.depth;
    if (geom_id) geom_id[i] = p.geom_id;
    if (body_id) body_id[i] = p.body_id;
    if (semantic) semantic[i] = p.semantic;
    if (range) range[i] = p.range;
    if (normal_O) {
      normal_O[3 * i] = p.normal_O.x;
      normal_O[3 * i + 1] = p.normal_O.y;
      normal_O[3 * i + 2] = p.normal_O.z;
    }
  }
  /// true if any plane is wanted.
  PB_HOST_DEVICE bool any() const {
    return depth || geom_id || body_id || semantic || range || normal_O;
  }
};

/// the world ray o + t (x ex + y ey + ez) of normalised image coordinates (x, y) of a camera at
/// o with axes ex, ey, ez (W) and near plane `near` (m): tmin = near, tmax = infinity; d is not
/// unit (its z along ez is 1, so t is depth), as Camera::GenerateRay. kRn: each product and sum
/// rounded on its own (MulRn, AddRn: Camera::GenerateRay's bits on the GPU too, for the
/// realtime splat of particle streaks); else the device may fuse them.
template <bool kRn = false>
PB_HOST_DEVICE inline TraceRay NormalizedPixelRay(F3 o, F3 ex, F3 ey, F3 ez, float x, float y,
                                                  float near) {
  TraceRay r;
  r.o = o;
  if constexpr (kRn)
    r.d = {AddRn(AddRn(MulRn(x, ex.x), MulRn(y, ey.x)), ez.x),
           AddRn(AddRn(MulRn(x, ex.y), MulRn(y, ey.y)), ez.y),
           AddRn(AddRn(MulRn(x, ex.z), MulRn(y, ey.z)), ez.z)};
  else
    r.d = {x * ex.x + y * ey.x + ez.x, x * ex.y + y * ey.y + ez.y, x * ex.z + y * ey.z + ez.z};
  r.tmin = near;
  r.tmax = INFINITY;
  return r;
}

/// the world ray of pixel (u, v) of a pinhole camera given as origin o, axes ex, ey, ez (W),
/// principal point (cx, cy) px, inverse focal lengths inv_fx, inv_fy (1/px) and near plane
/// `near` (m): NormalizedPixelRay<kRn> of ((u - cx) inv_fx, (v - cy) inv_fy).
template <bool kRn = false>
PB_HOST_DEVICE inline TraceRay PinholePixelRay(F3 o, F3 ex, F3 ey, F3 ez, float cx, float cy,
                                               float inv_fx, float inv_fy, float near, int u,
                                               int v) {
  const float x = (static_cast<float>(u) - cx) * inv_fx;
  const float y = (static_cast<float>(v) - cy) * inv_fy;
  return NormalizedPixelRay<kRn>(o, ex, ey, ez, x, y, near);
}

/// the unit world normal of hit h of world ray r (the geometric normal of the triangle or
/// analytic shape), facing the ray; *front_face (if given): the ray hit the outward side.
PB_HOST_DEVICE inline F3 HitNormal(const SceneView& s, const TraceRay& r, const TraceHit& h,
                                   bool* front_face = nullptr) {
  const Instance& in = s.instances[h.instance];
  const PrimRef& pr = s.prims[h.prim];
  F3 n_I;
  if (pr.kind == 0) {
    const Triangle& t = s.triangles[pr.index];
    n_I = {t.e1.y * t.e2.z - t.e1.z * t.e2.y, t.e1.z * t.e2.x - t.e1.x * t.e2.z,
           t.e1.x * t.e2.y - t.e1.y * t.e2.x};
  } else {
    const AnalyticPrim& a = s.analytics[pr.index];
    const F3 o = TransformPoint(in.X_IW, r.o), d = TransformVector(in.X_IW, r.d);
    const double p_I[3] = {o.x + static_cast<double>(h.t) * d.x,
                           o.y + static_cast<double>(h.t) * d.y,
                           o.z + static_cast<double>(h.t) * d.z};
    double p_G[3], n_G[3];
    for (int k = 0; k < 3; ++k)
      p_G[k] = a.R_GI[3 * k] * p_I[0] + a.R_GI[3 * k + 1] * p_I[1] + a.R_GI[3 * k + 2] * p_I[2] +
               a.p_GI[k];
    AnalyticNormalArrays(a.kind, a.size, p_G, h.part, n_G);
    // n_I = R_GI^T n_G
    n_I = {static_cast<float>(a.R_GI[0] * n_G[0] + a.R_GI[3] * n_G[1] + a.R_GI[6] * n_G[2]),
           static_cast<float>(a.R_GI[1] * n_G[0] + a.R_GI[4] * n_G[1] + a.R_GI[7] * n_G[2]),
           static_cast<float>(a.R_GI[2] * n_G[0] + a.R_GI[5] * n_G[1] + a.R_GI[8] * n_G[2])};
  }
  F3 n = TransformVector(in.X_WI, n_I);
  const float len = sqrtf(n.x * n.x + n.y * n.y + n.z * n.z);
  n = len > 0 ? F3{n.x / len, n.y / len, n.z / len} : F3{0, 0, 1};
  const bool front = !(n.x * r.d.x + n.y * r.d.y + n.z * r.d.z > 0);
  if (!front) n = {-n.x, -n.y, -n.z};
  if (front_face) *front_face = front;
  return n;
}

/// the shading attributes of hit h (a triangle's TriangleShading), or null where the hit
/// primitive has none (an analytic shape, a box, a mesh without normals and texcoords).
PB_HOST_DEVICE inline const TriangleShading* HitShading(const SceneView& s, const TraceHit& h) {
  const PrimRef& pr = s.prims[h.prim];
  return pr.kind == 0 && pr.shading >= 0 && s.shading ? s.shading + pr.shading : nullptr;
}

/// the unit shading normal of hit h, world frame, facing as its geometric normal does
/// (front_face: HitNormal's): the triangle's vertex normals mixed at the hit's barycentrics
/// (BarycentricMix, as RayScene::FinishHit), normalised and posed by the hit's instance. false
/// (no change) where the triangle has no vertex normals or their mix is zero: the geometric
/// normal shades there.
PB_HOST_DEVICE inline bool HitShadingNormal(const SceneView& s, const TraceHit& h, bool front_face,
                                            Float3* ns_W) {
  const TriangleShading* ts = HitShading(s, h);
  if (!ts || ts->has_normals == 0) return false;
  const Float3 ns_I = BarycentricMix(Float3{ts->n[0].x, ts->n[0].y, ts->n[0].z},
                                     Float3{ts->n[1].x, ts->n[1].y, ts->n[1].z},
                                     Float3{ts->n[2].x, ts->n[2].y, ts->n[2].z}, h.u, h.v);
  const float ls = sqrtf(ns_I.x * ns_I.x + ns_I.y * ns_I.y + ns_I.z * ns_I.z);
  if (!(ls > 0)) return false;
  const F3 n =
      TransformVector(s.instances[h.instance].X_WI, F3{ns_I.x / ls, ns_I.y / ls, ns_I.z / ls});
  *ns_W = front_face ? Float3{n.x, n.y, n.z} : Float3{-n.x, -n.y, -n.z};
  return true;
}

/// the texture coordinates (u, v) of hit h: the triangle's vertex texcoords mixed at the hit's
/// barycentrics (BarycentricMix, as RayScene::FinishHit), and the triangle's shading record
/// (its uv_per_m and duv_dp_G); null where the triangle has no texcoords (planar mapping).
PB_HOST_DEVICE inline const TriangleShading* HitTexcoords(const SceneView& s, const TraceHit& h,
                                                          float* uv_u, float* uv_v) {
  const TriangleShading* ts = HitShading(s, h);
  if (!ts || ts->has_uv == 0) return nullptr;
  const Float3 uv =
      BarycentricMix(Float3{ts->uv[0][0], ts->uv[0][1], 0}, Float3{ts->uv[1][0], ts->uv[1][1], 0},
                     Float3{ts->uv[2][0], ts->uv[2][1], 0}, h.u, h.v);
  *uv_u = uv.x;
  *uv_v = uv.y;
  return ts;
}

/// traces ray r (PinholePixelRay's) through scene s and returns the pixel's ground truth; with
/// axes_W (the camera's ex, ey, ez in W, 3 values) also its normal in the camera frame.
PB_HOST_DEVICE inline PixelTruth TracePixelTruth(const SceneView& s, const TraceRay& r,
                                                 const F3* axes_W = nullptr) {
  TraceHit h;
  TraceClosest(s, r, &h);
  PixelTruth p;
  if (h.instance < 0) return p;
  const Record& rec = s.records[s.prims[h.prim].record];
  p.depth = h.t;
  p.range = h.t * sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  p.geom_id = rec.geom >= 0 ? rec.mujoco_id : -1;
  p.body_id = rec.body;
  p.semantic = rec.semantic_class;
  if (axes_W) {
    const F3 w = HitNormal(s, r, h);
    const F3 &ex = axes_W[0], &ey = axes_W[1], &ez = axes_W[2];
    p.normal_O = {ex.x * w.x + ex.y * w.y + ex.z * w.z, ey.x * w.x + ey.y * w.y + ey.z * w.z,
                  ez.x * w.x + ez.y * w.y + ez.z * w.z};
  }
  return p;
}

}  // namespace penumbra::cuda

#pragma once
// one pixel of a pinhole camera's ground-truth images, written once as PB_HOST_DEVICE
// functions: the batch kernel (cuda_batch_kernels.cu) runs them on the GPU, the host tests
// (tests/render/cuda/batch_layout_test.cc) on the CPU over the same BvhScene arrays. the ray
// through pixel (u, v) (pixel centres are integers) is o + t (((u - cx) inv_fx) ex +
// ((v - cy) inv_fy) ey + ez) of PinholeCamera (cuda_kernels.h), as Camera::GenerateRay
// (render/camera.h) for a camera without distortion or motion.

#include <cmath>
#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/cuda/bvh_traversal.h"
#include "penumbra/render/cuda/bvh_types.h"

namespace penumbra::cuda {

/// the ground truth of one pixel: depth along the optical axis (m; 0 = miss), range along the
/// ray (m; 0 = miss), the MuJoCo geom id (-1 = miss or no geom), the body (instance) id (-1 =
/// miss) and the semantic class (0 = miss), as RenderedFrame's depth_m, range_m, geom_id,
/// body_id and semantic_class.
struct PixelTruth {
  float depth = 0;
  float range = 0;
  int32_t geom_id = -1;
  int32_t body_id = -1;
  int32_t semantic = 0;
};

/// the world ray of pixel (u, v) of a pinhole camera given as origin o, axes ex, ey, ez (W),
/// principal point (cx, cy) px, inverse focal lengths inv_fx, inv_fy (1/px) and near plane
/// `near` (m): tmin = near, tmax = infinity; d is not unit (its z along ez is 1, so t is depth).
PB_HOST_DEVICE inline TraceRay PinholePixelRay(F3 o, F3 ex, F3 ey, F3 ez, float cx, float cy,
                                               float inv_fx, float inv_fy, float near, int u,
                                               int v) {
  const float x = (static_cast<float>(u) - cx) * inv_fx;
  const float y = (static_cast<float>(v) - cy) * inv_fy;
  TraceRay r;
  r.o = o;
  r.d = {x * ex.x + y * ey.x + ez.x, x * ex.y + y * ey.y + ez.y, x * ex.z + y * ey.z + ez.z};
  r.tmin = near;
  r.tmax = INFINITY;
  return r;
}

/// traces ray r (PinholePixelRay's) through scene s and returns the pixel's ground truth.
PB_HOST_DEVICE inline PixelTruth TracePixelTruth(const SceneView& s, const TraceRay& r) {
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
  return p;
}

}  // namespace penumbra::cuda

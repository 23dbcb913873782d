#pragma once
// smooth shading and texture coordinates at a triangle hit, written once for both backends
// (docs/gpu.md, "One shading code"): RayScene::FinishHit (render/embree/ray_scene.cc) mixes a
// mesh's vertex normals and texcoords with it on the CPU, the CUDA backend's HitShadingNormal
// and HitTexcoords (render/transport/primary_pixel.h) on the GPU and in BvhScene::FinishHit.
// C++17, Eigen-free.

#include "penumbra/core/host_device.h"

namespace penumbra {

/// the barycentric mix (1 - u - v) a0 + u a1 + v a2 of a triangle's vertex attributes at a
/// hit's barycentrics (u, v) (Embree's and Moller-Trumbore's: u weights vertex 1, v vertex 2).
/// V: any vector type with float scaling and addition (Eigen's vectors on the CPU, Float3 on
/// the GPU); per component the operations run in the order ((w a0 + u a1) + v a2).
template <typename V>
PB_HOST_DEVICE inline V BarycentricMix(const V& a0, const V& a1, const V& a2, float u, float v) {
  const float w = 1.0f - u - v;
  return w * a0 + u * a1 + v * a2;
}

}  // namespace penumbra

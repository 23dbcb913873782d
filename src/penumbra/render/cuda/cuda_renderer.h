#pragma once
// the CUDA backend's Renderer (render/renderer.h). on the GPU now: the images of the pixel
// centre's primary ray of a pinhole camera (no lens distortion, no motion) under clear
// conditions: depth, segmentation (geom ids), instance (body) and semantic segmentation,
// range and normals, traced by bvh_traversal.h's code in cuda_kernels.cu. everything else (rgb
// and radiance, distorted or moving cameras, effects) is not on the GPU yet: such a frame is
// rendered whole by the CPU renderer handed in (`cpu`), so every output exists and equals the
// CPU backend's for those frames; docs/gpu.md lists what is where.

#include <memory>
#include <string>

#include "penumbra/render/cuda/bvh_scene.h"
#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/renderer.h"

namespace penumbra::cuda {

/// Renderer on the GPU (see the file comment).
class CudaRenderer final : public Renderer {
 public:
  /// copies `scene` and builds its BVH on the host and device. `cpu` renders the frames the GPU
  /// cannot yet (not null).
  /// @throws Error as BvhScene, or if the CUDA runtime fails.
  CudaRenderer(const SceneDescription& scene, std::unique_ptr<Renderer> cpu);

  void Render(const WorldSnapshot& snapshot, const EffectsFrame* effects, const CameraView& view,
              RenderedFrame* out) override;

  /// true if `view` under `effects` renders on the GPU (else on the CPU renderer).
  static bool OnGpu(const EffectsFrame* effects, const CameraView& view);

  /// frames rendered on the GPU and on the CPU renderer so far.
  int64_t gpu_frames() const { return gpu_frames_; }
  int64_t cpu_frames() const { return cpu_frames_; }

  /// the scene's BVH (host side) and device copy, for benchmarks.
  const BvhScene& bvh() const { return *bvh_; }
  DeviceScene& device() { return *device_; }

  /// the GPU's pinhole form of `view` (view must be OnGpu).
  static PinholeCamera PinholeOf(const CameraView& view);

 private:
  SceneDescription scene_;
  std::unique_ptr<BvhScene> bvh_;
  std::unique_ptr<DeviceScene> device_;
  std::unique_ptr<Renderer> cpu_;
  int64_t gpu_frames_ = 0;
  int64_t cpu_frames_ = 0;
  bool told_cpu_ = false;
};

}  // namespace penumbra::cuda

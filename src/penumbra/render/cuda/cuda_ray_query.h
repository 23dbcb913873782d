#pragma once
// the CUDA backend's RayQuery (render/ray_query.h): the rays of a batch traced by
// bvh_traversal.h on the GPU (cuda_kernels.h), their hits finished on the host as BvhRayQuery
// finishes them (BvhScene::FinishHit). the LiDAR and the sky irradiance volume use it through
// MakeRayQuery (render/backends/renderer_factory.h) with backend cuda.

#include <memory>
#include <mutex>
#include <span>

#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/ray_query.h"

namespace penumbra::cuda {

/// the arrays and sizes of `scene` as DeviceScene::Sync takes them (`wait` as there).
void SyncDevice(const BvhScene& scene, DeviceScene* device, bool wait = true);

/// RayQuery on the GPU (see the file comment).
class CudaRayQuery final : public RayQuery {
 public:
  /// @throws Error as BvhScene, or if the CUDA runtime fails (no device: check ProbeDevice
  /// first). `scene` is referenced: it must outlive the query.
  explicit CudaRayQuery(const SceneDescription& scene);
  /// a query over another's BVH and its device copy (CudaRenderer's: the media's shadow rays
  /// of its frames), both referenced: they must outlive the query, and their owner poses them
  /// (Update throws). its batches run on device's stream, after what was queued there.
  CudaRayQuery(const BvhScene& bvh, DeviceScene* device);
  const SceneDescription& scene() const override { return bvh_->scene(); }
  /// @throws Error for a query over another's BVH (its owner poses it).
  void Update(const WorldSnapshot& snapshot) override;

 private:
  void IntersectBatch(std::span<const Ray> rays, std::span<SurfaceHit> hits,
                      std::span<bool> did_hit) const override;
  /// RayQuery::Occluded: the batch's verdicts in one kernel launch (TraceOccluded in
  /// (tmin, tmax); untraceable rays are not occluded).
  void OccludedBatch(std::span<const Ray> rays, std::span<bool> occluded) const override;
  std::unique_ptr<BvhScene> own_bvh_;        // null for a query over another's BVH
  std::unique_ptr<DeviceScene> own_device_;  // likewise
  const BvhScene* bvh_;
  DeviceScene* device_;
  // Intersect is thread-safe (RayQuery): one batch at a time on the device
  mutable std::mutex mutex_;
};

}  // namespace penumbra::cuda

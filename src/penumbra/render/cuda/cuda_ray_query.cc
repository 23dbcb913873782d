#include "penumbra/render/cuda/cuda_ray_query.h"

#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/frame/bvh_ray_query.h"

namespace penumbra::cuda {
namespace {

// the traversal's form of each ray; an untraceable ray is a miss, traced as an empty segment
// (tmax < tmin).
std::vector<TraceRay> TraceRaysOf(std::span<const Ray> rays) {
  std::vector<TraceRay> in(rays.size());
  for (size_t i = 0; i < rays.size(); ++i) {
    in[i] = ToTraceRay(rays[i]);
    if (!IsTraceableRay(rays[i])) in[i] = {{0, 0, 0}, {0, 0, 1}, 1, 0};
  }
  return in;
}

}  // namespace

void SyncDevice(const BvhScene& scene, DeviceScene* device, bool wait) {
  DeviceScene::Sizes n;
  n.nodes = static_cast<int64_t>(scene.nodes().size());
  n.prims = static_cast<int64_t>(scene.prims().size());
  n.triangles = static_cast<int64_t>(scene.triangles().size());
  n.analytics = static_cast<int64_t>(scene.analytics().size());
  n.blases = static_cast<int64_t>(scene.blases().size());
  n.records = static_cast<int64_t>(scene.records().size());
  n.shading = static_cast<int64_t>(scene.shading().size());
  device->Sync(scene.view(), n, scene.geometry_version(), wait);
}

CudaRayQuery::CudaRayQuery(const SceneDescription& scene)
    : own_bvh_(std::make_unique<BvhScene>(scene)),
      own_device_(std::make_unique<DeviceScene>()),
      bvh_(own_bvh_.get()),
      device_(own_device_.get()) {
  SyncDevice(*bvh_, device_);
}

CudaRayQuery::CudaRayQuery(const BvhScene& bvh, DeviceScene* device)
    : bvh_(&bvh), device_(device) {}

void CudaRayQuery::Update(const WorldSnapshot& snapshot) {
  if (!own_bvh_)
    throw Error("CudaRayQuery::Update: a query over another's BVH is posed by its owner");
  own_bvh_->Update(snapshot);
  SyncDevice(*own_bvh_, device_);
}

void CudaRayQuery::IntersectBatch(std::span<const Ray> rays, std::span<SurfaceHit> hits,
                                  std::span<bool> did_hit) const {
  const std::vector<TraceRay> in = TraceRaysOf(rays);
  std::vector<TraceHit> out(rays.size());
  // one batch at a time on the device; the hits are finished outside the lock, so that the
  // threads of a parallel caller (the sky irradiance volume's build) finish theirs together
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    device_->Trace(in.data(), static_cast<int64_t>(in.size()), out.data());
  }
  for (size_t i = 0; i < rays.size(); ++i) {
    did_hit[i] = out[i].instance >= 0;
    if (did_hit[i]) bvh_->FinishHit(rays[i], out[i], &hits[i]);
  }
}

void CudaRayQuery::OccludedBatch(std::span<const Ray> rays, std::span<bool> occluded) const {
  const std::vector<TraceRay> in = TraceRaysOf(rays);
  std::vector<uint8_t> out(rays.size());
  {
    const std::lock_guard<std::mutex> lock(mutex_);
    device_->Occluded(in.data(), static_cast<int64_t>(in.size()), out.data());
  }
  for (size_t i = 0; i < rays.size(); ++i) occluded[i] = out[i] != 0;
}

}  // namespace penumbra::cuda

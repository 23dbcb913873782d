#pragma once
// the CUDA backend's realtime path run on the CPU (RenderRealtimeOnHost: the kernels'
// PB_HOST_DEVICE functions) for one scene at one snapshot, shared by the host-path tests
// (realtime_effects_test.cc, realtime_media_test.cc). no GPU needed.

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/cuda/realtime_host.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/ray_query.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/render/renderer.h"

namespace penumbra::host_path {

/// the BVH and frame data of `scene` at `snap` built once (the frame data's sky irradiance
/// volume, traced through the host BVH, is most of a host-path test's time), then any number of
/// frames, as CudaRenderer renders frame after frame with one RealtimeFrameData. `snap` must
/// outlive this object.
class HostPath {
 public:
  HostPath(const SceneDescription& scene, const WorldSnapshot& snap,
           const RenderSettings& settings = RenderSettings())
      : snap_(snap), bvh_(scene), data_(scene, settings) {
    bvh_.Update(snap);
  }

  /// the frame of `view` under `fx` (null: none), stored surface terms (the kernels' default),
  /// the media's shadow rays through `media_rays` (null: the frame data's own BvhRayQuery);
  /// *has_media (may be null) says whether the frame built media.
  RenderedFrame Render(const CameraView& view, const EffectsFrame* fx, bool* has_media = nullptr,
                       const RayQuery* media_rays = nullptr) {
    data_.Prepare(snap_, view, &pool_, fx, nullptr, media_rays);
    if (has_media != nullptr) *has_media = data_.has_media();
    RenderedFrame out;
    cuda::RenderRealtimeOnHost(data_, bvh_, &pool_, &out, /*stored_surface=*/true);
    return out;
  }

  cuda::RealtimeFrameData& data() { return data_; }
  ThreadPool& pool() { return pool_; }
  /// the host BVH posed for the snapshot (RenderRealtimeOnHost's).
  const cuda::BvhScene& bvh() const { return bvh_; }

 private:
  const WorldSnapshot& snap_;
  cuda::BvhScene bvh_;
  cuda::RealtimeFrameData data_;
  ThreadPool pool_{0};
};

}  // namespace penumbra::host_path

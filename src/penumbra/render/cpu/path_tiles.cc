#include "penumbra/render/cpu/path_tiles.h"

#include <utility>

#include "penumbra/render/cpu/embree_tracer.h"
#include "penumbra/render/transport/path_trace.h"

namespace penumbra {

PathTiles::PathTiles(const SceneDescription& scene, const RenderSettings& settings,
                     ThreadPool* pool)
    : bvh_(scene, pool),
      data_(scene, settings, RaySceneFactory()),
      emitters_(scene),
      emitter_host_(emitters_) {}

void PathTiles::Prepare(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                        const CameraView& view, ThreadPool* pool) {
  bvh_.Update(snapshot);
  // the media are the paths' own (media_), not the realtime tier's volumes
  data_.Prepare(snapshot, view, pool, cuda::EffectsWithoutMedia(effects, &no_media_));
  media_.Build(effects != nullptr && !effects->empty() ? effects : nullptr);
  pf_ = cuda::PathView(data_, data_.View(bvh_.view(), nullptr), data_.frame_sky().sampling_pod());
  if (!emitters_.empty()) {
    emitter_host_.SetPoses(emitters_, snapshot.X_WB);
    pf_.emitters = emitter_host_.View();
  }
  if (!media_.empty()) pf_.media = media_.View();
  pf_.streaks = data_.path_streaks().View();
  const cuda::PinholeCamera& c = data_.camera();
  buffers_.Resize(static_cast<int64_t>(c.width) * c.height);
  pf_.radiance = buffers_.radiance.data();
  pf_.albedo = buffers_.albedo.data();
  pf_.normal = buffers_.normal.data();
  pf_.depth = buffers_.depth.data();
}

int64_t PathTiles::TraceTile(const RayScene& rays, const PixelTile& tile,
                             const std::atomic<int>* stop_request,
                             std::atomic<bool>* stopped) const {
  const EmbreeTracer tracer{rays, bvh_};
  const auto stop = [stop_request] {
    return stop_request != nullptr && stop_request->load(std::memory_order_relaxed) != 0;
  };
  for (int y = tile.y0; y < tile.y0 + tile.height; ++y)
    for (int x = tile.x0; x < tile.x0 + tile.width; ++x)
      if (!cuda::PathTracePixel(pf_, tracer, x, y, stop)) {
        if (stopped != nullptr) stopped->store(true, std::memory_order_relaxed);
        return tracer.traced;
      }
  return tracer.traced;
}

void PathTiles::Finish(const Denoiser* denoiser, const Eigen::Vector3f& white_balance_gains,
                       bool develop, ThreadPool* pool, RenderedFrame* out) const {
  if (develop) {
    ImageF depth = std::move(out->depth_m);
    cuda::FinishPathFrame(data_, buffers_, denoiser, white_balance_gains, false, pool, out);
    out->depth_m = std::move(depth);
    return;
  }
  const cuda::PinholeCamera& c = data_.camera();
  if (out->radiance.width != c.width || out->radiance.height != c.height ||
      out->radiance.channels != 3)
    out->radiance = ImageF(c.width, c.height, 3);
  for (size_t i = 0; i < buffers_.radiance.size(); ++i) {
    out->radiance.data[3 * i] = buffers_.radiance[i].x;
    out->radiance.data[3 * i + 1] = buffers_.radiance[i].y;
    out->radiance.data[3 * i + 2] = buffers_.radiance[i].z;
  }
}

}  // namespace penumbra

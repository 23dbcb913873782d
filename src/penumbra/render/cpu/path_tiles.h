#pragma once
// the `pathtraced` tier on the CPU: the transport's one path chain (render/transport/
// path_trace.h, where the model is documented: PathTracePixel) traced over Embree
// (EmbreeTracer), pixel by pixel in the renderer's tiles, on the plain-data frame both backends
// build (render/frame: RealtimeFrameData's posed scene, materials, textures, lights, sky, camera
// and particle streaks, PathView, the emissive geoms of EmitterSampler, the media of MediaScene),
// then finished as every pathtraced frame is (FinishPathFrame: the a-trous denoiser guided by
// the chain's albedo, normal and depth when the settings denoise, the film's auto exposure and
// development). the GPU runs the same chain (render/cuda/path_kernels.cu) over its BVH.
//
// random numbers: sample s of pixel (u, v) draws from Rng(HashKeys(HashKeys(frame key, v W + u),
// s)) only (TracePath; the frame key is FrameContext::FrameKey of the seed, camera and frame),
// as on the GPU, so images are bit-identical for any thread count and tile order.
//
// stopping: before every sample the tile reads the renderer's stop request; once it is set the
// tile is left unfinished and *stopped set, so a stop (SIGINT) waits for at most one path per
// render thread.

#include <atomic>
#include <cstdint>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/cpu/integrator.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/film/denoiser.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/frame/path_buffers.h"
#include "penumbra/render/frame/path_frame.h"
#include "penumbra/render/frame/realtime_frame.h"
#include "penumbra/render/light/emitter_sampler.h"
#include "penumbra/render/media/media_scene.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/effects_frame.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// the pathtraced tier's frames on the CPU. Prepare, then TraceTile for disjoint tiles from
/// any threads, then Finish.
class PathTiles {
 public:
  /// the frame data of `scene` (referenced: it must outlive this) under `settings` (samples per
  /// pixel, bounces, seed, film); the BVH scene's arrays (the hits' names) built over `pool`
  /// (referenced; may be null).
  /// @throws Error as BvhScene, RealtimeFrameData and EmitterSampler (missing meshes,
  /// materials, textures with too many levels).
  PathTiles(const SceneDescription& scene, const RenderSettings& settings, ThreadPool* pool);

  /// the frame of `view` at `snapshot` under `effects` (null: none): the BVH scene's poses, the
  /// frame data (RealtimeFrameData::Prepare without the media, which the paths trace
  /// themselves: MediaScene), the emitters' poses, and the output buffers for the view's pixels.
  /// @throws ConfigError for effects out of range or malformed particle sets (as Prepare).
  void Prepare(const WorldSnapshot& snapshot, const EffectsFrame* effects, const CameraView& view,
               ThreadPool* pool);

  /// traces the pixels of `tile` (PathTracePixel over EmbreeTracer on `rays`, posed for the
  /// prepared snapshot) into the frame's buffers; returns the rays traced. reads `stop_request`
  /// (may be null) before every sample: once it is non-zero, leaves the tile and sets *stopped.
  /// tiles may run concurrently.
  int64_t TraceTile(const RayScene& rays, const PixelTile& tile,
                    const std::atomic<int>* stop_request, std::atomic<bool>* stopped) const;

  /// the finish of the traced frame: `develop` (FinishPathFrame): out->radiance, denoised when
  /// `denoiser` is given, out->ev100 and out->rgb (`white_balance_gains`: the view's); else
  /// out->radiance only, as traced. out->depth_m is left as it is.
  void Finish(const Denoiser* denoiser, const Eigen::Vector3f& white_balance_gains, bool develop,
              ThreadPool* pool, RenderedFrame* out) const;

  /// the prepared frame's plain data (tests).
  const cuda::PathFrameView& frame() const { return pf_; }
  const cuda::BvhScene& bvh() const { return bvh_; }

 private:
  cuda::BvhScene bvh_;
  cuda::RealtimeFrameData data_;
  EmitterSampler emitters_;
  cuda::PathEmitterHost emitter_host_;
  MediaScene media_;
  EffectsFrame no_media_;  // the frame's effects without media (EffectsWithoutMedia)
  cuda::PathBuffers buffers_;
  cuda::PathFrameView pf_;
};

}  // namespace penumbra

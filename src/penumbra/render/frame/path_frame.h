#pragma once
// the host side of the pathtraced tier (render/transport/path_trace.h per pixel: the GPU's
// path_kernels.cu, the CPU's render/cpu/path_tiles.h): the frame's plain data (PathFrameView over
// a prepared RealtimeFrameData: the same posed scene, materials, textures, lights and sky; the
// emissive geoms), and the finish every pathtraced frame gets on the host: the a-trous denoiser
// (render/film/denoiser.h, guided by the chain's albedo, normal and depth) when the settings ask
// for it, then the film's auto exposure and development (render/film/film.h). no CUDA runtime
// here.

#include <vector>

#include "penumbra/core/image.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/film/denoiser.h"
#include "penumbra/render/frame/path_buffers.h"
#include "penumbra/render/frame/realtime_frame.h"
#include "penumbra/render/light/emitter_sampler.h"
#include "penumbra/render/renderer.h"
#include "penumbra/render/transport/path_trace.h"

namespace penumbra::cuda {

/// the emissive geoms of an EmitterSampler as the path kernels take them (PathEmitters over
/// host arrays: the pods and pick cdf point into the sampler, which must outlive this) and the
/// frame's poses (SetPoses).
struct PathEmitterHost {
  std::vector<EmitterPod> pods;
  std::vector<Float3> Le;
  std::vector<int32_t> emitter_of_geom;
  std::vector<double> poses;  ///< 12 an emitter: rotation row-major, translation
  const std::vector<double>* pick_cdf = nullptr;
  /// the sampler's emitters (poses: none yet).
  explicit PathEmitterHost(const EmitterSampler& sampler);
  /// every emitter's geom pose for body poses X_WB (EmitterSampler::EmitterPose).
  void SetPoses(const EmitterSampler& sampler, const std::vector<Pose>& X_WB);
  /// the view over these arrays (num 0 without emitters).
  PathEmitters View() const;
};

/// the pathtraced frame of `data` (Prepared for the view; its settings' samples_per_pixel and
/// max_bounces) as the path kernels read it, with the output arrays left null: `frame` is
/// data's View (host arrays) or its device copy (DeviceRealtime::DeviceFrame), `sky_sampling`
/// the frame sky's sampling tables in the same memory.
PathFrameView PathView(const RealtimeFrameData& data, const RealtimeFrameView& frame,
                       const SkySamplingPod& sky_sampling);

/// the finish of a pathtraced frame: out->radiance from b.radiance, denoised with the albedo,
/// normal and depth guides when `denoiser` is given, out->ev100 and out->rgb from data's film
/// (the view's white-balance gains), and out->depth_m from b.depth when `want_depth`.
void FinishPathFrame(const RealtimeFrameData& data, const PathBuffers& b, const Denoiser* denoiser,
                     const Eigen::Vector3f& white_balance_gains, bool want_depth, ThreadPool* pool,
                     RenderedFrame* out);

/// `effects` without its media (null where nothing else is left): what the pathtraced tier's
/// RealtimeFrameData::Prepare takes (the paths trace the media themselves, so the realtime
/// tier's media volumes are not built).
const EffectsFrame* EffectsWithoutMedia(const EffectsFrame* effects, EffectsFrame* storage);

}  // namespace penumbra::cuda

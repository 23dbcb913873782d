#pragma once
// the realtime chain of render/transport/realtime.h run on the host over the BVH (tests: the
// parity of the GPU path with the CPU backend without a GPU), and the sky's plain data for the
// device copies. the frame data comes from render/frame/realtime_frame.h.

#include <vector>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/cuda/cuda_realtime.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/frame/realtime_frame.h"
#include "penumbra/render/renderer.h"

namespace penumbra::cuda {

/// the sky model's and the sky volume's plain data of `data`'s prepared frame (host arrays) for
/// the device copies (DeviceRealtime::UploadSky); current while data.sky_generation() is
/// unchanged.
RealtimeSky SkyDataOf(const RealtimeFrameData& data);

/// the host arrays of the media volumes a frame builds itself (BuildMediaVolumesOnHost).
struct MediaVolumeArrays {
  std::vector<float> trans, vis;  // the world light volume, [cell][light]
  std::vector<Rgb4> fog;          // the fog froxels' records
  std::vector<float> inv_log_far;
  GridVolumeArrays grids;  // the grids' light volumes and froxels
};

/// the media volumes that frame f leaves to itself (f->media_build) built on the CPU with the
/// kernels' functions over `pool` into *out, and f->media pointed at them, in the device's
/// order: the grids' light volumes (MediaGridLightCell, its shadow rays through f->scene), the
/// grid froxels (MediaGridFroxelColumn), the world light volume (MediaLightVolumeCell), the fog
/// froxels (MediaFogColumn). nothing without media or such volumes.
void BuildMediaVolumesOnHost(RealtimeFrameView* f, ThreadPool* pool, MediaVolumeArrays* out);

/// renders a realtime frame (rgb, radiance, depth) with the GPU path's per-pixel functions on
/// the CPU over `bvh` (posed for the frame) and `data` (Prepared for it): the parity of the GPU
/// path with the CPU backend can be checked on machines without a GPU. rows over `pool`.
/// `stored_surface`: shade each pixel from the material terms its primary geometry kept
/// (ShadeRealtimeStored, the kernels' default) instead of evaluating the surface again
/// (ShadeRealtimePixel); the two give the same bits. `strided_terms` (with stored_surface):
/// the lights' terms wait between ShadeRealtimePoint's loops in a row's array interleaved over
/// its pixels (StridedLightTerms, as the shading kernel's shared memory) instead of each pixel's
/// own (LocalLightTerms); the same bits. `queued_shadows` (with stored_surface, at most
/// kMaxQueuedShadowLights lights): the shadow rays apart in three passes as the kernels'
/// queued shadow rays (ShadeQueuedStored, each ray traced from QueuedRay, SumQueuedLights; the
/// lights' terms in each pixel's own arrays); the same bits. `tiled_visibility`: the shared
/// visibility by 16x16 shadow tiles, each tile's verdicts, ray counts and fractions copied into
/// tile arrays where the windows find their neighbours, as the kernels' blocks do in shared
/// memory (SharedVisibilityRays' tile form, SharedWindowFraction, SharedLampFraction); the same
/// bits.
void RenderRealtimeOnHost(const RealtimeFrameData& data, const BvhScene& bvh, ThreadPool* pool,
                          RenderedFrame* out, bool stored_surface = false,
                          bool strided_terms = false, bool queued_shadows = false,
                          bool tiled_visibility = false);

}  // namespace penumbra::cuda

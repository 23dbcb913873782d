// the realtime tier's kernels (cuda_realtime.h): each runs the PB_HOST_DEVICE per-pixel
// functions of realtime_shading.h, which RenderRealtimeOnHost runs on the CPU.

#include <cooperative_groups.h>
#include <cooperative_groups/scan.h>
#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/cuda/cuda_realtime.h"
#include "penumbra/render/cuda/media_grid_upload.h"
#include "penumbra/render/cuda/realtime_shading.h"
#include "penumbra/render/cuda/streak_upload.h"

namespace penumbra::cuda {
namespace {

namespace cg = cooperative_groups;

constexpr unsigned kFullWarp = 0xffffffffu;

// where a kernel finds its frame: one frame passed by value (Render), or camera blockIdx.z's of
// a batch's array of frames in device memory (RealtimeBatch). a kernel's per-pixel arrays that
// are not in the frame hold every camera's image in turn (camera z at z * width * height), so
// Pixels(f) is the offset of this block's camera (0 for one frame).
struct OneFrame {
  RealtimeFrameView f;
  __device__ const RealtimeFrameView& get() const { return f; }
  __device__ const RealtimeFrameView& at(int) const { return f; }
};
struct BatchFrames {
  const RealtimeFrameView* __restrict__ f;
  __device__ const RealtimeFrameView& get() const { return f[blockIdx.z]; }
  __device__ const RealtimeFrameView& at(int camera) const { return f[camera]; }
};
__device__ inline int64_t CameraOffset(const RealtimeFrameView& f) {
  return static_cast<int64_t>(blockIdx.z) * f.camera.width * f.camera.height;
}

// the pixel of a per-pixel kernel's thread (PixelOf): column u, row v, its index i in its
// frame's image and k in the arrays of every camera (i + CameraOffset); false outside the image
// or its rows.
struct FramePixel {
  int u = 0, v = 0;
  int64_t i = 0, k = 0;
  bool inside = false;
  __device__ explicit operator bool() const { return inside; }
};

// the blocks of the kernels that work a shadow tile (render/shadow_window_math.h) at a time:
// one thread a pixel of the tile (whose pixels' windows never leave it).
constexpr int kTilePixels = kShadowTileSize * kShadowTileSize;
const dim3 kTileBlock(kShadowTileSize, kShadowTileSize);

// this thread's pixel of frame f in a grid over rows [row0, row1) (row1 < 0: to the last row),
// one thread a pixel (blockIdx and threadIdx x and y).
__device__ inline FramePixel PixelOf(const RealtimeFrameView& f, int row0 = 0, int row1 = -1) {
  FramePixel p;
  p.u = static_cast<int>(blockIdx.x * blockDim.x + threadIdx.x);
  p.v = row0 + static_cast<int>(blockIdx.y * blockDim.y + threadIdx.y);
  if (p.u >= f.camera.width || p.v >= (row1 < 0 ? f.camera.height : row1)) return p;
  p.i = static_cast<int64_t>(p.v) * f.camera.width + p.u;
  p.k = CameraOffset(f) + p.i;
  p.inside = true;
  return p;
}

// hits, surfaces: null, or where the primary hits and their material terms are kept for the
// shading kernel. kMinBlocks: as ShadeKernel's (5: at most 102 registers, 5 blocks of 128
// threads an SM).
template <class Frames, int kMinBlocks>
__global__ void __launch_bounds__(128, kMinBlocks)
    GeometryKernel(Frames frames, PixelGeometry* geometry, float* depth, TraceHit* hits,
                   SurfaceTerms* surfaces) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (!p) return;
  float t;
  geometry[p.k] = PrimaryGeometry(f, p.u, p.v, &t, hits ? &hits[p.k] : nullptr,
                                  surfaces ? &surfaces[p.k] : nullptr);
  depth[p.k] = t;
}

// the particle streaks over the final radiance (ApplyStreak): one thread per streak pixel, each
// pixel at most once.
__global__ void StreakKernel(const StreakPixel* streaks, int64_t count, const float* depth,
                             Float3* radiance) {
  const int64_t k = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (k >= count) return;
  const StreakPixel s = streaks[k];
  radiance[s.pixel] = ApplyStreak(s, depth[s.pixel], radiance[s.pixel]);
}

// the splat's warps at most when the streaks' count is on the device (StreakSplatView::count):
// about as many as an H100 holds resident (132 SMs x 64), more than a rain frame's streaks.
constexpr int64_t kSplatWarps = 8192;

// the realtime particle streaks' splat (SplatStreakRow): a warp per streak, its lanes over the
// rows of the streak's pixel box (rain falls: a streak is mostly taller than wide), every hit
// kept by a 64-bit integer atomicMin of its StreakKey (order-independent: deterministic). the
// warps stride over the streaks, whose count is f.splat.streaks.num or, for the device
// culling's streaks read in place, *f.splat.count (num then only a bound: LaunchStreakSplat
// sizes the grid by it).
__global__ void StreakSplatKernel(RealtimeFrameView f) {
  const int64_t warp = (blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x) / 32;
  const int64_t warps = gridDim.x * static_cast<int64_t>(blockDim.x) / 32;
  const int lane = static_cast<int>(threadIdx.x & 31);
  const int64_t num = SplatStreakCount(f.splat);
  for (int64_t k = warp; k < num; k += warps) {
    const StreakProjection p = SplatProjection(f, f.splat.streaks.streaks[k]);
    if (p.empty()) continue;
    for (int v = p.v0 + lane; v <= p.v1; v += 32) SplatStreakRow(f, static_cast<int>(k), p, v);
  }
}

// the splat's nearest streak of every pixel shaded (ShadeSplatPixel): one thread per pixel.
__global__ void StreakShadeKernel(RealtimeFrameView f) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= f.camera.width || v >= f.camera.height) return;
  ShadeSplatPixel(f, u, v);
}

// the splat's streaks over the final radiance (ApplyStreak; with media: MediaViewQuad): one
// thread per pixel.
__global__ void StreakSplatApplyKernel(RealtimeFrameView f, const float* depth, Float3* radiance) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= f.camera.width || v >= f.camera.height) return;
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  StreakPixel s;
  if (PixelStreakOf(f, i, &s)) radiance[i] = ApplyStreak(s, depth[i], radiance[i]);
}

// the media (homogeneous and grids) and the particle streaks seen through them over the final
// radiance (MediaViewQuad): one thread per 2x2 quad, each writing its own pixels.
__global__ void MediaViewKernel(RealtimeFrameView f, const float* depth, Float3* radiance) {
  const int qu = blockIdx.x * blockDim.x + threadIdx.x;
  const int qv = blockIdx.y * blockDim.y + threadIdx.y;
  if (2 * qu >= f.camera.width || 2 * qv >= f.camera.height) return;
  MediaViewQuad(f, 2 * qu, 2 * qv, depth, radiance);
}

// the media volumes a frame builds itself (RealtimeFrameView::media_build), before the kernels
// that read them: one thread per cell of the world light volume (its shadow rays traced in the
// thread), then the fog froxels (which read the light volume's visibility).
__global__ void MediaLightVolumeKernel(RealtimeFrameView f, int64_t cells, float* trans_cl,
                                       float* vis_cl) {
  const int64_t c = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (c >= cells) return;
  MediaLightVolumeCell(f, c, trans_cl, vis_cl);
}
// one block per fog froxel column, one thread per slice (kFogFroxelSlices of kFogSliceBlock),
// then the column's records summed in slice order by its first thread (FogFroxelRecords: the
// bits of MediaFogColumn's serial loop).
constexpr int kFogSliceBlock = 64;
static_assert(kFogFroxelSlices <= kFogSliceBlock, "one block holds a column's slices");
__global__ void MediaFogSliceKernel(RealtimeFrameView f, const float* vis_cl, Rgb4* S,
                                    float* inv_log_far) {
  // the increments as plain floats (a __shared__ array takes no initialisers: Float3 has them)
  __shared__ float inc[3 * kFogFroxelSlices];
  const int c = blockIdx.x, k = threadIdx.x;
  if (k < kFogFroxelSlices) {
    const Float3 v = MediaFogSlice(f, c, k, vis_cl, inv_log_far);
    inc[3 * k] = v.x;
    inc[3 * k + 1] = v.y;
    inc[3 * k + 2] = v.z;
  }
  __syncthreads();
  if (k != 0) return;
  Float3 column[kFogFroxelSlices];
  for (int i = 0; i < kFogFroxelSlices; ++i)
    column[i] = Float3{inc[3 * i], inc[3 * i + 1], inc[3 * i + 2]};
  FogFroxelRecords(column,
                   reinterpret_cast<float*>(S + static_cast<int64_t>(c) * (kFogFroxelSlices + 1)));
}

// the grids' light volumes a frame builds itself (f.media_build.grids), before the kernels
// that read them: one thread per cell of every grid's volume, counted end to end (its shadow
// rays traced in the thread; MediaGridLightCell).
__global__ void MediaGridLightKernel(RealtimeFrameView f, int64_t cells, float* grid_T,
                                     Float3* source) {
  const int64_t c = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (c >= cells) return;
  MediaGridLightCell(f, c, grid_T, source);
}
// the grid froxels (after the grids' light volumes, whose sources they read): one block per
// column, one thread per slice (kFroxelSlices of kGridSliceBlock; MediaGridSlice), then the
// column's records accumulated in slice order by its first thread (GridFroxelRecords: the bits of
// MediaGridFroxelColumn's serial loop).
constexpr int kGridSliceBlock = 32;
static_assert(kFroxelSlices <= kGridSliceBlock, "one block holds a column's slices");
__global__ void MediaGridFroxelKernel(RealtimeFrameView f, const Float3* source, float* t0,
                                      float* t1, float* slices_per_m,
                                      GridFroxelRecord<Rgb4>* records) {
  // each slice's step as 10 plain floats (a __shared__ array takes no initialisers)
  __shared__ float step[10 * kFroxelSlices];
  const int c = blockIdx.x, k = threadIdx.x;
  const MediaGridColumnInputs in = MediaGridColumnOf(f, c, source);
  if (k < kFroxelSlices) {
    const GridFroxelStep s = MediaGridSlice(in, k);
    float* o = step + 10 * k;
    o[0] = s.src.x, o[1] = s.src.y, o[2] = s.src.z;
    o[3] = s.step_T.x, o[4] = s.step_T.y, o[5] = s.step_T.z;
    o[6] = s.factor.x, o[7] = s.factor.y, o[8] = s.factor.z;
    o[9] = static_cast<float>(s.any);
  }
  __syncthreads();
  if (k != 0) return;
  MediaGridColumnSpan(in, c, t0, t1, slices_per_m);
  GridFroxelStep column[kFroxelSlices];
  for (int i = 0; i < kFroxelSlices; ++i) {
    const float* o = step + 10 * i;
    column[i].src = Float3{o[0], o[1], o[2]};
    column[i].step_T = Float3{o[3], o[4], o[5]};
    column[i].factor = Float3{o[6], o[7], o[8]};
    column[i].any = o[9] != 0.0f ? 1 : 0;
  }
  GridFroxelRecords(
      column, reinterpret_cast<float*>(records + static_cast<int64_t>(c) * (kFroxelSlices + 1)));
}

// the mirror layer (realtime_shading.h): the mirrored rays after the geometry kernel; their
// shading and the blend after the shared visibility.
// they run only where the frame has a mirror layer (a batch launches them for every camera
// when one of its worlds has one).
template <class Frames>
__global__ void MirrorTraceKernel(Frames frames) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (p && f.any_mirror != 0) TraceMirrorRay(f, p.u, p.v);
}

template <class Frames>
__global__ void MirrorShadeKernel(Frames frames) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (p && f.any_mirror != 0) ShadeMirrorHit(f, p.u, p.v);
}

template <class Frames>
__global__ void MirrorBlendKernel(Frames frames, Float3* radiance) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (p && f.any_mirror != 0) radiance[p.k] = ApplyMirrorLayer(f, p.u, p.v, radiance[p.k]);
}

// the sky terms (realtime_shading.h): one thread per 2x2 quad of primary geometry (the quads
// that share one probe blend), and one per mirrored ray.
template <class Frames>
__global__ void SkyQuadKernel(Frames frames, Float3* sky) {
  const RealtimeFrameView& f = frames.get();
  const int qu = blockIdx.x * blockDim.x + threadIdx.x;
  const int qv = blockIdx.y * blockDim.y + threadIdx.y;
  const int W = f.camera.width, H = f.camera.height;
  if (2 * qu >= W || 2 * qv >= H) return;
  QuadSkyTerms(f.sky, f.volume, f.geometry, W, H, 2 * qu, 2 * qv, sky + CameraOffset(f));
}

template <class Frames>
__global__ void MirrorSkyKernel(Frames frames, Float3* mirror_sky) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (p && f.any_mirror != 0)
    MirrorSkyTerm(f.sky, f.volume, f.mirror_geometry[p.i], &mirror_sky[p.k]);
}

// kReuse: the primary hit from GeometryKernel (else traced again); kMinBlocks: blocks of 128
// threads each SM must hold (__launch_bounds__: at most 65536 / (128 kMinBlocks) registers).
// rows [row0, row1) of the frame (Render shades the image band by band as the bands' sky terms
// arrive).
template <bool kReuse, int kMinBlocks>
__global__ void __launch_bounds__(128, kMinBlocks)
    ShadeKernel(RealtimeFrameView f, const TraceHit* hits, Float3* radiance, int row0, int row1) {
  const FramePixel p = PixelOf(f, row0, row1);
  if (!p) return;
  const TraceRay r = PrimaryRay(f.camera, p.u, p.v);
  TraceHit h;
  if (kReuse)
    h = hits[p.i];
  else
    TraceClosest(f.scene, r, &h);
  radiance[p.i] = ShadeRealtimeHit(f, p.u, p.v, r, h);
}

// this thread's StridedLightTerms of `lights` lights in its block's dynamic shared memory
// (ShadeLightTermBytes of it: the block's threads interleaved).
__device__ inline StridedLightTerms BlockLightTerms(int lights) {
  extern __shared__ float light_terms[];
  StridedLightTerms terms;
  terms.at = light_terms + threadIdx.y * blockDim.x + threadIdx.x;
  terms.stride = static_cast<int>(blockDim.x * blockDim.y);
  terms.lights = lights;
  return terms;
}

// ShadeKernel from the shading points GeometryKernel kept (their geometry and material terms,
// ShadeRealtimeStored): no second surface evaluation. kMedia false: frames without media only
// (the default variant of frames without media and batches; ShadeRealtimePoint). kSharedTerms
// (RealtimeKernelOptions::shared_light_terms): the first `lights` lights' unshadowed terms wait
// between the light loops in the block's dynamic shared memory (StridedLightTerms,
// ShadeLightTermBytes of it), not in the thread's stack (LocalLightTerms).
template <class Frames, int kMinBlocks, bool kMedia = true, bool kSharedTerms = false>
__global__ void __launch_bounds__(128, kMinBlocks)
    ShadeStoredKernel(Frames frames, const SurfaceTerms* surfaces, Float3* radiance, int row0,
                      int row1, int lights = 0) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f, row0, row1);
  if (!p) return;
  if constexpr (kSharedTerms) {
    StridedLightTerms terms = BlockLightTerms(lights);
    radiance[p.k] = ShadeRealtimeStored<kMedia>(f, p.u, p.v, f.geometry[p.i], surfaces[p.k], terms);
  } else {
    radiance[p.k] = ShadeRealtimeStored<kMedia>(f, p.u, p.v, f.geometry[p.i], surfaces[p.k]);
  }
}

// the lights whose terms ShadeStoredKernel<..., true> keeps in shared memory for a frame of
// `num_lights` lights, and the bytes that takes for a block of `threads` threads.
inline int ShadeSharedLights(int num_lights) {
  return std::min(std::max(num_lights, 0), kShadeCachedLights);
}
inline size_t ShadeLightTermBytes(int lights, int threads) {
  return sizeof(float) * StridedLightTerms::kLightTermFloats * lights * threads;
}

// the queued shadow rays (RealtimeKernelOptions::queue_shadow_rays): the device's queue and
// each pixel's masks and verdicts (per pixel of the frame, or of the whole batch).
struct ShadowRayQueue {
  QueuedShadowRay* rays = nullptr;
  unsigned* count = nullptr;  // rays queued (never more than the room: a ray per pixel and light)
  QueuedLightMasks* masks = nullptr;
  uint32_t* occluded = nullptr;  // bit j: light j's ray hit something (integer atomicOr)
};

// ShadeQueuedLights' queue on the device: the lanes that push at once take their room with one
// atomic add (the order varies from run to run; each ray's verdict is its own).
struct DeviceShadowPush {
  QueuedShadowRay* rays;
  unsigned* count;
  uint32_t pixel;  // in the whole batch
  __device__ void Push(int j, const TraceRay& r) const {
    const cg::coalesced_group g = cg::coalesced_threads();
    unsigned base = 0;
    if (g.thread_rank() == 0) base = atomicAdd(count, g.size());
    const unsigned at = g.shfl(base, 0) + g.thread_rank();
    rays[at] = QueueEntryOf(r, pixel, j);
  }
};

// pass 1 of the queued shadow rays (ShadeQueuedStored): rows [row0, row1), the ambient term to
// `radiance`, the masks, the verdicts cleared, the shadow rays to the queue. kSharedTerms: the
// lights' terms in the block's dynamic shared memory (as ShadeStoredKernel's).
template <class Frames, bool kMedia, bool kSharedTerms>
__global__ void __launch_bounds__(128)
    ShadeQueuedKernel(Frames frames, const SurfaceTerms* surfaces, Float3* radiance,
                      ShadowRayQueue q, int row0, int row1, int lights) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f, row0, row1);
  if (!p) return;
  const DeviceShadowPush push{q.rays, q.count, static_cast<uint32_t>(p.k)};
  const PixelGeometry& g = f.geometry[p.i];
  QueuedLightMasks m;
  if constexpr (kSharedTerms) {
    StridedLightTerms terms = BlockLightTerms(lights);
    radiance[p.k] = ShadeQueuedStored<kMedia>(f, p.u, p.v, g, surfaces[p.k], terms, push, &m);
  } else {
    LocalLightTerms terms;
    radiance[p.k] = ShadeQueuedStored<kMedia>(f, p.u, p.v, g, surfaces[p.k], terms, push, &m);
  }
  q.masks[p.k] = m;
  q.occluded[p.k] = 0;
}

// pass 2: the queued rays, one a thread, one wave of resident blocks striding over the queue;
// `pixels`: a camera's (the ray's camera is its pixel / pixels). its registers are the
// compiler's (98 with nvcc 13 for sm_90: 4 blocks an SM; capped at 64, 8 blocks, it was slower).
template <class Frames>
__global__ void __launch_bounds__(128)
    TraceQueuedKernel(Frames frames, ShadowRayQueue q, int64_t pixels) {
  const int64_t total = *q.count;
  const int64_t stride = static_cast<int64_t>(gridDim.x) * blockDim.x;
  for (int64_t at = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x; at < total;
       at += stride) {
    const QueuedShadowRay e = q.rays[at];
    const uint32_t pixel = e.key / kMaxQueuedShadowLights;
    const RealtimeFrameView& f = frames.at(static_cast<int>(pixel / pixels));
    if (TraceOccluded(f.scene, QueuedRay(e)))
      atomicOr(q.occluded + pixel, 1u << (e.key % kMaxQueuedShadowLights));
  }
}

// the current device's SMs.
inline int DeviceSms() {
  int device = 0, sms = 0;
  Check(cudaGetDevice(&device), "cudaGetDevice");
  Check(cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device),
        "cudaDeviceGetAttribute");
  return std::max(sms, 1);
}

// as many blocks of 128 threads of `kernel` as the current device holds at once (one wave).
template <class Kernel>
unsigned ResidentBlocks(Kernel* kernel) {
  int per_sm = 0;
  Check(cudaOccupancyMaxActiveBlocksPerMultiprocessor(&per_sm, kernel, 128, 0),
        "cudaOccupancyMaxActiveBlocksPerMultiprocessor");
  return static_cast<unsigned>(DeviceSms() * std::max(1, per_sm));
}

// TraceQueuedKernel's grid: one wave of its blocks.
template <class Frames>
unsigned TraceQueuedBlocks() {
  static const unsigned blocks = ResidentBlocks(TraceQueuedKernel<Frames>);
  return blocks;
}

// pass 3 (SumQueuedLights): rows [row0, row1), each pixel's lights summed in light order.
template <class Frames>
__global__ void SumQueuedKernel(Frames frames, Float3* radiance, ShadowRayQueue q, int row0,
                                int row1) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f, row0, row1);
  if (!p) return;
  const QueuedLightMasks m = q.masks[p.k];
  if (m.lit == 0) return;
  const int64_t n = static_cast<int64_t>(f.camera.width) * f.camera.height;
  radiance[p.k] = SumQueuedLights(f, p.i, n, radiance[p.k], m, q.occluded[p.k]);
}

// the shared visibility of lights with an extent (realtime_shading.h), one kernel per step:
// each reads its neighbours' results of the step before.
__global__ void VisibilityRaysKernel(RealtimeFrameView f) {
  const FramePixel p = PixelOf(f);
  if (p) SharedVisibilityRays(f, p.u, p.v);
}

// the shared visibility's penumbra rays with a queue (RealtimeKernelOptions::queue_penumbra):
// VisibilityRaysWarpKernel spreads a warp's short jobs over its lanes as before, but queues the
// long ones (more than kPenumbraQueueRays rays: a tile's ring in a penumbra traces up to 63) in
// chunks of RealtimeKernelOptions::penumbra_chunk_rays (a batch's of kPenumbraChunkRays, at most
// kMaxPenumbraChunkRays); VisibilityChunkKernel traces the chunks, all threads of the
// device sharing them, and adds each chunk's integer counts to its pixel's (integer atomics:
// the sums do not depend on the order); the chunk that completes a pixel's job writes its
// totals. the same integer counts as SharedVisibilityRays, so the same bits, without a warp
// waiting on its ring pixels while the rest of the device is idle.
constexpr int kPenumbraChunkRays = 4;
constexpr int kMaxPenumbraChunkRays = 8;
constexpr int kPenumbraQueueRays = 8;

// rays [r0, r0 + rays) of light `light` at pixel `pixel` of camera `camera`, one of the job's
// `chunks` (rays 0: an unused entry).
struct PenumbraChunk {
  int32_t camera;
  int32_t pixel;
  int16_t points;  // PenumbraRays::points
  uint8_t light;
  uint8_t own;  // PenumbraRays::own
  uint8_t r0;
  uint8_t rays;
  uint8_t chunks;
  uint8_t pad;
};
static_assert(sizeof(PenumbraChunk) == 16, "PenumbraChunk: 16 bytes");

// a queued job's count: chunks done (bits 24-31), rays traced (12-23), rays visible (0-11).
__device__ inline uint32_t PackChunkCounts(int traced, int visible) {
  return (1u << 24) | (static_cast<uint32_t>(traced) << 12) | static_cast<uint32_t>(visible);
}

// the queue's room in chunks of `chunk_rays` rays: a ray for every light's pixel, at least 1 Mi
// entries, at most 16 Mi (256 MiB); a job that does not fit is spread over its warp's lanes.
inline int64_t PenumbraQueueCapacity(int64_t nl, int chunk_rays) {
  return std::min<int64_t>(std::max<int64_t>(nl / chunk_rays, int64_t{1} << 20), int64_t{1} << 24);
}

// where VisibilityRaysWarpKernel queues its long jobs (queue null: it queues none).
struct PenumbraQueue {
  PenumbraChunk* queue = nullptr;
  unsigned long long* queued = nullptr;  // chunks queued (may pass capacity: those are not)
  int64_t capacity = 0;
  int chunk_rays = kPenumbraChunkRays;  // rays a chunk (1 to kMaxPenumbraChunkRays)
  uint32_t* counts = nullptr;           // (camera, light, pixel) at camera nl + light n + pixel
  int64_t nl = 0;                       // a camera's per-light entries
};

// queues light j's rays 1 .. extra - 1 of `job` at pixel i of camera `camera` (n pixels) if
// they fit: the lanes that call it at once take their room with one atomic add.
__device__ inline bool QueuePenumbraJob(const PenumbraQueue& q, const PenumbraRays& job, int j,
                                        int64_t i, int64_t n, int camera) {
  const int rays = job.extra - 1;
  const int chunks = (rays + q.chunk_rays - 1) / q.chunk_rays;
  const cg::coalesced_group g = cg::coalesced_threads();
  const int before = cg::exclusive_scan(g, chunks);
  const int all = g.shfl(before + chunks, g.size() - 1);
  unsigned long long base = 0;
  if (g.thread_rank() == 0) base = atomicAdd(q.queued, static_cast<unsigned long long>(all));
  const unsigned long long at = g.shfl(base, 0) + before;
  const auto capacity = static_cast<unsigned long long>(q.capacity);
  const bool fits = at + chunks <= capacity;
  if (fits) q.counts[static_cast<int64_t>(camera) * q.nl + j * n + i] = 0;
  for (int c = 0; c < chunks && at + c < capacity; ++c) {
    PenumbraChunk e;
    e.camera = camera;
    e.pixel = static_cast<int32_t>(i);
    e.points = static_cast<int16_t>(job.points);
    e.light = static_cast<uint8_t>(j);
    e.own = static_cast<uint8_t>(job.own);
    e.r0 = static_cast<uint8_t>(1 + c * q.chunk_rays);
    e.rays = fits ? static_cast<uint8_t>(min(q.chunk_rays, rays - c * q.chunk_rays)) : uint8_t{0};
    e.chunks = static_cast<uint8_t>(chunks);
    e.pad = 0;
    q.queue[at + c] = e;
  }
  return fits;
}

template <class Frames>
__global__ void VisibilityChunkKernel(Frames frames, PenumbraQueue q) {
  const int64_t total = min(static_cast<int64_t>(*q.queued), q.capacity);
  const int64_t stride = static_cast<int64_t>(gridDim.x) * blockDim.x;
  for (int64_t at = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x; at < total;
       at += stride) {
    const PenumbraChunk e = q.queue[at];
    if (e.rays == 0) continue;
    const RealtimeFrameView& f = frames.at(e.camera);
    const int W = f.camera.width;
    const int64_t n = static_cast<int64_t>(W) * f.camera.height;
    const int u = e.pixel % W, v = e.pixel / W;
    const PixelGeometry& g = f.geometry[e.pixel];
    PenumbraRays job;
    job.p = g.p_or_d;
    job.ng = g.ng;
    job.first = kLightPenumbraRays * LightStratum(u, v);
    job.points = e.points;
    job.own = e.own;
    int traced, visible;
    CountPenumbraRays(f, e.light, job, e.r0, e.r0 + e.rays, &traced, &visible);
    const int64_t k = e.light * n + e.pixel;
    const uint32_t add = PackChunkCounts(traced, visible);
    const uint32_t sum = atomicAdd(q.counts + static_cast<int64_t>(e.camera) * q.nl + k, add) + add;
    // the job's last chunk: its totals after the pixel's own verdict (area_visible holds it)
    if ((sum >> 24) == e.chunks) {
      f.area_visible[k] = f.area_visible[k] + static_cast<float>(sum & 0xfffu);
      f.area_rays[k] = 1.0f + static_cast<float>((sum >> 12) & 0xfffu);
    }
  }
}

// the most lights whose verdicts VisibilityRaysWarpKernel<..., true, ...> keeps in shared
// memory (TilePenumbraBytes: 32 KiB, under the 48 KiB a kernel gets without asking); frames
// with more take the kernel of 128 threads a block.
constexpr int kMaxTilePenumbraLights = 128;
// the dynamic shared memory of the tile kernel: every light's int8 verdicts of the tile, or
// with `rows` their bit rows (kShadowVerdictRows words a light, 80 bytes instead of 256).
inline size_t TilePenumbraBytes(int lights, bool rows) {
  return static_cast<size_t>(std::max(lights, 1)) *
         (rows ? sizeof(uint32_t) * kShadowVerdictRows : kTilePixels);
}

// VisibilityChunkKernel's grid: as many blocks of 128 threads as the device holds at once.
template <class Frames>
unsigned ChunkBlocks() {
  static const unsigned blocks = ResidentBlocks(VisibilityChunkKernel<Frames>);
  return blocks;
}

// VisibilityRaysKernel with a warp's penumbra rays spread over its 32 lanes: per light, the
// lanes' rays (pixel l's rays 1 .. extra_l - 1) are numbered in lane order (an inclusive scan),
// lane t of round b traces ray b 32 + t of the pixel whose range holds it, and each pixel sums
// its rays' verdicts (ballots): the same integer counts as one thread per pixel, so the same
// bits, without the warp waiting on the one ring pixel that traces 63 rays. whole warps run
// every step (pixels outside the image take part with no rays).
// at most 128 registers (4 blocks an SM: the queue's code would otherwise take it to 131, 3).
// kTile (RealtimeKernelOptions::tile_penumbra): a block of kTilePixels threads per shadow tile
// (kTileBlock, 2 blocks an SM at 128 registers) first copies every light's verdicts of its tile
// into its dynamic shared memory (TilePenumbraBytes of it), where the pixels' windows, cut at the
// tile's edges, find their neighbours' (SharedVisibilityPenumbra's vis_j: the same values).
// kStaged (with kTile; RealtimeKernelOptions::staged_window): each thread also copies its own
// pixel's surface (TileWindowSurfaces: geom of a hit, normal, point) into shared memory, where
// the window masks read their 24 neighbours' (instead of up to 25 threads reading each pixel's
// PixelGeometry from global memory). kRows (with kStaged; RealtimeKernelOptions::
// window_verdict_rows): each warp (two tile rows of 16 pixels) puts a light's verdicts into the
// tile's bit rows with two ballots (ShadowVerdictBits' layout) instead of the int8 copy, where a
// window's "both verdicts seen" is five shifted rows (RowWindowVerdicts) instead of a shared
// int8 read per set bit. the same masks and booleans, so the same bits.
template <class Frames, bool kTile, bool kStaged, bool kRows>
__global__ void __launch_bounds__(kTile ? kTilePixels : 128, kTile ? 2 : 4)
    VisibilityRaysWarpKernel(Frames frames, PenumbraQueue q) {
  static_assert(kTile || !kStaged, "the staged window works a tile at a time");
  static_assert(kStaged || !kRows, "the bit rows come with the staged window");
  extern __shared__ uint32_t tile_shared[];
  constexpr int kSurfaces = kStaged ? kTilePixels : 1;
  __shared__ int32_t key[kSurfaces];
  __shared__ float ng_x[kSurfaces], ng_y[kSurfaces], ng_z[kSurfaces], p_x[kSurfaces],
      p_y[kSurfaces], p_z[kSurfaces];
  int8_t* const tile_vis = reinterpret_cast<int8_t*>(tile_shared);
  uint32_t* const tile_rows = tile_shared;
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  const int u = p.u, v = p.v;
  const int W = f.camera.width, H = f.camera.height;
  const bool inside = p.inside;
  const int t = static_cast<int>(threadIdx.y * blockDim.x + threadIdx.x);
  const int lane = t & 31;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int64_t i = p.i;
  if constexpr (kStaged) {
    // this pixel's surface
    key[t] = TileWindowSurfaces::kNoWindowSurface;
    if (inside) {
      const PixelGeometry& g = f.geometry[i];
      key[t] = TileWindowSurfaces::KeyOf(g);
      ng_x[t] = g.ng.x, ng_y[t] = g.ng.y, ng_z[t] = g.ng.z;
      p_x[t] = g.p_or_d.x, p_y[t] = g.p_or_d.y, p_z[t] = g.p_or_d.z;
    }
  }
  if constexpr (kRows) {
    // every light's verdicts as bit rows: warp w holds tile rows 2w (lanes 0-15) and 2w + 1
    // (lanes 16-31); the two words above and below the tile stay 0
    const int row = kShadowWindowRadius + 2 * (t >> 5);
#pragma unroll 4
    for (int j = 0; j < f.num_lights; ++j) {
      const int vis = inside ? f.area_vis[j * n + i] : -1;
      const uint32_t ones = __ballot_sync(kFullWarp, vis > 0);
      const uint32_t zeros = __ballot_sync(kFullWarp, vis == 0);
      uint32_t* const rows = tile_rows + j * kShadowVerdictRows;
      if (lane == 0) {
        rows[row] = (ones & 0xffffu) | zeros << kShadowTileSize;
        rows[row + 1] = ones >> kShadowTileSize | (zeros & 0xffff0000u);
      }
      if (t < 2 * kShadowWindowRadius) rows[t < kShadowWindowRadius ? t : kShadowTileSize + t] = 0u;
    }
    __syncthreads();
  } else if constexpr (kTile) {
    for (int j = 0; j < f.num_lights; ++j)
      tile_vis[j * kTilePixels + t] = inside ? f.area_vis[j * n + i] : int8_t{-1};
    __syncthreads();
  }
  uint32_t bits = 0;
  if (inside) {
    if constexpr (kStaged)
      bits = SharedVisibilityWindow(
          f, u, v, TileWindowSurfaces{key, ng_x, ng_y, ng_z, p_x, p_y, p_z}, t, kShadowTileSize);
    else
      bits = SharedVisibilityWindow(f, u, v);
  }
  for (int j = 0; j < f.num_lights; ++j) {
    PenumbraRays job;
    if (inside && kRows)
      job = SharedVisibilityPenumbraOf(
          f, u, v, j, bits,
          RowWindowVerdicts{tile_rows + j * kShadowVerdictRows, static_cast<int>(threadIdx.x),
                            static_cast<int>(threadIdx.y)});
    else if (inside && kTile)
      job = SharedVisibilityPenumbra(f, u, v, j, bits, tile_vis + j * kTilePixels, t,
                                     kShadowTileSize);
    else if (inside)
      job = SharedVisibilityPenumbra(f, u, v, j, bits);
    int count = job.active != 0 && job.extra > 1 ? job.extra - 1 : 0;
    // a long job to the queue (VisibilityChunkKernel writes its totals), if it fits
    bool queued = false;
    if (q.queue != nullptr && count > kPenumbraQueueRays)
      queued = QueuePenumbraJob(q, job, j, i, n, static_cast<int>(blockIdx.z));
    if (queued) count = 0;
    int end = count;  // inclusive scan: this lane's rays are [end - count, end)
    for (int d = 1; d < 32; d *= 2) {
      const int x = __shfl_up_sync(kFullWarp, end, d);
      if (lane >= d) end += x;
    }
    const int begin = end - count;
    const int total = __shfl_sync(kFullWarp, end, 31);
    int traced = 0, visible = 0;
    for (int base = 0; base < total; base += 32) {
      const int t = base + lane;
      // the owner: the lowest lane whose range ends beyond t
      int owner = 0;
      for (int step = 16; step > 0; step /= 2) {
        const int e = __shfl_sync(kFullWarp, end, owner + step - 1);
        if (e <= t) owner += step;
      }
      PenumbraRays o;
      o.p.x = __shfl_sync(kFullWarp, job.p.x, owner);
      o.p.y = __shfl_sync(kFullWarp, job.p.y, owner);
      o.p.z = __shfl_sync(kFullWarp, job.p.z, owner);
      o.ng.x = __shfl_sync(kFullWarp, job.ng.x, owner);
      o.ng.y = __shfl_sync(kFullWarp, job.ng.y, owner);
      o.ng.z = __shfl_sync(kFullWarp, job.ng.z, owner);
      o.first = __shfl_sync(kFullWarp, job.first, owner);
      o.points = __shfl_sync(kFullWarp, job.points, owner);
      o.own = __shfl_sync(kFullWarp, job.own, owner);
      const int owner_begin = __shfl_sync(kFullWarp, begin, owner);
      const int verdict = t < total ? PenumbraRayVerdict(f, j, o, t - owner_begin + 1) : -1;
      const uint32_t traced_lanes = __ballot_sync(kFullWarp, verdict >= 0);
      const uint32_t visible_lanes = __ballot_sync(kFullWarp, verdict > 0);
      // this lane's rays among this round's lanes
      const int lo = max(begin, base) - base, hi = min(end, base + 32) - base;
      if (hi > lo) {
        const uint32_t mine = (hi - lo == 32 ? kFullWarp : ((1u << (hi - lo)) - 1u)) << lo;
        traced += __popc(traced_lanes & mine);
        visible += __popc(visible_lanes & mine);
      }
    }
    if (inside && job.active != 0) {
      f.area_visible[j * n + i] = job.visible + static_cast<float>(visible);
      f.area_rays[j * n + i] = 1.0f + static_cast<float>(traced);
    }
  }
}

template <class Frames>
__global__ void VisibilityFractionKernel(Frames frames) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (p) SharedVisibilityFraction(f, p.u, p.v);
}

template <class Frames>
__global__ void VisibilityResolveKernel(Frames frames, Float3* radiance) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  if (p) radiance[p.k] = SharedVisibilityResolve(f, p.u, p.v, radiance[p.k]);
}

// VisibilityResolveKernel and, with kMirror, MirrorBlendKernel in one pass over rows [row0,
// row1) (RealtimeKernelOptions::fuse_resolve; after MirrorShadeKernel): the same functions in
// the same order on each pixel's own radiance, so the same bits.
template <class Frames, bool kMirror>
__global__ void ResolveBandKernel(Frames frames, Float3* radiance, int row0, int row1) {
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f, row0, row1);
  if (!p) return;
  Float3 L = SharedVisibilityResolve(f, p.u, p.v, radiance[p.k]);
  if (kMirror && f.any_mirror != 0) L = ApplyMirrorLayer(f, p.u, p.v, L);
  radiance[p.k] = L;
}

// VisibilityFractionKernel and ResolveBandKernel in one pass (RealtimeKernelOptions::
// tile_visibility): a block of kTilePixels threads per shadow tile of rows [row0, row1) (row0
// a multiple of kShadowTileSize, row1 one or the image's last row + 1), kTileLightGroup lights
// at a time: their verdicts, ray counts and own flags loaded together (every load issued before
// the first use: one memory latency a group, not three a light) into shared memory (with
// kPacked, RealtimeKernelOptions::packed_window_counts, each pixel's two counts packed once into
// one word, ShadowWindowCounts, instead of both floats), each
// pixel's fractions from there (SharedWindowFraction) into shared memory, then each pixel's V
// from its neighbours' there (SharedLampFraction) added to its radiance (AddSharedVisibility),
// the lights in order; with kMirror, then ApplyMirrorLayer (after MirrorShadeKernel). the same
// functions on the same values in the same order as the two kernels, so the same bits; the
// windows never leave their tile, so no neighbour is missing.
constexpr int kTileLightGroup = 8;
template <class Frames, bool kMirror, bool kPacked>
__global__ void __launch_bounds__(kTilePixels)
    VisibilityTileKernel(Frames frames, Float3* radiance, int row0, int row1) {
  // the unpacked form's counts (kPacked: one element each, never read)
  constexpr int kCountPixels = kPacked ? 1 : kTilePixels;
  __shared__ int8_t vis[kTileLightGroup][kTilePixels];
  __shared__ uint8_t own[kTileLightGroup][kTilePixels];
  __shared__ uint32_t counts[kTileLightGroup][kPacked ? kTilePixels : 1];
  __shared__ float visible[kTileLightGroup][kCountPixels], rays[kTileLightGroup][kCountPixels],
      fraction[kTileLightGroup][kTilePixels];
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f, row0, row1);
  const int t = static_cast<int>(threadIdx.y * blockDim.x + threadIdx.x);
  const int64_t n = static_cast<int64_t>(f.camera.width) * f.camera.height;
  const ShadowTile tile = ShadowTileOf(p.u, p.v, f.camera.width, f.camera.height);
  const uint32_t window = p ? f.window[p.i] : 0u;
  Float3 L = p ? radiance[p.k] : Float3{};
  for (int g = 0; g < f.num_lights; g += kTileLightGroup) {
    const int lights = min(kTileLightGroup, f.num_lights - g);
    // the group's arrays into registers (independent loads), then into shared memory; the
    // counts of a pixel without a verdict are loaded but never read
    int8_t w[kTileLightGroup];
    uint8_t o[kTileLightGroup];
    float a[kTileLightGroup], r[kTileLightGroup];
#pragma unroll
    for (int l = 0; l < kTileLightGroup; ++l) {
      w[l] = -1;
      o[l] = 0;
      a[l] = r[l] = 0;
      if (p && l < lights) {
        const int64_t k = (g + l) * n + p.i;
        w[l] = f.area_vis[k];
        o[l] = f.area_own[k];
        a[l] = f.area_visible[k];
        r[l] = f.area_rays[k];
      }
    }
#pragma unroll
    for (int l = 0; l < kTileLightGroup; ++l) {
      vis[l][t] = w[l];
      own[l][t] = o[l];
      if (kPacked) {
        counts[l][t] = ShadowWindowCounts(w[l], a[l], r[l]);
      } else {
        visible[l][t] = a[l];
        rays[l][t] = r[l];
      }
    }
    __syncthreads();
    VisibilityTaps taps[kTileLightGroup];
#pragma unroll
    for (int l = 0; l < kTileLightGroup; ++l) {
      taps[l].vis = vis[l];
      taps[l].visible = visible[l];
      taps[l].rays = rays[l];
      taps[l].fraction = fraction[l];
      taps[l].stride = kShadowTileSize;
      if (kPacked) taps[l].counts = counts[l];
      if (l < lights && w[l] >= 0 && IsExtendedLightPod(f.lights[g + l]))
        fraction[l][t] = SharedWindowFraction(taps[l], t, window, o[l] != 0);
    }
    __syncthreads();
    // the contributions of the lights with a verdict (independent loads), then the resolve in
    // light order
    Float3 c[kTileLightGroup];
#pragma unroll
    for (int l = 0; l < kTileLightGroup; ++l)
      if (p && l < lights && w[l] >= 0) c[l] = f.area_c[(g + l) * n + p.i];
#pragma unroll
    for (int l = 0; l < kTileLightGroup; ++l) {
      if (l >= lights || w[l] < 0 || !IsExtendedLightPod(f.lights[g + l])) continue;
      const bool lamp = f.lights[g + l].kind != LightKind::kDirectional && o[l] == 0;
      const float V =
          SharedLampFraction(taps[l], t, window, lamp, p.u - tile.x0, p.v - tile.y0, tile);
      L = AddSharedVisibility(L, V, c[l]);
    }
    // the group's arrays are read before the next group's are written
    __syncthreads();
  }
  if (!p) return;
  if (kMirror && f.any_mirror != 0) L = ApplyMirrorLayer(f, p.u, p.v, L);
  radiance[p.k] = L;
}

// the VisibilityTileKernel of frames `Frames` with (kMirror) or without the mirror blend, the
// counts packed in shared memory (RealtimeKernelOptions::packed_window_counts) or not.
template <class Frames>
auto TileKernel(bool mirror, bool packed) {
  return mirror ? (packed ? VisibilityTileKernel<Frames, true, true>
                          : VisibilityTileKernel<Frames, true, false>)
                : (packed ? VisibilityTileKernel<Frames, false, true>
                          : VisibilityTileKernel<Frames, false, false>);
}

// the grid of VisibilityTileKernel over rows [row0, row1) of frames W pixels wide.
dim3 TileGrid(int W, int row0, int row1) {
  return dim3((W + kShadowTileSize - 1) / kShadowTileSize,
              (row1 - row0 + kShadowTileSize - 1) / kShadowTileSize);
}

__global__ void RowSumKernel(const Float3* radiance, int width, int height, double* rows) {
  const int v = blockIdx.x * blockDim.x + threadIdx.x;
  if (v >= height) return;
  rows[v] = RowLogLuminance(radiance, width, v, 1e-4);
}

// one warp per row: lane k sums columns k, k + 32, ... in order, then a fixed butterfly.
// camera blockIdx.y of a batch (radiance and rows hold every camera's in turn).
__global__ void RowSumWarpKernel(const Float3* radiance, int width, int height, double* rows) {
  const int lane = threadIdx.x & 31;
  const int v = blockIdx.x * (blockDim.x / 32) + threadIdx.x / 32;
  if (v >= height) return;  // whole warps leave together
  radiance += static_cast<int64_t>(blockIdx.y) * width * height;
  rows += static_cast<int64_t>(blockIdx.y) * height;
  double sum = 0;
  for (int u = lane; u < width; u += 32) {
    const Float3& c = radiance[static_cast<int64_t>(v) * width + u];
    const float rgb[3] = {c.x, c.y, c.z};
    sum += LogLuminanceTerm(rgb, 1e-4);
  }
  for (int offset = 16; offset > 0; offset /= 2) sum += __shfl_xor_sync(kFullWarp, sum, offset);
  if (lane == 0) rows[v] = sum;
}

struct Exposure {
  float e[3];
};

// the device's exposure of a frame (ExposureKernel): the per-channel exposures and the EV100.
struct DeviceExposure {
  float e[3];
  double ev100;
};

// film_math.h's FrameExposure of a frame's `height` row sums (height <= kMaxDeviceExposureRows)
// by the calling block: its threads bring the rows into shared memory (height doubles), one
// thread adds them in row order.
__device__ void BlockExposure(const double* rows, int height, int64_t pixels,
                              const FilmExposurePod& film, const float gains[3],
                              DeviceExposure* out) {
  extern __shared__ double shared_rows[];
  for (int v = threadIdx.x; v < height; v += blockDim.x) shared_rows[v] = rows[v];
  __syncthreads();
  if (threadIdx.x != 0) return;
  DeviceExposure d;
  d.ev100 = FrameExposure(film, shared_rows, height, pixels, kMinLuminance, gains, d.e);
  *out = d;
}

__global__ void ExposureKernel(const double* rows, int height, int64_t pixels, FilmExposurePod film,
                               Exposure gains, DeviceExposure* out) {
  BlockExposure(rows, height, pixels, film, gains.e, out);
}

// ExposureKernel over a batch: block k makes camera k's exposure from its rows (camera-major,
// `height` each) with its own film.
__global__ void BatchExposureKernel(const double* rows, int height, int64_t pixels,
                                    const RealtimeBatchFilm* film, DeviceExposure* out) {
  const int k = blockIdx.x;
  BlockExposure(rows + static_cast<int64_t>(k) * height, height, pixels, film[k].exposure,
                film[k].white_balance_gains, out + k);
}

// ExposureKernel on `stream`: the exposure of the `height` row sums at `rows` into `out`.
void LaunchExposure(const double* rows, int height, int64_t pixels, const FilmExposurePod& film,
                    const float gains[3], DeviceExposure* out, cudaStream_t stream) {
  const Exposure g{{gains[0], gains[1], gains[2]}};
  ExposureKernel<<<1, 256, sizeof(double) * height, stream>>>(rows, height, pixels, film, g, out);
  Check(cudaGetLastError(), "ExposureKernel");
}

__global__ void DevelopKernel(const Float3* radiance, int64_t n, Exposure exposure, int filmic,
                              const uint8_t* lut, uint8_t* rgb) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  DevelopPixel(radiance[i], exposure.e, filmic != 0, lut, rgb + 3 * i);
}

// DevelopKernel with the exposure the device computed (ExposureKernel).
__global__ void DevelopDeviceExposureKernel(const Float3* radiance, int64_t n,
                                            const DeviceExposure* exposure, int filmic,
                                            const uint8_t* lut, uint8_t* rgb) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const float e[3] = {exposure->e[0], exposure->e[1], exposure->e[2]};
  DevelopPixel(radiance[i], e, filmic != 0, lut, rgb + 3 * i);
}

// DevelopKernel over a batch: camera blockIdx.y's n pixels with its own film and the exposure
// the device computed (BatchExposureKernel).
__global__ void BatchDevelopKernel(const Float3* radiance, int64_t n, const RealtimeBatchFilm* film,
                                   const DeviceExposure* exposure, uint8_t* rgb) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  const RealtimeBatchFilm& c = film[blockIdx.y];
  const DeviceExposure& x = exposure[blockIdx.y];
  const float e[3] = {x.e[0], x.e[1], x.e[2]};
  const int64_t k = static_cast<int64_t>(blockIdx.y) * n + i;
  DevelopPixel(radiance[k], e, c.filmic != 0, c.lut, rgb + 3 * k);
}

using Clock = std::chrono::steady_clock;
double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// the grid of the per-pixel kernels (whole warps of 16 x 2 pixels).
const dim3 kPixelBlock(16, 8);
dim3 PixelGrid(int W, int H) {
  return dim3((W + kPixelBlock.x - 1) / kPixelBlock.x, (H + kPixelBlock.y - 1) / kPixelBlock.y);
}

// the per-pixel device arrays of `cameras` frames of n pixels and `lights` lights each (one
// frame: Render; a batch: RealtimeBatch), camera k's at k n (k n lights for the per-light ones).
struct PixelBuffers {
  Buffer geometry, sky, radiance, surfaces;
  // the shared visibility's buffers (RealtimeFrameView)
  Buffer window, total, area_c, area_vis, area_visible, area_rays, area_own, area_fraction;
  // the penumbra rays' queue (queue_penumbra): the chunks, their count, each pixel's counts
  Buffer penumbra_queue, penumbra_queued, penumbra_counts;
  // the mirror layer's buffers (RealtimeFrameView)
  Buffer mirror_geometry, mirror_hits, mirror_sky, mirror_radiance;
  // the queued shadow rays (queue_shadow_rays; reserved by the first frame that takes them):
  // room for a ray per pixel and light, the count, each pixel's masks and verdicts
  Buffer shadow_rays, shadow_count, shadow_masks, shadow_occluded;
  // room for n pixels (all cameras) and nl = n x lights (lights >= 1); the material terms if
  // `with_surfaces`, the mirror layer's if `mirror`
  void Reserve(int64_t n, int64_t nl, bool with_surfaces, bool mirror) {
    geometry.Reserve(sizeof(PixelGeometry) * n);
    sky.Reserve(sizeof(Float3) * n);
    radiance.Reserve(sizeof(Float3) * n);
    if (with_surfaces) surfaces.Reserve(sizeof(SurfaceTerms) * n);
    window.Reserve(sizeof(uint32_t) * n);
    total.Reserve(sizeof(float) * n);
    area_c.Reserve(sizeof(Float3) * nl);
    area_vis.Reserve(sizeof(int8_t) * nl);
    area_visible.Reserve(sizeof(float) * nl);
    area_rays.Reserve(sizeof(float) * nl);
    area_own.Reserve(sizeof(uint8_t) * nl);
    area_fraction.Reserve(sizeof(float) * nl);
    penumbra_queue.Reserve(sizeof(PenumbraChunk) * PenumbraQueueCapacity(nl, 1));
    penumbra_queued.Reserve(sizeof(unsigned long long));
    penumbra_counts.Reserve(sizeof(uint32_t) * nl);
    if (mirror) {
      mirror_geometry.Reserve(sizeof(PixelGeometry) * n);
      mirror_hits.Reserve(sizeof(TraceHit) * n);
      mirror_sky.Reserve(sizeof(Float3) * n);
      mirror_radiance.Reserve(sizeof(Float3) * n);
    }
  }
  // the penumbra rays of `cameras` frames of W x H pixels, at most `lights` lights and nl
  // per-light entries each on `stream`: spread over each warp's lanes (VisibilityRaysWarpKernel),
  // the long jobs through the queue (VisibilityChunkKernel) in chunks of `chunk_rays` rays if
  // `queue`, a block per shadow tile with the verdicts in shared memory if `tile` (and the
  // lights fit: kMaxTilePenumbraLights).
  template <class Frames>
  void LaunchPenumbraRays(Frames frames, int W, int H, int lights, int64_t nl, int cameras,
                          bool queue, int chunk_rays, bool tile, bool staged, bool rows,
                          cudaStream_t stream) const {
    PenumbraQueue q;
    if (queue) {
      q.queue = penumbra_queue.as<PenumbraChunk>();
      q.queued = penumbra_queued.as<unsigned long long>();
      q.chunk_rays = std::clamp(chunk_rays, 1, kMaxPenumbraChunkRays);
      q.capacity = PenumbraQueueCapacity(nl * cameras, q.chunk_rays);
      q.counts = penumbra_counts.as<uint32_t>();
      q.nl = nl;
      Check(cudaMemsetAsync(q.queued, 0, sizeof(unsigned long long), stream), "cudaMemsetAsync");
    }
    if (tile && lights <= kMaxTilePenumbraLights) {
      dim3 grid = TileGrid(W, 0, H);
      grid.z = cameras;
      if (staged && rows)
        VisibilityRaysWarpKernel<Frames, true, true, true>
            <<<grid, kTileBlock, TilePenumbraBytes(lights, true), stream>>>(frames, q);
      else if (staged)
        VisibilityRaysWarpKernel<Frames, true, true, false>
            <<<grid, kTileBlock, TilePenumbraBytes(lights, false), stream>>>(frames, q);
      else
        VisibilityRaysWarpKernel<Frames, true, false, false>
            <<<grid, kTileBlock, TilePenumbraBytes(lights, false), stream>>>(frames, q);
    } else {
      dim3 grid = PixelGrid(W, H);
      grid.z = cameras;
      VisibilityRaysWarpKernel<Frames, false, false, false>
          <<<grid, kPixelBlock, 0, stream>>>(frames, q);
    }
    Check(cudaGetLastError(), "VisibilityRaysWarpKernel");
    if (!queue) return;
    // one wave of resident blocks strides over the chunks (their number stays on the device)
    VisibilityChunkKernel<<<ChunkBlocks<Frames>(), 128, 0, stream>>>(frames, q);
    Check(cudaGetLastError(), "VisibilityChunkKernel");
  }
  // whether frames of `n` pixels in all (every camera's) and `lights` lights can queue their
  // shadow rays: the lights fit a pixel's masks, the rays' keys and count fit 32 bits.
  static bool CanQueueShadowRays(int64_t n, int lights) {
    const int64_t most = int64_t{1} << 32;
    return lights <= kMaxQueuedShadowLights && n * kMaxQueuedShadowLights < most &&
           n * std::max(lights, 1) < most;
  }
  // the pixels of one wave of the fused shading kernel (ShadeStoredKernel at its 4 blocks of
  // 128 threads an SM) on the current device.
  static int64_t ShadeWavePixels() {
    static const int64_t pixels = int64_t{4} * 128 * DeviceSms();
    return pixels;
  }
  // whether frames of `n` pixels in all and `lights` lights take the queued shadow rays as `o`
  // says (queue_shadow_rays, queue_shadow_rays_always).
  static bool QueueShadowRays(const RealtimeKernelOptions& o, int64_t n, int lights) {
    return o.queue_shadow_rays && o.reuse_hit && o.reuse_surface &&
           (o.queue_shadow_rays_always || n <= ShadeWavePixels()) && CanQueueShadowRays(n, lights);
  }
  // the shading of rows [row0, row1) of `cameras` frames (grid: a camera's rows, z the camera)
  // of `pixels` pixels and `lights` lights each, their shadow rays through the queue, on
  // `stream`: ShadeQueuedKernel, TraceQueuedKernel, SumQueuedKernel.
  // smem: the light terms' shared memory (kSharedTerms) for `term_lights` lights.
  // CanQueueShadowRays must hold.
  template <class Frames, bool kMedia, bool kSharedTerms>
  void LaunchQueuedShade(Frames frames, dim3 grid, const SurfaceTerms* surfaces, Float3* L,
                         int row0, int row1, int64_t pixels, int cameras, int lights,
                         int term_lights, size_t smem, cudaStream_t stream) {
    const int64_t n = pixels * cameras;
    shadow_rays.Reserve(sizeof(QueuedShadowRay) * n * std::max(lights, 1));
    shadow_count.Reserve(sizeof(unsigned));
    shadow_masks.Reserve(sizeof(QueuedLightMasks) * n);
    shadow_occluded.Reserve(sizeof(uint32_t) * n);
    ShadowRayQueue q;
    q.rays = shadow_rays.as<QueuedShadowRay>();
    q.count = shadow_count.as<unsigned>();
    q.masks = shadow_masks.as<QueuedLightMasks>();
    q.occluded = shadow_occluded.as<uint32_t>();
    Check(cudaMemsetAsync(q.count, 0, sizeof(unsigned), stream), "cudaMemsetAsync");
    ShadeQueuedKernel<Frames, kMedia, kSharedTerms>
        <<<grid, kPixelBlock, smem, stream>>>(frames, surfaces, L, q, row0, row1, term_lights);
    Check(cudaGetLastError(), "ShadeQueuedKernel");
    TraceQueuedKernel<<<TraceQueuedBlocks<Frames>(), 128, 0, stream>>>(frames, q, pixels);
    Check(cudaGetLastError(), "TraceQueuedKernel");
    SumQueuedKernel<<<grid, kPixelBlock, 0, stream>>>(frames, L, q, row0, row1);
    Check(cudaGetLastError(), "SumQueuedKernel");
  }
  // f's per-pixel arrays: the part at pixel `at` and, per light, at `at_l`
  void Point(RealtimeFrameView* f, int64_t at, int64_t at_l, bool mirror) const {
    f->sky_term = sky.as<Float3>() + at;
    f->geometry = geometry.as<PixelGeometry>() + at;
    f->window = window.as<uint32_t>() + at;
    f->total = total.as<float>() + at;
    f->area_c = area_c.as<Float3>() + at_l;
    f->area_vis = area_vis.as<int8_t>() + at_l;
    f->area_visible = area_visible.as<float>() + at_l;
    f->area_rays = area_rays.as<float>() + at_l;
    f->area_own = area_own.as<uint8_t>() + at_l;
    f->area_fraction = area_fraction.as<float>() + at_l;
    if (mirror) {
      f->mirror_geometry = mirror_geometry.as<PixelGeometry>() + at;
      f->mirror_hits = mirror_hits.as<TraceHit>() + at;
      f->mirror_sky = mirror_sky.as<Float3>() + at;
      f->mirror_radiance = mirror_radiance.as<Float3>() + at;
    }
  }
};

}  // namespace

struct DeviceRealtime::Impl : PixelBuffers {
  Buffer materials, textures, texels, decode, lut, geoms, lights;
  // rgb: the frame's tail, one device buffer copied back at once with device_exposure: the rgb
  // (3 n bytes), then, 16-byte aligned, the row sums (H doubles) and the device's exposure
  // (TailRows, rows, exposure); pin_rgb holds its copy
  Buffer depth, rgb, hits, streaks;
  // the realtime splat's streaks (shared with the pathtraced tier's upload) and per pixel its
  // StreakKeys and shaded streaks (StreakSplatView)
  StreakBuffers splat_streaks;
  Buffer splat_nearest, splat_pixels, splat_rows;
  double* rows = nullptr;
  DeviceExposure* exposure_out = nullptr;
  // the frame's homogeneous media (RealtimeMediaView's arrays) and the sky volume's pod
  Buffer media_pods, media_fog, media_inv_log_far, media_axes, media_trans, volume_pod;
  Buffer media_vis;  // the world light volume's visibility when the frame builds it
  // the grids' froxels (records; t0, t1 and slices per m end to end; axis tables), their boxes
  // and light volumes (branch gpu12)
  Buffer media_grid_records, media_grid_columns, media_grid_axes, media_grid_pods, media_grid_T;
  // the grids' arrays when the frame builds their volumes (branch gpu17): densities, emission,
  // their MediaGridPods (the arrays of grid_generation, uploaded again when it changes), and
  // the light volumes' in-scatter sources
  Buffer media_grid_density, media_grid_emission, media_grid_media, media_grid_source;
  bool grid_arrays_held = false;
  uint64_t grid_generation = 0;
  // what the last frame built there (DownloadGridVolumes): T values, cells, froxel columns
  size_t grid_built_values = 0;
  int64_t grid_built_cells = 0;
  int grid_built_columns = 0;
  // the sky's and the sky volume's arrays (UploadSky) and their pods with these pointers
  Buffer sky_irradiance, skybox, volume_sh, volume_cells, volume_depth;
  SkyModelPod device_sky;
  SkyVolumePod device_volume;
  bool sky_uploaded = false;
  // the device_sky path's stage times (CUDA events with timing): start, geometry, sky terms, row
  // sums, film (device_exposure), the tail on the host, the radiance on the host
  cudaEvent_t stage[7] = {};
  // pinned: the round trip of the geometry and sky terms, the row sums and the outputs
  PinnedBuffer pin_geometry, pin_sky, pin_rows, pin_rgb, pin_radiance, pin_depth;
  PinnedBuffer pin_mirror_geometry, pin_mirror_sky;
  // pinned staging of the per-frame uploads (posed geoms, lights; the late streaks: the host
  // splat's pixels, the device splat's streaks)
  PinnedBuffer pin_geoms, pin_lights, pin_streak_pixels, pin_splat, pin_splat_rows;
  // the bytes of the geoms and lights the device holds (upload_changed_only); `uploaded`
  // false when they are not known (DeviceFrame uploaded others)
  std::vector<uint8_t> uploaded_geoms, uploaded_lights;
  bool uploaded = false;
  RealtimeExposureChecks checks;
  std::vector<PixelGeometry> host_geometry, host_mirror_geometry;
  std::vector<Float3> host_sky, host_mirror_sky;
  std::vector<double> host_rows;
  cudaStream_t copy_stream = nullptr;
  // mirror_stream: the mirror layer's kernels' stream, the event it forks at (the primary
  // geometry traced) and the one it joins at (the mirrored radiance shaded)
  cudaStream_t side_stream = nullptr, side_stream_high = nullptr;  // lowest, highest priority
  cudaEvent_t mirror_fork = nullptr, mirror_join = nullptr;
  // fuse_resolve: band k of the radiance is final (its copy back waits for it)
  cudaEvent_t resolved_band[kMaxSkyBands] = {};
  cudaEvent_t geometry_done = nullptr;
  cudaEvent_t radiance_done = nullptr;  // the radiance is final (before the film kernel)
  cudaEvent_t depth_copied = nullptr;   // the depth is in its pinned buffer
  cudaEvent_t rgb_copied = nullptr;     // device_exposure: the rgb is in its pinned buffer
  // band k's geometry is on the host (Render's bands)
  cudaEvent_t band_done[kMaxSkyBands] = {};
  // band k of the radiance is in its pinned buffer (RealtimeKernelOptions::output_bands)
  cudaEvent_t radiance_band[kMaxSkyBands] = {};
  RealtimeKernelOptions options;
  RealtimeStageTimes times;
  // the last frame, for TimeKernels.
  RealtimeFrameView frame;
  Exposure exposure{{1, 1, 1}};
  RealtimeFilm film;
  int filmic = 1;
  bool rendered = false;
  // the shared-terms shading kernels may take kShadeCachedLights lights' shared memory
  bool shade_smem_set = false;

  // the tail's layout (rgb above): the row sums' offset, and its bytes
  static size_t TailRows(int64_t n) { return (static_cast<size_t>(3 * n) + 15) / 16 * 16; }
  static size_t TailBytes(int64_t n, int H) {
    return TailRows(n) + sizeof(double) * H + sizeof(DeviceExposure);
  }
  // the tail for frames of n pixels and H rows on the device (rows and exposure_out into it)
  void ReserveTail(int64_t n, int H) {
    rgb.Reserve(TailBytes(n, H));
    rows = reinterpret_cast<double*>(rgb.as<char>() + TailRows(n));
    exposure_out = reinterpret_cast<DeviceExposure*>(rows + H);
  }

  // the posed geoms and lights of `f` (host arrays, num_geoms geoms) to the device on `stream`:
  // pinned, asynchronous (the last frame's copies are done: it ended with a synchronisation);
  // with upload_changed_only only when their bytes differ from the last upload's
  void UploadPosed(const RealtimeFrameView& f, int64_t num_geoms, const RealtimeKernelOptions& o,
                   cudaStream_t stream) {
    const size_t geom_bytes = sizeof(GeomPod) * num_geoms;
    const size_t light_bytes = sizeof(LightPod) * f.num_lights;
    const auto* g = reinterpret_cast<const uint8_t*>(f.geoms);
    const auto* l = reinterpret_cast<const uint8_t*>(f.lights);
    const auto same = [](const std::vector<uint8_t>& a, const uint8_t* b, size_t n) {
      return a.size() == n && (n == 0 || std::memcmp(a.data(), b, n) == 0);
    };
    if (o.upload_changed_only && uploaded && same(uploaded_geoms, g, geom_bytes) &&
        same(uploaded_lights, l, light_bytes))
      return;
    if (o.pinned) {
      pin_geoms.Reserve(geom_bytes > 0 ? geom_bytes : 1);
      pin_lights.Reserve(light_bytes > 0 ? light_bytes : 1);
      if (geom_bytes > 0) std::memcpy(pin_geoms.p, f.geoms, geom_bytes);
      if (light_bytes > 0) std::memcpy(pin_lights.p, f.lights, light_bytes);
      geoms.Upload(pin_geoms.p, geom_bytes, stream);
      lights.Upload(pin_lights.p, light_bytes, stream);
    } else {
      geoms.Upload(f.geoms, geom_bytes, stream);
      lights.Upload(f.lights, light_bytes, stream);
    }
    uploaded_geoms.assign(g, g + geom_bytes);
    uploaded_lights.assign(l, l + light_bytes);
    uploaded = true;
  }
  // the frame's homogeneous media (host arrays of `h`, RealtimeFrameData::View) to the device on
  // `stream` (pageable: staged before the calls return), *d pointing to them; the media's sky
  // volume is the frame's (UploadSky's copy of its pod)
  // a froxel volume's four axis tables, ax and ax_half [width], ay and ay_half [height], into
  // `b` end to end; *d_tables[k] points at table k on the device.
  static void UploadAxes(const MediaAxis* const tables[4], int width, int height, Buffer* b,
                         cudaStream_t stream, const MediaAxis** const d_tables[4]) {
    const size_t len[4] = {static_cast<size_t>(width), static_cast<size_t>(width),
                           static_cast<size_t>(height), static_cast<size_t>(height)};
    std::vector<MediaAxis> axes(len[0] + len[1] + len[2] + len[3]);
    size_t at[4], off = 0;
    for (int k = 0; k < 4; ++k) {
      std::copy(tables[k], tables[k] + len[k], axes.begin() + off);
      at[k] = off;
      off += len[k];
    }
    b->Upload(axes.data(), sizeof(MediaAxis) * axes.size(), stream);
    for (int k = 0; k < 4; ++k) *d_tables[k] = b->as<MediaAxis>() + at[k];
  }

  void UploadMedia(const RealtimeMediaView& h, RealtimeMediaView* d, cudaStream_t stream) {
    *d = h;
    media_pods.Upload(h.media, sizeof(MediumPod) * h.num_media, stream);
    d->media = h.num_media > 0 ? media_pods.as<MediumPod>() : nullptr;
    if (h.sky_volume != nullptr) {
      if (!sky_uploaded || device_volume.empty())
        throw Error("DeviceRealtime::Render: media lit by a sky volume the device does not hold");
      d->sky_volume = volume_pod.as<SkyVolumePod>();
    }
    if (h.fog_S != nullptr) {
      const size_t columns = static_cast<size_t>(h.fog_nx) * h.fog_ny;
      media_fog.Upload(h.fog_S, sizeof(Rgb4) * columns * (kFogFroxelSlices + 1), stream);
      media_inv_log_far.Upload(h.fog_inv_log_far, sizeof(float) * columns, stream);
      d->fog_S = media_fog.as<Rgb4>();
      d->fog_inv_log_far = media_inv_log_far.as<float>();
    }
    if (h.fog_ax != nullptr) {
      const MediaAxis* const fog[4] = {h.fog_ax, h.fog_ax_half, h.fog_ay, h.fog_ay_half};
      const MediaAxis** const fog_d[4] = {&d->fog_ax, &d->fog_ax_half, &d->fog_ay, &d->fog_ay_half};
      UploadAxes(fog, h.width, h.height, &media_axes, stream, fog_d);
    }
    if (h.light_trans != nullptr) {
      const CellLightsPod& v = h.light_volume;
      const size_t n = static_cast<size_t>(v.r[0]) * v.r[1] * v.r[2] * v.stride;
      media_trans.Upload(h.light_trans, sizeof(float) * n, stream);
      d->light_trans = media_trans.as<float>();
    }
    if (h.grid_records != nullptr) {  // built on the host (else BuildGridMedia's)
      const size_t columns = static_cast<size_t>(h.grid_nx) * h.grid_ny;
      media_grid_records.Upload(
          h.grid_records, sizeof(GridFroxelRecord<Rgb4>) * columns * (kFroxelSlices + 1), stream);
      // t0, t1, slices per m [columns] end to end, then the four axis tables as the fog's
      std::vector<float> cols(3 * columns);
      std::copy(h.grid_t0, h.grid_t0 + columns, cols.begin());
      std::copy(h.grid_t1, h.grid_t1 + columns, cols.begin() + columns);
      std::copy(h.grid_slices_per_m, h.grid_slices_per_m + columns, cols.begin() + 2 * columns);
      media_grid_columns.Upload(cols.data(), sizeof(float) * cols.size(), stream);
      d->grid_records = media_grid_records.as<GridFroxelRecord<Rgb4>>();
      const float* c = media_grid_columns.as<float>();
      d->grid_t0 = c;
      d->grid_t1 = c + columns;
      d->grid_slices_per_m = c + 2 * columns;
    }
    if (h.grid_ax != nullptr) {
      const MediaAxis* const grid[4] = {h.grid_ax, h.grid_ax_half, h.grid_ay, h.grid_ay_half};
      const MediaAxis** const grid_d[4] = {&d->grid_ax, &d->grid_ax_half, &d->grid_ay,
                                           &d->grid_ay_half};
      UploadAxes(grid, h.width, h.height, &media_grid_axes, stream, grid_d);
    }
    if (h.num_grids > 0) {
      media_grid_pods.Upload(h.grids, sizeof(GridLightPod) * h.num_grids, stream);
      d->grids = media_grid_pods.as<GridLightPod>();
      if (h.grid_light_T != nullptr) {  // built on the host (else BuildGridMedia's)
        // every grid's [light][cell] transmittances, end to end (the last pod's offset + its own)
        media_grid_T.Upload(h.grid_light_T, sizeof(float) * GridLightValues(h), stream);
        d->grid_light_T = media_grid_T.as<float>();
      }
    }
  }
  // the values of every grid's [light][cell] transmittances end to end in view m (the last
  // pod's offset + its own; at least 1)
  static size_t GridLightValues(const RealtimeMediaView& m) {
    const GridLightPod& last = m.grids[m.num_grids - 1];
    const size_t n =
        last.offset + static_cast<size_t>(m.num_grid_lights) * last.r[0] * last.r[1] * last.r[2];
    return n > 0 ? n : 1;
  }
  // the grids' volumes frame f builds itself (f->media_build.grids), on `stream` after
  // UploadMedia and before the world light volume and fog froxels (which read them): the grids'
  // arrays uploaded when their generation changed, MediaGridLightKernel, then
  // MediaGridFroxelKernel; f->media pointed at their buffers
  void BuildGridMedia(const RealtimeMediaView& h, RealtimeFrameView* f, cudaStream_t stream) {
    MediaVolumesToBuild& b = f->media_build;
    RealtimeMediaView& m = f->media;
    grid_built_values = grid_built_cells = grid_built_columns = 0;
    if (b.grids == 0 || m.num_grids <= 0) return;
    // the densities and emission when their generation changed; the pods (transforms and
    // coefficients, which may change over the same arrays) every frame
    const bool arrays = !grid_arrays_held || b.grid_generation != grid_generation;
    b.grid_media = UploadMediaGrids(b.grid_media, m.num_grids, &media_grid_density,
                                    &media_grid_emission, &media_grid_media, stream, arrays);
    grid_generation = b.grid_generation;
    grid_arrays_held = true;
    int64_t cells = 0;
    for (int g = 0; g < h.num_grids; ++g) cells += GridLightCells(h.grids[g]);
    media_grid_T.Reserve(sizeof(float) * GridLightValues(h));
    media_grid_source.Reserve(sizeof(Float3) * static_cast<size_t>(cells > 0 ? cells : 1));
    if (cells > 0) {
      MediaGridLightKernel<<<static_cast<unsigned>((cells + 63) / 64), 64, 0, stream>>>(
          *f, cells, media_grid_T.as<float>(), media_grid_source.as<Float3>());
      Check(cudaGetLastError(), "MediaGridLightKernel");
    }
    m.grid_light_T = media_grid_T.as<float>();
    const GridLightPod& last = h.grids[h.num_grids - 1];
    grid_built_values = last.offset + static_cast<size_t>(h.num_grid_lights) * GridLightCells(last);
    grid_built_cells = cells;
    const int columns = m.grid_nx * m.grid_ny;
    grid_built_columns = columns > 0 ? columns : 0;
    if (columns <= 0) return;
    media_grid_columns.Reserve(sizeof(float) * 3 * static_cast<size_t>(columns));
    media_grid_records.Reserve(sizeof(GridFroxelRecord<Rgb4>) * static_cast<size_t>(columns) *
                               (kFroxelSlices + 1));
    float* cols = media_grid_columns.as<float>();
    MediaGridFroxelKernel<<<static_cast<unsigned>(columns), kGridSliceBlock, 0, stream>>>(
        *f, media_grid_source.as<Float3>(), cols, cols + columns, cols + 2 * columns,
        media_grid_records.as<GridFroxelRecord<Rgb4>>());
    Check(cudaGetLastError(), "MediaGridFroxelKernel");
    m.grid_t0 = cols;
    m.grid_t1 = cols + columns;
    m.grid_slices_per_m = cols + 2 * columns;
    m.grid_records = media_grid_records.as<GridFroxelRecord<Rgb4>>();
  }
  // the media volumes frame f builds itself (f->media_build), on `stream` after UploadMedia:
  // MediaLightVolumeKernel, then MediaFogSliceKernel; f->media pointed at their buffers
  void BuildMedia(RealtimeFrameView* f, cudaStream_t stream) {
    const MediaVolumesToBuild& b = f->media_build;
    RealtimeMediaView& m = f->media;
    float* vis = nullptr;
    if (b.light_volume != 0) {
      const int64_t cells = LightVolumeCells(m.light_volume);
      const size_t bytes = sizeof(float) * static_cast<size_t>(cells) * m.light_volume.stride;
      media_trans.Reserve(bytes > 0 ? bytes : 4);
      if (b.with_visibility != 0) {
        media_vis.Reserve(bytes > 0 ? bytes : 4);
        vis = media_vis.as<float>();
      }
      MediaLightVolumeKernel<<<static_cast<unsigned>((cells + 127) / 128), 128, 0, stream>>>(
          *f, cells, media_trans.as<float>(), vis);
      Check(cudaGetLastError(), "MediaLightVolumeKernel");
      m.light_trans = media_trans.as<float>();
    }
    if (b.fog != 0) {
      const int columns = m.fog_nx * m.fog_ny;
      media_fog.Reserve(sizeof(Rgb4) * static_cast<size_t>(columns) * (kFogFroxelSlices + 1));
      media_inv_log_far.Reserve(sizeof(float) * static_cast<size_t>(columns));
      MediaFogSliceKernel<<<static_cast<unsigned>(columns), kFogSliceBlock, 0, stream>>>(
          *f, vis, media_fog.as<Rgb4>(), media_inv_log_far.as<float>());
      Check(cudaGetLastError(), "MediaFogSliceKernel");
      m.fog_S = media_fog.as<Rgb4>();
      m.fog_inv_log_far = media_inv_log_far.as<float>();
    }
  }
  // the film kernel with the exposure the device computed (LaunchExposure)
  void LaunchFilmDeviceExposure(int64_t n, int tone_map, cudaStream_t stream) {
    DevelopDeviceExposureKernel<<<static_cast<unsigned>((n + 255) / 256), 256, 0, stream>>>(
        radiance.as<Float3>(), n, exposure_out, tone_map, lut.as<uint8_t>(), rgb.as<uint8_t>());
    Check(cudaGetLastError(), "DevelopKernel");
  }

  void LaunchGeometry(const RealtimeFrameView& f, const RealtimeKernelOptions& o,
                      cudaStream_t stream) {
    const dim3 grid = PixelGrid(f.camera.width, f.camera.height);
    TraceHit* h = o.reuse_hit && !o.reuse_surface ? hits.as<TraceHit>() : nullptr;
    SurfaceTerms* st = o.reuse_hit && o.reuse_surface ? surfaces.as<SurfaceTerms>() : nullptr;
    if (o.geometry_min_blocks >= 5)
      GeometryKernel<OneFrame, 5><<<grid, kPixelBlock, 0, stream>>>(
          OneFrame{f}, geometry.as<PixelGeometry>(), depth.as<float>(), h, st);
    else
      GeometryKernel<OneFrame, 1><<<grid, kPixelBlock, 0, stream>>>(
          OneFrame{f}, geometry.as<PixelGeometry>(), depth.as<float>(), h, st);
    Check(cudaGetLastError(), "GeometryKernel");
    if (f.any_mirror != 0) {
      // mirror_stream: the mirror layer forks here, beside the rest of the frame
      cudaStream_t s = stream;
      if (ForkMirror(f, o)) {
        s = Side(o);
        Check(cudaEventRecord(mirror_fork, stream), "cudaEventRecord");
        Check(cudaStreamWaitEvent(s, mirror_fork, 0), "cudaStreamWaitEvent");
      }
      MirrorTraceKernel<<<PixelGrid(f.camera.width, f.camera.height), kPixelBlock, 0, s>>>(
          OneFrame{f});
      Check(cudaGetLastError(), "MirrorTraceKernel");
    }
  }
  // whether frame f's mirror layer runs on the side stream (RealtimeKernelOptions::
  // mirror_stream; with the sky terms on the device, whose kernel queues its shading)
  bool ForkMirror(const RealtimeFrameView& f, const RealtimeKernelOptions& o) const {
    return o.mirror_stream && o.device_sky && sky_uploaded && side_stream != nullptr &&
           f.any_mirror != 0;
  }
  // whether kernels change frame f's radiance after the shared visibility's resolve (the media's
  // view pass, the host's or the device's streak splat), so that no output band is final before
  static bool AfterResolve(const RealtimeFrameView& f) {
    return f.has_media != 0 || f.num_streaks > 0 || f.splat.streaks.num > 0;
  }
  // the side stream as `o` says (mirror_low_priority)
  cudaStream_t Side(const RealtimeKernelOptions& o) const {
    return o.mirror_low_priority ? side_stream : side_stream_high;
  }
  // the sky terms of frame f (its geometry and mirrored rays traced) on `stream`; mirror_stream:
  // the mirrored rays' sky terms and shading on the side stream, which then joins.
  void LaunchSky(const RealtimeFrameView& f, const RealtimeKernelOptions& o, cudaStream_t stream) {
    const int W = f.camera.width, H = f.camera.height;
    SkyQuadKernel<<<PixelGrid((W + 1) / 2, (H + 1) / 2), kPixelBlock, 0, stream>>>(
        OneFrame{f}, sky.as<Float3>());
    Check(cudaGetLastError(), "SkyQuadKernel");
    if (f.any_mirror != 0) {
      const bool fork = ForkMirror(f, o);
      cudaStream_t s = fork ? Side(o) : stream;
      MirrorSkyKernel<<<PixelGrid(W, H), kPixelBlock, 0, s>>>(OneFrame{f}, mirror_sky.as<Float3>());
      Check(cudaGetLastError(), "MirrorSkyKernel");
      if (fork) {
        MirrorShadeKernel<<<PixelGrid(W, H), kPixelBlock, 0, s>>>(OneFrame{f});
        Check(cudaGetLastError(), "MirrorShadeKernel");
        Check(cudaEventRecord(mirror_join, s), "cudaEventRecord");
      }
    }
  }
  // row k of the radiance's `bands` bands of rows (Render's output bands) of a frame H rows high:
  // whole shadow tiles (VisibilityTileKernel resolves a tile at a time)
  static int OutputBandRow(int H, int bands, int k) {
    const int rows = (H + bands - 1) / bands;
    const int tiles = (rows + kShadowTileSize - 1) / kShadowTileSize;
    return std::min(H, k * tiles * kShadowTileSize);
  }
  // the shading kernel of rows [row0, row1) of frame f on `stream` as `o` says.
  void LaunchShade(const RealtimeFrameView& f, const RealtimeKernelOptions& o, cudaStream_t stream,
                   int row0, int row1) {
    if (row1 <= row0) return;
    const dim3 grid = PixelGrid(f.camera.width, row1 - row0);
    TraceHit* h = hits.as<TraceHit>();
    Float3* L = radiance.as<Float3>();
    SurfaceTerms* st = surfaces.as<SurfaceTerms>();
    // shared_light_terms: the kernels may take up to kShadeCachedLights lights' terms (once)
    const int threads = static_cast<int>(kPixelBlock.x * kPixelBlock.y);
    const int lights = ShadeSharedLights(f.num_lights);
    const size_t smem = ShadeLightTermBytes(lights, threads);
    if (o.shared_light_terms && !shade_smem_set) {
      const int most = static_cast<int>(ShadeLightTermBytes(kShadeCachedLights, threads));
      Check(cudaFuncSetAttribute(ShadeStoredKernel<OneFrame, 4, true, true>,
                                 cudaFuncAttributeMaxDynamicSharedMemorySize, most),
            "cudaFuncSetAttribute");
      Check(cudaFuncSetAttribute(ShadeStoredKernel<OneFrame, 4, false, true>,
                                 cudaFuncAttributeMaxDynamicSharedMemorySize, most),
            "cudaFuncSetAttribute");
      Check(cudaFuncSetAttribute(ShadeQueuedKernel<OneFrame, true, true>,
                                 cudaFuncAttributeMaxDynamicSharedMemorySize, most),
            "cudaFuncSetAttribute");
      Check(cudaFuncSetAttribute(ShadeQueuedKernel<OneFrame, false, true>,
                                 cudaFuncAttributeMaxDynamicSharedMemorySize, most),
            "cudaFuncSetAttribute");
      shade_smem_set = true;
    }
    // queue_shadow_rays: the shadow rays apart, through the queue (the same bits)
    const int64_t pixels = static_cast<int64_t>(f.camera.width) * f.camera.height;
    if (QueueShadowRays(o, pixels, f.num_lights)) {
      const OneFrame fr{f};
      const bool media = f.has_media != 0;
      if (o.shared_light_terms && media)
        LaunchQueuedShade<OneFrame, true, true>(fr, grid, st, L, row0, row1, pixels, 1,
                                                f.num_lights, lights, smem, stream);
      else if (o.shared_light_terms)
        LaunchQueuedShade<OneFrame, false, true>(fr, grid, st, L, row0, row1, pixels, 1,
                                                 f.num_lights, lights, smem, stream);
      else if (media)
        LaunchQueuedShade<OneFrame, true, false>(fr, grid, st, L, row0, row1, pixels, 1,
                                                 f.num_lights, 0, 0, stream);
      else
        LaunchQueuedShade<OneFrame, false, false>(fr, grid, st, L, row0, row1, pixels, 1,
                                                  f.num_lights, 0, 0, stream);
      return;
    }
    if (!o.reuse_hit)
      ShadeKernel<false, 1><<<grid, kPixelBlock, 0, stream>>>(f, nullptr, L, row0, row1);
    else if (o.reuse_surface && o.min_blocks >= 6 && f.has_media != 0)
      ShadeStoredKernel<OneFrame, 6, true>
          <<<grid, kPixelBlock, 0, stream>>>(OneFrame{f}, st, L, row0, row1);
    else if (o.reuse_surface && o.min_blocks >= 6)
      ShadeStoredKernel<OneFrame, 6, false>
          <<<grid, kPixelBlock, 0, stream>>>(OneFrame{f}, st, L, row0, row1);
    else if (o.reuse_surface && o.min_blocks >= 4 && o.shared_light_terms && f.has_media != 0)
      ShadeStoredKernel<OneFrame, 4, true, true>
          <<<grid, kPixelBlock, smem, stream>>>(OneFrame{f}, st, L, row0, row1, lights);
    else if (o.reuse_surface && o.min_blocks >= 4 && o.shared_light_terms)
      ShadeStoredKernel<OneFrame, 4, false, true>
          <<<grid, kPixelBlock, smem, stream>>>(OneFrame{f}, st, L, row0, row1, lights);
    else if (o.reuse_surface && o.min_blocks >= 4 && f.has_media != 0)
      ShadeStoredKernel<OneFrame, 4, true>
          <<<grid, kPixelBlock, 0, stream>>>(OneFrame{f}, st, L, row0, row1);
    else if (o.reuse_surface && o.min_blocks >= 4)
      ShadeStoredKernel<OneFrame, 4, false>
          <<<grid, kPixelBlock, 0, stream>>>(OneFrame{f}, st, L, row0, row1);
    else if (o.reuse_surface && f.has_media != 0)
      ShadeStoredKernel<OneFrame, 1, true>
          <<<grid, kPixelBlock, 0, stream>>>(OneFrame{f}, st, L, row0, row1);
    else if (o.reuse_surface)
      ShadeStoredKernel<OneFrame, 1, false>
          <<<grid, kPixelBlock, 0, stream>>>(OneFrame{f}, st, L, row0, row1);
    else if (o.min_blocks >= 6)
      ShadeKernel<true, 6><<<grid, kPixelBlock, 0, stream>>>(f, h, L, row0, row1);
    else if (o.min_blocks >= 4)
      ShadeKernel<true, 4><<<grid, kPixelBlock, 0, stream>>>(f, h, L, row0, row1);
    else
      ShadeKernel<true, 1><<<grid, kPixelBlock, 0, stream>>>(f, h, L, row0, row1);
    Check(cudaGetLastError(), "ShadeKernel");
  }
  // the shading, shared-visibility and row-sum kernels of frame f on `stream` as `o` says.
  void LaunchShading(const RealtimeFrameView& f, const RealtimeKernelOptions& o,
                     cudaStream_t stream) {
    LaunchShade(f, o, stream, 0, f.camera.height);
    LaunchAfterShade(f, o, stream);
  }
  // the kernels after the shading kernel: shared visibility, mirror layer, row sums.
  void LaunchAfterShade(const RealtimeFrameView& f, const RealtimeKernelOptions& o,
                        cudaStream_t stream) {
    const int W = f.camera.width, H = f.camera.height;
    const dim3 grid = PixelGrid(W, H);
    if (o.warp_penumbra || o.queue_penumbra) {
      LaunchPenumbraRays(OneFrame{f}, W, H, f.num_lights,
                         static_cast<int64_t>(W) * H * f.num_lights, 1, o.queue_penumbra,
                         o.penumbra_chunk_rays, o.tile_penumbra, o.staged_window,
                         o.window_verdict_rows, stream);
    } else {
      VisibilityRaysKernel<<<grid, kPixelBlock, 0, stream>>>(f);
      Check(cudaGetLastError(), "VisibilityRaysKernel");
    }
    // tile_visibility: the fraction in the resolve's kernel
    if (!o.tile_visibility) {
      VisibilityFractionKernel<<<grid, kPixelBlock, 0, stream>>>(OneFrame{f});
      Check(cudaGetLastError(), "VisibilityFractionKernel");
    }
    const bool mirror = f.any_mirror != 0;
    const bool fork = ForkMirror(f, o);
    if (o.fuse_resolve) {
      // the mirrored radiance first (or the side stream's), then the resolve and blend in the
      // output bands, each band final behind its event (one band where media or streaks follow)
      if (mirror && !fork) {
        MirrorShadeKernel<<<grid, kPixelBlock, 0, stream>>>(OneFrame{f});
        Check(cudaGetLastError(), "MirrorShadeKernel");
      }
      if (fork) Check(cudaStreamWaitEvent(stream, mirror_join, 0), "cudaStreamWaitEvent");
      const bool after = AfterResolve(f);
      const int bands = after ? 1 : std::clamp(o.output_bands, 1, kMaxSkyBands);
      for (int k = 0; k < bands; ++k) {
        const int r0 = OutputBandRow(H, bands, k), r1 = OutputBandRow(H, bands, k + 1);
        // tile_visibility: the fraction too, a block per shadow tile of the band
        void (*kernel)(OneFrame, Float3*, int, int) =
            o.tile_visibility
                ? TileKernel<OneFrame>(mirror, o.packed_window_counts)
                : (mirror ? ResolveBandKernel<OneFrame, true> : ResolveBandKernel<OneFrame, false>);
        if (r1 > r0) {
          const dim3 band = o.tile_visibility ? TileGrid(W, r0, r1) : PixelGrid(W, r1 - r0);
          kernel<<<band, o.tile_visibility ? kTileBlock : kPixelBlock, 0, stream>>>(
              OneFrame{f}, radiance.as<Float3>(), r0, r1);
          Check(cudaGetLastError(), "ResolveBandKernel");
        }
        if (!after) Check(cudaEventRecord(resolved_band[k], stream), "cudaEventRecord");
      }
    } else {
      if (o.tile_visibility)
        TileKernel<OneFrame>(false,
                             o.packed_window_counts)<<<TileGrid(W, 0, H), kTileBlock, 0, stream>>>(
            OneFrame{f}, radiance.as<Float3>(), 0, H);
      else
        VisibilityResolveKernel<<<grid, kPixelBlock, 0, stream>>>(OneFrame{f},
                                                                  radiance.as<Float3>());
      Check(cudaGetLastError(), "VisibilityResolveKernel");
      if (mirror) {
        if (fork) {
          Check(cudaStreamWaitEvent(stream, mirror_join, 0), "cudaStreamWaitEvent");
        } else {
          MirrorShadeKernel<<<grid, kPixelBlock, 0, stream>>>(OneFrame{f});
          Check(cudaGetLastError(), "MirrorShadeKernel");
        }
        MirrorBlendKernel<<<grid, kPixelBlock, 0, stream>>>(OneFrame{f}, radiance.as<Float3>());
        Check(cudaGetLastError(), "MirrorBlendKernel");
      }
    }
    if (f.has_media != 0) {
      MediaViewKernel<<<PixelGrid((W + 1) / 2, (H + 1) / 2), kPixelBlock, 0, stream>>>(
          f, depth.as<float>(), radiance.as<Float3>());
      Check(cudaGetLastError(), "MediaViewKernel");
    }
    if (f.num_streaks > 0 && f.has_media == 0) {  // with media: in MediaViewKernel
      StreakKernel<<<static_cast<unsigned>((f.num_streaks + 255) / 256), 256, 0, stream>>>(
          f.streaks, f.num_streaks, depth.as<float>(), radiance.as<Float3>());
      Check(cudaGetLastError(), "StreakKernel");
    }
    if (f.splat.streaks.num > 0 && f.has_media == 0) {
      StreakSplatApplyKernel<<<grid, kPixelBlock, 0, stream>>>(f, depth.as<float>(),
                                                               radiance.as<Float3>());
      Check(cudaGetLastError(), "StreakSplatApplyKernel");
    }
    // fuse_resolve with media or streaks: every band final after them
    if (o.fuse_resolve && AfterResolve(f))
      for (cudaEvent_t& e : resolved_band) Check(cudaEventRecord(e, stream), "cudaEventRecord");
    if (o.rows_per_warp)
      RowSumWarpKernel<<<(H + 3) / 4, 128, 0, stream>>>(radiance.as<Float3>(), W, H, rows);
    else
      RowSumKernel<<<(H + 127) / 128, 128, 0, stream>>>(radiance.as<Float3>(), W, H, rows);
    Check(cudaGetLastError(), "RowSumKernel");
  }
  // the splat of frame f's particle streaks (f.splat, its arrays on the device) on `stream`:
  // every pixel's key cleared, the streaks splatted, the pixels with one shaded
  void LaunchStreakSplat(const RealtimeFrameView& f, cudaStream_t stream) {
    const StreakSplatView& sp = f.splat;
    if (sp.streaks.num <= 0) return;
    const int W = f.camera.width, H = f.camera.height;
    Check(cudaMemsetAsync(sp.nearest, 0xff, sizeof(unsigned long long) * W * H, stream),
          "cudaMemsetAsync");
    // a warp per streak; with the count on the device (the device culling's streaks, num a
    // bound: the drops'), at most kSplatWarps warps striding over them
    const int64_t warps = sp.count != nullptr ? std::min<int64_t>(sp.streaks.num, kSplatWarps)
                                              : static_cast<int64_t>(sp.streaks.num);
    const int64_t threads = 32 * warps;
    StreakSplatKernel<<<static_cast<unsigned>((threads + 127) / 128), 128, 0, stream>>>(f);
    Check(cudaGetLastError(), "StreakSplatKernel");
    StreakShadeKernel<<<PixelGrid(W, H), kPixelBlock, 0, stream>>>(f);
    Check(cudaGetLastError(), "StreakShadeKernel");
  }
  // the particle streaks of host frame h to the device on `stream`, f's streak fields pointing
  // at them (n: the frame's pixels): the host splat's pixels (StreakKernel's), or the device
  // splat's streaks (host arrays; or the device culling's, read in place: their sets only, the
  // count on the device, StreakSplatView::count), then their splat queued (LaunchStreakSplat).
  // staged: through page-locked staging (the last frame's copies from it are done: it ended
  // with a synchronisation), so that the host never waits for a busy stream (the late
  // streaks); else from h's pageable arrays (staged by the runtime before the calls return)
  void QueueStreaks(const RealtimeFrameView& h, RealtimeFrameView* f, int64_t n, bool staged,
                    cudaStream_t stream) {
    f->streaks = h.streaks;
    f->num_streaks = h.num_streaks;
    f->splat = h.splat;
    // src, or (staged) its copy in *pin
    const auto source = [staged](const void* src, size_t bytes, PinnedBuffer* pin) {
      if (!staged) return src;
      pin->Reserve(bytes);
      std::memcpy(pin->p, src, bytes);
      return static_cast<const void*>(pin->p);
    };
    if (h.num_streaks > 0) {
      const size_t bytes = sizeof(StreakPixel) * h.num_streaks;
      streaks.Upload(source(h.streaks, bytes, &pin_streak_pixels), bytes, stream);
      f->streaks = streaks.as<StreakPixel>();
    }
    if (h.splat.streaks.num > 0 && h.splat.count != nullptr) {
      // the device culling's streaks, read in place (their culler made `stream` wait for
      // them): only their sets go over
      f->splat.streaks =
          splat_streaks.UploadSets(h.splat.streaks, staged ? &pin_splat : nullptr, stream);
    } else if (h.splat.streaks.num > 0) {
      const PathStreaks list =
          staged ? StreakBuffers::Stage(h.splat.streaks, &pin_splat) : h.splat.streaks;
      f->splat.streaks = splat_streaks.Upload(list, stream);
    }
    if (h.splat.streaks.num > 0) {
      if (h.splat.poses != nullptr) {
        // a moving camera's row poses (StreakSplatView::poses, and rows where it has them)
        const size_t bytes = sizeof(double) * 12 * f->camera.height;
        splat_rows.Upload(source(h.splat.poses, bytes, &pin_splat_rows), bytes, stream);
        f->splat.poses = splat_rows.as<double>();
        f->splat.rows = h.splat.rows != nullptr ? splat_rows.as<double>() : nullptr;
      }
      splat_nearest.Reserve(sizeof(unsigned long long) * n);
      splat_pixels.Reserve(sizeof(StreakPixel) * n);
      f->splat.nearest = splat_nearest.as<unsigned long long>();
      f->splat.pixels = splat_pixels.as<StreakPixel>();
      LaunchStreakSplat(*f, stream);
    }
  }
  // f's scene-wide arrays: the device copies of Upload, UploadSky and the posed geoms and lights
  void WithDeviceArrays(RealtimeFrameView* f) const {
    f->materials = materials.as<MaterialPod>();
    f->textures = textures.as<TexturePod>();
    f->texels = texels.as<uint8_t>();
    f->srgb_decode = decode.as<float>();
    f->geoms = geoms.as<GeomPod>();
    f->lights = lights.as<LightPod>();
    if (sky_uploaded) {
      f->sky = device_sky;
      f->volume = device_volume;
    }
  }
  void LaunchFilm(int64_t n, const Exposure& e, int film, cudaStream_t stream) {
    DevelopKernel<<<static_cast<unsigned>((n + 255) / 256), 256, 0, stream>>>(
        radiance.as<Float3>(), n, e, film, lut.as<uint8_t>(), rgb.as<uint8_t>());
    Check(cudaGetLastError(), "DevelopKernel");
  }
  ~Impl() {
    if (copy_stream) cudaStreamDestroy(copy_stream);
    if (side_stream) cudaStreamDestroy(side_stream);
    if (side_stream_high) cudaStreamDestroy(side_stream_high);
    if (mirror_fork) cudaEventDestroy(mirror_fork);
    if (mirror_join) cudaEventDestroy(mirror_join);
    for (cudaEvent_t e : resolved_band)
      if (e) cudaEventDestroy(e);
    if (geometry_done) cudaEventDestroy(geometry_done);
    if (radiance_done) cudaEventDestroy(radiance_done);
    if (depth_copied) cudaEventDestroy(depth_copied);
    if (rgb_copied) cudaEventDestroy(rgb_copied);
    for (cudaEvent_t e : radiance_band)
      if (e) cudaEventDestroy(e);
    for (cudaEvent_t e : band_done)
      if (e) cudaEventDestroy(e);
    for (cudaEvent_t e : stage)
      if (e) cudaEventDestroy(e);
  }
};

DeviceRealtime::DeviceRealtime() : impl_(new Impl) {}
DeviceRealtime::~DeviceRealtime() { delete impl_; }

void DeviceRealtime::set_options(const RealtimeKernelOptions& options) { impl_->options = options; }
const RealtimeKernelOptions& DeviceRealtime::options() const { return impl_->options; }
const RealtimeStageTimes& DeviceRealtime::last_stage_times() const { return impl_->times; }
const RealtimeExposureChecks& DeviceRealtime::exposure_checks() const { return impl_->checks; }

bool DeviceRealtime::DownloadStreakKeys(std::vector<unsigned long long>* out) const {
  const Impl& m = *impl_;
  const StreakSplatView& sp = m.frame.splat;
  if (!m.rendered || sp.streaks.num <= 0) return false;
  Check(cudaDeviceSynchronize(), "DownloadStreakKeys");
  out->assign(static_cast<size_t>(m.frame.camera.width) * m.frame.camera.height, 0);
  Check(cudaMemcpy(out->data(), sp.nearest, sizeof(unsigned long long) * out->size(),
                   cudaMemcpyDeviceToHost),
        "DownloadStreakKeys");
  return true;
}

bool DeviceRealtime::DownloadGridVolumes(GridVolumeArrays* out) const {
  const Impl& m = *impl_;
  if (m.grid_built_cells <= 0 && m.grid_built_columns <= 0) return false;
  Check(cudaDeviceSynchronize(), "DownloadGridVolumes");
  auto get = [](const Buffer& b, void* dst, size_t bytes) {
    if (bytes > 0)
      Check(cudaMemcpy(dst, b.p, bytes, cudaMemcpyDeviceToHost), "DownloadGridVolumes");
  };
  const size_t columns = static_cast<size_t>(m.grid_built_columns);
  out->T.assign(m.grid_built_values, 0.0f);
  out->source.assign(static_cast<size_t>(m.grid_built_cells), Float3{});
  out->t0.assign(columns, 0.0f);
  out->t1.assign(columns, 0.0f);
  out->slices_per_m.assign(columns, 0.0f);
  out->records.assign(columns * (kFroxelSlices + 1), GridFroxelRecord<Rgb4>{});
  get(m.media_grid_T, out->T.data(), sizeof(float) * out->T.size());
  get(m.media_grid_source, out->source.data(), sizeof(Float3) * out->source.size());
  std::vector<float> cols(3 * columns);
  get(m.media_grid_columns, cols.data(), sizeof(float) * cols.size());
  std::copy(cols.begin(), cols.begin() + columns, out->t0.begin());
  std::copy(cols.begin() + columns, cols.begin() + 2 * columns, out->t1.begin());
  std::copy(cols.begin() + 2 * columns, cols.end(), out->slices_per_m.begin());
  get(m.media_grid_records, out->records.data(),
      sizeof(GridFroxelRecord<Rgb4>) * out->records.size());
  return true;
}

void DeviceRealtime::Upload(const RealtimeStatic& d) {
  Impl& m = *impl_;
  m.materials.Upload(d.materials, sizeof(MaterialPod) * d.num_materials, nullptr);
  m.textures.Upload(d.textures, sizeof(TexturePod) * d.num_textures, nullptr);
  m.texels.Upload(d.texels, static_cast<size_t>(d.num_texel_bytes), nullptr);
  m.decode.Upload(d.srgb_decode, sizeof(float) * 256, nullptr);
  m.lut.Upload(d.oetf_lut, kFilmLutSize, nullptr);
  Check(cudaDeviceSynchronize(), "uploading the realtime scene");
}

void DeviceRealtime::UploadSky(const RealtimeSky& d) {
  Impl& m = *impl_;
  SkyModelPod sky = d.sky;
  m.sky_irradiance.Upload(d.sky.irradiance, sizeof(float) * 3 * kSkyIrrSide * kSkyIrrSide, nullptr);
  sky.irradiance = m.sky_irradiance.as<float>();
  if (d.sky.skybox != nullptr) {
    const size_t w = static_cast<size_t>(d.sky.skybox_width);
    m.skybox.Upload(d.sky.skybox, 6 * w * w * 3, nullptr);
    sky.skybox = m.skybox.as<uint8_t>();
    sky.srgb_decode = m.decode.as<float>();
  }
  SkyVolumePod v = d.volume;
  if (!v.empty() && d.num_probes > 0) {
    const size_t n = static_cast<size_t>(d.num_probes);
    m.volume_sh.Upload(d.volume.sh, sizeof(float) * kSkyShStride * n, nullptr);
    m.volume_cells.Upload(d.volume.cell_pos, sizeof(float) * 24 * n, nullptr);
    m.volume_depth.Upload(d.volume.depth_q, static_cast<size_t>(kSkyNumTexels) * n, nullptr);
    v.sh = m.volume_sh.as<float>();
    v.cell_pos = m.volume_cells.as<float>();
    v.depth_q = m.volume_depth.as<uint8_t>();
  } else {
    v = SkyVolumePod();
  }
  if (!v.empty()) m.volume_pod.Upload(&v, sizeof(SkyVolumePod), nullptr);
  Check(cudaDeviceSynchronize(), "uploading the realtime sky");
  m.device_sky = sky;
  m.device_volume = v;
  m.sky_uploaded = true;
}

RealtimeFrameView DeviceRealtime::DeviceFrame(const RealtimeFrameView& host_frame,
                                              int64_t num_geoms) {
  Impl& m = *impl_;
  m.uploaded = false;  // Render's next frame uploads its own
  m.geoms.Upload(host_frame.geoms, sizeof(GeomPod) * num_geoms, nullptr);
  m.lights.Upload(host_frame.lights, sizeof(LightPod) * host_frame.num_lights, nullptr);
  Check(cudaStreamSynchronize(nullptr), "uploading the realtime geoms and lights");
  RealtimeFrameView f = host_frame;
  m.WithDeviceArrays(&f);
  return f;
}

const uint8_t* DeviceRealtime::device_lut() const { return impl_->lut.as<uint8_t>(); }

double DeviceRealtime::Render(DeviceScene* scene, const RealtimeFrameView& host_frame,
                              int64_t num_geoms, const RealtimeFilm& film, const SkyFn& sky,
                              const ExposureFn& exposure, const RealtimeOutputs& out,
                              const StreaksFn& streaks) {
  Impl& m = *impl_;
  const RealtimeKernelOptions o = m.options;
  const auto t0 = Clock::now();
  cudaStream_t stream = static_cast<cudaStream_t>(scene->stream());
  if (!m.copy_stream) {
    Check(cudaStreamCreateWithFlags(&m.copy_stream, cudaStreamNonBlocking), "cudaStreamCreate");
    Check(cudaEventCreateWithFlags(&m.geometry_done, cudaEventDisableTiming), "cudaEventCreate");
    Check(cudaEventCreateWithFlags(&m.radiance_done, cudaEventDisableTiming), "cudaEventCreate");
    Check(cudaEventCreateWithFlags(&m.depth_copied, cudaEventDisableTiming), "cudaEventCreate");
    Check(cudaEventCreateWithFlags(&m.rgb_copied, cudaEventDisableTiming), "cudaEventCreate");
    for (cudaEvent_t& e : m.radiance_band)
      Check(cudaEventCreateWithFlags(&e, cudaEventDisableTiming), "cudaEventCreate");
    int least = 0, greatest = 0;
    Check(cudaDeviceGetStreamPriorityRange(&least, &greatest), "cudaDeviceGetStreamPriorityRange");
    Check(cudaStreamCreateWithPriority(&m.side_stream, cudaStreamNonBlocking, least),
          "cudaStreamCreate");
    Check(cudaStreamCreateWithPriority(&m.side_stream_high, cudaStreamNonBlocking, greatest),
          "cudaStreamCreate");
    Check(cudaEventCreateWithFlags(&m.mirror_fork, cudaEventDisableTiming), "cudaEventCreate");
    Check(cudaEventCreateWithFlags(&m.mirror_join, cudaEventDisableTiming), "cudaEventCreate");
    for (cudaEvent_t& e : m.resolved_band)
      Check(cudaEventCreateWithFlags(&e, cudaEventDisableTiming), "cudaEventCreate");
    for (cudaEvent_t& e : m.band_done)
      Check(cudaEventCreateWithFlags(&e, cudaEventDisableTiming), "cudaEventCreate");
    for (cudaEvent_t& e : m.stage) Check(cudaEventCreate(&e), "cudaEventCreate");
  }
  if (o.device_sky && !m.sky_uploaded)
    throw Error("DeviceRealtime::Render: device sky terms without UploadSky");
  if (o.device_sky) Check(cudaEventRecord(m.stage[0], stream), "cudaEventRecord");
  const PinholeCamera& c = host_frame.camera;
  const int W = c.width, H = c.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int filmic = film.filmic ? 1 : 0;
  // the exposure on the device: the film kernel follows the row sums without the host
  const bool device_exposure = o.device_exposure && o.pinned && H <= kMaxDeviceExposureRows;
  m.UploadPosed(host_frame, num_geoms, o, stream);
  // the host's copies of the outputs into the frame's images: over the caller's threads or one
  const RealtimeOutputs::ParallelFn no_threads;
  const RealtimeOutputs::ParallelFn& parallel = o.parallel_copies ? out.parallel : no_threads;
  const size_t chunk = static_cast<size_t>(std::max(o.copy_chunk_kib, 4)) << 10;
  const size_t serial = static_cast<size_t>(std::max(o.serial_copy_kib, 0)) << 10;
  m.depth.Reserve(sizeof(float) * n);
  m.ReserveTail(n, H);
  if (o.reuse_hit) m.hits.Reserve(sizeof(TraceHit) * n);
  const int64_t nl = n * (host_frame.num_lights > 0 ? host_frame.num_lights : 1);
  const bool mirror = host_frame.any_mirror != 0;
  m.PixelBuffers::Reserve(n, nl, o.reuse_hit && o.reuse_surface, mirror);
  // the frame with the device copies
  RealtimeFrameView f = host_frame;
  f.scene = scene->device_view();
  f.scene.occlusion_tlas = o.occlusion_tlas ? 1 : 0;
  f.scene.closest_tlas = o.closest_tlas ? 1 : 0;
  m.WithDeviceArrays(&f);
  m.Point(&f, 0, 0, mirror);
  // the particle streaks: the frame's now (the host splat's pixels, or the streaks the host
  // culled and their splat, first), or late (`streaks`: none until the shading is queued)
  if (streaks)
    m.QueueStreaks(RealtimeFrameView(), &f, n, /*staged=*/false, stream);
  else
    m.QueueStreaks(host_frame, &f, n, /*staged=*/false, stream);
  if (f.has_media != 0) {
    m.UploadMedia(host_frame.media, &f.media, stream);
    m.BuildGridMedia(host_frame.media, &f, stream);
    m.BuildMedia(&f, stream);
  }
  // host buffers of the round trips and outputs
  PixelGeometry* host_geometry;
  Float3* host_sky;
  double* host_rows;
  PixelGeometry* host_mirror_geometry = nullptr;
  Float3* host_mirror_sky = nullptr;
  if (o.pinned) {
    m.pin_geometry.Reserve(sizeof(PixelGeometry) * n);
    m.pin_sky.Reserve(sizeof(Float3) * n);
    host_geometry = m.pin_geometry.as<PixelGeometry>();
    host_sky = m.pin_sky.as<Float3>();
    // device_exposure: the row sums come back in the tail's copy
    m.pin_rgb.Reserve(Impl::TailBytes(n, H));
    if (device_exposure) {
      host_rows = reinterpret_cast<double*>(m.pin_rgb.as<char>() + Impl::TailRows(n));
    } else {
      m.pin_rows.Reserve(sizeof(double) * H);
      host_rows = m.pin_rows.as<double>();
    }
    if (out.radiance) m.pin_radiance.Reserve(sizeof(Float3) * n);
    if (out.depth) m.pin_depth.Reserve(sizeof(float) * n);
    if (mirror) {
      m.pin_mirror_geometry.Reserve(sizeof(PixelGeometry) * n);
      m.pin_mirror_sky.Reserve(sizeof(Float3) * n);
      host_mirror_geometry = m.pin_mirror_geometry.as<PixelGeometry>();
      host_mirror_sky = m.pin_mirror_sky.as<Float3>();
    }
  } else {
    m.host_geometry.resize(n);
    m.host_sky.resize(n);
    m.host_rows.resize(H);
    host_geometry = m.host_geometry.data();
    host_sky = m.host_sky.data();
    host_rows = m.host_rows.data();
    if (mirror) {
      m.host_mirror_geometry.resize(n);
      m.host_mirror_sky.resize(n);
      host_mirror_geometry = m.host_mirror_geometry.data();
      host_mirror_sky = m.host_mirror_sky.data();
    }
  }
  // (1) primary geometry (materials and normal maps included) and depth; device_sky: (2) the
  // sky-term kernels; else the geometry back to the host in bands of rows (even row counts:
  // the sky terms' 2x2 quads stay in one band); pinned: the bands and the depth go back on the
  // copy stream
  m.LaunchGeometry(f, o, stream);
  if (o.device_sky) {
    Check(cudaEventRecord(m.stage[1], stream), "cudaEventRecord");
    m.LaunchSky(f, o, stream);
    Check(cudaEventRecord(m.stage[2], stream), "cudaEventRecord");
  }
  cudaStream_t down = o.pinned ? m.copy_stream : stream;
  if (o.pinned) {
    Check(cudaEventRecord(m.geometry_done, stream), "cudaEventRecord");
    Check(cudaStreamWaitEvent(m.copy_stream, m.geometry_done, 0), "cudaStreamWaitEvent");
  }
  const int bands = o.device_sky ? 0 : o.pinned ? std::clamp(o.sky_bands, 1, kMaxSkyBands) : 1;
  const int band_rows = bands <= 1 ? H : ((H + bands - 1) / bands + 1) / 2 * 2;
  auto band_row = [&](int k) { return std::min(H, k * band_rows); };
  for (int k = 0; k < bands; ++k) {
    const int r0 = band_row(k), r1 = band_row(k + 1);
    if (r1 > r0) {
      const size_t off = static_cast<size_t>(r0) * W, count = static_cast<size_t>(r1 - r0) * W;
      Check(cudaMemcpyAsync(host_geometry + off, m.geometry.as<PixelGeometry>() + off,
                            sizeof(PixelGeometry) * count, cudaMemcpyDeviceToHost, down),
            "cudaMemcpyAsync");
      if (mirror)
        Check(
            cudaMemcpyAsync(host_mirror_geometry + off, m.mirror_geometry.as<PixelGeometry>() + off,
                            sizeof(PixelGeometry) * count, cudaMemcpyDeviceToHost, down),
            "cudaMemcpyAsync");
    }
    Check(cudaEventRecord(m.band_done[k], down), "cudaEventRecord");
  }
  if (out.depth) {
    if (o.pinned) {
      m.depth.Download(m.pin_depth.p, sizeof(float) * n, m.copy_stream);
      Check(cudaEventRecord(m.depth_copied, m.copy_stream), "cudaEventRecord");
    } else
      m.depth.Download(out.depth, sizeof(float) * n, stream);
  }
  // (2) per band: its sky terms on the host, up to the device, and (3) its shading kernel,
  // which overlaps the next band's sky terms
  double sky_ms = 0;
  Clock::time_point t1 = t0;
  for (int k = 0; k < bands; ++k) {
    const int r0 = band_row(k), r1 = band_row(k + 1);
    Check(cudaEventSynchronize(m.band_done[k]), "GeometryKernel");
    const auto ts = Clock::now();
    if (k == 0) t1 = ts;
    if (r1 <= r0) continue;
    sky(host_geometry, host_mirror_geometry, n, r0, r1, host_sky, host_mirror_sky);
    sky_ms += MsSince(ts);
    const size_t off = static_cast<size_t>(r0) * W, count = static_cast<size_t>(r1 - r0) * W;
    Check(cudaMemcpyAsync(m.sky.as<Float3>() + off, host_sky + off, sizeof(Float3) * count,
                          cudaMemcpyHostToDevice, stream),
          "cudaMemcpyAsync");
    if (mirror)
      Check(cudaMemcpyAsync(m.mirror_sky.as<Float3>() + off, host_mirror_sky + off,
                            sizeof(Float3) * count, cudaMemcpyHostToDevice, stream),
            "cudaMemcpyAsync");
    m.LaunchShade(f, o, stream, r0, r1);
  }
  if (o.device_sky) m.LaunchShade(f, o, stream, 0, H);
  if (streaks) {
    // the late streaks: made on the host while the GPU runs the kernels queued so far (none of
    // which reads them), then uploaded (staged: the stream is busy) and splatted before the
    // kernels that draw them (the media's view pass or StreakSplatApplyKernel); on a throw the
    // queued work is waited for (the next frame reuses its pinned buffers)
    RealtimeFrameView late;
    try {
      streaks(&late);
    } catch (...) {
      cudaDeviceSynchronize();
      throw;
    }
    m.QueueStreaks(late, &f, n, /*staged=*/o.pinned, stream);
  }
  // the shared visibility, the mirror layer and (4) the rows' log-luminance sums; pinned: the
  // radiance goes back on the copy stream while the host computes the exposure and the film
  // kernel runs
  m.LaunchAfterShade(f, o, stream);
  // the radiance goes back in bands of rows, each behind an event, so that the host copies band
  // k into the frame's image while band k + 1 comes back
  const int out_bands = std::clamp(o.output_bands, 1, kMaxSkyBands);
  auto out_row = [&](int k) { return Impl::OutputBandRow(H, out_bands, k); };
  if (out.radiance && o.pinned) {
    // fuse_resolve: band k as soon as it is resolved (the row sums still running); else after
    // the row sums
    if (!o.fuse_resolve) {
      Check(cudaEventRecord(m.radiance_done, stream), "cudaEventRecord");
      Check(cudaStreamWaitEvent(m.copy_stream, m.radiance_done, 0), "cudaStreamWaitEvent");
    }
    for (int k = 0; k < out_bands; ++k) {
      const size_t off = static_cast<size_t>(out_row(k)) * W;
      const size_t count = static_cast<size_t>(out_row(k + 1) - out_row(k)) * W;
      if (o.fuse_resolve)
        Check(cudaStreamWaitEvent(m.copy_stream, m.resolved_band[k], 0), "cudaStreamWaitEvent");
      if (count > 0)
        Check(cudaMemcpyAsync(m.pin_radiance.as<Float3>() + off, m.radiance.as<Float3>() + off,
                              sizeof(Float3) * count, cudaMemcpyDeviceToHost, m.copy_stream),
              "cudaMemcpyAsync");
      Check(cudaEventRecord(m.radiance_band[k], m.copy_stream), "cudaEventRecord");
    }
    if (o.device_sky) Check(cudaEventRecord(m.stage[6], m.copy_stream), "cudaEventRecord");
  }
  if (device_exposure) {
    // (5) the exposure and the film on the device, the row sums, the device's exposure and the
    // rgb back on the same stream: the host waits once, at the end
    if (o.device_sky) Check(cudaEventRecord(m.stage[3], stream), "cudaEventRecord");
    LaunchExposure(m.rows, H, n, film.exposure, film.white_balance_gains, m.exposure_out, stream);
    m.LaunchFilmDeviceExposure(n, filmic, stream);
    if (o.device_sky) Check(cudaEventRecord(m.stage[4], stream), "cudaEventRecord");
    // the rgb, the row sums and the device's exposure: one copy (the rows' part alone without
    // the rgb)
    const size_t from = out.rgb ? 0 : Impl::TailRows(n);
    Check(cudaMemcpyAsync(m.pin_rgb.as<char>() + from, m.rgb.as<char>() + from,
                          Impl::TailBytes(n, H) - from, cudaMemcpyDeviceToHost, stream),
          "cudaMemcpyAsync");
    Check(cudaEventRecord(m.rgb_copied, stream), "cudaEventRecord");
    if (o.device_sky) Check(cudaEventRecord(m.stage[5], stream), "cudaEventRecord");
  } else {
    Check(cudaMemcpyAsync(host_rows, m.rows, sizeof(double) * H, cudaMemcpyDeviceToHost, stream),
          "cudaMemcpyAsync");
    if (o.device_sky) Check(cudaEventRecord(m.stage[3], stream), "cudaEventRecord");
  }
  m.times.launched = MsSince(t0);
  // pinned: the depth into the frame's image while the GPU shades
  if (out.depth && o.pinned) {
    Check(cudaEventSynchronize(m.depth_copied), "copying the realtime depth");
    ParallelCopy(parallel, {{out.depth, m.pin_depth.p, sizeof(float) * n}}, chunk, serial);
  }
  // the radiance into the frame's image, band by band as it comes back
  const auto copy_radiance = [&] {
    if (!out.radiance) return;
    for (int k = 0; k < out_bands; ++k) {
      Check(cudaEventSynchronize(m.radiance_band[k]), "copying the realtime radiance");
      const size_t off = static_cast<size_t>(out_row(k)) * W;
      const size_t count = static_cast<size_t>(out_row(k + 1) - out_row(k)) * W;
      ParallelCopy(
          parallel,
          {{out.radiance + 3 * off, m.pin_radiance.as<Float3>() + off, sizeof(Float3) * count}},
          chunk, serial);
    }
  };
  Exposure e;
  double ev100 = 0;
  m.times.outputs = 0;
  Clock::time_point t3 = t0;  // the row sums on the host
  if (device_exposure) {
    // the radiance bands and the rgb in one loop over the host's threads, each chunk as soon as
    // its band or the rgb is back (the radiance while the row sums, exposure and film run);
    // then the host's exposure from the same row sums: where the device's differs, the film
    // again with the host's, and its rgb copied over the device exposure's
    const auto tc = Clock::now();
    std::vector<HostCopy> copies;
    if (out.radiance)
      for (int k = 0; k < out_bands; ++k) {
        const size_t off = static_cast<size_t>(out_row(k)) * W;
        const size_t count = static_cast<size_t>(out_row(k + 1) - out_row(k)) * W;
        copies.push_back({out.radiance + 3 * off, m.pin_radiance.as<Float3>() + off,
                          sizeof(Float3) * count, m.radiance_band[k]});
      }
    if (out.rgb) copies.push_back({out.rgb, m.pin_rgb.p, static_cast<size_t>(3 * n), m.rgb_copied});
    ParallelCopy(parallel, copies, chunk, serial);
    Check(cudaStreamSynchronize(stream), "DevelopKernel");
    t3 = Clock::now();
    m.host_rows.assign(host_rows, host_rows + H);
    ev100 = exposure(m.host_rows, e.e);
    const DeviceExposure& d = *reinterpret_cast<const DeviceExposure*>(host_rows + H);
    ++m.checks.frames;
    if (std::memcmp(&d.ev100, &ev100, sizeof(double)) != 0) ++m.checks.ev100_differs;
    if (std::memcmp(d.e, e.e, sizeof(e.e)) != 0) {
      ++m.checks.redeveloped;
      m.LaunchFilm(n, e, filmic, stream);
      if (out.rgb) m.rgb.Download(m.pin_rgb.p, 3 * n, stream);
      Check(cudaStreamSynchronize(stream), "DevelopKernel");
      if (out.rgb)
        ParallelCopy(parallel, {{out.rgb, m.pin_rgb.p, static_cast<size_t>(3 * n)}}, chunk, serial);
    }
    Check(cudaStreamSynchronize(m.copy_stream), "copying the realtime outputs");
    m.times.outputs = MsSince(tc);
  } else {
    Check(cudaStreamSynchronize(stream), "ShadeKernel");
    t3 = Clock::now();
    if (o.pinned) m.host_rows.assign(host_rows, host_rows + H);
    ev100 = exposure(m.host_rows, e.e);
    // (5) film
    m.LaunchFilm(n, e, filmic, stream);
    if (o.pinned) {
      // the radiance into the frame's image while the film kernel runs, then the rgb
      if (out.rgb) m.rgb.Download(m.pin_rgb.p, 3 * n, stream);
      const auto tc = Clock::now();
      copy_radiance();
      Check(cudaStreamSynchronize(m.copy_stream), "copying the realtime outputs");
      Check(cudaStreamSynchronize(stream), "DevelopKernel");
      if (out.rgb)
        ParallelCopy(parallel, {{out.rgb, m.pin_rgb.p, static_cast<size_t>(3 * n)}}, chunk, serial);
      m.times.outputs = MsSince(tc);
    } else {
      if (out.rgb) m.rgb.Download(out.rgb, 3 * n, stream);
      if (out.radiance) m.radiance.Download(out.radiance, sizeof(Float3) * n, stream);
      Check(cudaStreamSynchronize(stream), "DevelopKernel");
    }
  }
  m.times.total = MsSince(t0);
  if (o.device_sky) {
    float ms[3] = {0, 0, 0};
    for (int k = 0; k < 3; ++k)
      Check(cudaEventElapsedTime(&ms[k], m.stage[k], m.stage[k + 1]), "cudaEventElapsedTime");
    m.times.geometry = ms[0];
    m.times.sky = ms[1];
    m.times.shade = ms[2];
    m.times.film = m.times.total - (m.times.geometry + m.times.sky + m.times.shade);
    // the device's end of the kernels and of the copies back (device_exposure)
    m.times.kernels_end = m.times.copies_end = 0;
    if (device_exposure) {
      float end = 0;
      Check(cudaEventElapsedTime(&end, m.stage[0], m.stage[4]), "cudaEventElapsedTime");
      m.times.kernels_end = end;
      Check(cudaEventElapsedTime(&end, m.stage[0], m.stage[5]), "cudaEventElapsedTime");
      m.times.copies_end = end;
      if (out.radiance) {
        Check(cudaEventElapsedTime(&end, m.stage[0], m.stage[6]), "cudaEventElapsedTime");
        m.times.copies_end = std::max<double>(m.times.copies_end, end);
      }
    }
  } else {
    m.times.geometry = std::chrono::duration<double, std::milli>(t1 - t0).count();
    m.times.sky = sky_ms;
    m.times.shade = std::chrono::duration<double, std::milli>(t3 - t1).count() - sky_ms;
    m.times.film = m.times.total - (m.times.geometry + m.times.sky + m.times.shade);
  }
  m.frame = f;
  m.exposure = e;
  m.film = film;
  m.filmic = filmic;
  m.rendered = true;
  return ev100;
}

double DeviceRealtime::TimeKernels(DeviceScene* scene, int count) {
  return TimeKernels(scene, count, impl_->options);
}

double DeviceRealtime::TimeKernels(DeviceScene* scene, int count,
                                   const RealtimeKernelOptions& options) {
  Impl& m = *impl_;
  if (!m.rendered || count < 1) return 0;
  cudaStream_t stream = static_cast<cudaStream_t>(scene->stream());
  const RealtimeFrameView& f = m.frame;
  const int64_t n = static_cast<int64_t>(f.camera.width) * f.camera.height;
  if (options.reuse_hit) m.hits.Reserve(sizeof(TraceHit) * n);
  if (options.reuse_hit && options.reuse_surface) m.surfaces.Reserve(sizeof(SurfaceTerms) * n);
  // the exposure as Render makes it: on the device (its kernel, then the film reading it) or
  // the host's of the last Render
  const int H = f.camera.height;
  const bool device_exposure = options.device_exposure && H <= kMaxDeviceExposureRows;
  const auto film = [&] {
    if (device_exposure) {
      LaunchExposure(m.rows, H, n, m.film.exposure, m.film.white_balance_gains, m.exposure_out,
                     stream);
      m.LaunchFilmDeviceExposure(n, m.filmic, stream);
    } else {
      m.LaunchFilm(n, m.exposure, m.filmic, stream);
    }
  };
  // one untimed run (first launch of a kernel variant)
  m.LaunchStreakSplat(f, stream);
  m.LaunchGeometry(f, options, stream);
  if (options.device_sky && m.sky_uploaded) m.LaunchSky(f, options, stream);
  m.LaunchShading(f, options, stream);
  film();
  Check(cudaStreamSynchronize(stream), "realtime kernels");
  return TimeOnStream(stream, count, [&] {
    m.LaunchStreakSplat(f, stream);
    m.LaunchGeometry(f, options, stream);
    if (options.device_sky && m.sky_uploaded) m.LaunchSky(f, options, stream);
    m.LaunchShading(f, options, stream);
    film();
  });
}

double DeviceFrameExposure(const FilmExposurePod& film, const std::vector<double>& rows,
                           int64_t pixels, const float white_balance_gains[3], float exposure[3]) {
  const int height = static_cast<int>(rows.size());
  if (rows.size() > static_cast<size_t>(kMaxDeviceExposureRows))
    throw Error("DeviceFrameExposure: " + std::to_string(rows.size()) + " rows, at most " +
                std::to_string(kMaxDeviceExposureRows));
  Buffer device_rows, out;
  device_rows.Upload(rows.data(), sizeof(double) * rows.size(), nullptr);
  out.Reserve(sizeof(DeviceExposure));
  LaunchExposure(device_rows.as<double>(), height, pixels, film, white_balance_gains,
                 out.as<DeviceExposure>(), nullptr);
  DeviceExposure d;
  out.Download(&d, sizeof(d), nullptr);
  Check(cudaStreamSynchronize(nullptr), "ExposureKernel");
  for (int c = 0; c < 3; ++c) exposure[c] = d.e[c];
  return d.ev100;
}

namespace {

// the stage events of RealtimeBatch: start, then the end of each RealtimeBatchTimes stage
constexpr int kBatchStages = 8;

}  // namespace

struct RealtimeBatch::Impl : PixelBuffers {
  int width = 0, height = 0, max_cameras = 0, lights = 1, slots = 0;
  bool mirror = false;
  Buffer frames, film, exposure, depth, rows;
  std::vector<RealtimeFrameView> host_frames;
  std::vector<std::vector<cudaEvent_t>> events;  // [slot][kBatchStages + 1]
  ~Impl() {
    for (auto& slot : events)
      for (cudaEvent_t e : slot)
        if (e) cudaEventDestroy(e);
  }
};

RealtimeBatch::RealtimeBatch(int width, int height, int max_cameras, int max_lights, bool mirror,
                             int slots)
    : impl_(new Impl) {
  Impl& m = *impl_;
  try {
    if (width < 1 || height < 1 || height > kMaxDeviceExposureRows || max_cameras < 1 ||
        max_cameras > 65535 || max_lights < 0 || slots < 1)
      throw Error("RealtimeBatch: " + std::to_string(width) + "x" + std::to_string(height) + ", " +
                  std::to_string(max_cameras) + " cameras, " + std::to_string(max_lights) +
                  " lights, " + std::to_string(slots) +
                  " slots; expected a size >= 1x1 with at most " +
                  std::to_string(kMaxDeviceExposureRows) +
                  " rows, 1 to 65535 cameras, lights >= 0, slots >= 1");
    m.width = width;
    m.height = height;
    m.max_cameras = max_cameras;
    m.lights = max_lights > 0 ? max_lights : 1;
    m.mirror = mirror;
    m.slots = slots;
    const size_t n = static_cast<size_t>(width) * height * max_cameras;
    const size_t nl = n * m.lights;
    m.frames.Reserve(sizeof(RealtimeFrameView) * max_cameras);
    m.film.Reserve(sizeof(RealtimeBatchFilm) * max_cameras);
    m.exposure.Reserve(sizeof(DeviceExposure) * max_cameras);
    m.depth.Reserve(sizeof(float) * n);
    m.rows.Reserve(sizeof(double) * height * max_cameras);
    m.Reserve(n, nl, /*with_surfaces=*/true, mirror);
    m.events.assign(slots, std::vector<cudaEvent_t>(kBatchStages + 1, nullptr));
    for (auto& slot : m.events)
      for (cudaEvent_t& e : slot) Check(cudaEventCreate(&e), "cudaEventCreate");
  } catch (...) {
    delete impl_;
    throw;
  }
}

RealtimeBatch::~RealtimeBatch() { delete impl_; }

void RealtimeBatch::Launch(const RealtimeFrameView* frames, const RealtimeBatchFilm* film,
                           int count, float* depth, uint8_t* rgb, int slot, void* stream_ptr) {
  Impl& m = *impl_;
  if (count < 1 || count > m.max_cameras || slot < 0 || slot >= m.slots)
    throw Error("RealtimeBatch::Launch: " + std::to_string(count) + " cameras, slot " +
                std::to_string(slot) + "; expected 1 to " + std::to_string(m.max_cameras) +
                " cameras and a slot in [0, " + std::to_string(m.slots) + ")");
  cudaStream_t stream = static_cast<cudaStream_t>(stream_ptr);
  const int W = m.width, H = m.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int64_t nl = n * m.lights;
  // each camera's frame with its part of the per-pixel arrays
  m.host_frames.assign(frames, frames + count);
  for (int k = 0; k < count; ++k) {
    RealtimeFrameView& f = m.host_frames[k];
    if (f.camera.width != W || f.camera.height != H || f.num_lights > m.lights ||
        (f.any_mirror != 0 && !m.mirror))
      throw Error("RealtimeBatch::Launch: camera " + std::to_string(k) + ": " +
                  std::to_string(f.camera.width) + "x" + std::to_string(f.camera.height) + ", " +
                  std::to_string(f.num_lights) + " lights" +
                  (f.any_mirror != 0 ? ", a mirror layer" : "") + "; expected " +
                  std::to_string(W) + "x" + std::to_string(H) + ", at most " +
                  std::to_string(m.lights) + " lights" + (m.mirror ? "" : ", no mirror layer"));
    m.Point(&f, k * n, k * nl, m.mirror);
  }
  // from pageable memory: staged before the call returns
  m.frames.Upload(m.host_frames.data(), sizeof(RealtimeFrameView) * count, stream);
  m.film.Upload(film, sizeof(RealtimeBatchFilm) * count, stream);
  const BatchFrames fr{m.frames.as<RealtimeFrameView>()};
  cudaEvent_t* ev = m.events[slot].data();
  const auto stage = [&](int i) { Check(cudaEventRecord(ev[i], stream), "cudaEventRecord"); };
  dim3 grid = PixelGrid(W, H);
  grid.z = count;
  Float3* L = m.radiance.as<Float3>();
  stage(0);
  GeometryKernel<BatchFrames, 5><<<grid, kPixelBlock, 0, stream>>>(
      fr, m.geometry.as<PixelGeometry>(), depth ? depth : m.depth.as<float>(), nullptr,
      m.surfaces.as<SurfaceTerms>());
  Check(cudaGetLastError(), "GeometryKernel (batch)");
  if (m.mirror) {
    MirrorTraceKernel<<<grid, kPixelBlock, 0, stream>>>(fr);
    Check(cudaGetLastError(), "MirrorTraceKernel (batch)");
  }
  stage(1);
  dim3 quads = PixelGrid((W + 1) / 2, (H + 1) / 2);
  quads.z = count;
  SkyQuadKernel<<<quads, kPixelBlock, 0, stream>>>(fr, m.sky.as<Float3>());
  Check(cudaGetLastError(), "SkyQuadKernel (batch)");
  if (m.mirror) {
    MirrorSkyKernel<<<grid, kPixelBlock, 0, stream>>>(fr, m.mirror_sky.as<Float3>());
    Check(cudaGetLastError(), "MirrorSkyKernel (batch)");
  }
  stage(2);
  // batches hold no media (BatchRenderer::UpdateWorld refuses them)
  // the batch's shading as a frame's with the default options (one wave or less: the queue)
  if (Impl::QueueShadowRays(RealtimeKernelOptions(), n * count, m.lights)) {
    m.LaunchQueuedShade<BatchFrames, false, false>(fr, grid, m.surfaces.as<SurfaceTerms>(), L, 0, H,
                                                   n, count, m.lights, 0, 0, stream);
  } else {
    ShadeStoredKernel<BatchFrames, 4, false>
        <<<grid, kPixelBlock, 0, stream>>>(fr, m.surfaces.as<SurfaceTerms>(), L, 0, H);
    Check(cudaGetLastError(), "ShadeStoredKernel (batch)");
  }
  stage(3);
  // the shared visibility as a frame's with the default options, the queue's chunks of
  // kPenumbraChunkRays rays (many cameras fill the device: fewer, longer chunks)
  const RealtimeKernelOptions defaults;
  m.LaunchPenumbraRays(fr, W, H, m.lights, nl, count, /*queue=*/true, kPenumbraChunkRays,
                       defaults.tile_penumbra, defaults.staged_window, defaults.window_verdict_rows,
                       stream);
  if (defaults.tile_visibility) {
    dim3 tiles = TileGrid(W, 0, H);
    tiles.z = count;
    TileKernel<BatchFrames>(false, defaults.packed_window_counts)<<<tiles, kTileBlock, 0, stream>>>(
        fr, L, 0, H);
    Check(cudaGetLastError(), "VisibilityTileKernel (batch)");
  } else {
    VisibilityFractionKernel<<<grid, kPixelBlock, 0, stream>>>(fr);
    Check(cudaGetLastError(), "VisibilityFractionKernel (batch)");
    VisibilityResolveKernel<<<grid, kPixelBlock, 0, stream>>>(fr, L);
    Check(cudaGetLastError(), "VisibilityResolveKernel (batch)");
  }
  stage(4);
  if (m.mirror) {
    MirrorShadeKernel<<<grid, kPixelBlock, 0, stream>>>(fr);
    Check(cudaGetLastError(), "MirrorShadeKernel (batch)");
    MirrorBlendKernel<<<grid, kPixelBlock, 0, stream>>>(fr, L);
    Check(cudaGetLastError(), "MirrorBlendKernel (batch)");
  }
  stage(5);
  RowSumWarpKernel<<<dim3((H + 3) / 4, count), 128, 0, stream>>>(L, W, H, m.rows.as<double>());
  Check(cudaGetLastError(), "RowSumWarpKernel (batch)");
  stage(6);
  // the exposures on the device, one block a camera
  BatchExposureKernel<<<count, 256, sizeof(double) * H, stream>>>(
      m.rows.as<double>(), H, n, m.film.as<RealtimeBatchFilm>(), m.exposure.as<DeviceExposure>());
  Check(cudaGetLastError(), "BatchExposureKernel");
  stage(7);
  if (rgb) {
    BatchDevelopKernel<<<dim3(static_cast<unsigned>((n + 255) / 256), count), 256, 0, stream>>>(
        L, n, m.film.as<RealtimeBatchFilm>(), m.exposure.as<DeviceExposure>(), rgb);
    Check(cudaGetLastError(), "BatchDevelopKernel");
  }
  stage(8);
}

RealtimeBatchTimes RealtimeBatch::times(int slot) const {
  const Impl& m = *impl_;
  RealtimeBatchTimes t;
  if (slot < 0 || slot >= m.slots) return t;
  double ms[kBatchStages] = {};
  for (int i = 0; i < kBatchStages; ++i) {
    float x = 0;
    Check(cudaEventElapsedTime(&x, m.events[slot][i], m.events[slot][i + 1]),
          "cudaEventElapsedTime");
    ms[i] = x;
  }
  t.geometry = ms[0];
  t.sky = ms[1];
  t.shade = ms[2];
  t.visibility = ms[3];
  t.mirror = ms[4];
  t.row_sums = ms[5];
  t.exposure = ms[6];
  t.film = ms[7];
  for (double x : ms) t.total += x;
  return t;
}

}  // namespace penumbra::cuda

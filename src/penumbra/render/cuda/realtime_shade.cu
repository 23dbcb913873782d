// the realtime tier's shading kernels (realtime_kernels.cuh): the fused kernel and the three
// passes of the queued shadow rays.

#include <cooperative_groups.h>

#include "penumbra/render/cuda/realtime_kernels.cuh"

namespace penumbra::cuda::realtime {
namespace {

namespace cg = cooperative_groups;

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

// the shading from the shading points the geometry kernel kept (their geometry and material
// terms, ShadeRealtimeStored): at most 128 registers (4 blocks of 128 threads an SM, no
// spills). kMedia false: frames without media only (ShadeRealtimePoint). kSharedTerms: the first
// `lights` lights' unshadowed terms wait between the light loops in the block's dynamic shared
// memory (StridedLightTerms, ShadeLightTermBytes of it: 3.5 KiB a light for 128 threads), not in
// the thread's stack in local memory (LocalLightTerms): the same values, so the same bits.
template <class Frames, bool kMedia, bool kSharedTerms>
__global__ void __launch_bounds__(128, 4)
    ShadeStoredKernel(Frames frames, const SurfaceTerms* surfaces, Float3* radiance, int row0,
                      int row1, int lights) {
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

// the lights whose terms the shared-terms kernels keep in shared memory for a frame of
// `num_lights` lights, and the bytes that takes for a block of `threads` threads.
inline int ShadeSharedLights(int num_lights) {
  return std::min(std::max(num_lights, 0), kShadeCachedLights);
}
inline size_t ShadeLightTermBytes(int lights, int threads) {
  return sizeof(float) * StridedLightTerms::kLightTermFloats * lights * threads;
}

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

// the three passes of the queued shadow rays over rows [row0, row1) of `cameras` frames (grid:
// a camera's rows, z the camera) of `pixels` pixels each; smem: the light terms' shared memory
// (kSharedTerms) for `term_lights` lights.
template <class Frames, bool kMedia, bool kSharedTerms>
void LaunchQueued(Frames frames, dim3 grid, const SurfaceTerms* surfaces, Float3* L,
                  const ShadowRayQueue& q, int row0, int row1, int64_t pixels, int term_lights,
                  size_t smem, cudaStream_t stream) {
  Check(cudaMemsetAsync(q.count, 0, sizeof(unsigned), stream), "cudaMemsetAsync");
  LaunchKernel("ShadeQueuedKernel", ShadeQueuedKernel<Frames, kMedia, kSharedTerms>, grid,
               PixelBlock(), smem, stream, frames, surfaces, L, q, row0, row1, term_lights);
  LaunchKernel("TraceQueuedKernel", TraceQueuedKernel<Frames>, TraceQueuedBlocks<Frames>(), 128, 0,
               stream, frames, q, pixels);
  LaunchKernel("SumQueuedKernel", SumQueuedKernel<Frames>, grid, PixelBlock(), 0, stream, frames, L,
               q, row0, row1);
}

// the frame's shared-terms kernels may take up to kShadeCachedLights lights' terms (set once)
void AllowSharedLightTerms() {
  static const bool set = [] {
    const int threads = static_cast<int>(PixelBlock().x * PixelBlock().y);
    const int most = static_cast<int>(ShadeLightTermBytes(kShadeCachedLights, threads));
    const auto allow = [most](const void* kernel) {
      Check(cudaFuncSetAttribute(kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, most),
            "cudaFuncSetAttribute");
    };
    allow(reinterpret_cast<const void*>(ShadeStoredKernel<OneFrame, true, true>));
    allow(reinterpret_cast<const void*>(ShadeStoredKernel<OneFrame, false, true>));
    allow(reinterpret_cast<const void*>(ShadeQueuedKernel<OneFrame, true, true>));
    allow(reinterpret_cast<const void*>(ShadeQueuedKernel<OneFrame, false, true>));
    return true;
  }();
  (void)set;
}

// the pixels of one wave of the fused shading kernel (4 blocks of 128 threads an SM) on the
// current device.
int64_t ShadeWavePixels() {
  static const int64_t pixels = int64_t{4} * 128 * DeviceSms();
  return pixels;
}

}  // namespace

bool QueueShadowRays(int64_t n, int lights) {
  const int64_t most = int64_t{1} << 32;
  return n <= ShadeWavePixels() && lights <= kMaxQueuedShadowLights &&
         n * kMaxQueuedShadowLights < most && n * std::max(lights, 1) < most;
}

void LaunchFrameShade(const RealtimeFrameView& f, const SurfaceTerms* surfaces, Float3* L,
                      const ShadowRayQueue* queue, int row0, int row1, cudaStream_t stream) {
  if (row1 <= row0) return;
  AllowSharedLightTerms();
  const dim3 grid = PixelGrid(f.camera.width, row1 - row0);
  const int threads = static_cast<int>(PixelBlock().x * PixelBlock().y);
  const int lights = ShadeSharedLights(f.num_lights);
  const size_t smem = ShadeLightTermBytes(lights, threads);
  const OneFrame fr{f};
  const bool media = f.has_media != 0;
  if (queue != nullptr) {
    const int64_t pixels = static_cast<int64_t>(f.camera.width) * f.camera.height;
    if (media)
      LaunchQueued<OneFrame, true, true>(fr, grid, surfaces, L, *queue, row0, row1, pixels, lights,
                                         smem, stream);
    else
      LaunchQueued<OneFrame, false, true>(fr, grid, surfaces, L, *queue, row0, row1, pixels, lights,
                                          smem, stream);
    return;
  }
  LaunchKernel(
      "ShadeStoredKernel",
      media ? ShadeStoredKernel<OneFrame, true, true> : ShadeStoredKernel<OneFrame, false, true>,
      grid, PixelBlock(), smem, stream, fr, surfaces, L, row0, row1, lights);
}

void LaunchBatchShade(BatchFrames frames, int W, int H, int cameras, const SurfaceTerms* surfaces,
                      Float3* L, const ShadowRayQueue* queue, cudaStream_t stream) {
  const dim3 grid = PixelGrid(W, H, cameras);
  if (queue != nullptr) {
    LaunchQueued<BatchFrames, false, false>(frames, grid, surfaces, L, *queue, 0, H,
                                            static_cast<int64_t>(W) * H, 0, 0, stream);
    return;
  }
  LaunchKernel("ShadeStoredKernel (batch)", ShadeStoredKernel<BatchFrames, false, false>, grid,
               PixelBlock(), 0, stream, frames, surfaces, L, 0, H, 0);
}

}  // namespace penumbra::cuda::realtime

// the realtime tier's shared visibility of lights with an extent (realtime_shading.h,
// realtime_kernels.cuh): the penumbra rays (a warp's spread over its lanes, the long jobs
// through a queue) and the fraction and resolve, a block per shadow tile.

#include <cooperative_groups.h>
#include <cooperative_groups/scan.h>

#include "penumbra/render/cuda/realtime_kernels.cuh"

namespace penumbra::cuda::realtime {
namespace {

namespace cg = cooperative_groups;

// the shared visibility's penumbra rays through a queue: VisibilityRaysWarpKernel spreads a
// warp's short jobs over its lanes, but queues the long ones (more than kPenumbraQueueRays rays:
// a tile's ring in a penumbra traces up to 63) in chunks of kFramePenumbraChunkRays rays (a
// batch's of kBatchPenumbraChunkRays, at most kMaxPenumbraChunkRays): a thread of
// VisibilityChunkKernel traces its chunk's rays one after another, so where the queue holds
// fewer chunks than the device has threads (narrow penumbrae) shorter chunks shorten the
// kernel, at one integer atomic a chunk. VisibilityChunkKernel traces the chunks, all threads of
// the device sharing them, and adds each chunk's integer counts to its pixel's (integer atomics:
// the sums do not depend on the order); the chunk that completes a pixel's job writes its
// totals. the same integer counts as SharedVisibilityRays, so the same bits, without a warp
// waiting on its ring pixels while the rest of the device is idle.
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
  int chunk_rays = kFramePenumbraChunkRays;  // rays a chunk (1 to kMaxPenumbraChunkRays)
  uint32_t* counts = nullptr;  // (camera, light, pixel) at camera nl + light n + pixel
  int64_t nl = 0;              // a camera's per-light entries
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

// the most lights whose verdicts VisibilityRaysWarpKernel<..., true> keeps in shared
// memory (TilePenumbraBytes: 32 KiB, under the 48 KiB a kernel gets without asking); frames
// with more take the kernel of 128 threads a block.
constexpr int kMaxTilePenumbraLights = 128;
// the dynamic shared memory of the tile kernel: every light's verdicts of the tile as bit rows
// (kShadowVerdictRows words a light).
inline size_t TilePenumbraBytes(int lights) {
  return static_cast<size_t>(std::max(lights, 1)) * sizeof(uint32_t) * kShadowVerdictRows;
}

// VisibilityChunkKernel's grid: as many blocks of 128 threads as the device holds at once.
template <class Frames>
unsigned ChunkBlocks() {
  static const unsigned blocks = ResidentBlocks(VisibilityChunkKernel<Frames>);
  return blocks;
}

// the penumbra rays, a warp's spread over its 32 lanes: per light, the
// lanes' rays (pixel l's rays 1 .. extra_l - 1) are numbered in lane order (an inclusive scan),
// lane t of round b traces ray b 32 + t of the pixel whose range holds it, and each pixel sums
// its rays' verdicts (ballots): the same integer counts as one thread per pixel, so the same
// bits, without the warp waiting on the one ring pixel that traces 63 rays. whole warps run
// every step (pixels outside the image take part with no rays).
// at most 128 registers (4 blocks an SM: the queue's code would otherwise take it to 131, 3).
// kTile (frames of at most kMaxTilePenumbraLights lights): a block of kTilePixels threads per
// shadow tile (TileBlock, 2 blocks an SM at 128 registers) first copies its pixels' surfaces
// (TileWindowSurfaces: geom of a hit, normal, point) into shared memory, where the window masks
// read their 24 neighbours' (instead of up to 25 threads reading each pixel's PixelGeometry from
// global memory), and every light's verdicts of its tile into its dynamic shared memory
// (TilePenumbraBytes of it) as bit rows, two ballots a warp (two tile rows of 16 pixels:
// ShadowVerdictBits' layout), where a window's "both verdicts seen" is five shifted rows
// (RowWindowVerdicts); the windows, cut at the tile's edges, find their neighbours' there. the
// same masks and booleans as the frame's arrays give, so the same bits.
template <class Frames, bool kTile>
__global__ void __launch_bounds__(kTile ? kTilePixels : 128, kTile ? 2 : 4)
    VisibilityRaysWarpKernel(Frames frames, PenumbraQueue q) {
  extern __shared__ uint32_t tile_rows[];
  constexpr int kSurfaces = kTile ? kTilePixels : 1;
  __shared__ int32_t key[kSurfaces];
  __shared__ float ng_x[kSurfaces], ng_y[kSurfaces], ng_z[kSurfaces], p_x[kSurfaces],
      p_y[kSurfaces], p_z[kSurfaces];
  const RealtimeFrameView& f = frames.get();
  const FramePixel p = PixelOf(f);
  const int u = p.u, v = p.v;
  const int W = f.camera.width, H = f.camera.height;
  const bool inside = p.inside;
  const int t = static_cast<int>(threadIdx.y * blockDim.x + threadIdx.x);
  const int lane = t & 31;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int64_t i = p.i;
  if constexpr (kTile) {
    // this pixel's surface
    key[t] = TileWindowSurfaces::kNoWindowSurface;
    if (inside) {
      const PixelGeometry& g = f.geometry[i];
      key[t] = TileWindowSurfaces::KeyOf(g);
      ng_x[t] = g.ng.x, ng_y[t] = g.ng.y, ng_z[t] = g.ng.z;
      p_x[t] = g.p_or_d.x, p_y[t] = g.p_or_d.y, p_z[t] = g.p_or_d.z;
    }
  }
  if constexpr (kTile) {
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
  }
  uint32_t bits = 0;
  if (inside) {
    if constexpr (kTile)
      bits = SharedVisibilityWindow(
          f, u, v, TileWindowSurfaces{key, ng_x, ng_y, ng_z, p_x, p_y, p_z}, t, kShadowTileSize);
    else
      bits = SharedVisibilityWindow(f, u, v);
  }
  for (int j = 0; j < f.num_lights; ++j) {
    PenumbraRays job;
    if (inside && kTile)
      job = SharedVisibilityPenumbraOf(
          f, u, v, j, bits,
          RowWindowVerdicts{tile_rows + j * kShadowVerdictRows, static_cast<int>(threadIdx.x),
                            static_cast<int>(threadIdx.y)});
    else if (inside)
      job = SharedVisibilityPenumbra(f, u, v, j, bits);
    int count = job.active != 0 && job.extra > 1 ? job.extra - 1 : 0;
    // a long job to the queue (VisibilityChunkKernel writes its totals), if it fits
    bool queued = false;
    if (count > kPenumbraQueueRays)
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

// the shared visibility's fraction (SharedVisibilityFraction) and resolve
// (SharedVisibilityResolve) in one pass: a block of kTilePixels threads per shadow tile of rows
// [row0, row1) (row0 a multiple of kShadowTileSize, row1 one or the image's last row + 1),
// kTileLightGroup lights at a time: their verdicts, ray counts and own flags loaded together (every
// load issued before the first use: one memory latency a group, not three a light) into shared
// memory (each pixel's two counts packed once into one word, ShadowWindowCounts, which the window's
// integer sums read at each tap), each pixel's fractions from there (SharedWindowFraction) into
// shared memory, then each pixel's V from its neighbours' there (SharedLampFraction) added to its
// radiance (AddSharedVisibility), the lights in order; with kMirror, then ApplyMirrorLayer (after
// MirrorShadeKernel). the same functions on the same values in the same order as a kernel per step,
// so the same bits; the windows never leave their tile, so no neighbour is missing.
constexpr int kTileLightGroup = 8;
template <class Frames, bool kMirror>
__global__ void __launch_bounds__(kTilePixels)
    VisibilityTileKernel(Frames frames, Float3* radiance, int row0, int row1) {
  __shared__ int8_t vis[kTileLightGroup][kTilePixels];
  __shared__ uint8_t own[kTileLightGroup][kTilePixels];
  __shared__ uint32_t counts[kTileLightGroup][kTilePixels];
  __shared__ float fraction[kTileLightGroup][kTilePixels];
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
      counts[l][t] = ShadowWindowCounts(w[l], a[l], r[l]);
    }
    __syncthreads();
    VisibilityTaps taps[kTileLightGroup];
#pragma unroll
    for (int l = 0; l < kTileLightGroup; ++l) {
      taps[l].vis = vis[l];
      taps[l].fraction = fraction[l];
      taps[l].stride = kShadowTileSize;
      taps[l].counts = counts[l];
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

}  // namespace

int64_t PenumbraQueueBytes(int64_t nl) {
  return static_cast<int64_t>(sizeof(PenumbraChunk)) * PenumbraQueueCapacity(nl, 1);
}

template <class Frames>
void LaunchPenumbraRays(Frames frames, int W, int H, int lights, int64_t nl, int cameras,
                        int chunk_rays, void* queue, void* queued, void* counts,
                        cudaStream_t stream) {
  PenumbraQueue q;
  q.queue = static_cast<PenumbraChunk*>(queue);
  q.queued = static_cast<unsigned long long*>(queued);
  q.chunk_rays = std::clamp(chunk_rays, 1, kMaxPenumbraChunkRays);
  q.capacity = PenumbraQueueCapacity(nl * cameras, q.chunk_rays);
  q.counts = static_cast<uint32_t*>(counts);
  q.nl = nl;
  Check(cudaMemsetAsync(q.queued, 0, sizeof(unsigned long long), stream), "cudaMemsetAsync");
  if (lights <= kMaxTilePenumbraLights) {
    dim3 grid = TileGrid(W, 0, H);
    grid.z = cameras;
    VisibilityRaysWarpKernel<Frames, true>
        <<<grid, TileBlock(), TilePenumbraBytes(lights), stream>>>(frames, q);
  } else {
    VisibilityRaysWarpKernel<Frames, false>
        <<<PixelGrid(W, H, cameras), PixelBlock(), 0, stream>>>(frames, q);
  }
  Check(cudaGetLastError(), "VisibilityRaysWarpKernel");
  // one wave of resident blocks strides over the chunks (their number stays on the device)
  LaunchKernel("VisibilityChunkKernel", VisibilityChunkKernel<Frames>, ChunkBlocks<Frames>(), 128,
               0, stream, frames, q);
}

template <class Frames>
void LaunchVisibilityTiles(Frames frames, int W, int row0, int row1, int cameras, bool mirror,
                           Float3* radiance, cudaStream_t stream) {
  if (row1 <= row0) return;
  dim3 grid = TileGrid(W, row0, row1);
  grid.z = cameras;
  LaunchKernel("VisibilityTileKernel",
               mirror ? VisibilityTileKernel<Frames, true> : VisibilityTileKernel<Frames, false>,
               grid, TileBlock(), 0, stream, frames, radiance, row0, row1);
}

template void LaunchPenumbraRays<OneFrame>(OneFrame, int, int, int, int64_t, int, int, void*, void*,
                                           void*, cudaStream_t);
template void LaunchPenumbraRays<BatchFrames>(BatchFrames, int, int, int, int64_t, int, int, void*,
                                              void*, void*, cudaStream_t);
template void LaunchVisibilityTiles<OneFrame>(OneFrame, int, int, int, int, bool, Float3*,
                                              cudaStream_t);
template void LaunchVisibilityTiles<BatchFrames>(BatchFrames, int, int, int, int, bool, Float3*,
                                                 cudaStream_t);

}  // namespace penumbra::cuda::realtime

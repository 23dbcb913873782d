#pragma once
// the realtime tier's kernels on the device (cuda_realtime.h), shared by the realtime_*.cu files
// only (it includes the CUDA runtime): where a kernel finds its frame and pixel, the per-pixel
// buffers of a frame or a batch, and the launches of each job's kernels, defined by job:
// realtime_geometry.cu (primary geometry, sky terms, the mirror layer), realtime_shade.cu (the
// shading and the queued shadow rays), realtime_visibility.cu (the shared visibility),
// realtime_media.cu (the media volumes, the media view pass and the particle streaks),
// realtime_film.cu (row sums, exposure, film). realtime_device.cu and realtime_batch.cu run them
// for one frame (DeviceRealtime) and for a batch of cameras (RealtimeBatch). every kernel runs
// the PB_HOST_DEVICE per-pixel functions of render/transport/realtime.h.

#include <cuda_runtime.h>

#include <algorithm>
#include <cstdint>
#include <type_traits>
#include <utility>
#include <vector>

#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/cuda/cuda_realtime.h"
#include "penumbra/render/cuda/streak_upload.h"
#include "penumbra/render/transport/realtime.h"

namespace penumbra::cuda::realtime {

constexpr unsigned kFullWarp = 0xffffffffu;

// where a kernel finds its frame: one frame passed by value (DeviceRealtime), or camera
// blockIdx.z's of a batch's array of frames in device memory (RealtimeBatch). a kernel's
// per-pixel arrays that are not in the frame hold every camera's image in turn (camera z at
// z * width * height), so CameraOffset(f) is the offset of this block's camera (0 for one frame).
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

// the blocks of the kernels that work a shadow tile (render/light/shadow_window_math.h) at a time:
// one thread a pixel of the tile (whose pixels' windows never leave it).
constexpr int kTilePixels = kShadowTileSize * kShadowTileSize;
inline dim3 TileBlock() { return dim3(kShadowTileSize, kShadowTileSize); }
// the grid of the tile kernels over rows [row0, row1) of frames W pixels wide.
inline dim3 TileGrid(int W, int row0, int row1) {
  return dim3((W + kShadowTileSize - 1) / kShadowTileSize,
              (row1 - row0 + kShadowTileSize - 1) / kShadowTileSize);
}

// the block and grid of the per-pixel kernels (whole warps of 16 x 2 pixels).
inline dim3 PixelBlock() { return dim3(16, 8); }
inline dim3 PixelGrid(int W, int H) { return dim3((W + 15) / 16, (H + 7) / 8); }
// PixelGrid over `cameras` cameras (grid z).
inline dim3 PixelGrid(int W, int H, int cameras) {
  dim3 g = PixelGrid(W, H);
  g.z = cameras;
  return g;
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

// ---- geometry, sky terms and the mirror layer (realtime_geometry.cu) ----

// the primary geometry, depth and material terms (SurfaceTerms, for ShadeRealtimeStored) of
// every pixel of `frames` on grid `grid` (PixelGrid, z the camera).
template <class Frames>
void LaunchGeometry(Frames frames, dim3 grid, PixelGeometry* geometry, float* depth,
                    SurfaceTerms* surfaces, cudaStream_t stream);
// the sky terms of every 2x2 quad of primary geometry into `sky`; `quads`: PixelGrid of the
// quads (z the camera).
template <class Frames>
void LaunchSkyQuads(Frames frames, dim3 quads, Float3* sky, cudaStream_t stream);
// the mirror layer, where a frame has one: the mirrored rays (after the geometry), their sky
// terms, their shading (after the sky terms) and the blend into `radiance`.
template <class Frames>
void LaunchMirrorTrace(Frames frames, dim3 grid, cudaStream_t stream);
template <class Frames>
void LaunchMirrorSky(Frames frames, dim3 grid, Float3* mirror_sky, cudaStream_t stream);
template <class Frames>
void LaunchMirrorShade(Frames frames, dim3 grid, cudaStream_t stream);
template <class Frames>
void LaunchMirrorBlend(Frames frames, dim3 grid, Float3* radiance, cudaStream_t stream);

// ---- shading (realtime_shade.cu) ----

// the queued shadow rays' device arrays (per pixel of the frame, or of the whole batch).
struct ShadowRayQueue {
  QueuedShadowRay* rays = nullptr;
  unsigned* count = nullptr;  // rays queued (never more than the room: a ray per pixel and light)
  QueuedLightMasks* masks = nullptr;
  uint32_t* occluded = nullptr;  // bit j: light j's ray hit something (integer atomicOr)
};

// whether frames of `n` pixels in all (every camera's) and `lights` lights shade with their
// shadow rays apart (ShadeQueuedStored, SumQueuedLights, in three passes): when the pixels fit
// one wave of the fused kernel's blocks (4 blocks of 128 threads an SM), which leaves SMs idle
// while the queue spreads the rays over all of them, and the lights fit a pixel's masks and the
// rays' keys and count 32 bits. larger frames fill the device, where the fused kernel, whose
// shading hides its rays' latency, is faster. the same bits either way.
bool QueueShadowRays(int64_t n, int lights);

// the shading of rows [row0, row1) of frame f (ShadeRealtimeStored from the geometry kernel's
// material terms) into `radiance`: the fused kernel, the first kShadeCachedLights lights'
// unshadowed terms in the block's shared memory (StridedLightTerms), or with `queue` (non-null
// where QueueShadowRays holds) the three passes.
void LaunchFrameShade(const RealtimeFrameView& f, const SurfaceTerms* surfaces, Float3* radiance,
                      const ShadowRayQueue* queue, int row0, int row1, cudaStream_t stream);
// the same over a batch (`cameras` cameras of W x H pixels, no media;
// the lights' terms in each thread's stack, LocalLightTerms).
void LaunchBatchShade(BatchFrames frames, int W, int H, int cameras, const SurfaceTerms* surfaces,
                      Float3* radiance, const ShadowRayQueue* queue, cudaStream_t stream);

// ---- the shared visibility (realtime_visibility.cu) ----

// the penumbra rays' queue: its chunks' room for frames of nl per-light entries.
int64_t PenumbraQueueBytes(int64_t nl);
// the penumbra rays of `cameras` frames of W x H pixels, at most `lights` lights and nl
// per-light entries each: a warp's short jobs spread over its lanes, the long ones through a
// queue of chunks of `chunk_rays` rays every thread of the device takes from (the same integer
// counts as one thread a pixel, so the same bits). `queue`, `queued`, `counts`: the queue's
// device arrays (PenumbraQueueBytes, 8 bytes, 4 nl bytes).
template <class Frames>
void LaunchPenumbraRays(Frames frames, int W, int H, int lights, int64_t nl, int cameras,
                        int chunk_rays, void* queue, void* queued, void* counts,
                        cudaStream_t stream);
// the shared visibility's fraction and resolve over rows [row0, row1) (whole shadow tiles, or
// to the image's last row) of `cameras` frames, a block per shadow tile, into `radiance`; with
// `mirror`, then the mirror blend (after LaunchMirrorShade).
template <class Frames>
void LaunchVisibilityTiles(Frames frames, int W, int row0, int row1, int cameras, bool mirror,
                           Float3* radiance, cudaStream_t stream);

// ---- media and particle streaks (realtime_media.cu) ----

// the device side of a frame's media and particle streaks (DeviceRealtime's): the media's
// arrays and the volumes the frame builds, the streaks' uploads and the splat's buffers.
struct MediaStreakBuffers {
  // the frame's homogeneous media (RealtimeMediaView's arrays)
  Buffer media_pods, media_fog, media_inv_log_far, media_axes, media_trans;
  Buffer media_vis;  // the world light volume's visibility when the frame builds it
  // the grids' froxels (records; t0, t1 and slices per m end to end; axis tables), their boxes
  // and light volumes
  Buffer media_grid_records, media_grid_columns, media_grid_axes, media_grid_pods, media_grid_T;
  // the grids' arrays when the frame builds their volumes: densities, emission, their
  // MediaGridPods (the arrays of grid_generation, uploaded again when it changes), and the
  // light volumes' in-scatter sources
  Buffer media_grid_density, media_grid_emission, media_grid_media, media_grid_source;
  bool grid_arrays_held = false;
  uint64_t grid_generation = 0;
  // what the last frame built there (DownloadGridVolumes): T values, cells, froxel columns
  size_t grid_built_values = 0;
  int64_t grid_built_cells = 0;
  int grid_built_columns = 0;
  // the realtime splat's streaks (shared with the pathtraced tier's upload) and per pixel its
  // StreakKeys and shaded streaks (StreakSplatView)
  StreakBuffers splat_streaks;
  Buffer splat_nearest, splat_pixels, splat_rows;
  // page-locked staging of the late streaks: the splat's streaks and row poses
  PinnedBuffer pin_splat, pin_splat_rows;

  // the frame's media (host arrays of `h`, RealtimeFrameData::View) to the device on `stream`
  // (pageable: staged before the calls return), *d pointing to them; `volume`: the device's
  // sky volume pod (null: none uploaded).
  void UploadMedia(const RealtimeMediaView& h, const SkyVolumePod* volume, RealtimeMediaView* d,
                   cudaStream_t stream);
  // the volumes frame f builds itself (f->media_build), on `stream` after UploadMedia: the
  // grids' light volumes and froxels, then the world light volume and the fog froxels;
  // f->media pointed at their buffers. `h`: the host's media view.
  void BuildMedia(const RealtimeMediaView& h, RealtimeFrameView* f, cudaStream_t stream);
  // the particle streaks of host frame h to the device on `stream`, f's streak fields pointing
  // at them (n: the frame's pixels): the splat's streaks (host arrays; or the device
  // culling's, read in place: their sets only, the count on the device,
  // StreakSplatView::count), then their splat queued (LaunchStreakSplat). staged:
  // through page-locked staging (the last frame's copies from it are done: it ended with a
  // synchronisation), so that the host never waits for a busy stream (the late streaks).
  void QueueStreaks(const RealtimeFrameView& h, RealtimeFrameView* f, int64_t n, bool staged,
                    cudaStream_t stream);
  // the grids' volumes of the last frame copied into *out (DeviceRealtime::DownloadGridVolumes).
  bool DownloadGridVolumes(GridVolumeArrays* out) const;

 private:
  void BuildGridMedia(const RealtimeMediaView& h, RealtimeFrameView* f, cudaStream_t stream);
};

// the splat of frame f's particle streaks (f.splat, its arrays on the device) on `stream`:
// every pixel's key cleared, the streaks splatted, the pixels with one shaded.
void LaunchStreakSplat(const RealtimeFrameView& f, cudaStream_t stream);
// what changes frame f's radiance after the shared visibility's resolve: the media's view pass
// (with the streaks seen through them), else the splat's streaks.
void LaunchViewPasses(const RealtimeFrameView& f, const float* depth, Float3* radiance,
                      cudaStream_t stream);
// whether frame f has such passes (so no output band is final before them).
inline bool HasViewPasses(const RealtimeFrameView& f) {
  return f.has_media != 0 || f.splat.streaks.num > 0;
}

// ---- row sums, exposure and film (realtime_film.cu) ----

// the device's exposure of a frame (ExposureKernel): the per-channel exposures and the EV100.
struct DeviceExposure {
  float e[3];
  double ev100;
};

// each row's log-luminance sum of `cameras` frames of W x H pixels (camera-major), a warp a row
// (32 strided partial sums, then a fixed butterfly).
void LaunchRowSums(const Float3* radiance, int W, int H, int cameras, double* rows,
                   cudaStream_t stream);
// film_math.h's FrameExposure of the `height` row sums at `rows` into `out` (one block).
void LaunchExposure(const double* rows, int height, int64_t pixels, const FilmExposurePod& film,
                    const float gains[3], DeviceExposure* out, cudaStream_t stream);
// the film (DevelopPixel) of n pixels with the host's exposure `e`, or with the device's.
void LaunchDevelop(const Float3* radiance, int64_t n, const float e[3], int filmic,
                   const uint8_t* lut, uint8_t* rgb, cudaStream_t stream);
void LaunchDevelop(const Float3* radiance, int64_t n, const DeviceExposure* exposure, int filmic,
                   const uint8_t* lut, uint8_t* rgb, cudaStream_t stream);
// the exposures of `count` cameras from their row sums (one block each, the rows camera-major,
// `height` each), and their films (n pixels each, camera-major).
void LaunchBatchExposure(const double* rows, int height, int64_t n, int count,
                         const RealtimeBatchFilm* film, DeviceExposure* exposure,
                         cudaStream_t stream);
void LaunchBatchDevelop(const Float3* radiance, int64_t n, int count, const RealtimeBatchFilm* film,
                        const DeviceExposure* exposure, uint8_t* rgb, cudaStream_t stream);

// ---- the per-pixel buffers of a frame or a batch ----

// the element type of the RealtimeFrameView array (T* or const T*) that member pointer type M
// names.
template <class M>
using ViewElement = std::remove_const_t<std::remove_pointer_t<
    std::remove_reference_t<decltype(std::declval<RealtimeFrameView&>().*std::declval<M>())>>>;

// the chunks of the penumbra rays' queue of a frame (DeviceRealtime) and of a batch (many
// cameras fill the device: fewer, longer chunks).
constexpr int kFramePenumbraChunkRays = 1;
constexpr int kBatchPenumbraChunkRays = 4;

// the per-pixel device arrays of `cameras` frames of n pixels and `lights` lights each (one
// frame: DeviceRealtime; a batch: RealtimeBatch), camera k's at k n (k n lights for the
// per-light ones).
struct PixelBuffers {
  Buffer geometry, sky, radiance, surfaces;
  // the shared visibility's buffers (RealtimeFrameView)
  Buffer window, total, area_c, area_vis, area_visible, area_rays, area_own, area_fraction;
  // the penumbra rays' queue: the chunks, their count, each pixel's counts
  Buffer penumbra_queue, penumbra_queued, penumbra_counts;
  // the mirror layer's buffers (RealtimeFrameView)
  Buffer mirror_geometry, mirror_hits, mirror_sky, mirror_radiance;
  // the queued shadow rays (reserved by the first frame that takes them): room for a ray per
  // pixel and light, the count, each pixel's masks and verdicts
  Buffer shadow_rays, shadow_count, shadow_masks, shadow_occluded;

  // room for n pixels (all cameras) and nl = n x lights (lights >= 1); the mirror layer's if
  // `mirror`
  void Reserve(int64_t n, int64_t nl, bool mirror) {
    radiance.Reserve(sizeof(Float3) * n);
    surfaces.Reserve(sizeof(SurfaceTerms) * n);
    ForEachViewArray(*this, mirror, [n, nl](Buffer& b, auto field, bool per_light) {
      b.Reserve(sizeof(ViewElement<decltype(field)>) * (per_light ? nl : n));
    });
    penumbra_queue.Reserve(static_cast<size_t>(PenumbraQueueBytes(nl)));
    penumbra_queued.Reserve(sizeof(unsigned long long));
    penumbra_counts.Reserve(sizeof(uint32_t) * nl);
  }
  // the shadow-ray queue for `n` pixels in all and `lights` lights (QueueShadowRays holds)
  ShadowRayQueue ShadowQueue(int64_t n, int lights) {
    shadow_rays.Reserve(sizeof(QueuedShadowRay) * n * std::max(lights, 1));
    shadow_count.Reserve(sizeof(unsigned));
    shadow_masks.Reserve(sizeof(QueuedLightMasks) * n);
    shadow_occluded.Reserve(sizeof(uint32_t) * n);
    ShadowRayQueue q;
    q.rays = shadow_rays.as<QueuedShadowRay>();
    q.count = shadow_count.as<unsigned>();
    q.masks = shadow_masks.as<QueuedLightMasks>();
    q.occluded = shadow_occluded.as<uint32_t>();
    return q;
  }
  // the penumbra rays of LaunchPenumbraRays through this queue
  template <class Frames>
  void PenumbraRays(Frames frames, int W, int H, int lights, int64_t nl, int cameras,
                    int chunk_rays, cudaStream_t stream) {
    LaunchPenumbraRays(frames, W, H, lights, nl, cameras, chunk_rays, penumbra_queue.p,
                       penumbra_queued.p, penumbra_counts.p, stream);
  }
  // f's per-pixel arrays: the part at pixel `at` and, per light, at `at_l`
  void Point(RealtimeFrameView* f, int64_t at, int64_t at_l, bool mirror) const {
    ForEachViewArray(*this, mirror, [f, at, at_l](const Buffer& b, auto field, bool per_light) {
      f->*field = b.as<ViewElement<decltype(field)>>() + (per_light ? at_l : at);
    });
  }

 private:
  // fn(buffer, its field of RealtimeFrameView, whether it holds a value per pixel and light or
  // per pixel) for every buffer a frame's view points into (Point), each field's type the
  // buffer's element (Reserve); the mirror layer's with `mirror`.
  template <class Self, class Fn>
  static void ForEachViewArray(Self& self, bool mirror, Fn&& fn) {
    using V = RealtimeFrameView;
    fn(self.sky, &V::sky_term, false);
    fn(self.geometry, &V::geometry, false);
    fn(self.window, &V::window, false);
    fn(self.total, &V::total, false);
    fn(self.area_c, &V::area_c, true);
    fn(self.area_vis, &V::area_vis, true);
    fn(self.area_visible, &V::area_visible, true);
    fn(self.area_rays, &V::area_rays, true);
    fn(self.area_own, &V::area_own, true);
    fn(self.area_fraction, &V::area_fraction, true);
    if (!mirror) return;
    fn(self.mirror_geometry, &V::mirror_geometry, false);
    fn(self.mirror_hits, &V::mirror_hits, false);
    fn(self.mirror_sky, &V::mirror_sky, false);
    fn(self.mirror_radiance, &V::mirror_radiance, false);
  }
};

}  // namespace penumbra::cuda::realtime

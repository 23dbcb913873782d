#pragma once
// the realtime tier on the GPU (realtime_shading.h per pixel, realtime_frame.h on the host):
// device copies of a scene's materials, textures, geoms and lights, and the frame's kernels.
// implemented in realtime_kernels.cu; plain structs only here (no Eigen, no CUDA headers).
// every function throws penumbra::Error naming the CUDA call when the runtime reports an error.
//
// a frame: (1) a kernel traces every pixel's primary ray and writes its geometry and depth
// (and, by default, the hit's material terms, SurfaceTerms, for the shading kernel);
// with a mirror layer in the scene it also traces the mirrored rays (TraceMirrorRay);
// (2) a kernel turns the geometry into sky terms, one thread per 2x2 quad (QuadSkyTerms) and,
// with a mirror layer, one per mirrored ray (MirrorSkyTerm): the shared lookups of
// render/sky_eval_math.h over the device copies of the SkyModel's and SkyIrradianceVolume's
// arrays (UploadSky), the functions the CPU backend calls. the sky terms can still be made on
// the host instead (RealtimeKernelOptions::device_sky false, the benchmark's ablation: `sky`
// runs the same functions on the CPU, realtime_frame.h, in bands of rows with pinned copies,
// RealtimeKernelOptions::sky_bands: band k's geometry comes back while the host computes band
// k - 1's sky terms, and band k's shading kernel runs while the host computes band k + 1's);
// (3) the shading kernel (ShadeRealtimeStored, or ShadeRealtimePixel), the shared visibility's
// kernels (a warp's penumbra rays spread over its lanes) and
// the mirror layer's (ShadeMirrorHit, ApplyMirrorLayer); (4) per-row log-luminance sums, which
// one thread block turns into the frame's EV100 and exposures (film_math.h's FrameExposure, the
// rows added in row order: RealtimeKernelOptions::device_exposure; else the host, `exposure`,
// between the row sums and the film kernel); (5) the film kernel (DevelopPixel). the host
// computes the exposure from the same row sums too and, in the rare frame where the device's
// double exp, log2 and exp2 gave other float exposures than its C library, develops the frame
// again with its own: the rgb and EV100 are always the host path's bits.
// every sum runs in a fixed order and no atomics touch an output: frames are bit-identical run to
// run on one GPU.

#include <cstdint>
#include <functional>
#include <vector>

#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/cuda/realtime_shading.h"
#include "penumbra/render/film_math.h"

namespace penumbra::cuda {

/// a frame's host buffers (width x height pixels; radiance and rgb x 3), each may be null.
struct RealtimeOutputs {
  /// runs body(0) .. body(count - 1), in any order and possibly at once (a thread pool).
  using ParallelFn = cuda::ParallelFn;
  float* radiance = nullptr;
  uint8_t* rgb = nullptr;
  float* depth = nullptr;
  /// copies the pinned outputs into these buffers in chunks through it (empty: one thread).
  ParallelFn parallel;
};

/// the film of a frame of DeviceRealtime::Render: its tone map and what its exposure is made
/// of (film_math.h's FrameExposure).
struct RealtimeFilm {
  bool filmic = true;        ///< the hue-preserving filmic map (else a clamp)
  FilmExposurePod exposure;  ///< auto or manual EV100 and compensation (Film::exposure_pod)
  float white_balance_gains[3] = {1, 1, 1};  ///< the view's (CameraView::white_balance_gains)
};

/// how Render's exposures on the device compared with the host's, over the frames so far
/// (RealtimeKernelOptions::device_exposure).
struct RealtimeExposureChecks {
  int64_t frames = 0;         ///< frames whose exposure the device computed
  int64_t ev100_differs = 0;  ///< of them, frames whose device EV100 differed in some bit
  int64_t redeveloped = 0;    ///< of them, frames developed again with the host's exposures
};

/// the scene-constant data of the realtime path (host arrays, copied once by Upload).
struct RealtimeStatic {
  const MaterialPod* materials = nullptr;
  int64_t num_materials = 0;
  const TexturePod* textures = nullptr;
  int64_t num_textures = 0;
  const uint8_t* texels = nullptr;
  int64_t num_texel_bytes = 0;
  const float* srgb_decode = nullptr;  ///< 256 entries
  const uint8_t* oetf_lut = nullptr;   ///< kFilmLutSize entries
};

/// the sky's and the sky volume's arrays (host pointers in the pods; realtime_frame.h's
/// SkyData), copied by UploadSky: the irradiance table (kSkyIrrSide^2 x 3 floats), the skybox's
/// level 0 (6 x skybox_width^2 x 3 bytes, if any), and per probe its SH (kSkyShStride floats),
/// its cell's corner positions (24 floats) and its texels' depths (kSkyNumTexels bytes).
struct RealtimeSky {
  SkyModelPod sky;
  SkyVolumePod volume;
  int64_t num_probes = 0;
};

/// the most bands of rows RealtimeKernelOptions::sky_bands may ask for.
constexpr int kMaxSkyBands = 16;

/// how the realtime kernels run (the defaults are the fast ones; the others stay for the
/// benchmark's ablations, render_cuda_bench --realtime). every variant computes the same
/// radiance and depth; only the order of a row's log-luminance sum (rows_per_warp) could move
/// the exposure's last bits.
struct RealtimeKernelOptions {
  /// the shading kernel takes the primary hit the geometry kernel traced (else it traces it
  /// again).
  bool reuse_hit = true;
  /// with reuse_hit: the geometry kernel keeps each hit's material terms (SurfaceTerms, 40 bytes
  /// a pixel) and the shading kernel shades from them and the primary geometry
  /// (ShadeRealtimeStored) instead of evaluating the surface (textures, normal map) again.
  bool reuse_surface = true;
  /// one warp sums a row's log-luminance terms (32 strided partial sums, then a fixed tree);
  /// else one thread sums the row in column order.
  bool rows_per_warp = true;
  /// Render() copies through page-locked host buffers (the geometry and sky terms' round trip,
  /// the row sums, and the outputs, which are then copied into the frame's images; the depth
  /// and radiance on a second stream, overlapped); else to and from pageable memory directly.
  bool pinned = true;
  /// with pinned copies and host sky terms (device_sky false), Render()'s bands of rows (1 to
  /// kMaxSkyBands): band k's geometry goes to the host, its sky terms come back and it is shaded
  /// while the host computes band k + 1's (1: the whole frame at once). pageable copies: always 1.
  int sky_bands = 4;
  /// the shading kernel's __launch_bounds__ minimum of resident blocks of 128 threads per SM:
  /// 0 or 1 leaves the registers to the compiler (130); 4 caps them at 128 a thread (4 blocks an
  /// SM instead of 3, no spills), 6 at 85 (more warps in flight, spills). with reuse_hit only.
  int min_blocks = 4;
  /// with reuse_surface and min_blocks 4 or 5 (the 128-register kernel, the default): the
  /// shading kernel keeps the lights' unshadowed terms between its two light loops
  /// (ShadeRealtimePoint: the first kShadeCachedLights lights' contribution, direction and
  /// distance, 28 bytes a light and pixel) in its block's shared memory (StridedLightTerms:
  /// 3.5 KiB a light for 128 threads, 31.5 KiB for the house's 9 lights) instead of each
  /// thread's stack in local memory (LocalLightTerms; the stack goes from 1,280 to 832 bytes):
  /// the same values, so the same bits.
  bool shared_light_terms = true;
  /// with reuse_surface: small frames shade with their shadow rays apart, in three passes
  /// (branch gpu22; realtime_shading.h's ShadeQueuedStored, SumQueuedLights): a kernel evaluates
  /// every light's unshadowed term, keeps the lit ones' contributions (area_c) and puts the
  /// shadow rays worth tracing into one queue for the frame (32 bytes a ray, room for one per
  /// pixel and light); a lean kernel traces the queue, each verdict a bit of its pixel's mask
  /// (integer atomicOr); a third sums each pixel's lights in light order as the fused kernel
  /// does: the same bits. small: the frame's pixels (a batch's: all its cameras') fit one wave
  /// of the fused kernel's blocks (4 blocks of 128 threads an SM; 67,584 pixels on an H100's
  /// 132 SMs), where that kernel leaves SMs idle and the queue spreads the rays over all of
  /// them (128x128 on an H100: the house's kernels 0.267 ms instead of 0.305); larger frames
  /// fill the device, and there the fused kernel, whose shading hides its rays' latency, is
  /// faster (640x480: 0.722 against 0.757 ms). frames of more than kMaxQueuedShadowLights
  /// lights take the fused kernel.
  bool queue_shadow_rays = true;
  /// with queue_shadow_rays: every frame's shadow rays through the queue, whatever its size.
  bool queue_shadow_rays_always = false;
  /// the geometry kernel's __launch_bounds__ minimum of resident blocks of 128 threads per SM:
  /// 5 caps its registers at 102 (five blocks an SM, as before it kept the material terms for
  /// reuse_surface), below 5 leaves them to the compiler.
  int geometry_min_blocks = 5;
  /// with pinned copies, the radiance goes back in this many bands of rows (1 to
  /// kMaxSkyBands), each copied into the frame's image while the next one comes back.
  int output_bands = 2;
  /// the shared visibility's penumbra rays: a warp's rays spread over its 32 lanes
  /// (VisibilityRaysWarpKernel, the same integer counts); else each pixel traces its own in
  /// turn (SharedVisibilityRays).
  bool warp_penumbra = true;
  /// the shared visibility's long penumbra jobs (more than 8 rays: a tile's ring traces up to
  /// 63) through one queue for the whole frame (or batch): their rays go into chunks of 4 that
  /// every thread of the device takes from, the pixels' integer counts summed with integer
  /// atomics (the same counts, so the same bits), so no warp waits on its ring pixels; the
  /// short ones spread over their warp's lanes (as warp_penumbra, which this implies).
  bool queue_penumbra = true;
  /// with queue_penumbra: the rays of a queued chunk (1 to 8; a batch's chunks hold 4). a
  /// thread of VisibilityChunkKernel traces its chunk's rays one after another, so where the
  /// queue holds fewer chunks than the device has threads (the house's narrow penumbrae) the
  /// kernel lasts as long as one chunk's rays; shorter chunks shorten it, at one integer atomic
  /// a chunk. the same integer counts, so the same bits.
  int penumbra_chunk_rays = 1;
  /// with device_sky, a frame with a mirror layer traces, sky-terms and shades its mirrored rays
  /// (MirrorTraceKernel, MirrorSkyKernel, MirrorShadeKernel) on a second stream that forks from
  /// the frame's stream after the geometry kernel and joins it before the mirror blend, so they
  /// run beside the sky quads, the shading and the shared visibility (which neither read nor
  /// write their arrays: the same bits); else after them on the frame's stream.
  bool mirror_stream = true;
  /// with mirror_stream: the side stream has the device's lowest priority, below the frame's
  /// stream (DeviceScene's, the highest), so the mirror layer's blocks take the SMs the frame's
  /// own kernels leave; else the same priority as the frame's stream.
  bool mirror_low_priority = true;
  /// the shared visibility's resolve and the mirror blend in one kernel (the mirrored radiance
  /// shaded before it), launched in the radiance's output_bands bands of rows, each band's copy
  /// back behind its own event (without media and streaks, which change the radiance after
  /// it): band k goes back while band k + 1 is resolved and the row sums run. else the resolve,
  /// then the blend over the whole frame, and the copies behind the row sums.
  bool fuse_resolve = true;
  /// the shared visibility's fraction and resolve (with fuse_resolve also the mirror blend) in
  /// one kernel of a block per 16x16 shadow tile (VisibilityTileKernel; a batch's too): the
  /// tile's verdicts, ray counts and fractions of one light after another in shared memory,
  /// where every pixel's window finds its neighbours (the windows never leave their tile), the
  /// same functions on the same values (SharedWindowFraction, SharedLampFraction), so the same
  /// bits; else VisibilityFractionKernel, then the resolve, each reading its neighbours from the
  /// frame's arrays.
  bool tile_visibility = true;
  /// with tile_visibility: the tile kernel packs each pixel's two ray counts once into one word
  /// of shared memory (ShadowWindowCounts, render/shadow_window_math.h), which the window's
  /// integer sums read at each tap; else it keeps both floats there and packs them at each tap
  /// (WindowTapCounts). the same integers, so the same bits.
  bool packed_window_counts = true;
  /// with warp_penumbra or queue_penumbra: the penumbra rays' kernel in blocks of one 16x16
  /// shadow tile that copy every light's verdicts of their tile into shared memory first, where
  /// each pixel's window looks for a penumbra (SharedVisibilityPenumbra; frames of at most 128
  /// lights, a batch's too); else blocks of 16x8 pixels reading the frame's verdicts.
  bool tile_penumbra = true;
  /// with tile_penumbra: the penumbra rays' tile blocks copy each pixel's surface (geom of a
  /// hit, normal, point: TileWindowSurfaces) into shared memory once, where the window masks
  /// read their neighbours' (SharedVisibilityWindow; else each pixel's PixelGeometry is read
  /// from global memory by up to 25 threads). the same masks, so the same bits.
  bool staged_window = true;
  /// with staged_window: those blocks keep every light's verdicts as the tile's bit rows (two
  /// ballots a warp: RowWindowVerdicts, ShadowWindowVerdicts), where a window sees both
  /// verdicts or not in five shifted rows; else as an int8 copy read at each set bit of the
  /// window (StridedWindowVerdicts). the same booleans, so the same bits.
  bool window_verdict_rows = true;
  /// occlusion rays (the lights' shadow rays, the penumbra rays) walk the top level over the
  /// instances' world boxes (SceneView::tlas, TraceOccluded in bvh_traversal.h); else they test
  /// every instance's box in turn. the same verdicts, so the same bits.
  bool occlusion_tlas = true;
  /// closest hits (the camera's rays, the mirror's) walk the same top level nearer child first
  /// (TraceClosest); else they test every instance in index order. the same hits, so the same
  /// bits.
  bool closest_tlas = true;
  /// the sky terms come from a kernel (QuadSkyTerms, MirrorSkyTerm over UploadSky's copies);
  /// else from the host (Render's `sky`, in sky_bands bands with pinned copies).
  bool device_sky = true;
  /// with pinned copies and at most kMaxDeviceExposureRows rows: the exposure is computed on
  /// the device after the row sums (one block, FrameExposure) and the film kernel reads it there,
  /// so Render synchronises once, at the end (the host checks the device's exposures against
  /// its own, Render's `exposure`, and develops again in the rare frame where they differ);
  /// else the row sums go to the host, which computes the exposure and then launches the film
  /// kernel.
  bool device_exposure = true;
  /// Render uploads the posed geoms and lights only when their bytes differ from the last
  /// upload's (else every frame).
  bool upload_changed_only = true;
  /// with pinned copies, the host copies the outputs into the frame's images in chunks over
  /// RealtimeOutputs::parallel (else on the calling thread alone).
  bool parallel_copies = true;
  /// the size of those chunks, KiB (at least 4).
  int copy_chunk_kib = 256;
  /// with parallel_copies: a loop of copies of at most this many KiB (a small frame's) runs on
  /// the calling thread alone (waking the pool costs more than such copies).
  int serial_copy_kib = 512;
};

/// the most rows whose sums the device's exposure takes (its block keeps them in shared
/// memory); taller frames take the host's.
constexpr int kMaxDeviceExposureRows = 6144;

/// the time of Render()'s stages, milliseconds (benchmarks). geometry + sky + shade + film =
/// total. with device_sky the first three are CUDA-event times on the GPU's stream (no
/// synchronisation between them) and film is the rest of the host clock's total; else all are
/// host clock times.
struct RealtimeStageTimes {
  /// device_sky: the geoms' and lights' upload and the geometry (and mirrored-ray) kernels;
  /// else those and the first band's geometry on the host
  double geometry = 0;
  /// device_sky: the sky-term kernels; else the host's sky terms, all bands
  /// (RealtimeFrameData::FrameSkyTerms)
  double sky = 0;
  /// device_sky: the shading, shared-visibility, mirror-layer and row-sum kernels and the row
  /// sums' copy; else the rest until the row sums are on the host: waiting for the other
  /// bands' geometry, sky terms up, those kernels, row sums back
  double shade = 0;
  /// exposure, film kernel, the outputs copied to the frame's images (device_sky: and the
  /// host's launch and wait overheads; with device_exposure the shade stage ends at the row
  /// sums, and this is the rest)
  double film = 0;
  /// of film: the host's copies of the radiance and rgb into the frame's images (pinned), from
  /// the copy stream's end to the last copy (the depth is copied while the GPU shades); with
  /// device_exposure from the end of the launches, so it includes waiting for the kernels
  double outputs = 0;
  double total = 0;
  /// host clock: from the start until every kernel and copy of the frame is queued (the host's
  /// waits for the outputs come after)
  double launched = 0;
  /// device_sky with device_exposure (else 0), CUDA events from the frame's first event on the
  /// stream (before the geoms' upload): the film kernel's end, and the end of the last copy to
  /// page-locked memory (the rgb's, row sums' and exposure's, or the radiance's last band); the
  /// host's clock total minus copies_end is what the host adds after the device: its
  /// preparation before the first event, its copies into the frame's images after the last
  /// transfer, its waits and checks
  double kernels_end = 0;
  double copies_end = 0;
};

/// one camera's film in a batch (RealtimeBatch): how its exposure is metered (its world's
/// Film::exposure_pod) and white-balanced (linear rgb gains, ones = none), its tone map and its
/// world's encoding table (device pointer, DeviceRealtime::device_lut). the batch computes the
/// per-channel exposures from the camera's row sums on the device (film_math.h's
/// FrameExposure, as Render's device_exposure).
struct RealtimeBatchFilm {
  FilmExposurePod exposure;
  float white_balance_gains[3] = {1, 1, 1};
  int32_t filmic = 1;
  const uint8_t* lut = nullptr;
};

/// the GPU time of a batch's realtime stages, milliseconds (CUDA events around each stage's
/// launches on the stream; benchmarks).
struct RealtimeBatchTimes {
  double geometry = 0;    ///< primary geometry, depth, material terms (and mirrored rays)
  double sky = 0;         ///< the sky-term kernels
  double shade = 0;       ///< the shading kernel (ShadeRealtimeStored)
  double visibility = 0;  ///< the shared visibility: penumbra rays, fraction, resolve
  double mirror = 0;      ///< the mirror layer's shading and blend (0 without one)
  double row_sums = 0;    ///< the rows' log-luminance sums
  double exposure = 0;    ///< the exposure kernel (one block a camera, FrameExposure)
  double film = 0;        ///< the film kernel (DevelopPixel)
  double total = 0;
};

/// film_math.h's FrameExposure of `rows` (row-major sums of a frame of `pixels` pixels, at
/// most kMaxDeviceExposureRows) computed on the device as Render's device_exposure does it
/// (tests: the device's EV100 and exposures against the host's).
/// @throws Error for too many rows, or if the CUDA runtime fails.
double DeviceFrameExposure(const FilmExposurePod& film, const std::vector<double>& rows,
                           int64_t pixels, const float white_balance_gains[3], float exposure[3]);

/// the realtime tier over a batch of cameras of the same size (cuda_batch_renderer.h): each
/// stage of Render's default path (device sky terms, stored surfaces, warp-shared penumbra rays,
/// a warp per row's sum) launched once over every camera of the batch, camera k in the grid's
/// z (the row sums' and film's y); camera k's images are the same bits as Render of that camera
/// alone. each camera's exposure is computed on the device from its row sums (one block a
/// camera: film_math.h's FrameExposure over the rows in row order, the function the host's
/// RealtimeFrameData::Ev100 calls; no atomics), so a batch never waits for the host.
class RealtimeBatch {
 public:
  /// working buffers for batches of up to max_cameras cameras of width x height pixels
  /// (height <= kMaxDeviceExposureRows) and `max_lights` lights, with the mirror layer's if
  /// `mirror`, and `slots` sets of stage events.
  /// @throws Error for a bad size or count, or if the CUDA runtime fails.
  RealtimeBatch(int width, int height, int max_cameras, int max_lights, bool mirror, int slots);
  ~RealtimeBatch();
  RealtimeBatch(const RealtimeBatch&) = delete;
  RealtimeBatch& operator=(const RealtimeBatch&) = delete;

  /// enqueues on `stream` (a cudaStream_t) the realtime frames of cameras[0 .. count):
  /// frames[k] (host array) is camera k's frame with device pointers (DeviceRealtime::DeviceFrame
  /// of its world, its camera, spread and frame key; its per-pixel arrays are set here) and
  /// film[k] its film (host array). writes each camera's depth (m; `depth` may be
  /// null) and rgb (3 bytes a pixel; may be null) camera-major into the device arrays given.
  /// the stage times go to slot `slot`'s events. every camera's num_lights must be at most
  /// max_lights, and any_mirror 0 unless the batch was made with `mirror`.
  /// @throws Error for a bad count, slot or camera, or if the CUDA runtime fails.
  void Launch(const RealtimeFrameView* frames, const RealtimeBatchFilm* film, int count,
              float* depth, uint8_t* rgb, int slot, void* stream);
  /// the stage times of slot `slot`'s last Launch (call after its stream passed it).
  RealtimeBatchTimes times(int slot) const;

 private:
  struct Impl;
  Impl* impl_;
};

/// the device side of the realtime path.
/// the grids' light volumes and froxels of a frame (RealtimeFrameView::media_build.grids) as
/// host arrays: the built by BuildMediaVolumesOnHost (realtime_frame.h), or the device's copied
/// back (DeviceRealtime::DownloadGridVolumes).
struct GridVolumeArrays {
  std::vector<float> T;        ///< the light volumes' [light][cell], end to end (pod offsets)
  std::vector<Float3> source;  ///< their in-scatter sources [cell], end to end
  std::vector<float> t0, t1, slices_per_m;      ///< the froxel columns' spans [column]
  std::vector<GridFroxelRecord<Rgb4>> records;  ///< [column][boundary 0 .. kFroxelSlices]
};

class DeviceRealtime {
 public:
  DeviceRealtime();
  ~DeviceRealtime();
  DeviceRealtime(const DeviceRealtime&) = delete;
  DeviceRealtime& operator=(const DeviceRealtime&) = delete;

  /// copies the scene-constant data to the device.
  void Upload(const RealtimeStatic& data);

  /// copies the sky's and the sky volume's arrays to the device (after Upload: the skybox is
  /// decoded through its sRGB table); Render's device_sky path needs it once, and again
  /// whenever they change (RealtimeFrameData::sky_generation).
  void UploadSky(const RealtimeSky& data);

  /// host sky pass: the sky terms of the pixels of rows [row0, row1) from their primary
  /// geometry, and of their mirrored rays from theirs (mirror and mirror_sky null when the
  /// frame has no mirror layer, RealtimeFrameView::any_mirror). every array holds all n
  /// pixels of the frame (row-major); row0 is even, row1 even or the last row + 1.
  using SkyFn = std::function<void(const PixelGeometry* geometry, const PixelGeometry* mirror,
                                   int64_t n, int row0, int row1, Float3* sky, Float3* mirror_sky)>;
  /// host exposure: the EV100 from the rows' log-luminance sums, and the per-channel exposures.
  using ExposureFn = std::function<double(const std::vector<double>& rows, float exposure[3])>;

  /// the late streaks (Render's `streaks`, branch gpu23): sets the particle streak fields of
  /// *frame (streaks and num_streaks, splat: host arrays that stay valid until Render returns;
  /// RealtimeFrameData::StreakFields) and leaves the rest alone. called on Render's thread once
  /// every kernel before the streaks' is queued, so the host makes the streaks while the GPU
  /// traces and shades the frame.
  using StreaksFn = std::function<void(RealtimeFrameView* frame)>;

  /// renders one frame of `frame` (host pointers for its geoms and lights; the scene arrays,
  /// materials and textures are replaced by the device copies of `scene` and Upload) with
  /// `num_geoms` geoms; returns the EV100 (`exposure`'s, the host's). `film`: the tone map, and
  /// the exposure's settings for the device (which must make what `exposure` makes).
  /// `streaks` (may be empty): the frame's particle streaks are made late, and replace
  /// `frame`'s (which should have none): Render queues the geoms' and lights' upload, the media
  /// volumes and the geometry, sky-term and shading kernels (none of which reads the streaks),
  /// then calls it, then uploads its streaks through page-locked staging (so the host does not
  /// wait for the busy stream) and queues the splat (StreakSplatKernel, StreakShadeKernel) and
  /// the rest (shared visibility, media view pass and streaks drawn over the radiance, row sums,
  /// exposure, film): the same kernels on the same data as without it, where the splat runs
  /// first, so the same bits. if it throws, Render waits for the queued work and rethrows.
  double Render(DeviceScene* scene, const RealtimeFrameView& frame, int64_t num_geoms,
                const RealtimeFilm& film, const SkyFn& sky, const ExposureFn& exposure,
                const RealtimeOutputs& out, const StreaksFn& streaks = StreaksFn());

  /// `count` runs of the frame's device work as Render left it (geometry, shading, row sums
  /// and film kernels; the sky terms and exposure of the last Render, no copies), timed with
  /// CUDA events: mean milliseconds per frame (benchmarks).
  double TimeKernels(DeviceScene* scene, int count);
  /// TimeKernels with the kernels run as `options` says (Render's options are unchanged).
  double TimeKernels(DeviceScene* scene, int count, const RealtimeKernelOptions& options);

  /// `host_frame` with this scene's device arrays in place of its host ones: the materials,
  /// textures, texels, sRGB table and sky of Upload and UploadSky, and its posed geoms and lights,
  /// which are copied to the device now (the call blocks until they are there; they stay until
  /// the next DeviceFrame or Render). the per-pixel arrays and the scene are left as they are.
  /// batch rendering makes each world's frame with it (RealtimeBatch).
  RealtimeFrameView DeviceFrame(const RealtimeFrameView& host_frame, int64_t num_geoms);
  /// the device copy of the film's encoding table (Upload's oetf_lut).
  const uint8_t* device_lut() const;

  /// the options of the next Render calls.
  void set_options(const RealtimeKernelOptions& options);
  const RealtimeKernelOptions& options() const;
  /// the stages of the last Render.
  const RealtimeStageTimes& last_stage_times() const;
  /// the device's exposures against the host's over the Renders so far.
  const RealtimeExposureChecks& exposure_checks() const;
  /// the grids' light volumes and froxels the last Render built on the device (its frame's
  /// media_build.grids) copied into *out (tests); false (*out untouched) if it built none.
  /// @throws Error on a CUDA failure.
  bool DownloadGridVolumes(GridVolumeArrays* out) const;
  /// the realtime splat's per-pixel StreakKeys of the last Render (StreakSplatView::nearest,
  /// width x height, row-major; render/particle_math.h's kNoStreakKey where no streak) copied
  /// into *out (tests); false (*out untouched) if that frame splatted none.
  /// @throws Error on a CUDA failure.
  bool DownloadStreakKeys(std::vector<unsigned long long>* out) const;

 private:
  struct Impl;
  Impl* impl_;
};

}  // namespace penumbra::cuda

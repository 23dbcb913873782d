#pragma once
// the realtime tier on the GPU (render/transport/realtime.h per pixel, realtime_frame.h on the
// host): device copies of a scene's materials, textures, geoms and lights, and the frame's
// kernels (realtime_kernels.cuh: realtime_device.cu for a frame, realtime_batch.cu for a batch).
// plain structs only here (no Eigen, no CUDA headers). every function throws penumbra::Error
// naming the CUDA call when the runtime reports an error.
//
// a frame: (1) a kernel traces every pixel's primary ray and writes its geometry, depth and the
// hit's material terms (SurfaceTerms, for the shading kernel); with a mirror layer in the scene
// it also traces the mirrored rays (TraceMirrorRay); (2) a kernel turns the geometry into sky
// terms, one thread per 2x2 quad (QuadSkyTerms) and, with a mirror layer, one per mirrored ray
// (MirrorSkyTerm): the shared lookups of render/sky/sky_eval_math.h over the device copies of the
// SkyModel's and SkyIrradianceVolume's arrays (UploadSky), the functions the CPU backend calls;
// (3) the shading kernel (ShadeRealtimeStored; small frames with their shadow rays through a
// queue), the shared visibility's kernels (a warp's penumbra rays spread over its lanes, the
// fraction and resolve a block per shadow tile) and the mirror layer's (ShadeMirrorHit,
// ApplyMirrorLayer; on a second stream of the lowest priority beside the frame's); (4) per-row
// log-luminance sums, which one thread block turns into the frame's EV100 and exposures
// (film_math.h's FrameExposure, the rows added in row order; frames of more than
// kMaxDeviceExposureRows rows: the host, `exposure`, between the row sums and the film kernel);
// (5) the film kernel (DevelopPixel). the host computes the exposure from the same row sums too
// and, in the rare frame where the device's double exp, log2 and exp2 gave other float exposures
// than its C library, develops the frame again with its own: the rgb and EV100 are always the
// host path's bits. the outputs come back through page-locked buffers (the radiance in bands of
// rows as they are resolved), copied into the frame's images over RealtimeOutputs::parallel.
// every sum runs in a fixed order and no atomics touch an output: frames are bit-identical run to
// run on one GPU.

#include <cstdint>
#include <functional>
#include <vector>

#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/film/film_math.h"
#include "penumbra/render/transport/realtime.h"

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

/// how Render's exposures on the device compared with the host's, over the frames so far.
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

/// the most rows whose sums the device's exposure takes (its block keeps them in shared
/// memory); taller frames take the host's.
constexpr int kMaxDeviceExposureRows = 6144;

/// the time of Render()'s stages, milliseconds (benchmarks). geometry + sky + shade + film =
/// total. the first three are CUDA-event times on the GPU's stream (no synchronisation between
/// them) and film is the rest of the host clock's total.
struct RealtimeStageTimes {
  /// the geoms' and lights' upload and the geometry (and mirrored-ray) kernels
  double geometry = 0;
  /// the sky-term kernels
  double sky = 0;
  /// the shading, shared-visibility, mirror-layer and row-sum kernels (and, for frames too tall
  /// for the device's exposure, the row sums' copy)
  double shade = 0;
  /// exposure, film kernel, the outputs copied to the frame's images, and the host's launch and
  /// wait overheads (the shade stage ends at the row sums, and this is the rest)
  double film = 0;
  /// of film: the host's copies of the radiance and rgb into the frame's images (the depth is
  /// copied while the GPU shades), from the end of the launches, so it includes waiting for the
  /// kernels
  double outputs = 0;
  double total = 0;
  /// host clock: from the start until every kernel and copy of the frame is queued (the host's
  /// waits for the outputs come after)
  double launched = 0;
  /// with the device's exposure (else 0), CUDA events from the frame's first event on the
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
/// FrameExposure, as Render's).
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
/// most kMaxDeviceExposureRows) computed on the device as Render does it
/// (tests: the device's EV100 and exposures against the host's).
/// @throws Error for too many rows, or if the CUDA runtime fails.
double DeviceFrameExposure(const FilmExposurePod& film, const std::vector<double>& rows,
                           int64_t pixels, const float white_balance_gains[3], float exposure[3]);

/// the realtime tier over a batch of cameras of the same size (cuda_batch_renderer.h): each
/// stage of Render's (device sky terms, stored surfaces, warp-shared penumbra rays, a warp per
/// row's sum) launched once over every camera of the batch, camera k in the grid's
/// z (the row sums' and film's y); camera k's images are the same bits as Render of that camera
/// alone. each camera's exposure is computed on the device from its row sums (one block a
/// camera: film_math.h's FrameExposure over the rows in row order, the function the host's
/// RealtimeFrameData::Ev100 calls; no atomics), so a batch never waits for the host.
class RealtimeBatch : NonCopyable {
 public:
  /// working buffers for batches of up to max_cameras cameras of width x height pixels
  /// (height <= kMaxDeviceExposureRows) and `max_lights` lights, with the mirror layer's if
  /// `mirror`, and `slots` sets of stage events.
  /// @throws Error for a bad size or count, or if the CUDA runtime fails.
  RealtimeBatch(int width, int height, int max_cameras, int max_lights, bool mirror, int slots);
  ~RealtimeBatch();

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

class DeviceRealtime : NonCopyable {
 public:
  DeviceRealtime();
  ~DeviceRealtime();

  /// copies the scene-constant data to the device.
  void Upload(const RealtimeStatic& data);

  /// copies the sky's and the sky volume's arrays to the device (after Upload: the skybox is
  /// decoded through its sRGB table); Render needs it before the first frame, and again
  /// whenever they change (RealtimeFrameData::sky_generation).
  void UploadSky(const RealtimeSky& data);

  /// host exposure: the EV100 from the rows' log-luminance sums, and the per-channel exposures.
  using ExposureFn = std::function<double(const std::vector<double>& rows, float exposure[3])>;

  /// the late streaks (Render's `streaks`): sets the particle streak fields of
  /// *frame (splat: host arrays that stay valid until Render returns;
  /// RealtimeFrameData::StreakFields) and leaves the rest alone. called on Render's thread once
  /// every kernel before the streaks' is queued, so the host makes the streaks while the GPU
  /// traces and shades the frame.
  using StreaksFn = std::function<void(RealtimeFrameView* frame)>;

  /// renders one frame of `frame` (host pointers for its geoms and lights; the scene arrays,
  /// materials and textures are replaced by the device copies of `scene` and Upload) with
  /// `num_geoms` geoms (after UploadSky); returns the EV100 (`exposure`'s, the host's). `film`: the
  /// tone map, and the exposure's settings for the device (which must make what `exposure` makes).
  /// `streaks` (may be empty): the frame's particle streaks are made late, and replace
  /// `frame`'s (which should have none): Render queues the geoms' and lights' upload, the media
  /// volumes and the geometry, sky-term and shading kernels (none of which reads the streaks),
  /// then calls it, then uploads its streaks through page-locked staging (so the host does not
  /// wait for the busy stream) and queues the splat (StreakSplatKernel, StreakShadeKernel) and
  /// the rest (shared visibility, media view pass and streaks drawn over the radiance, row sums,
  /// exposure, film): the same kernels on the same data as without it, where the splat runs
  /// first, so the same bits. if it throws, Render waits for the queued work and rethrows.
  double Render(DeviceScene* scene, const RealtimeFrameView& frame, int64_t num_geoms,
                const RealtimeFilm& film, const ExposureFn& exposure, const RealtimeOutputs& out,
                const StreaksFn& streaks = StreaksFn());

  /// `count` runs of the frame's device work as Render left it (geometry, shading, row sums
  /// and film kernels; the sky terms and exposure of the last Render, no copies), timed with
  /// CUDA events: mean milliseconds per frame (benchmarks).
  double TimeKernels(DeviceScene* scene, int count);

  /// `host_frame` with this scene's device arrays in place of its host ones: the materials,
  /// textures, texels, sRGB table and sky of Upload and UploadSky, and its posed geoms and lights,
  /// which are copied to the device now (the call blocks until they are there; they stay until
  /// the next DeviceFrame or Render). the per-pixel arrays and the scene are left as they are.
  /// batch rendering makes each world's frame with it (RealtimeBatch).
  RealtimeFrameView DeviceFrame(const RealtimeFrameView& host_frame, int64_t num_geoms);
  /// the device copy of the film's encoding table (Upload's oetf_lut).
  const uint8_t* device_lut() const;

  /// the stages of the last Render.
  const RealtimeStageTimes& last_stage_times() const;
  /// the device's exposures against the host's over the Renders so far.
  const RealtimeExposureChecks& exposure_checks() const;
  /// the grids' light volumes and froxels the last Render built on the device (its frame's
  /// media_build.grids) copied into *out (tests); false (*out untouched) if it built none.
  /// @throws Error on a CUDA failure.
  bool DownloadGridVolumes(GridVolumeArrays* out) const;
  /// the realtime splat's per-pixel StreakKeys of the last Render (StreakSplatView::nearest,
  /// width x height, row-major; render/particles/particle_math.h's kNoStreakKey where no streak)
  /// copied into *out (tests); false (*out untouched) if that frame splatted none.
  /// @throws Error on a CUDA failure.
  bool DownloadStreakKeys(std::vector<unsigned long long>* out) const;

 private:
  struct Impl;
  Impl* impl_;
};

}  // namespace penumbra::cuda

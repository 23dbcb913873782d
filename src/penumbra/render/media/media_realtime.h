#pragma once
// participating media in the `realtime` tier: single scattering along the camera ray, with
// per-frame precomputed light volumes instead of shadow rays per step.
//
// per frame (Build):
//  - every grid medium gets a coarse light volume (about kGridLightCells cells on its box, at
//    most the grid's resolution): per light j the transmittance T_j through the grid from the
//    cell centre to the light (midpoint-rule march of the full-resolution density, at most
//    kGridLightSteps steps), and an isotropic in-scatter source S = sum_j E_j V_j T_j Th_j /
//    (4 pi) + L_sky(cell), with V_j one shadow ray per cell and light, Th_j the homogeneous
//    media's transmittance to the light and L_sky(p) the sky's sphere-average radiance seen
//    from p past the static geometry (SkyIrradianceVolume::AmbientRadiance; the unoccluded
//    sky_ambient without a volume). the grid's phase function is isotropic in this tier.
//  - a world light volume (kLightVolumeCells cells) over the scene's bounding box
//    (SceneDescription::center_W, extent_m; clipped to the media boxes when every homogeneous
//    medium is boxed) stores per light the channel-mean transmittance Th T_grid to the light,
//    and with homogeneous media also V Th T_grid (one shadow ray per cell and light). outside
//    it lights are unshadowed in media and transmittances are computed exactly.
//    nothing is cached between frames (moving bodies would make frames depend on history).
// per camera ray (IntegrateView), over [0, t_end] (t_end = surface distance or +inf):
//  - homogeneous media: closed-form transmittance (media_scene.h); the sky in-scatter
//    albedo (1 - T) L_sky in closed form, with the sky treated as an isotropic source that
//    reaches every point of the medium unattenuated (Koschmieder's setting). L_sky is the
//    sphere-average sky radiance that the static geometry lets through
//    (SkyIrradianceVolume::AmbientRadiance: 0 inside a closed room, so fog there is lit by the
//    lamps only), sampled once per ray (SkyAlongRay) at the point where half of the ray's
//    in-scatter weight 1 - T has accrued (in the medium of largest optical depth); without a
//    sky volume (no finite static geometry) it is the open sky's. one sample per ray is exact
//    where L_sky is uniform along it (a closed room, the open); a ray that leaves a room
//    through a door or window gets the sky of one point, not the mean along it;
//    light in-scatter from a second, coarser froxel volume (one column per kFogFroxelBlock^2
//    pixels, kFogFroxelSlices slices spaced exponentially from kFogFroxelNear to where the
//    media's transmittance falls to 1 %, jittered per column from the centre pixel stream 3):
//    per slice sum_j p_HG(theta) E_j times the visibility volume, times the transmittance
//    from the camera (media and grids), accumulated and looked up like the grid froxels.
//  - grid media: a camera-aligned froxel volume (Wronski, "Volumetric fog", SIGGRAPH 2014;
//    Hillaire, "Physically based and unified volumetric rendering in Frostbite", SIGGRAPH
//    2015), built per frame: one column ray per kFroxelBlock x kFroxelBlock pixels, marched
//    in kFroxelSlices slices (midpoints jittered per column from the column's centre pixel
//    stream 2) over the column's overlap with the grid boxes; each slice adds T (sigma_s S Th +
//    emission Th) (1 - e^-x) / sigma_t with exact per-slice transmittance e^-x, x = sigma_t
//    ds, Th the homogeneous media's transmittance from the camera, and the accumulated
//    in-scatter and transmittance are stored at every slice boundary. a pixel looks them up
//    at its own distance (linear between slice boundaries, bilinear between columns).
//  - homogeneous in-scatter behind a grid is attenuated by the grid's transmittance.
//  - the realtime integrator looks the two froxel volumes up once per 2x2 pixel quad whose
//    pixels all hit a surface or all see the sky (MediaQuad): at the quad's centre and mean
//    distance, with the slices' slopes in distance for each pixel's own distance while it stays
//    in the same slices (else the pixel looks them up itself). default world, major preset:
//    8-bit output within 1 code of per-pixel lookups (mean 0.02 codes).
// every camera segment starts at the camera (particle compositing uses two of them).
// surfaces: each light's contribution is multiplied by LightTransmittance (the world light
// volume; outside it: closed form for the homogeneous media times the grid's light volume at
// the shadow ray's entry into the grid box).
// random numbers: the froxel columns' jitter, from their centre pixels' streams 2 and 3.
// written once for a device (render/media/media_build_math.h): the world
// light volume's cells (LightVolumeCellLight), the fog froxels' columns (FogFroxelColumn), the
// grids' light volumes' cells (GridLightCellLight, GridLightCellSource) and the grid froxels'
// columns (GridFroxelSlice, GridFroxelRecords); Build's device_volumes leaves all four to the
// CUDA backend's kernels, which run the same functions with the shadow rays traced in the
// cell's thread.

#include <Eigen/Core>
#include <array>
#include <memory>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/media/media_build_math.h"
#include "penumbra/render/media/media_realtime_math.h"
#include "penumbra/render/media/media_scene.h"
#include "penumbra/render/ray_query.h"
#include "penumbra/render/sky/sky_irradiance_volume.h"

namespace penumbra {

// kGridLightCells and kGridLightSteps (the grids' light volumes): media_build_math.h.
/// cells of the world light volume.
constexpr int kLightVolumeCells = 4096;
// kFroxelBlock, kFroxelSlices, kFogFroxelBlock, kFogFroxelSlices, kFogFroxelNear and
// kMaxVolumeLights: render/media/media_realtime_math.h (the per-pixel formulas read them).
/// shadow rays of the light volumes per RayQuery::Occluded call (the batches of a frame are
/// traced in parallel; a ray's verdict does not depend on its batch).
constexpr int kShadowRayBatch = 4096;

/// what a camera-ray segment through media does to the radiance L behind it: T L + L_add.
struct MediaSegment {
  Eigen::Vector3f T{1, 1, 1};
  Eigen::Vector3f L_add{0, 0, 0};
};

/// the froxel lookups of one 2x2 pixel quad, made once (RealtimeMedia::PrepareQuad) and shared
/// by its four pixels: both froxel volumes interpolated bilinearly at the quad's centre and
/// linearly in distance (grid volume) or log distance (light in-scatter volume) from the quad's
/// reference distance t_c, within the distance ranges where the lookups stay in one slice of
/// every column; a pixel whose distance lies outside a range looks that volume up itself.
struct MediaQuad {
  /// grid: the in-scatter and transmittance at t_c, their slopes in distance and where they
  /// hold (GridQuadPrepare of media_realtime_math.h; empty range: none)
  GridQuad<Eigen::Array4f> grid{0,
                                0,
                                1,
                                0,
                                Eigen::Array4f::Zero(),
                                Eigen::Array4f::Zero(),
                                Eigen::Array4f::Zero(),
                                Eigen::Array4f::Zero()};
  /// fog: the light in-scatter at t_c, its slope in log distance and where they hold
  /// (FogQuadPrepare of media_realtime_math.h; empty range: none)
  FogQuad<Eigen::Array4f> fog{0, 1, 0, Eigen::Array4f::Zero(), Eigen::Array4f::Zero()};
  bool has_sky = false;                         ///< sky holds SkyAlongRay of the quad
  Eigen::Array4f sky = Eigen::Array4f::Zero();  ///< occluded sky radiance of the media
};

/// host copies of RealtimeMedia's arrays in the plain types of RealtimeMediaView (HostView): the
/// fog and grid froxels' records as Rgb4, the grids' boxes and light volumes (pods, their
/// transmittances end to end), the sky volume's plain data.
struct RealtimeMediaHostArrays {
  std::vector<Rgb4> fog_records;
  std::vector<GridFroxelRecord<Rgb4>> grid_records;
  std::vector<GridLightPod> grid_pods;
  std::vector<float> grid_light_T;
  SkyVolumePod sky_pod;
};

/// the realtime tier's per-frame media structures. Build, then the queries are thread-safe.
class RealtimeMedia {
 public:
  /// precomputes the light volumes of `media` (which must outlive this object until the next
  /// Build) for the posed `lights`; `sky_ambient` is the sphere-average sky radiance (cd/m^2)
  /// of the open sky; `sky_volume` (may be null or empty: the sky then lights the media
  /// unoccluded) occludes it by the static geometry and must outlive this object likewise.
  /// shadow rays go through `scene` (any backend's RayQuery: the CPU renderer passes its
  /// Embree RayScene, whose Occluded is rtcOccluded1 ray by ray; the CUDA backend its
  /// CudaRayQuery), in batches of kShadowRayBatch; the cells and the batches are spread over
  /// `pool` (may be null). the froxel volume is built for `camera`; `frame_key` is
  /// FrameContext::FrameKey(). the volumes are made by render/media/media_build_math.h's functions
  /// (the world light volume's cells LightVolumeCellLight, the fog froxels FogFroxelColumn, the
  /// grids' light volumes GridLightCellLight / GridLightCellSource, the grid froxels
  /// GridFroxelSlice / GridFroxelRecords). `device_volumes`: the four are left to a device
  /// (their layouts set, their arrays empty: device_build() says which, with the grids' arrays;
  /// the CUDA backend's kernels run the same functions); the queries that read them
  /// (LightTransmittance, LightTransmittances, LightVisibilities, IntegrateView, PrepareQuad)
  /// must then not be called, HostView's pointers to them are null.
  void Build(const MediaScene& media, const LightSampler& lights, const RayQuery& scene,
             const Camera& camera, uint64_t frame_key, const Eigen::Vector3f& bounds_center_W,
             double bounds_extent_m, const Eigen::Vector3f& sky_ambient,
             const SkyIrradianceVolume* sky_volume, ThreadPool* pool, bool device_volumes = false);
  /// what the last Build left to a device (all 0 unless device_volumes).
  const MediaVolumesToBuild& device_build() const { return device_build_; }
  /// milliseconds of the last Build's stages (host clock; benchmarks): the grids' light volumes
  /// (their march, shadow rays and sources), the world light volume (cells and shadow rays),
  /// the grid froxels, the fog froxels.
  struct BuildTimes {
    double grid_light = 0, light_volume = 0, grid_froxels = 0, fog_froxels = 0;
  };
  const BuildTimes& build_times() const { return build_times_; }

  /// rgb transmittance from p_W towards light j (unit direction wi, distance dist, +inf for
  /// directional lights) through every medium.
  Eigen::Vector3f LightTransmittance(int j, const Eigen::Vector3f& p_W, const Eigen::Vector3f& wi,
                                     float dist) const;

  /// channel-mean transmittance from p_W to every light that has a light volume: writes T[j]
  /// for j < num_volume_lights() (T must hold kMaxVolumeLights floats; trilinear in the world
  /// light volume, all lights in one pass). false outside the volume (T untouched; use
  /// LightTransmittance(j, p, wi, dist) there).
  bool LightTransmittances(const Eigen::Vector3f& p_W, float* T) const;
  /// number of lights that have light volumes (the first ones).
  int num_volume_lights() const { return num_lights_; }

  /// single scattering along the camera ray o + t d (d unit, o the camera centre) of pixel
  /// (u, v), t in [0, t_end]. with `quad` (PrepareQuad of the 2x2 quad holding the pixel; may
  /// be null) the froxel volumes are read from it where it holds the pixel's distance: their
  /// columns are then interpolated at the quad's centre instead of the pixel's (half a pixel
  /// away, 1/24 of the grid and 1/48 of the in-scatter columns' spacing); the homogeneous
  /// media's closed-form terms stay per pixel.
  MediaSegment IntegrateView(const LightSampler& lights, const Eigen::Vector3f& o,
                             const Eigen::Vector3f& d, float t_end, int u, int v,
                             const MediaQuad* quad = nullptr) const;

  /// the shared froxel lookups of the 2x2 quad of pixels (u0, v0) .. (u0 + 1, v0 + 1) at the
  /// reference distance t_c (m; the mean of the pixels' distances, +inf for sky pixels), and
  /// the occluded sky of the media (SkyAlongRay) along the ray from the camera centre o in the
  /// quad's mean direction d_c (unit).
  void PrepareQuad(int u0, int v0, float t_c, const Eigen::Vector3f& o, const Eigen::Vector3f& d_c,
                   MediaQuad* quad) const;

  const MediaScene* media() const { return media_; }
  const Eigen::Vector3f& sky_ambient() const { return sky_ambient_; }
  /// the occluded sphere-average sky radiance at p_W (the sky volume's AmbientRadiance, or
  /// sky_ambient() without one).
  Eigen::Vector3f SkyAmbientAt(const Eigen::Vector3f& p_W) const;
  /// the sky radiance lighting the homogeneous media along o + t d (d unit), t in [0, t_end]
  /// (rgb, 4th lane 0): SkyAmbientAt at the ray's in-scatter median point (file comment).
  Eigen::Array4f SkyAlongRay(const Eigen::Vector3f& o, const Eigen::Vector3f& d, float t_end) const;

  /// one axis of the bilinear interpolation between froxel columns at an image position
  /// (MediaAxisAt of media_realtime_math.h; tables per frame).
  using AxisBilerp = MediaAxis;

  /// the homogeneous media as the shared per-pixel formulas read them (MediumPod: h_cam for
  /// this frame's camera), in MediaScene::analytic() order; and the camera's height.
  const std::vector<MediumPod>& medium_pods() const { return pods_; }
  float camera_height() const { return h_cam_oz_; }
  /// every homogeneous medium's sigma_t is grey (MediaViewClosedForm's `grey`).
  bool grey_extinction() const { return grey_t_; }
  /// the world light volume's layout (stride 0: no volume) and its [cell][light] arrays of
  /// V Th Tgrid (empty without homogeneous media) and Th Tgrid, for CellLightsLookup.
  const CellLightsPod& light_volume_pod() const { return cl_pod_; }
  const std::vector<float>& light_volume_visibility() const { return vol_.vis_cl; }
  const std::vector<float>& light_volume_transmittance() const { return vol_.trans_cl; }
  /// the grids' light volumes' isotropic in-scatter sources (cd/m^2), [cell] per grid end to end
  /// (GridSourceOffset of media_build_math.h; empty when left to a device).
  const std::vector<Float3>& grid_light_source() const { return grid_source_; }
  /// this frame's media as a RealtimeMediaView (media_realtime_math.h) over this object's
  /// arrays (host pointers, valid until the next Build), with the froxels' records, the grids'
  /// light volumes and the sky volume's plain data copied to *arrays, which must outlive the
  /// view. MediaViewSegment over it is IntegrateView (MediaPrepareQuad's quads PrepareQuad's),
  /// MediaLightTransmittance the surface loop's transmittance (bit for bit:
  /// tests/render/media/media_realtime_math_test.cc); a GPU path uploads the same arrays.
  RealtimeMediaView HostView(RealtimeMediaHostArrays* arrays) const;
  /// CellLightsLookup on the CPU (SSE; the shared function's arithmetic, tested against it)
  /// of the world light volume's visibility (V Th Tgrid) at p_W into T[0 .. stride); false
  /// outside the volume or without it.
  bool LightVisibilities(const Eigen::Vector3f& p_W, float* T) const;

 private:
  struct GridLight {
    int r[3] = {1, 1, 1};
    Eigen::Vector3f cells_per_m{1, 1, 1};
    std::vector<float> T;  // [light][cell] grid transmittance to the light
    GridLightPod pod;      // the grid's box and this volume for GridLightTransmittance (offset 0)
  };
  struct LightVolume {
    bool active = false;
    bool with_visibility = false;  // vis is filled (homogeneous media present)
    // its box, cells and lights per cell (num lights rounded up to 4): RealtimeMedia::cl_pod_
    std::vector<float> trans;     // [light][cell] Th Tgrid (channel mean)
    std::vector<float> vis;       // [light][cell] V Th Tgrid
    std::vector<float> trans_cl;  // [cell][light] copy of trans (LightTransmittances)
    std::vector<float> vis_cl;    // [cell][light] copy of vis (BuildFogFroxels)
    // lo, hi, cells_per_m, r - 1 and max(r - 2, 0) per axis, 4th lane 0 (CellLightsLookup).
    std::array<float, 4> lo4{}, hi4{}, cpm4{}, rmax4{}, imax4{};
  };
  // in-scatter and transmittance (rgb, 4th lane 0) from the camera to a slice boundary.
  using FroxelRecord = GridFroxelRecord<Eigen::Array4f>;
  struct Froxels {
    int nx = 0, ny = 0;
    std::vector<float> t0, t1;          // [column] overlap of the column ray with the grids
    std::vector<float> slices_per_m;    // [column] kFroxelSlices / (t1 - t0), 0 without overlap
    std::vector<FroxelRecord> records;  // [column][slice boundary 0..kFroxelSlices]
    // the column interpolation per pixel column / row and per quad (pixel + 0.5).
    std::vector<AxisBilerp> ax, ax_half, ay, ay_half;
  };
  /// grid in-scatter S and transmittance T from the camera to distance t for pixel (u, v)
  /// (rgb in lanes 0..2); returns the smallest entry distance of the four columns (+inf if
  /// none meets a grid; then S = 0, T = 1).
  float LookupFroxels(int u, int v, float t, Eigen::Array4f* S, Eigen::Array4f* T) const;
  /// LookupFroxels from `quad` where it holds t, else per pixel.
  float QuadFroxels(const MediaQuad& quad, int u, int v, float t, Eigen::Array4f* S,
                    Eigen::Array4f* T) const;
  /// LookupFogFroxels from `quad` where it holds t, else per pixel.
  Eigen::Array4f QuadFogFroxels(const MediaQuad& quad, int u, int v, float t) const;
  struct FogFroxels {
    int nx = 0, ny = 0;
    std::vector<float> inv_log_far;  // [column] 1 / log(last slice boundary / near)
    std::vector<Eigen::Array4f> S;   // [column][slice boundary 0..kFogFroxelSlices], rgb + 0
    std::vector<AxisBilerp> ax, ax_half, ay, ay_half;  // as in Froxels
  };
  /// light in-scatter of the homogeneous media from the camera to distance t, pixel (u, v)
  /// (rgb in lanes 0..2).
  Eigen::Array4f LookupFogFroxels(int u, int v, float t) const;
  // the fog froxels' layout and, unless `device`, their columns (FogFroxelColumn)
  void BuildFogFroxels(const LightSampler& lights, const Camera& camera, uint64_t frame_key,
                       ThreadPool* pool, bool device);
  // the grid froxels' layout and, unless `device`, their columns (GridFroxelColumnInterval,
  // GridFroxelSlice, GridFroxelRecords)
  void BuildFroxels(const LightSampler& lights, const Camera& camera, uint64_t frame_key,
                    ThreadPool* pool, bool device);

  /// trilinear lookup at p_W of every light's value in a [cell][light] array of the world light
  /// volume (trans_cl or vis_cl) into out[0 .. stride); false outside the volume: the shared
  /// CellLightsLookup (media_realtime_math.h) in SSE, with its bits.
  bool CellLightsLookupSse(const float* cl, const Eigen::Vector3f& p_W, float* out) const;
  float GridLightT(int g, int j, const Eigen::Vector3f& p_W, const Eigen::Vector3f& wi,
                   float dist) const;
  float FogVisibility(int j, const Eigen::Vector3f& p_W, const Eigen::Vector3f& wi,
                      float dist) const;

  const MediaScene* media_ = nullptr;
  Eigen::Vector3f sky_ambient_{0, 0, 0};
  const SkyIrradianceVolume* sky_volume_ = nullptr;  // non-empty, or null
  // the sky ambient as a 4-lane array (rgb, 0) built once per frame.
  Eigen::Array4f sky_ambient4_ = Eigen::Array4f::Zero();
  // relative density h(0) per homogeneous medium for rays from height h_cam_oz_ (the camera's
  // pixel rays; in pods_), and whether every homogeneous medium's sigma_t is grey.
  float h_cam_oz_ = 0;
  std::vector<MediumPod> pods_;
  CellLightsPod cl_pod_;  // the world light volume's layout (vol_'s box, cells, stride)
  bool grey_t_ = false;
  int num_lights_ = 0;  // lights with volumes
  std::vector<GridLight> grid_light_;
  // every grid's pod (offset into grid_light_T_) and light volume end to end (the shared build
  // functions and HostView read them)
  std::vector<GridLightPod> grid_pods_;
  std::vector<float> grid_light_T_;
  // every grid's light volume's in-scatter source ([cell], cd/m^2) end to end (GridSourceOffset)
  std::vector<Float3> grid_source_;
  // the grids as the shared build functions read them (MediaScene's pods: host pointers), and the
  // sky volume's plain data for GridLightCellSky
  std::vector<MediaGridPod> grid_media_;
  SkyVolumePod grid_sky_pod_;
  // device builds: the grids' arrays of grid_generation_ (held so that their addresses stay
  // unique while compared)
  std::vector<std::shared_ptr<const std::vector<float>>> held_grid_arrays_;
  uint64_t grid_generation_ = 0;
  MediaVolumesToBuild device_build_;
  BuildTimes build_times_;
  LightVolume vol_;
  Froxels froxels_;
  FogFroxels fog_froxels_;
};

}  // namespace penumbra

#pragma once
// the realtime media volumes' per-cell and per-column build (RealtimeMedia::Build, render/
// media_realtime.h), written once for the CPU and the CUDA backend's kernels (branch gpu15):
//  - the world light volume, one cell at a time (LightVolumeCellCentre, LightVolumeCellLight):
//    per light the channel-mean transmittance Th Tgrid to the light (the homogeneous media's
//    closed form times every grid's light volume at the shadow ray's entry into its box) and,
//    with homogeneous media, the shadow ray its visibility asks (none, lit, or traced). the CPU
//    gathers the rays and traces them in batches through its RayQuery; a kernel traces each
//    one where it is made, against the device BVH;
//  - the fog (light in-scatter) froxels, one column at a time (FogFroxelColumn) or one slice
//    at a time (FogFroxelSlice, then FogFroxelRecords): the slices' far end (where the media's
//    transmittance falls to 1 %), then per slice the in-scatter of every light (the visibility
//    volume, or the closed form outside it, times the mixture of the media's Henyey-Greenstein
//    lobes), times the transmittance from the camera (media and grid froxels), accumulated in
//    slice order.
// the grids' parts (their light volumes' march and the grid froxels) stay on the host: their
// density lookups are GridVolume's (render/media_scene.h).
// operation order: the CPU code's before the move (the bit-for-bit rule of shading_math.h);
// the CPU's images did not change (docs/gpu-notes.md, "Media volumes built on the GPU").

#include <stdint.h>

#include "penumbra/core/host_device.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/light_math.h"
#include "penumbra/render/media_realtime_math.h"

namespace penumbra {

/// what a world light volume cell asks of a light's visibility: nothing (the light adds
/// nothing there, or there are no homogeneous media), none (the light casts no shadows: seen),
/// or one shadow ray's verdict.
constexpr uint8_t kMediaRayNone = 0, kMediaRayLit = 1, kMediaRayTrace = 2;

/// the inputs of the world light volume's cells: its layout (CellLightsPod, stride = lights
/// per cell rounded up to 4), the first num_lights lights (at most kMaxVolumeLights), whether
/// the visibility is asked (homogeneous media present), the homogeneous media and the grids'
/// light volumes (their [light][cell] transmittances end to end at GridLightPod::offset, for
/// the same num_lights lights).
struct LightVolumeBuild {
  CellLightsPod layout;
  int num_lights = 0;
  int with_visibility = 0;
  const LightPod* lights = nullptr;
  const MediumPod* media = nullptr;
  int num_media = 0;
  const GridLightPod* grids = nullptr;
  const float* grid_light_T = nullptr;
  int num_grids = 0;
};

/// the number of cells of the volume `v` (r[0] r[1] r[2]).
PB_HOST_DEVICE inline int64_t LightVolumeCells(const CellLightsPod& v) {
  return static_cast<int64_t>(v.r[0]) * v.r[1] * v.r[2];
}

/// the world position (m) of cell c (x fastest) of the volume `v`: lo + (i + 0.5) / cells_per_m
/// per axis.
PB_HOST_DEVICE inline void LightVolumeCellCentre(const CellLightsPod& v, int64_t c, float p[3]) {
  const int i = static_cast<int>(c % v.r[0]);
  const int j = static_cast<int>((c / v.r[0]) % v.r[1]);
  const int k = static_cast<int>(c / (static_cast<int64_t>(v.r[0]) * v.r[1]));
  p[0] = v.lo[0] + (i + 0.5f) / v.cells_per_m[0];
  p[1] = v.lo[1] + (j + 0.5f) / v.cells_per_m[1];
  p[2] = v.lo[2] + (k + 0.5f) / v.cells_per_m[2];
}

/// light l at cell centre p: *T the channel-mean transmittance Th Tgrid (0 where the light
/// sends nothing to p); returns what the visibility asks (kMediaRayNone without visibility or
/// where T <= 1e-4), and for kMediaRayTrace the shadow ray from p along *d (unit) to *tmax
/// (the light's distance less 1e-4 of it; +inf for directional lights). the visibility volume's
/// value is T where the light is seen (kMediaRayLit, or a traced ray not occluded), else 0.
PB_HOST_DEVICE inline uint8_t LightVolumeCellLight(const LightVolumeBuild& b, const float p[3],
                                                   int l, float* T, float d[3], float* tmax) {
  Float3 wi, E;
  float dist = 0;
  bool valid = false;
  SampleLight<float, Float3, bool, true>(b.lights[l], Float3{p[0], p[1], p[2]}, 0.5f, 0.5f, &wi,
                                         &dist, &E, &valid);
  if (!valid) {
    *T = 0.0f;
    return kMediaRayNone;
  }
  const float w[3] = {wi.x, wi.y, wi.z};
  float t = 1.0f;
  if (b.num_media > 0) {
    const Float3 tau = AnalyticOpticalDepthOf(b.media, b.num_media, p, w, 0.0f, dist);
    const float v[3] = {tau.x, tau.y, tau.z};
    t = expf(-MediaMean3(v));
  }
  for (int g = 0; g < b.num_grids; ++g)
    t *= GridLightTransmittance(b.grids[g], b.grid_light_T + b.grids[g].offset, b.num_lights, l, p,
                                w, dist);
  *T = t;
  if (b.with_visibility == 0 || !(t > 1e-4f)) return kMediaRayNone;
  if (b.lights[l].cast_shadow == 0) return kMediaRayLit;
  for (int k = 0; k < 3; ++k) d[k] = w[k];
  *tmax = MediaIsInf(dist) ? INFINITY : dist * (1.0f - 1e-4f);
  return kMediaRayTrace;
}

/// the parts of a frame's media volumes that RealtimeMedia::Build left to a device (Build's
/// `device_volumes`): the world light volume's cells (layout RealtimeMediaView::light_volume,
/// stride lights per cell; with_visibility: also its visibility, with one shadow ray per cell
/// and light traced where LightVolumeCellLight asks) and the fog froxels (fog_nx x fog_ny
/// columns with their axis tables; jitter FroxelColumnJitter of frame_key, stream 3).
struct MediaVolumesToBuild {
  int light_volume = 0;
  int with_visibility = 0;
  int fog = 0;
  uint64_t frame_key = 0;
};

/// the inputs of the fog froxels' columns: the homogeneous media (their MediumPod::g read), all
/// the frame's lights, the world light volume's visibility V Th Tgrid ([cell][light], null
/// without it) for its first num_volume_lights lights, the grids' light volumes (as
/// LightVolumeBuild's), and the grid froxels (grid_records null: none) whose transmittance from
/// the camera attenuates the in-scatter.
template <typename R>
struct FogFroxelBuild {
  const MediumPod* media = nullptr;
  int num_media = 0;
  const LightPod* lights = nullptr;
  int num_lights = 0;
  int num_volume_lights = 0;
  CellLightsPod vis_layout;
  const float* vis_cl = nullptr;
  const GridLightPod* grids = nullptr;
  const float* grid_light_T = nullptr;
  int num_grids = 0;
  const float* grid_t0 = nullptr;
  const float* grid_t1 = nullptr;
  const float* grid_slices_per_m = nullptr;
  const GridFroxelRecord<R>* grid_records = nullptr;
};

/// the random stream of froxel column jitter: stream `stream` (2: grid froxels, 3: fog
/// froxels) of the column's centre pixel (uc, vc) of a W-pixel-wide image.
PB_HOST_DEVICE inline float FroxelColumnJitter(uint64_t frame_key, int uc, int vc, int W,
                                               uint64_t stream) {
  const uint64_t pixel = static_cast<uint64_t>(vc) * static_cast<uint64_t>(W) + uc;
  Rng rng(HashKeys(HashKeys(frame_key, pixel), stream));
  return rng.Uniform();
}

/// the far end of a fog froxel column along o + t d (d unit): where the transmittance of the
/// medium that reaches it first falls to 1 % (optical depth 4.6, channel-mean sigma_t), at
/// least 2 kFogFroxelNear and at most 2,000 m.
PB_HOST_DEVICE inline float FogColumnFar(const MediumPod* media, int n, const float* o,
                                         const float* d) {
  float t_far = 2 * kFogFroxelNear;
  for (int i = 0; i < n; ++i) {
    const MediumPod& m = media[i];
    float a, b;
    if (!MediumInterval(m, o, d, 0.0f, INFINITY, &a, &b)) continue;
    const double tt = MediaInvertDensityIntegral(m.falloff, m.base, o[2], d[2], a, b,
                                                 4.6 / MediaMean3(m.sigma_t));
    const double end = tt == tt && !MediaIsInfD(tt) ? tt : static_cast<double>(b);
    t_far = pbm::Max(t_far, static_cast<float>(pbm::Min(end, 2000.0)));
  }
  return pbm::Min(t_far, 2000.0f);
}

/// boundary k (0 .. kFogFroxelSlices) of a fog froxel column reaching t_far: 0, then
/// kFogFroxelNear (t_far / kFogFroxelNear)^((k - 1) / (kFogFroxelSlices - 1)) (FogSlice's).
PB_HOST_DEVICE inline float FogBoundary(int k, float t_far) {
  if (k == 0) return 0.0f;
  return kFogFroxelNear *
         powf(t_far / kFogFroxelNear, static_cast<float>(k - 1) / (kFogFroxelSlices - 1));
}

/// the light in-scatter seen from direction wo (unit, towards the camera) at point x of a fog
/// slice: sum over the lights j of E_j V_j sum_i sigma_s,i h_i(x) p_HG,i(wo . wi_j) over the
/// homogeneous media i holding x, V_j from the visibility volume where x lies in it (lights
/// with a volume), else e^-mean(tau) of the media times the grids' light volumes.
template <typename R>
PB_HOST_DEVICE inline Float3 FogSliceInScatter(const FogFroxelBuild<R>& b, const float x[3],
                                               const float wo[3]) {
  // per medium at the slice point: inside it, and its relative density (the same for every
  // light; the first kCached media kept, any further ones made again per light)
  constexpr int kCached = 8;
  float density[kCached];
  uint8_t inside[kCached];
  auto in_medium = [&](int i) {
    const MediumPod& m = b.media[i];
    return m.bounded == 0 ||
           (x[0] >= m.box_min[0] && x[1] >= m.box_min[1] && x[2] >= m.box_min[2] &&
            x[0] <= m.box_max[0] && x[1] <= m.box_max[1] && x[2] <= m.box_max[2]);
  };
  auto density_of = [&](int i) {
    return MediaDensityAlong(b.media[i].falloff, b.media[i].base, x[2], 0.0f, 0.0f, NAN);
  };
  for (int i = 0; i < b.num_media && i < kCached; ++i) {
    inside[i] = in_medium(i) ? 1 : 0;
    if (inside[i] != 0) density[i] = density_of(i);
  }
  Float3 Ls{0, 0, 0};
  // the visibility of every light with a volume in one lookup where x is in the volume
  float vis_all[kMaxVolumeLights];
  const bool located = b.vis_cl != nullptr && CellLightsLookup(b.vis_layout, b.vis_cl, x, vis_all);
  const Float3 w_o{wo[0], wo[1], wo[2]};
  for (int j = 0; j < b.num_lights; ++j) {
    // a light without visibility here adds nothing: skip its sample
    if (located && j < b.num_volume_lights && !(vis_all[j] > 0)) continue;
    Float3 wi, E;
    float dist = 0;
    bool valid = false;
    SampleLight<float, Float3, bool, true>(b.lights[j], Float3{x[0], x[1], x[2]}, 0.5f, 0.5f, &wi,
                                           &dist, &E, &valid);
    if (!valid) continue;
    float vis;
    if (located && j < b.num_volume_lights) {
      vis = vis_all[j];
    } else {
      const float w[3] = {wi.x, wi.y, wi.z};
      const Float3 tau = AnalyticOpticalDepthOf(b.media, b.num_media, x, w, 0.0f, dist);
      const float t3[3] = {tau.x, tau.y, tau.z};
      vis = expf(-MediaMean3(t3));
      for (int g = 0; g < b.num_grids; ++g)
        vis *= GridLightTransmittance(b.grids[g], b.grid_light_T + b.grids[g].offset,
                                      b.num_volume_lights, j, x, w, dist);
    }
    if (!(vis > 0)) continue;
    const float cos_t = DotAs<true, float>(w_o, wi);
    Float3 ph{0, 0, 0};
    for (int i = 0; i < b.num_media; ++i) {
      const bool in = i < kCached ? inside[i] != 0 : in_medium(i);
      if (!in) continue;
      const MediumPod& m = b.media[i];
      const float s = (i < kCached ? density[i] : density_of(i)) * MediaPhaseHG(cos_t, m.g);
      ph = {ph.x + m.sigma_s[0] * s, ph.y + m.sigma_s[1] * s, ph.z + m.sigma_s[2] * s};
    }
    Ls = {Ls.x + E.x * ph.x * vis, Ls.y + E.y * ph.y * vis, Ls.z + E.z * ph.z * vis};
  }
  return Ls;
}

/// slice k (0 .. kFogFroxelSlices - 1) of a fog froxel column along o + t d (o the camera
/// centre, d unit) reaching t_far (FogColumnFar), with the slice jitter `jitter`
/// (FroxelColumnJitter stream 3) and the column's grid froxel columns `grid_cols` (read where
/// b.grid_records is set): its in-scatter increment, the in-scatter at lo + jitter (hi - lo)
/// (FogSliceInScatter) times the transmittance from the camera there (the media's closed form,
/// the grid froxels') times hi - lo; 0 where no light scatters there.
template <typename R>
PB_HOST_DEVICE inline Float3 FogFroxelSlice(const FogFroxelBuild<R>& b, const float o[3],
                                            const float d[3], float jitter, float t_far, int k,
                                            const MediaColumns& grid_cols, const R& zero,
                                            const R& unit) {
  const float lo = FogBoundary(k, t_far), hi = FogBoundary(k + 1, t_far);
  const float t = lo + jitter * (hi - lo);
  const float x[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
  const float wo[3] = {-d[0], -d[1], -d[2]};
  const Float3 Ls = FogSliceInScatter(b, x, wo);
  if (!(pbm::Max(pbm::Max(Ls.x, Ls.y), Ls.z) > 0)) return Float3{0, 0, 0};
  const Float3 tau = AnalyticOpticalDepthOf(b.media, b.num_media, o, d, 0.0f, t);
  Float3 T_cam = MediaExpNeg(tau, false);
  if (b.grid_records != nullptr) {
    R gS = zero, gT = unit;
    GridFroxelLookup(grid_cols, b.grid_t0, b.grid_t1, b.grid_slices_per_m, b.grid_records, t, zero,
                     unit, &gS, &gT);
    const float* g = reinterpret_cast<const float*>(&gT);  // R: 4 floats, rgb first
    T_cam = {T_cam.x * g[0], T_cam.y * g[1], T_cam.z * g[2]};
  }
  const float w = hi - lo;
  return {T_cam.x * Ls.x * w, T_cam.y * Ls.y * w, T_cam.z * Ls.z * w};
}

/// a fog froxel column's kFogFroxelSlices + 1 records rec[k] (4 floats each: rgb, 0) from its
/// slices' increments inc[0 .. kFogFroxelSlices) (FogFroxelSlice): rec[0] = 0, rec[k + 1] =
/// rec[k] + inc[k], summed in slice order.
PB_HOST_DEVICE inline void FogFroxelRecords(const Float3* inc, float* rec) {
  float S[3] = {0, 0, 0};
  for (int c = 0; c < 4; ++c) rec[c] = 0.0f;
  for (int k = 0; k < kFogFroxelSlices; ++k) {
    S[0] = S[0] + inc[k].x;
    S[1] = S[1] + inc[k].y;
    S[2] = S[2] + inc[k].z;
    float* r = rec + 4 * (k + 1);
    r[0] = S[0];
    r[1] = S[1];
    r[2] = S[2];
    r[3] = 0.0f;
  }
}

/// one fog froxel column along o + t d (o the camera centre, d unit) through the column's centre
/// pixel, whose grid froxel columns are `grid_cols`, with the slice jitter `jitter`:
/// *inv_log_far = 1 / log(t_far / near) (FogColumnFar) and the kFogFroxelSlices + 1 records
/// rec[k] (4 floats each: rgb, 0), the accumulated in-scatter from the camera to boundary k:
/// FogFroxelRecords of the slices' FogFroxelSlice.
template <typename R>
PB_HOST_DEVICE inline void FogFroxelColumn(const FogFroxelBuild<R>& b, const float o[3],
                                           const float d[3], float jitter,
                                           const MediaColumns& grid_cols, const R& zero,
                                           const R& unit, float* inv_log_far, float* rec) {
  const float t_far = FogColumnFar(b.media, b.num_media, o, d);
  *inv_log_far = 1.0f / logf(t_far / kFogFroxelNear);
  Float3 inc[kFogFroxelSlices];
  for (int k = 0; k < kFogFroxelSlices; ++k)
    inc[k] = FogFroxelSlice(b, o, d, jitter, t_far, k, grid_cols, zero, unit);
  FogFroxelRecords(inc, rec);
}

}  // namespace penumbra

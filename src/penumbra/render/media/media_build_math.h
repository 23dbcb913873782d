#pragma once
// the realtime media volumes' per-cell and per-column build (RealtimeMedia::Build, render/
// media_realtime.h), written once for the CPU and the CUDA backend's kernels:
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
//    slice order;
//  - the grids' light volumes, one cell at a time (GridLightCellCentre, GridLightCellLight,
//    GridLightCellSource): per light the transmittance through the grid from the
//    cell centre (kGridLightSteps steps of MediaGridDensity, render/media/media_scene_math.h) and
//    the shadow ray its in-scatter source asks, then the source (the sky, and each light seen);
//  - the grid froxels, one column at a time (GridFroxelColumnInterval, then per slice
//    GridFroxelSlice and GridFroxelRecords, which accumulates the slices in slice order).
// operation order: the CPU's, bit for bit (the rule of shading_math.h;
// docs/journal/2026-11-26-gpu-effects.md,
// "Media volumes built on the GPU" and "Grid media volumes built on the GPU").

#include <stdint.h>

#include "penumbra/core/host_device.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/light/light_math.h"
#include "penumbra/render/media/media_realtime_math.h"
#include "penumbra/render/media/media_scene_math.h"

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

/// a light's sample at the centre of its area (u = v = 0.5) seen from p: the unit direction
/// to it, its distance (+inf for directional lights), its illuminance, and whether it sends
/// anything to p (SampleLight of light_math.h, Eigen's normalisation order).
struct MediaLightAt {
  Float3 wi, E;
  float dist = 0;
  bool valid = false;
};
PB_HOST_DEVICE inline MediaLightAt MediaSampleLightAt(const LightPod& light, const float p[3]) {
  MediaLightAt s;
  SampleLight<float, Float3, bool, true>(light, Float3{p[0], p[1], p[2]}, 0.5f, 0.5f, &s.wi,
                                         &s.dist, &s.E, &s.valid);
  return s;
}

/// e^-mean(tau) of the n homogeneous media along p + t w, t in [0, dist] (1 for n = 0): the
/// channel-mean transmittance the volumes keep.
PB_HOST_DEVICE inline float MediaMeanTransmittance(const MediumPod* media, int n, const float p[3],
                                                   const float w[3], float dist) {
  if (n <= 0) return 1.0f;
  const Float3 tau = AnalyticOpticalDepthOf(media, n, p, w, 0.0f, dist);
  const float t3[3] = {tau.x, tau.y, tau.z};
  return expf(-MediaMean3(t3));
}

/// what a volume cell whose transmittance to light `light` is T asks of its visibility:
/// nothing where T <= 1e-4, lit where the light casts no shadows, else one shadow ray along
/// *d = w (unit) to *tmax (the light's distance less 1e-4 of it; +inf for directional lights).
PB_HOST_DEVICE inline uint8_t MediaShadowAsk(const LightPod& light, float T, const float w[3],
                                             float dist, float d[3], float* tmax) {
  if (!(T > 1e-4f)) return kMediaRayNone;
  if (light.cast_shadow == 0) return kMediaRayLit;
  for (int k = 0; k < 3; ++k) d[k] = w[k];
  *tmax = MediaIsInf(dist) ? INFINITY : dist * (1.0f - 1e-4f);
  return kMediaRayTrace;
}

/// light l at cell centre p: *T the channel-mean transmittance Th Tgrid (0 where the light
/// sends nothing to p); returns what the visibility asks (kMediaRayNone without visibility or
/// where T <= 1e-4), and for kMediaRayTrace the shadow ray from p along *d (unit) to *tmax
/// (the light's distance less 1e-4 of it; +inf for directional lights). the visibility volume's
/// value is T where the light is seen (kMediaRayLit, or a traced ray not occluded), else 0.
PB_HOST_DEVICE inline uint8_t LightVolumeCellLight(const LightVolumeBuild& b, const float p[3],
                                                   int l, float* T, float d[3], float* tmax) {
  const MediaLightAt s = MediaSampleLightAt(b.lights[l], p);
  if (!s.valid) {
    *T = 0.0f;
    return kMediaRayNone;
  }
  const float w[3] = {s.wi.x, s.wi.y, s.wi.z};
  float t = MediaMeanTransmittance(b.media, b.num_media, p, w, s.dist);
  for (int g = 0; g < b.num_grids; ++g)
    t *= GridLightTransmittance(b.grids[g], b.grid_light_T + b.grids[g].offset, b.num_lights, l, p,
                                w, s.dist);
  *T = t;
  if (b.with_visibility == 0) return kMediaRayNone;
  return MediaShadowAsk(b.lights[l], t, w, s.dist, d, tmax);
}

/// the parts of a frame's media volumes that RealtimeMedia::Build left to a device (Build's
/// `device_volumes`): the world light volume's cells (layout RealtimeMediaView::light_volume,
/// stride lights per cell; with_visibility: also its visibility, with one shadow ray per cell
/// and light traced where LightVolumeCellLight asks) and the fog froxels (fog_nx x fog_ny
/// columns with their axis tables; jitter FroxelColumnJitter of frame_key, stream 3).
/// grids: the grids' light volumes (layouts RealtimeMediaView::grids, their
/// [light][cell] transmittances end to end at GridLightPod::offset, their in-scatter sources
/// [cell] end to end in grid order) and the grid froxels (grid_nx x grid_ny columns with their
/// axis tables; jitter stream 2), over the grids' densities `grid_media` (num_grids of them,
/// RealtimeMediaView::num_grids; host pointers from RealtimeMedia, device copies once a device
/// holds them); grid_generation changes whenever the grids' arrays do (a device keeps its copy
/// while it is unchanged).
struct MediaVolumesToBuild {
  int light_volume = 0;
  int with_visibility = 0;
  int fog = 0;
  uint64_t frame_key = 0;
  int grids = 0;
  const MediaGridPod* grid_media = nullptr;
  uint64_t grid_generation = 0;
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
    const double end = tt == tt && !MediaIsInf(tt) ? tt : static_cast<double>(b);
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
    const MediaLightAt at = MediaSampleLightAt(b.lights[j], x);
    if (!at.valid) continue;
    const Float3 &wi = at.wi, &E = at.E;
    float vis;
    if (located && j < b.num_volume_lights) {
      vis = vis_all[j];
    } else {
      // (the fog froxels exist only with homogeneous media: num_media > 0)
      const float w[3] = {wi.x, wi.y, wi.z};
      vis = MediaMeanTransmittance(b.media, b.num_media, x, w, at.dist);
      for (int g = 0; g < b.num_grids; ++g)
        vis *= GridLightTransmittance(b.grids[g], b.grid_light_T + b.grids[g].offset,
                                      b.num_volume_lights, j, x, w, at.dist);
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

/// cells of a grid medium's light volume (at most the grid's own resolution per axis).
constexpr int kGridLightCells = 1024;
/// most march steps from a light-volume cell to a light through its grid.
constexpr int kGridLightSteps = 16;

/// the inputs of the grids' light volumes (RealtimeMedia's GridLight): per grid its densities
/// (`grids`, MediaGridPod: transform, half extents, arrays) and its light volume's layout
/// (`layouts`: r, cells_per_m, offset of its [light][cell] transmittances), the first num_lights
/// lights (at most kMaxVolumeLights), the homogeneous media (their transmittance to a light
/// lowers the in-scatter source) and the sky lighting the media (the sky volume's, or
/// sky_ambient without one).
struct GridLightBuild {
  const MediaGridPod* grids = nullptr;
  const GridLightPod* layouts = nullptr;
  int num_grids = 0;
  const LightPod* lights = nullptr;
  int num_lights = 0;
  const MediumPod* media = nullptr;
  int num_media = 0;
  float sky_ambient[3] = {0, 0, 0};
  const SkyVolumePod* sky_volume = nullptr;
};

/// the number of cells of a grid's light volume `gl` (r[0] r[1] r[2]).
PB_HOST_DEVICE inline int64_t GridLightCells(const GridLightPod& gl) {
  return static_cast<int64_t>(gl.r[0]) * gl.r[1] * gl.r[2];
}

/// where grid g's in-scatter sources start in the grids' sources end to end (the cells of the
/// grids before it).
PB_HOST_DEVICE inline int64_t GridSourceOffset(const GridLightPod* layouts, int g) {
  int64_t at = 0;
  for (int i = 0; i < g; ++i) at += GridLightCells(layouts[i]);
  return at;
}

/// the world position (m) of cell c (x fastest) of the grid light volume `gl` (its grid's
/// transform and half extents, its cells): x_G = -half + (i + 0.5) / cells_per_m per axis, then
/// R_GW^T (x_G - p_GW) in the operation order of Eigen's 3x3 product (GridToFrame's).
PB_HOST_DEVICE inline void GridLightCellCentre(const GridLightPod& gl, int64_t c, float p[3]) {
  const int i = static_cast<int>(c % gl.r[0]);
  const int j = static_cast<int>((c / gl.r[0]) % gl.r[1]);
  const int k = static_cast<int>(c / (static_cast<int64_t>(gl.r[0]) * gl.r[1]));
  const int idx[3] = {i, j, k};
  float y[3];
  for (int a = 0; a < 3; ++a)
    y[a] = (-gl.half[a] + (idx[a] + 0.5f) / gl.cells_per_m[a]) - gl.p_GW[a];
  const float* R = gl.R_GW;  // row-major R_GW: R_WG(a, k) = R[3 k + a]
  for (int a = 0; a < 3; ++a) p[a] = R[a] * y[0] + (R[3 + a] * y[1] + R[6 + a] * y[2]);
}

/// light l at cell centre p of grid g's light volume: *Tg the grid's transmittance towards the
/// light (exp(-sigma ds sum of the densities at the midpoints of at most kGridLightSteps steps
/// over the light ray's part inside the box, one step per cell size at least; sigma the
/// channel-mean sigma_t; 1 where the ray misses the box; 0 where the light sends nothing to p).
/// returns what its source asks of the light's visibility: nothing (Tg <= 1e-4 or no light),
/// lit (the light casts no shadows), or one shadow ray from p along *d (unit) to *tmax (the
/// light's distance less 1e-4 of it; +inf for directional lights).
PB_HOST_DEVICE inline uint8_t GridLightCellLight(const GridLightBuild& b, int g, const float p[3],
                                                 int l, float* Tg, float d[3], float* tmax) {
  const MediaLightAt s = MediaSampleLightAt(b.lights[l], p);
  if (!s.valid) {
    *Tg = 0.0f;
    return kMediaRayNone;
  }
  const MediaGridPod& v = b.grids[g];
  const GridLightPod& gl = b.layouts[g];
  const float w[3] = {s.wi.x, s.wi.y, s.wi.z};
  float T = 1.0f, a, e;
  if (MediaGridInterval(v, p, w, 0.0f, s.dist, &a, &e)) {
    const float cell_m = pbm::Min(pbm::Min(1.0f / gl.cells_per_m[0], 1.0f / gl.cells_per_m[1]),
                                  1.0f / gl.cells_per_m[2]);
    const int steps =
        pbm::Clamp(static_cast<int>(ceilf((e - a) / cell_m)), 1, static_cast<int>(kGridLightSteps));
    const float ds = (e - a) / steps;
    float o_G[3], d_G[3];
    GridToFrame(v.box, p, o_G);
    GridRotate(v.box, w, d_G);
    float tau = 0;
    for (int k = 0; k < steps; ++k) {
      const float t = a + (k + 0.5f) * ds;
      const float x[3] = {o_G[0] + t * d_G[0], o_G[1] + t * d_G[1], o_G[2] + t * d_G[2]};
      tau += MediaGridDensity(v, x);
    }
    T = expf(-tau * MediaMean3(v.sigma_t) * ds);
  }
  *Tg = T;
  return MediaShadowAsk(b.lights[l], T, w, s.dist, d, tmax);
}

/// the sky's part of a grid light volume cell's in-scatter source at p: the sky volume's ambient
/// radiance there, or sky_ambient without one (RealtimeMedia::SkyAmbientAt).
PB_HOST_DEVICE inline Float3 GridLightCellSky(const GridLightBuild& b, const float p[3]) {
  float s[3] = {b.sky_ambient[0], b.sky_ambient[1], b.sky_ambient[2]};
  if (b.sky_volume != nullptr) SkyVolumeAmbientRadiance(*b.sky_volume, p, b.sky_ambient, s);
  return Float3{s[0], s[1], s[2]};
}

/// the in-scatter source `src` at cell centre p plus light l's part where the cell sees it
/// (GridLightCellLight asked nothing of it and Tg > 1e-4, or its shadow ray was not blocked):
/// E Tg Th / (4 pi), Th = e^-mean(tau) of the homogeneous media towards the light (1 without).
/// sources are summed in light order after the sky's (GridLightCellSky).
PB_HOST_DEVICE inline Float3 GridLightCellSource(const GridLightBuild& b, const float p[3], int l,
                                                 float Tg, const Float3& src) {
  const MediaLightAt s = MediaSampleLightAt(b.lights[l], p);
  const float w[3] = {s.wi.x, s.wi.y, s.wi.z};
  const float Th = MediaMeanTransmittance(b.media, b.num_media, p, w, s.dist);
  const float k = Tg * Th * kInv4Pi;
  return Float3{src.x + s.E.x * k, src.y + s.E.y * k, src.z + s.E.z * k};
}

/// the inputs of the grid froxels' columns: the grids (densities, emission, coefficients), their
/// light volumes' layouts and in-scatter sources ([cell] per grid end to end, GridSourceOffset),
/// and the homogeneous media (their transmittance from the camera lowers each slice's source).
struct GridFroxelBuild {
  const MediaGridPod* grids = nullptr;
  const GridLightPod* layouts = nullptr;
  const Float3* source = nullptr;
  int num_grids = 0;
  const MediumPod* media = nullptr;
  int num_media = 0;
};

/// the overlap [*t0, *t1] of a grid froxel column's ray o + t d (d unit, t >= 0) with the grids'
/// boxes (the smallest entry to the largest exit); false where it meets none.
PB_HOST_DEVICE inline bool GridFroxelColumnInterval(const GridFroxelBuild& b, const float o[3],
                                                    const float d[3], float* t0, float* t1) {
  float a = INFINITY, e = -INFINITY;
  for (int g = 0; g < b.num_grids; ++g) {
    float ga, gb;
    if (!MediaGridInterval(b.grids[g], o, d, 0.0f, INFINITY, &ga, &gb)) continue;
    a = pbm::Min(a, ga);
    e = pbm::Max(e, gb);
  }
  *t0 = a;
  *t1 = e;
  return a < e;
}

/// one slice of a grid froxel column: the in-scatter source at its sample (times the
/// homogeneous media's transmittance from the camera), its transmittance e^-sigma_t ds and the
/// in-scatter's integration factor (1 - e^-sigma_t ds) / sigma_t (ds where sigma_t ds <= 1e-5);
/// `any` 0 where the sample has neither extinction nor source (the slice changes nothing).
struct GridFroxelStep {
  Float3 src, step_T, factor;
  int any = 0;
};

/// slice k (0 .. kFroxelSlices - 1) of a grid froxel column along o + t d (o the camera centre,
/// d unit) over its overlap [t0, t1] with the grid boxes (GridFroxelColumnInterval) with jitter
/// `jitter` (FroxelColumnJitter stream 2): the sample at t = t0 + (k + jitter) ds, ds = (t1 -
/// t0) / kFroxelSlices; per grid its density's sigma_t and sigma_s times the trilinear source
/// of its light volume, plus its emission.
PB_HOST_DEVICE inline GridFroxelStep GridFroxelSlice(const GridFroxelBuild& b, const float o[3],
                                                     const float d[3], float t0, float t1,
                                                     float jitter, int k) {
  const float ds = (t1 - t0) / kFroxelSlices;
  const float t = t0 + (k + jitter) * ds;
  const float p[3] = {o[0] + t * d[0], o[1] + t * d[1], o[2] + t * d[2]};
  Float3 sig_t{0, 0, 0}, src{0, 0, 0};
  for (int g = 0; g < b.num_grids; ++g) {
    const MediaGridPod& v = b.grids[g];
    float x[3];
    GridToFrame(v.box, p, x);
    const float dens = MediaGridDensity(v, x);
    if (dens > 0) {
      const GridLightPod& gl = b.layouts[g];
      const Float3 s = MediaTrilinear(b.source + GridSourceOffset(b.layouts, g), gl.r,
                                      (x[0] + v.box.half[0]) * gl.cells_per_m[0] - 0.5f,
                                      (x[1] + v.box.half[1]) * gl.cells_per_m[1] - 0.5f,
                                      (x[2] + v.box.half[2]) * gl.cells_per_m[2] - 0.5f);
      sig_t = Float3{sig_t.x + dens * v.sigma_t[0], sig_t.y + dens * v.sigma_t[1],
                     sig_t.z + dens * v.sigma_t[2]};
      src = Float3{src.x + dens * v.sigma_s[0] * s.x, src.y + dens * v.sigma_s[1] * s.y,
                   src.z + dens * v.sigma_s[2] * s.z};
    }
    if (v.emission != nullptr) src = src + MediaGridEmission(v, x);
  }
  GridFroxelStep out;
  if (!(MediaMax3(sig_t) > 0 || MediaMax3(src) > 0)) return out;
  out.any = 1;
  if (b.num_media > 0) {
    const Float3 T =
        MediaExpNeg(AnalyticOpticalDepthOf(b.media, b.num_media, o, d, 0.0f, t), false);
    src = Float3{src.x * T.x, src.y * T.y, src.z * T.z};
  }
  out.src = src;
  out.step_T = Float3{expf(-sig_t.x * ds), expf(-sig_t.y * ds), expf(-sig_t.z * ds)};
  const float s3[3] = {sig_t.x, sig_t.y, sig_t.z},
              T3[3] = {out.step_T.x, out.step_T.y, out.step_T.z};
  float f[3];
  for (int ch = 0; ch < 3; ++ch) f[ch] = s3[ch] * ds > 1e-5f ? (1.0f - T3[ch]) / s3[ch] : ds;
  out.factor = Float3{f[0], f[1], f[2]};
  return out;
}

/// a grid froxel column's kFroxelSlices + 1 records (8 floats each: S rgb 0, T rgb 0) from its
/// slices (GridFroxelSlice): rec[0] = (0, 1), then in slice order S += T src factor and
/// T *= step_T where the slice has any, rec[k + 1] = (S, T).
PB_HOST_DEVICE inline void GridFroxelRecords(const GridFroxelStep* steps, float* rec) {
  float S[3] = {0, 0, 0}, T[3] = {1, 1, 1};
  auto put = [&](int k) {
    float* r = rec + 8 * k;
    r[0] = S[0], r[1] = S[1], r[2] = S[2], r[3] = 0.0f;
    r[4] = T[0], r[5] = T[1], r[6] = T[2], r[7] = 0.0f;
  };
  put(0);
  for (int k = 0; k < kFroxelSlices; ++k) {
    const GridFroxelStep& s = steps[k];
    if (s.any != 0) {
      const float src[3] = {s.src.x, s.src.y, s.src.z};
      const float f[3] = {s.factor.x, s.factor.y, s.factor.z};
      const float st[3] = {s.step_T.x, s.step_T.y, s.step_T.z};
      for (int c = 0; c < 3; ++c) {
        S[c] = S[c] + T[c] * src[c] * f[c];
        T[c] = T[c] * st[c];
      }
    }
    put(k + 1);
  }
}

}  // namespace penumbra

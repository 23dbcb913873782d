#pragma once
// the realtime tier's homogeneous media (fog, haze, dust; render/media/media_realtime_math.h): the
// light volumes' cells with their shadow rays (MediaLightVolumeCell, MediaGridLightCell), the
// view froxels' columns (MediaGridFroxelColumn, MediaFogColumn) and the view pass over each
// pixel's radiance, with its streak (MediaViewQuad), as the CPU's RealtimeMedia.

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/media/media_build_math.h"
#include "penumbra/render/media/media_realtime_math.h"
#include "penumbra/render/transport/realtime_streaks.h"
#include "penumbra/render/transport/scene_view.h"

namespace penumbra::cuda {

/// whether a media volume cell at p sees a light whose visibility asks `w` (LightVolumeCellLight,
/// GridLightCellLight): lit, or a shadow ray along d to tmax traced here through f.scene and
/// not occluded, as RealtimeMedia::Build's rays (a RayQuery's: the same TraceRay, tmin 0).
PB_HOST_DEVICE inline bool MediaCellSees(const RealtimeFrameView& f, uint8_t w, const float p[3],
                                         const float d[3], float tmax) {
  if (w != kMediaRayTrace) return w == kMediaRayLit;
  TraceRay r;
  r.o = F3{p[0], p[1], p[2]};
  r.d = F3{d[0], d[1], d[2]};
  r.tmin = 0.0f;
  r.tmax = tmax;
  return !TraceOccluded(f.scene, r);
}

/// cell c of the world light volume that frame f builds itself (f.media_build.light_volume;
/// layout f.media.light_volume): per light l < stride its [cell][light] transmittance
/// trans_cl[c stride + l] (LightVolumeCellLight; 0 past the volume's lights) and, where vis_cl
/// is not null (f.media_build.with_visibility), the visibility V Th Tgrid, each asked shadow ray
/// traced here through f.scene, as RealtimeMedia::Build's cells (whose rays go through a
/// RayQuery: the same TraceRay, o at the cell centre, tmin 0).
PB_HOST_DEVICE inline void MediaLightVolumeCell(const RealtimeFrameView& f, int64_t c,
                                                float* trans_cl, float* vis_cl) {
  const RealtimeMediaView& m = f.media;
  LightVolumeBuild b;
  b.layout = m.light_volume;
  b.num_lights = m.num_volume_lights;
  b.with_visibility = vis_cl != nullptr ? 1 : 0;
  b.lights = f.lights;
  b.media = m.media;
  b.num_media = m.num_media;
  b.grids = m.grids;
  b.grid_light_T = m.grid_light_T;
  b.num_grids = m.num_grids;
  float p[3];
  LightVolumeCellCentre(b.layout, c, p);
  const int S = b.layout.stride;
  for (int l = 0; l < S; ++l) {
    const int64_t at = c * S + l;
    if (l >= b.num_lights) {
      trans_cl[at] = 0.0f;
      if (vis_cl != nullptr) vis_cl[at] = 0.0f;
      continue;
    }
    float T, d[3], tmax;
    const uint8_t w = LightVolumeCellLight(b, p, l, &T, d, &tmax);
    trans_cl[at] = T;
    if (vis_cl == nullptr) continue;
    const bool seen = MediaCellSees(f, w, p, d, tmax);
    vis_cl[at] = seen ? T : 0.0f;
  }
}

/// the ray o + t d (PrimaryRay, d normalised) through the centre pixel (*uc, *vc) of froxel
/// column c of a volume of nx columns of block x block pixels in frame f (RealtimeMedia's
/// columns take Camera::GenerateRay's).
PB_HOST_DEVICE inline void MediaColumnRay(const RealtimeFrameView& f, int c, int nx, int block,
                                          int* uc, int* vc, float o[3], float d[3]) {
  const int W = f.camera.width, H = f.camera.height;
  *uc = MediaMinI((c % nx) * block + block / 2, W - 1);
  *vc = MediaMinI((c / nx) * block + block / 2, H - 1);
  const TraceRay r = PrimaryRay(f.camera, *uc, *vc);
  const float len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  o[0] = r.o.x, o[1] = r.o.y, o[2] = r.o.z;
  d[0] = r.d.x / len, d[1] = r.d.y / len, d[2] = r.d.z / len;
}

/// the inputs of the grids' light volumes of frame f (f.media_build.grids): the grids' arrays
/// (f.media_build.grid_media), their layouts (f.media.grids), the volume lights, the homogeneous
/// media and the sky lighting them.
PB_HOST_DEVICE inline GridLightBuild MediaGridLightBuildOf(const RealtimeFrameView& f) {
  const RealtimeMediaView& m = f.media;
  GridLightBuild b;
  b.grids = f.media_build.grid_media;
  b.layouts = m.grids;
  b.num_grids = m.num_grids;
  b.lights = f.lights;
  b.num_lights = m.num_grid_lights;
  b.media = m.media;
  b.num_media = m.num_media;
  for (int k = 0; k < 3; ++k) b.sky_ambient[k] = m.sky_ambient[k];
  b.sky_volume = m.sky_volume;
  return b;
}

/// cell c of the grids' light volumes of frame f counted end to end (grid g's cells follow those
/// of the grids before it, GridSourceOffset): per light l its transmittance grid_T[offset + l
/// cells + i] (GridLightCellLight; i the cell within its grid) and the cell's in-scatter source
/// source[c] (GridLightCellSky, then GridLightCellSource of each light seen, in light order),
/// each asked shadow ray traced here through f.scene, as RealtimeMedia::Build's cells (whose
/// rays go through a RayQuery: the same TraceRay, o at the cell centre, tmin 0).
PB_HOST_DEVICE inline void MediaGridLightCell(const RealtimeFrameView& f, int64_t c, float* grid_T,
                                              Float3* source) {
  const GridLightBuild b = MediaGridLightBuildOf(f);
  int g = 0;
  int64_t i = c;
  while (g < b.num_grids && i >= GridLightCells(b.layouts[g])) i -= GridLightCells(b.layouts[g++]);
  if (g >= b.num_grids) return;
  const GridLightPod& gl = b.layouts[g];
  const int64_t cells = GridLightCells(gl);
  float p[3];
  GridLightCellCentre(gl, i, p);
  Float3 src = GridLightCellSky(b, p);
  for (int l = 0; l < b.num_lights; ++l) {
    float Tg, d[3], tmax;
    const uint8_t w = GridLightCellLight(b, g, p, l, &Tg, d, &tmax);
    grid_T[gl.offset + l * cells + i] = Tg;
    const bool seen = MediaCellSees(f, w, p, d, tmax);
    if (seen) src = GridLightCellSource(b, p, l, Tg, src);
  }
  source[c] = src;
}

/// the inputs of grid froxel column c of frame f (f.media_build.grids; f.media.grid_nx x grid_ny
/// columns): the build over f's grids, their light volumes' sources `source` and the homogeneous
/// media, the column's centre pixel's ray o + t d (PrimaryRay, unit direction; RealtimeMedia::
/// BuildFroxels takes Camera::GenerateRay's), its slice jitter (stream 2) and its overlap
/// [t0, t1] with the grid boxes (`hit` 0: none).
struct MediaGridColumnInputs {
  GridFroxelBuild b;
  float o[3], d[3];
  float jitter;
  float t0, t1;
  int hit;
};
PB_HOST_DEVICE inline MediaGridColumnInputs MediaGridColumnOf(const RealtimeFrameView& f, int c,
                                                              const Float3* source) {
  const RealtimeMediaView& m = f.media;
  MediaGridColumnInputs in;
  int uc, vc;
  MediaColumnRay(f, c, m.grid_nx, kFroxelBlock, &uc, &vc, in.o, in.d);
  GridFroxelBuild& b = in.b;
  b.grids = f.media_build.grid_media;
  b.layouts = m.grids;
  b.source = source;
  b.num_grids = m.num_grids;
  b.media = m.media;
  b.num_media = m.num_media;
  in.jitter = FroxelColumnJitter(f.media_build.frame_key, uc, vc, f.camera.width, 2);
  in.hit = GridFroxelColumnInterval(b, in.o, in.d, &in.t0, &in.t1) ? 1 : 0;
  return in;
}

/// the grid froxel column c's overlap as RealtimeMedia::BuildFroxels keeps it: t0[c], t1[c] and
/// slices_per_m[c] = min(kFroxelSlices / (t1 - t0), 1e30) where the column meets a grid, else 0.
PB_HOST_DEVICE inline void MediaGridColumnSpan(const MediaGridColumnInputs& in, int c, float* t0,
                                               float* t1, float* slices_per_m) {
  t0[c] = in.hit != 0 ? in.t0 : 0.0f;
  t1[c] = in.hit != 0 ? in.t1 : 0.0f;
  slices_per_m[c] =
      in.hit != 0 ? pbm::Min(static_cast<float>(kFroxelSlices) / (in.t1 - in.t0), 1e30f) : 0.0f;
}

/// slice k of grid froxel column `in` (GridFroxelSlice; nothing where the column meets no grid).
PB_HOST_DEVICE inline GridFroxelStep MediaGridSlice(const MediaGridColumnInputs& in, int k) {
  if (in.hit == 0) return GridFroxelStep();
  return GridFroxelSlice(in.b, in.o, in.d, in.t0, in.t1, in.jitter, k);
}

/// grid froxel column c of frame f whole (the host path; the device runs its slices in parallel,
/// MediaGridSlice, then GridFroxelRecords: the same bits): its span (MediaGridColumnSpan) and its
/// kFroxelSlices + 1 records at records[c (kFroxelSlices + 1) ..].
PB_HOST_DEVICE inline void MediaGridFroxelColumn(const RealtimeFrameView& f, int c,
                                                 const Float3* source, float* t0, float* t1,
                                                 float* slices_per_m,
                                                 GridFroxelRecord<Rgb4>* records) {
  const MediaGridColumnInputs in = MediaGridColumnOf(f, c, source);
  MediaGridColumnSpan(in, c, t0, t1, slices_per_m);
  GridFroxelStep steps[kFroxelSlices];
  for (int k = 0; k < kFroxelSlices; ++k) steps[k] = MediaGridSlice(in, k);
  GridFroxelRecords(
      steps, reinterpret_cast<float*>(records + static_cast<int64_t>(c) * (kFroxelSlices + 1)));
}

/// the inputs of fog froxel column c of frame f (f.media_build.fog; f.media.fog_nx x fog_ny
/// columns): the build over f's media, lights, grid froxels and the visibility volume vis_cl
/// (null: none), its centre pixel's ray o + t d (PrimaryRay, unit direction; RealtimeMedia::
/// BuildFogFroxels takes Camera::GenerateRay's), its slice jitter and grid froxel columns.
struct MediaFogColumnInputs {
  FogFroxelBuild<Rgb4> b;
  float o[3], d[3];
  float jitter;
  MediaColumns grid_cols;
};
PB_HOST_DEVICE inline MediaFogColumnInputs MediaFogColumnOf(const RealtimeFrameView& f, int c,
                                                            const float* vis_cl) {
  const RealtimeMediaView& m = f.media;
  MediaFogColumnInputs in;
  int uc, vc;
  MediaColumnRay(f, c, m.fog_nx, kFogFroxelBlock, &uc, &vc, in.o, in.d);
  FogFroxelBuild<Rgb4>& b = in.b;
  b.media = m.media;
  b.num_media = m.num_media;
  b.lights = f.lights;
  b.num_lights = f.num_lights;
  b.num_volume_lights = m.num_volume_lights;
  b.vis_layout = m.light_volume;
  b.vis_cl = vis_cl;
  b.grids = m.grids;
  b.grid_light_T = m.grid_light_T;
  b.num_grids = m.num_grids;
  b.grid_t0 = m.grid_t0;
  b.grid_t1 = m.grid_t1;
  b.grid_slices_per_m = m.grid_slices_per_m;
  b.grid_records = m.grid_records;
  in.grid_cols = m.grid_records != nullptr ? MediaGridPixelColumns(m, uc, vc) : MediaColumns{};
  in.jitter = FroxelColumnJitter(f.media_build.frame_key, uc, vc, f.camera.width, 3);
  return in;
}

/// fog froxel column c of frame f (MediaFogColumnOf): FogFroxelColumn into the column's
/// kFogFroxelSlices + 1 records S[c (kFogFroxelSlices + 1) ..] and inv_log_far[c], as
/// RealtimeMedia::BuildFogFroxels (whose column ray is Camera::GenerateRay's). the device runs
/// its slices in parallel (MediaFogSlice, then FogFroxelRecords: the same bits).
PB_HOST_DEVICE inline void MediaFogColumn(const RealtimeFrameView& f, int c, const float* vis_cl,
                                          Rgb4* S, float* inv_log_far) {
  const MediaFogColumnInputs in = MediaFogColumnOf(f, c, vis_cl);
  FogFroxelColumn(in.b, in.o, in.d, in.jitter, in.grid_cols, Rgb4{0, 0, 0, 0}, Rgb4{1, 1, 1, 0},
                  inv_log_far + c,
                  reinterpret_cast<float*>(S + static_cast<int64_t>(c) * (kFogFroxelSlices + 1)));
}

/// slice k of fog froxel column c of frame f: its increment (FogFroxelSlice of
/// MediaFogColumnOf), and for k = 0 the column's inv_log_far[c].
PB_HOST_DEVICE inline Float3 MediaFogSlice(const RealtimeFrameView& f, int c, int k,
                                           const float* vis_cl, float* inv_log_far) {
  const MediaFogColumnInputs in = MediaFogColumnOf(f, c, vis_cl);
  const float t_far = FogColumnFar(in.b.media, in.b.num_media, in.o, in.d);
  if (k == 0) inv_log_far[c] = 1.0f / logf(t_far / kFogFroxelNear);
  return FogFroxelSlice(in.b, in.o, in.d, in.jitter, t_far, k, in.grid_cols, Rgb4{0, 0, 0, 0},
                        Rgb4{1, 1, 1, 0});
}

/// the media (homogeneous and grids) over the radiance of the pixels of the 2x2 quad (u0, v0) ..
/// (u0 + 1, v0 + 1) (u0, v0 even; pixels outside the image are skipped) once it is final (after
/// the shared visibility and the mirror layer), as RealtimeIntegrator's ApplyTileViewEffects: L
/// becomes T L + L_add (MediaViewSegment of f.media) along the pixel's ray (PrimaryRay, unit
/// direction) to its primary hit, t_end = depth[i] |d| (depth: the primary hits' t,
/// f.geometry[i].hit 0: the ray escapes, t_end = +inf). a quad inside the image whose four
/// pixels all hit or all escape shares the lookups of MediaPrepareQuad at the mean of their
/// t_end (+inf for escaping rays) and the normalised sum of their unit directions from the
/// first pixel's origin; the others look up per pixel. the CPU walks the quads of its 16x16
/// tiles, which start at even pixels, so its quads are these. a pixel with a particle streak in
/// front of its hit (PixelStreakOf) then gets it over L (ApplyStreak) with the streak's radiance
/// seen through the media up to it (MediaViewSegment to s.t |d|, the same quad lookups), as
/// the CPU's ApplyViewEffects; StreakSplatApplyKernel does not run for frames with media.
PB_HOST_DEVICE inline void MediaViewQuad(const RealtimeFrameView& f, int u0, int v0,
                                         const float* depth, Float3* radiance) {
  const int W = f.camera.width, H = f.camera.height;
  float o[4][3], d[4][3], t_end[4], d_len[4];
  int hit[4] = {0, 0, 0, 0};
  bool inside[4];
  for (int c = 0; c < 4; ++c) {
    const int u = u0 + (c & 1), v = v0 + (c >> 1);
    inside[c] = u < W && v < H;
    if (!inside[c]) continue;
    const int64_t i = static_cast<int64_t>(v) * W + u;
    const TraceRay r = PrimaryRay(f.camera, u, v);
    d_len[c] = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
    o[c][0] = r.o.x, o[c][1] = r.o.y, o[c][2] = r.o.z;
    d[c][0] = r.d.x / d_len[c], d[c][1] = r.d.y / d_len[c], d[c][2] = r.d.z / d_len[c];
    hit[c] = f.geometry[i].hit != 0 ? 1 : 0;
    t_end[c] = hit[c] != 0 ? depth[i] * d_len[c] : INFINITY;
  }
  const bool shared =
      u0 + 1 < W && v0 + 1 < H && hit[1] == hit[0] && hit[2] == hit[0] && hit[3] == hit[0];
  MediaQuadShared q;
  if (shared) {
    float t_c = INFINITY;
    if (hit[0] != 0) {
      t_c = 0;
      for (int c = 0; c < 4; ++c) t_c += 0.25f * t_end[c];
    }
    float dc[3] = {0, 0, 0};
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) dc[k] += d[c][k];
    const float dc_len = sqrtf(dc[0] * dc[0] + dc[1] * dc[1] + dc[2] * dc[2]);
    for (int k = 0; k < 3; ++k) dc[k] = dc[k] / dc_len;
    MediaPrepareQuad(f.media, u0, v0, t_c, o[0], dc, &q);
  }
  for (int c = 0; c < 4; ++c) {
    if (!inside[c]) continue;
    const int u = u0 + (c & 1), v = v0 + (c >> 1);
    const int64_t i = static_cast<int64_t>(v) * W + u;
    Float3 T, L_add;
    MediaViewSegment(f.media, u, v, o[c], d[c], t_end[c], &T, &L_add, shared ? &q : nullptr);
    const Float3 L = radiance[i];
    radiance[i] = Float3{T.x * L.x + L_add.x, T.y * L.y + L_add.y, T.z * L.z + L_add.z};
    // the pixel's streak over it, seen through the media in front of it: alpha (media to the
    // streak, then the streak) + (1 - alpha) (media to the end, then the surface)
    StreakPixel s;
    if (!PixelStreakOf(f, i, &s) || !StreakInFront(s, depth[i])) continue;
    Float3 T_f, L_f;
    MediaViewSegment(f.media, u, v, o[c], d[c], s.t * d_len[c], &T_f, &L_f, shared ? &q : nullptr);
    s.L = Float3{T_f.x * s.L.x + L_f.x, T_f.y * s.L.y + L_f.y, T_f.z * s.L.z + L_f.z};
    radiance[i] = ApplyStreak(s, depth[i], radiance[i]);
  }
}

}  // namespace penumbra::cuda

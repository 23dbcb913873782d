// the realtime tier's media and particle-streak kernels (realtime_kernels.cuh): the media
// volumes a frame builds on the device, the media's uploads, the view pass over the final
// radiance, and the particle streaks' uploads and splat.

#include <cstring>

#include "penumbra/render/cuda/media_grid_upload.h"
#include "penumbra/render/cuda/realtime_kernels.cuh"

namespace penumbra::cuda::realtime {
namespace {

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

// the light volumes a frame builds itself (RealtimeFrameView::media_build), before the kernels
// that read them: one thread per cell c < cells, its shadow rays traced in the thread,
// Cell(f, c, out...): the world light volume's (MediaLightVolumeCell, before the fog froxels,
// which read its visibility) and the grids' (MediaGridLightCell, every grid's cells counted end
// to end, before the grid froxels, which read their sources).
template <auto Cell, class... Out>
__global__ void LightVolumeCellKernel(RealtimeFrameView f, int64_t cells, Out... out) {
  const int64_t c = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (c >= cells) return;
  Cell(f, c, out...);
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

// a froxel volume's four axis tables, ax and ax_half [width], ay and ay_half [height], into
// `b` end to end; *d_tables[k] points at table k on the device.
void UploadAxes(const MediaAxis* const tables[4], int width, int height, Buffer* b,
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

// the values of every grid's [light][cell] transmittances end to end in view m (the last
// pod's offset + its own; at least 1)
size_t GridLightValues(const RealtimeMediaView& m) {
  const GridLightPod& last = m.grids[m.num_grids - 1];
  const size_t n =
      last.offset + static_cast<size_t>(m.num_grid_lights) * last.r[0] * last.r[1] * last.r[2];
  return n > 0 ? n : 1;
}
}  // namespace

void MediaStreakBuffers::UploadMedia(const RealtimeMediaView& h, const SkyVolumePod* volume,
                                     RealtimeMediaView* d, cudaStream_t stream) {
  *d = h;
  media_pods.Upload(h.media, sizeof(MediumPod) * h.num_media, stream);
  d->media = h.num_media > 0 ? media_pods.as<MediumPod>() : nullptr;
  if (h.sky_volume != nullptr) {
    if (volume == nullptr)
      throw Error("DeviceRealtime::Render: media lit by a sky volume the device does not hold");
    d->sky_volume = volume;
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
// the grids' volumes frame f builds itself (f->media_build.grids), on `stream` after
// UploadMedia and before the world light volume and fog froxels (which read them): the grids'
// arrays uploaded when their generation changed, the grids' light volumes, then
// MediaGridFroxelKernel; f->media pointed at their buffers
void MediaStreakBuffers::BuildGridMedia(const RealtimeMediaView& h, RealtimeFrameView* f,
                                        cudaStream_t stream) {
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
    LaunchKernel("MediaGridLightKernel", LightVolumeCellKernel<MediaGridLightCell, float*, Float3*>,
                 static_cast<unsigned>((cells + 63) / 64), 64, 0, stream, *f, cells,
                 media_grid_T.as<float>(), media_grid_source.as<Float3>());
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
  LaunchKernel("MediaGridFroxelKernel", MediaGridFroxelKernel, static_cast<unsigned>(columns),
               kGridSliceBlock, 0, stream, *f, media_grid_source.as<Float3>(), cols, cols + columns,
               cols + 2 * columns, media_grid_records.as<GridFroxelRecord<Rgb4>>());
  m.grid_t0 = cols;
  m.grid_t1 = cols + columns;
  m.grid_slices_per_m = cols + 2 * columns;
  m.grid_records = media_grid_records.as<GridFroxelRecord<Rgb4>>();
}
// the media volumes frame f builds itself (f->media_build), on `stream` after UploadMedia: the
// grids' (BuildGridMedia), then the world light volume, then MediaFogSliceKernel; f->media
// pointed at their buffers
void MediaStreakBuffers::BuildMedia(const RealtimeMediaView& h, RealtimeFrameView* f,
                                    cudaStream_t stream) {
  BuildGridMedia(h, f, stream);
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
    LaunchKernel("MediaLightVolumeKernel",
                 LightVolumeCellKernel<MediaLightVolumeCell, float*, float*>,
                 static_cast<unsigned>((cells + 127) / 128), 128, 0, stream, *f, cells,
                 media_trans.as<float>(), vis);
    m.light_trans = media_trans.as<float>();
  }
  if (b.fog != 0) {
    const int columns = m.fog_nx * m.fog_ny;
    media_fog.Reserve(sizeof(Rgb4) * static_cast<size_t>(columns) * (kFogFroxelSlices + 1));
    media_inv_log_far.Reserve(sizeof(float) * static_cast<size_t>(columns));
    LaunchKernel("MediaFogSliceKernel", MediaFogSliceKernel, static_cast<unsigned>(columns),
                 kFogSliceBlock, 0, stream, *f, vis, media_fog.as<Rgb4>(),
                 media_inv_log_far.as<float>());
    m.fog_S = media_fog.as<Rgb4>();
    m.fog_inv_log_far = media_inv_log_far.as<float>();
  }
}

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
  LaunchKernel("StreakSplatKernel", StreakSplatKernel, static_cast<unsigned>((threads + 127) / 128),
               128, 0, stream, f);
  LaunchKernel("StreakShadeKernel", StreakShadeKernel, PixelGrid(W, H), PixelBlock(), 0, stream, f);
}

void MediaStreakBuffers::QueueStreaks(const RealtimeFrameView& h, RealtimeFrameView* f, int64_t n,
                                      bool staged, cudaStream_t stream) {
  f->splat = h.splat;
  // src, or (staged) its copy in *pin
  const auto source = [staged](const void* src, size_t bytes, PinnedBuffer* pin) {
    if (!staged) return src;
    pin->Reserve(bytes);
    std::memcpy(pin->p, src, bytes);
    return static_cast<const void*>(pin->p);
  };
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
void LaunchViewPasses(const RealtimeFrameView& f, const float* depth, Float3* radiance,
                      cudaStream_t stream) {
  const int W = f.camera.width, H = f.camera.height;
  if (f.has_media != 0) {
    // the streaks seen through the media too
    LaunchKernel("MediaViewKernel", MediaViewKernel, PixelGrid((W + 1) / 2, (H + 1) / 2),
                 PixelBlock(), 0, stream, f, depth, radiance);
    return;
  }
  if (f.splat.streaks.num > 0) {
    LaunchKernel("StreakSplatApplyKernel", StreakSplatApplyKernel, PixelGrid(W, H), PixelBlock(), 0,
                 stream, f, depth, radiance);
  }
}

bool MediaStreakBuffers::DownloadGridVolumes(GridVolumeArrays* out) const {
  if (grid_built_cells <= 0 && grid_built_columns <= 0) return false;
  Check(cudaDeviceSynchronize(), "DownloadGridVolumes");
  auto get = [](const Buffer& b, void* dst, size_t bytes) {
    if (bytes > 0)
      Check(cudaMemcpy(dst, b.p, bytes, cudaMemcpyDeviceToHost), "DownloadGridVolumes");
  };
  const size_t columns = static_cast<size_t>(grid_built_columns);
  out->T.assign(grid_built_values, 0.0f);
  out->source.assign(static_cast<size_t>(grid_built_cells), Float3{});
  out->t0.assign(columns, 0.0f);
  out->t1.assign(columns, 0.0f);
  out->slices_per_m.assign(columns, 0.0f);
  out->records.assign(columns * (kFroxelSlices + 1), GridFroxelRecord<Rgb4>{});
  get(media_grid_T, out->T.data(), sizeof(float) * out->T.size());
  get(media_grid_source, out->source.data(), sizeof(Float3) * out->source.size());
  std::vector<float> cols(3 * columns);
  get(media_grid_columns, cols.data(), sizeof(float) * cols.size());
  std::copy(cols.begin(), cols.begin() + columns, out->t0.begin());
  std::copy(cols.begin() + columns, cols.begin() + 2 * columns, out->t1.begin());
  std::copy(cols.begin() + 2 * columns, cols.end(), out->slices_per_m.begin());
  get(media_grid_records, out->records.data(),
      sizeof(GridFroxelRecord<Rgb4>) * out->records.size());
  return true;
}

}  // namespace penumbra::cuda::realtime

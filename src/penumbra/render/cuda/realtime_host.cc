#include "penumbra/render/cuda/realtime_host.h"

#include <algorithm>
#include <cmath>
#include <vector>

namespace penumbra::cuda {

RealtimeSky SkyDataOf(const RealtimeFrameData& data) {
  RealtimeSky d;
  d.sky = data.frame_sky().pod();
  d.volume = data.sky_volume().pod();
  d.num_probes = data.sky_volume().num_probes();
  return d;
}

void BuildMediaVolumesOnHost(RealtimeFrameView* f, ThreadPool* pool, MediaVolumeArrays* out) {
  if (f->has_media == 0) return;
  const MediaVolumesToBuild& b = f->media_build;
  RealtimeMediaView& m = f->media;
  if (b.grids != 0 && m.num_grids > 0) {
    const GridLightPod& last = m.grids[m.num_grids - 1];
    out->grids.T.assign(last.offset + static_cast<size_t>(m.num_grid_lights) * GridLightCells(last),
                        0.0f);
    const int64_t cells = GridSourceOffset(m.grids, m.num_grids);
    out->grids.source.assign(cells, Float3{});
    ParallelForOrSerial(pool, cells, [&](int64_t c) {
      MediaGridLightCell(*f, c, out->grids.T.data(), out->grids.source.data());
    });
    m.grid_light_T = out->grids.T.data();
    const int columns = m.grid_nx * m.grid_ny;
    out->grids.t0.assign(columns, 0.0f);
    out->grids.t1.assign(columns, 0.0f);
    out->grids.slices_per_m.assign(columns, 0.0f);
    out->grids.records.assign(static_cast<size_t>(columns) * (kFroxelSlices + 1),
                              GridFroxelRecord<Rgb4>{});
    ParallelForOrSerial(pool, columns, [&](int64_t c) {
      MediaGridFroxelColumn(*f, static_cast<int>(c), out->grids.source.data(), out->grids.t0.data(),
                            out->grids.t1.data(), out->grids.slices_per_m.data(),
                            out->grids.records.data());
    });
    if (columns > 0) {
      m.grid_t0 = out->grids.t0.data();
      m.grid_t1 = out->grids.t1.data();
      m.grid_slices_per_m = out->grids.slices_per_m.data();
      m.grid_records = out->grids.records.data();
    }
  }
  float* vis = nullptr;
  if (b.light_volume != 0) {
    const int64_t cells = LightVolumeCells(m.light_volume);
    const size_t values = static_cast<size_t>(cells) * m.light_volume.stride;
    out->trans.assign(values, 0.0f);
    out->vis.assign(b.with_visibility != 0 ? values : 0, 0.0f);
    if (b.with_visibility != 0) vis = out->vis.data();
    ParallelForOrSerial(pool, cells,
                        [&](int64_t c) { MediaLightVolumeCell(*f, c, out->trans.data(), vis); });
    m.light_trans = out->trans.data();
  }
  if (b.fog != 0) {
    const int columns = m.fog_nx * m.fog_ny;
    out->fog.assign(static_cast<size_t>(columns) * (kFogFroxelSlices + 1), Rgb4{});
    out->inv_log_far.assign(columns, 0.0f);
    ParallelForOrSerial(pool, columns, [&](int64_t c) {
      MediaFogColumn(*f, static_cast<int>(c), vis, out->fog.data(), out->inv_log_far.data());
    });
    m.fog_S = out->fog.data();
    m.fog_inv_log_far = out->inv_log_far.data();
  }
}

namespace {

// ShadeQueuedLights' queue on the host (RenderRealtimeOnHost's queued_shadows): light j's ray
// of pixel `pixel` at rays[j n + pixel].
struct HostShadowPush {
  QueuedShadowRay* rays;
  int64_t pixel, n;
  void Push(int j, const TraceRay& r) const {
    rays[j * n + pixel] = QueueEntryOf(r, static_cast<uint32_t>(pixel), j);
  }
};

}  // namespace

namespace {

// fn(u, v) for every pixel of a W x H frame, its rows in parallel over `pool` (may be null), as
// the kernels' one thread a pixel
template <typename Fn>
void ForEachPixel(ThreadPool* pool, int W, int H, const Fn& fn) {
  ParallelForOrSerial(pool, H, [&](int64_t v) {
    for (int u = 0; u < W; ++u) fn(u, static_cast<int>(v));
  });
}

// the shared visibility of frame f by shadow tiles, as the kernels' blocks
// (VisibilityRaysWarpKernel, VisibilityTileKernel) do it in shared memory: per tile, its
// surfaces and every light's verdicts as bit rows copied for the penumbra rays
// (TileWindowSurfaces, RowLightVerdicts, SharedVisibilityRaysOf), then light after light its
// verdicts, ray counts (packed once, ShadowWindowCounts) and fractions (SharedWindowFraction)
// for the resolve (SharedLampFraction, AddSharedVisibility).
void TiledSharedVisibility(const RealtimeFrameView& f, ThreadPool* pool, Float3* radiance) {
  const int W = f.camera.width, H = f.camera.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int tiles_x = (W + kShadowTileSize - 1) / kShadowTileSize;
  const int tiles_y = (H + kShadowTileSize - 1) / kShadowTileSize;
  constexpr int kTile = kShadowTileSize * kShadowTileSize;
  // a tile's pixels (tile-local index t = y kShadowTileSize + x) in the image, -1 outside it
  const auto tile_pixel = [&](int64_t tile, int t) -> int64_t {
    const int u = static_cast<int>(tile % tiles_x) * kShadowTileSize + t % kShadowTileSize;
    const int v = static_cast<int>(tile / tiles_x) * kShadowTileSize + t / kShadowTileSize;
    return u < W && v < H ? static_cast<int64_t>(v) * W + u : -1;
  };
  ParallelForOrSerial(pool, int64_t{tiles_x} * tiles_y, [&](int64_t tile) {
    // the tile's surfaces (TileWindowSurfaces) and every light's verdicts as bit rows
    // (ShadowVerdictBits), as the kernels' shared memory keeps them
    std::vector<uint32_t> rows(static_cast<size_t>(kShadowVerdictRows) * std::max(f.num_lights, 1));
    int32_t key[kTile];
    float ng[3][kTile], p[3][kTile];
    for (int t = 0; t < kTile; ++t) {
      const int64_t i = tile_pixel(tile, t);
      key[t] = TileWindowSurfaces::kNoWindowSurface;
      ng[0][t] = ng[1][t] = ng[2][t] = p[0][t] = p[1][t] = p[2][t] = 0;
      if (i < 0) continue;
      const PixelGeometry& g = f.geometry[i];
      key[t] = TileWindowSurfaces::KeyOf(g);
      ng[0][t] = g.ng.x, ng[1][t] = g.ng.y, ng[2][t] = g.ng.z;
      p[0][t] = g.p_or_d.x, p[1][t] = g.p_or_d.y, p[2][t] = g.p_or_d.z;
      for (int j = 0; j < f.num_lights; ++j)
        rows[j * kShadowVerdictRows + kShadowWindowRadius + t / kShadowTileSize] |=
            ShadowVerdictBits(t % kShadowTileSize, f.area_vis[j * n + i]);
    }
    const TileWindowSurfaces surfaces{key, ng[0], ng[1], ng[2], p[0], p[1], p[2]};
    for (int t = 0; t < kTile; ++t) {
      const int64_t i = tile_pixel(tile, t);
      if (i >= 0)
        SharedVisibilityRaysOf(
            f, static_cast<int>(i % W), static_cast<int>(i / W), surfaces, t, kShadowTileSize,
            RowLightVerdicts{rows.data(), t % kShadowTileSize, t / kShadowTileSize});
    }
  });
  ParallelForOrSerial(pool, int64_t{tiles_x} * tiles_y, [&](int64_t tile) {
    int8_t vis[kTile];
    uint32_t counts[kTile];
    float fraction[kTile];
    const VisibilityTaps taps{vis, nullptr, nullptr, fraction, kShadowTileSize, counts};
    for (int j = 0; j < f.num_lights; ++j) {
      if (!IsExtendedLightPod(f.lights[j])) continue;
      for (int t = 0; t < kTile; ++t) {
        const int64_t i = tile_pixel(tile, t);
        vis[t] = i < 0 ? int8_t{-1} : f.area_vis[j * n + i];
        counts[t] = vis[t] < 0 ? 0u
                               : ShadowWindowCounts(vis[t], f.area_visible[j * n + i],
                                                    f.area_rays[j * n + i]);
      }
      for (int t = 0; t < kTile; ++t) {
        const int64_t i = tile_pixel(tile, t);
        if (vis[t] >= 0)
          fraction[t] = SharedWindowFraction(taps, t, f.window[i], f.area_own[j * n + i] != 0);
      }
      for (int t = 0; t < kTile; ++t) {
        const int64_t i = tile_pixel(tile, t);
        if (vis[t] < 0) continue;
        const int u = static_cast<int>(i % W), v = static_cast<int>(i / W);
        const ShadowTile st = ShadowTileOf(u, v, W, H);
        const bool lamp = f.lights[j].kind != LightKind::kDirectional && f.area_own[j * n + i] == 0;
        const float V = SharedLampFraction(taps, t, f.window[i], lamp, u - st.x0, v - st.y0, st);
        radiance[i] = AddSharedVisibility(radiance[i], V, f.area_c[j * n + i]);
      }
    }
  });
}

}  // namespace

void RenderRealtimeOnHost(const RealtimeFrameData& data, const BvhScene& bvh, ThreadPool* pool,
                          RenderedFrame* out, bool stored_surface, bool strided_terms,
                          bool queued_shadows, bool tiled_visibility) {
  const PinholeCamera& c = data.camera();
  const int W = c.width, H = c.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const SceneView scene = bvh.view();
  const RealtimeFrameView geo_view = data.View(scene, nullptr);
  std::vector<PixelGeometry> geometry(n);
  std::vector<SurfaceTerms> surfaces(stored_surface ? n : 0);
  if (out->depth_m.width != W || out->depth_m.height != H || out->depth_m.channels != 1)
    out->depth_m = ImageF(W, H, 1);
  ForEachPixel(pool, W, H, [&](int u, int v) {
    const int64_t i = int64_t{v} * W + u;
    geometry[i] = PrimaryGeometry(geo_view, u, v, &out->depth_m.data[i], nullptr,
                                  stored_surface ? &surfaces[i] : nullptr);
  });
  // the mirror layer's rays, traced from the primary geometry (on the GPU their geometry
  // makes the round trip to the host with the primary geometry's)
  std::vector<PixelGeometry> mirror_geometry;
  std::vector<TraceHit> mirror_hits;
  std::vector<Float3> mirror_sky, mirror_radiance;
  if (data.any_mirror()) {
    mirror_geometry.resize(n);
    mirror_hits.resize(n);
    mirror_sky.resize(n);
    mirror_radiance.resize(n);
    RealtimeFrameView mirror_view = geo_view;
    mirror_view.geometry = geometry.data();
    mirror_view.mirror_geometry = mirror_geometry.data();
    mirror_view.mirror_hits = mirror_hits.data();
    ForEachPixel(pool, W, H, [&](int u, int v) { TraceMirrorRay(mirror_view, u, v); });
    data.MirrorSkyTerms(mirror_geometry.data(), n, mirror_sky.data(), pool);
  }
  std::vector<Float3> sky(n);
  data.SkyTerms(geometry.data(), n, sky.data(), pool);
  RealtimeFrameView f = data.View(scene, sky.data());
  // the frame's own splat of the particle streaks, as the device's kernels: every streak's
  // rows (one streak at a time: a plain minimum per pixel), then the shading of every pixel
  // that has a streak
  std::vector<unsigned long long> splat_nearest;
  std::vector<StreakPixel> splat_pixels;
  if (f.splat.streaks.num > 0) {
    splat_nearest.assign(n, kNoStreakKey);
    splat_pixels.resize(n);
    f.splat.nearest = splat_nearest.data();
    f.splat.pixels = splat_pixels.data();
    const int32_t num = SplatStreakCount(f.splat);
    for (int k = 0; k < num; ++k) {
      const StreakProjection p = SplatProjection(f, f.splat.streaks.streaks[k]);
      for (int v = p.v0; v <= p.v1 && !p.empty(); ++v) SplatStreakRow(f, k, p, v);
    }
    ForEachPixel(pool, W, H, [&](int u, int v) { ShadeSplatPixel(f, u, v); });
  }
  // the media volumes the frame builds itself, as the device's kernels (before the shading)
  MediaVolumeArrays media_volumes;
  BuildMediaVolumesOnHost(&f, pool, &media_volumes);
  f.mirror_geometry = mirror_geometry.data();
  f.mirror_hits = mirror_hits.data();
  f.mirror_sky = mirror_sky.data();
  f.mirror_radiance = mirror_radiance.data();
  // the shared visibility's buffers (RealtimeFrameView), per pixel and per light and pixel.
  const size_t nl = static_cast<size_t>(n) * static_cast<size_t>(f.num_lights);
  std::vector<uint32_t> window(n);
  std::vector<float> total(n);
  std::vector<Float3> area_c(nl);
  std::vector<int8_t> area_vis(nl);
  std::vector<float> area_visible(nl), area_rays(nl), area_fraction(nl);
  std::vector<uint8_t> area_own(nl);
  f.geometry = geometry.data();
  f.window = window.data();
  f.total = total.data();
  f.area_c = area_c.data();
  f.area_vis = area_vis.data();
  f.area_visible = area_visible.data();
  f.area_rays = area_rays.data();
  f.area_own = area_own.data();
  f.area_fraction = area_fraction.data();
  std::vector<Float3> radiance(n);
  const int term_lights = std::min(std::max(f.num_lights, 0), kShadeCachedLights);
  // queued_shadows: the kernels' three passes (ShadeQueuedKernel, TraceQueuedKernel,
  // SumQueuedKernel), the rays at [light][pixel] in place of the device's queue
  std::vector<QueuedShadowRay> queued_rays;
  std::vector<QueuedLightMasks> queued_masks;
  std::vector<uint32_t> queued_occluded;
  if (stored_surface && queued_shadows && f.num_lights <= kMaxQueuedShadowLights) {
    queued_rays.resize(nl);
    queued_masks.resize(n);
    queued_occluded.assign(n, 0);
  }
  ParallelForOrSerial(pool, H, [&](int64_t v) {
    // strided_terms: the row's pixels share one array, interleaved as a block's threads
    std::vector<float> row_terms;
    if (strided_terms) row_terms.resize(StridedLightTerms::kLightTermFloats * term_lights * W);
    for (int u = 0; u < W; ++u) {
      const int64_t i = v * W + u;
      if (!queued_masks.empty()) {
        const HostShadowPush push{queued_rays.data(), i, n};
        LocalLightTerms terms;
        radiance[i] = ShadeQueuedStored<true>(f, u, static_cast<int>(v), geometry[i], surfaces[i],
                                              terms, push, &queued_masks[i]);
      } else if (stored_surface && strided_terms) {
        StridedLightTerms terms;
        terms.at = row_terms.data() + u;
        terms.stride = W;
        terms.lights = term_lights;
        radiance[i] =
            ShadeRealtimeStored(f, u, static_cast<int>(v), geometry[i], surfaces[i], terms);
      } else {
        radiance[i] = stored_surface
                          ? ShadeRealtimeStored(f, u, static_cast<int>(v), geometry[i], surfaces[i])
                          : ShadeRealtimePixel(f, u, static_cast<int>(v));
      }
    }
  });
  if (!queued_masks.empty()) {
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int64_t i = v * W; i < (v + 1) * W; ++i)
        for (uint32_t b = queued_masks[i].traced; b != 0; b &= b - 1) {
          const QueuedShadowRay& e = queued_rays[LowestSetBit(b) * n + i];
          if (TraceOccluded(f.scene, QueuedRay(e)))
            queued_occluded[i] |= 1u << (e.key % kMaxQueuedShadowLights);
        }
    });
    ParallelForOrSerial(pool, H, [&](int64_t v) {
      for (int64_t i = v * W; i < (v + 1) * W; ++i)
        radiance[i] = SumQueuedLights(f, i, n, radiance[i], queued_masks[i], queued_occluded[i]);
    });
  }
  if (tiled_visibility) {
    TiledSharedVisibility(f, pool, radiance.data());
  } else {
    ForEachPixel(pool, W, H, [&](int u, int v) { SharedVisibilityRays(f, u, v); });
    ForEachPixel(pool, W, H, [&](int u, int v) { SharedVisibilityFraction(f, u, v); });
    ForEachPixel(pool, W, H, [&](int u, int v) {
      Float3& L = radiance[int64_t{v} * W + u];
      L = SharedVisibilityResolve(f, u, v, L);
    });
  }
  if (f.any_mirror != 0) {
    ForEachPixel(pool, W, H, [&](int u, int v) { ShadeMirrorHit(f, u, v); });
    ForEachPixel(pool, W, H, [&](int u, int v) {
      Float3& L = radiance[int64_t{v} * W + u];
      L = ApplyMirrorLayer(f, u, v, L);
    });
  }
  // the media (and the streaks seen through them) over the final radiance, per 2x2 quad, as
  // MediaViewKernel
  if (f.has_media != 0) {
    ParallelForOrSerial(pool, (H + 1) / 2, [&](int64_t q) {
      for (int u0 = 0; u0 < W; u0 += 2)
        MediaViewQuad(f, u0, 2 * static_cast<int>(q), out->depth_m.data.data(), radiance.data());
    });
  }
  // the particle streaks over the final radiance, as StreakSplatApplyKernel (with media:
  // MediaViewQuad)
  for (int64_t i = 0; f.has_media == 0 && f.splat.streaks.num > 0 && i < n; ++i) {
    StreakPixel s;
    if (PixelStreakOf(f, i, &s)) radiance[i] = ApplyStreak(s, out->depth_m.data[i], radiance[i]);
  }
  std::vector<double> rows(H);
  ParallelForOrSerial(pool, H, [&](int64_t v) {
    rows[v] = RowLogLuminance(radiance.data(), W, static_cast<int>(v), kMinLuminance);
  });
  float exposure[3];
  out->ev100 = data.Ev100(rows, n, exposure);
  if (out->radiance.width != W || out->radiance.height != H || out->radiance.channels != 3)
    out->radiance = ImageF(W, H, 3);
  if (out->rgb.width != W || out->rgb.height != H || out->rgb.channels != 3)
    out->rgb = ImageU8(W, H, 3);
  const bool filmic = data.film().filmic();
  const uint8_t* lut = data.film().oetf_lut().data();
  for (int64_t i = 0; i < n; ++i) {
    out->radiance.data[3 * i] = radiance[i].x;
    out->radiance.data[3 * i + 1] = radiance[i].y;
    out->radiance.data[3 * i + 2] = radiance[i].z;
    DevelopPixel(radiance[i], exposure, filmic, lut, &out->rgb.data[3 * i]);
  }
  out->rays = n;
  out->stopped = false;
}
}  // namespace penumbra::cuda

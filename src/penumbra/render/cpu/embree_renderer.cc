#include "penumbra/render/cpu/embree_renderer.h"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <string>
#include <thread>

#include "penumbra/core/error.h"
#include "penumbra/render/camera/camera_ground_truth.h"
#include "penumbra/render/cpu/path_tiles.h"
#include "penumbra/render/cpu/realtime_integrator.h"
#include "penumbra/render/geometry/ray_cone.h"

namespace penumbra {
namespace {

// the realtime tier's integrator (the pathtraced tier runs the transport's path chain:
// PathTiles).
std::unique_ptr<Integrator> MakeIntegrator(const RenderSettings& settings) {
  switch (settings.tier) {
    case RenderSettings::Tier::kRealtime:
      return std::make_unique<RealtimeIntegrator>();
    case RenderSettings::Tier::kPathtraced:
      return nullptr;
  }
  throw Error("unknown render tier");
}

template <typename T>
void Reshape(Image<T>* img, int w, int h, int c) {
  if (img->width != w || img->height != h || img->channels != c) *img = Image<T>(w, h, c);
}

}  // namespace

EmbreeRenderer::EmbreeRenderer(const SceneDescription& scene, const RenderSettings& settings)
    : scene_(scene),
      settings_((settings.ValidateOrThrow(), settings)),
      ray_scene_(std::make_unique<RayScene>(scene_)),
      materials_(scene_, settings_.max_anisotropy),
      lights_(scene_),
      sky_(scene_.sky, MjcfSkyboxOf(scene_)),
      effects_(scene_, RaySceneFactory()),
      sky_volume_(RaySceneFactory()),
      film_(settings_),
      pool_(settings_.threads),
      integrator_(MakeIntegrator(settings_)) {
  if (settings_.tier == RenderSettings::Tier::kPathtraced) {
    path_ = std::make_unique<PathTiles>(scene_, settings_, &pool_);
    if (settings_.denoise) denoiser_ = std::make_unique<Denoiser>();
  }
}

void EmbreeRenderer::Render(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                            const CameraView& view, RenderedFrame* out) {
  CheckRenderInputs(scene_.bodies.size(), snapshot, view);
  ray_scene_->Update(snapshot);
  if (materials_.has_normal_maps()) {
    // normal maps find their tangent frames in the geom frame: every geom's rotation now
    std::vector<Eigen::Matrix3f> R_WG(scene_.geoms.size());
    for (size_t g = 0; g < scene_.geoms.size(); ++g) {
      const Geom& geom = scene_.geoms[g];
      R_WG[g] = (snapshot.X_WB[geom.body].linear() * geom.X_BG.linear()).cast<float>();
    }
    materials_.SetGeomRotations(std::move(R_WG));
  }
  const Camera camera(view.X_WO, view.intrinsics, view.motion);
  const CameraOutputs& want = view.outputs;
  // the pathtraced tier: the path chain's frame data (its own lights, sky, media and streaks)
  const bool paths = path_ != nullptr && want[ImageKind::kRgb];
  if (paths) path_->Prepare(snapshot, effects, view, &pool_);
  if (!path_) {
    lights_.Update(snapshot, effects);
    // adverse conditions (media, particles, sky and light changes): render/cpu/media_frame.h.
    effects_.Prepare(snapshot, effects, camera, view, settings_, lights_, *ray_scene_, sky_,
                     &sky_volume_, &pool_);
  }
  // realtime tier: sky light occluded by the static geometry, rebuilt only when the static
  // bodies move and relit when the sky changes (render/sky/sky_irradiance_volume.h).
  if (settings_.tier == RenderSettings::Tier::kRealtime)
    sky_volume_.Update(scene_, snapshot, *effects_.sky(), &pool_);
  // realtime tier: the sun shadow rays the static boxes block are not traced (same image;
  // render/sky/sun_occluder_map.h), rebuilt when the static bodies move or the sun turns.
  const bool use_sun_occluders =
      settings_.tier == RenderSettings::Tier::kRealtime && ablation_.sun_occluder;
  if (use_sun_occluders) sun_occluders_.Update(scene_, snapshot, lights_, &pool_);
  const int W = camera.width(), H = camera.height();

  if (want[ImageKind::kRgb]) {
    Reshape(&out->radiance, W, H, 3);
  } else {
    out->radiance = ImageF();
    out->rgb = ImageU8();
  }
  ImageF* depth = nullptr;
  if (want[ImageKind::kDepth]) {
    Reshape(&out->depth_m, W, H, 1);
    depth = &out->depth_m;
  } else {
    out->depth_m = ImageF();
  }
  if (want[ImageKind::kSegmentation]) {
    Reshape(&out->geom_id, W, H, 1);
  } else {
    out->geom_id = ImageI32();
  }
  const GroundTruthImages truth = PrepareGroundTruth(want, W, H, out);
  FrameBuffers buffers;
  if (want[ImageKind::kRgb]) buffers.radiance = &out->radiance;

  FrameContext ctx;
  ctx.scene = ray_scene_.get();
  ctx.materials = &materials_;
  ctx.lights = &lights_;
  if (!path_) {
    ctx.sky = effects_.sky();
    if (!sky_volume_.empty() && ablation_.sky_volume) ctx.sky_volume = &sky_volume_;
    ctx.effects = effects_.active() ? &effects_ : nullptr;
  }
  if (use_sun_occluders && !sun_occluders_.empty()) ctx.sun_occluders = &sun_occluders_;
  ctx.camera = &camera;
  ctx.settings = &settings_;
  ctx.ablation = &ablation_;
  ctx.camera_index = view.camera_index;
  ctx.frame_index = view.frame_index;
  std::atomic<bool> stopped{false};
  ctx.stop_request = stop_request_;
  ctx.stopped = &stopped;
  out->stopped = false;

  const int tiles_x = (W + kTileSize - 1) / kTileSize;
  const int tiles_y = (H + kTileSize - 1) / kTileSize;
  std::atomic<int64_t> secondary_rays{0};
  // progress of the pathtraced tier: samples of finished tiles, reported on this thread only
  const bool report = progress_ && buffers.radiance != nullptr &&
                      settings_.tier == RenderSettings::Tier::kPathtraced;
  const int spp = std::max(1, settings_.samples_per_pixel);
  const int64_t pixels = static_cast<int64_t>(W) * H;
  RenderProgress progress;
  progress.camera_index = view.camera_index;
  progress.frame_index = view.frame_index;
  progress.samples_total = pixels * spp;
  progress.passes = spp;
  std::atomic<int64_t> samples_done{0};
  const std::thread::id caller = std::this_thread::get_id();
  if (report) progress_(progress);
  const float near = static_cast<float>(view.near_m);
  ImageI32* seg = want[ImageKind::kSegmentation] ? &out->geom_id : nullptr;
  pool_.ParallelFor(static_cast<int64_t>(tiles_x) * tiles_y, [&](int64_t k) {
    // per-thread buffers of one tile, allocated once (no per-tile initialisation).
    constexpr int kMax = kTileSize * kTileSize;
    thread_local std::unique_ptr<Ray[]> rays(new Ray[kMax]);
    thread_local std::unique_ptr<SurfaceHit[]> hits(new SurfaceHit[kMax]);
    thread_local std::unique_ptr<bool[]> did_hit(new bool[kMax]);
    PrimaryHits primary;
    primary.tile.x0 = static_cast<int>(k % tiles_x) * kTileSize;
    primary.tile.y0 = static_cast<int>(k / tiles_x) * kTileSize;
    primary.tile.width = std::min(kTileSize, W - primary.tile.x0);
    primary.tile.height = std::min(kTileSize, H - primary.tile.y0);
    const PixelTile& t = primary.tile;
    for (int y = 0, i = 0; y < t.height; ++y)
      for (int x = 0; x < t.width; ++x, ++i) {
        rays[i] = camera.GenerateRay(static_cast<float>(t.x0 + x), static_cast<float>(t.y0 + y));
        rays[i].tmin = near;  // t is z-depth (optical-frame d.z = 1)
      }
    // a pinhole camera's tile: its rays lie in the cone of its corner rays (RayScene then
    // needs no pass over the rays to bound them).
    const int n = t.width * t.height;
    RayCone cone;
    if (camera.projective())
      cone = RayCone::FromCorners(
          rays[0].o, {rays[0].d, rays[t.width - 1].d, rays[n - 1].d, rays[n - t.width].d}, near);
    ray_scene_->IntersectGrid(rays.get(), t.width, t.height, hits.get(), did_hit.get(),
                              camera.projective() ? &cone : nullptr);
    for (int y = 0, i = 0; y < t.height; ++y) {
      const int v = t.y0 + y;
      float* depth_row = depth ? depth->at(t.x0, v) : nullptr;
      int32_t* seg_row = seg ? seg->at(t.x0, v) : nullptr;
      for (int x = 0; x < t.width; ++x, ++i) {
        if (depth_row) depth_row[x] = did_hit[i] ? hits[i].t : 0.0f;
        if (seg_row)
          seg_row[x] = did_hit[i] && hits[i].geom >= 0 ? scene_.geoms[hits[i].geom].id : -1;
        if (truth.any)
          WriteGroundTruth(truth, camera, scene_, rays[i], did_hit[i], hits[i], t.x0 + x, v);
      }
    }
    if (buffers.radiance && paths) {
      secondary_rays.fetch_add(path_->TraceTile(*ray_scene_, t, stop_request_, &stopped),
                               std::memory_order_relaxed);
    } else if (buffers.radiance) {
      // normal maps bend the shading normals the integrators see (after the ground truth,
      // whose normals stay the surfaces'); the materials over the pixels' ray cones where the
      // integrator takes them from here.
      thread_local std::unique_ptr<SurfaceMaterial[]> mats(new SurfaceMaterial[kMax]);
      const bool want_materials = integrator_->wants_primary_materials();
      if (want_materials || materials_.has_normal_maps()) {
        for (int i = 0; i < n; ++i) {
          if (!did_hit[i]) continue;
          const float d_len = rays[i].d.norm();
          const TextureFootprint footprint =
              ablation_.texture_filter ? ConeFootprint(camera.pixel_spread_rad(), hits[i].t * d_len,
                                                       rays[i].d / d_len, hits[i])
                                       : TextureFootprint{};
          if (want_materials)
            mats[i] = materials_.EvaluateAndMapNormal(&hits[i], footprint);
          else
            materials_.ApplyNormalMap(&hits[i], footprint);
        }
      }
      primary.materials = want_materials ? mats.get() : nullptr;
      primary.rays = rays.get();
      primary.hits = hits.get();
      primary.did_hit = did_hit.get();
      secondary_rays.fetch_add(integrator_->RenderTile(ctx, primary, buffers),
                               std::memory_order_relaxed);
    }
    if (report) {
      const int64_t tile_samples = static_cast<int64_t>(n) * spp;
      const int64_t done = samples_done.fetch_add(tile_samples) + tile_samples;
      const int passes_done = static_cast<int>(std::min<int64_t>(done / pixels, spp));
      // one report per pass crossed since the last (a tile may hold more than one pass)
      if (std::this_thread::get_id() == caller && !stopped.load(std::memory_order_relaxed)) {
        progress.samples_done = done;
        while (progress.passes_done < passes_done) {
          ++progress.passes_done;
          progress_(progress);
        }
      }
    }
  });
  // the passes the other threads finished after this one ran out of tiles
  if (report && !stopped.load()) {
    progress.samples_done = progress.samples_total;
    while (progress.passes_done < spp) {
      ++progress.passes_done;
      progress_(progress);
    }
  }
  out->rays = static_cast<int64_t>(W) * H + secondary_rays.load();
  // a stopped render's radiance is unfinished: not denoised, not developed
  out->stopped = stopped.load();
  if (out->stopped) return;

  if (paths) {
    // the chain's radiance, denoised with its guides and developed (FinishPathFrame)
    path_->Finish(denoiser_.get(), view.white_balance_gains, ablation_.film, &pool_, out);
    if (!ablation_.film) out->rgb = ImageU8();
  } else if (want[ImageKind::kRgb] && ablation_.film) {
    out->ev100 = film_.Ev100(out->radiance, &pool_);
    film_.Develop(out->radiance, out->ev100, &pool_, &out->rgb, view.white_balance_gains);
  } else {
    out->rgb = ImageU8();  // not developed (the film ablation): no rgb left from an earlier frame
  }
}

std::unique_ptr<Renderer> MakeEmbreeRenderer(const SceneDescription& scene,
                                             const RenderSettings& settings) {
  return std::make_unique<EmbreeRenderer>(scene, settings);
}

}  // namespace penumbra

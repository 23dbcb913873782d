#pragma once
// the realtime tier's light-transport interface on the CPU (the pathtraced tier runs the
// transport's path chain instead: render/cpu/path_tiles.h). the renderer
// (render/cpu/embree_renderer) splits a frame into tiles, traces the pixel-centre camera ray
// of every pixel of a tile once (those hits give the exact depth and segmentation
// images), and hands them to an Integrator, which estimates the radiance of every pixel
// of the tile. tiles never overlap, so integrators write their pixels without locks.
//
// determinism: an integrator draws random numbers only from Rng(ctx.PixelStream(u, v, s)),
// so images do not depend on the thread count or tile order.

#include <atomic>
#include <cstdint>

#include "penumbra/core/image.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/cpu/media_frame.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/material/material_eval.h"
#include "penumbra/render/render_ablation.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/render/sky/sky_irradiance_volume.h"
#include "penumbra/render/sky/sky_model.h"
#include "penumbra/render/sky/sun_occluder_map.h"

namespace penumbra {

/// a rectangle of pixels: columns [x0, x0 + width), rows [y0, y0 + height).
struct PixelTile {
  int x0 = 0, y0 = 0, width = 0, height = 0;
};

/// what an integrator reads during one frame; all of it is immutable for the frame.
struct FrameContext {
  const RayScene* scene = nullptr;  ///< posed for this frame
  const MaterialEvaluator* materials = nullptr;
  const LightSampler* lights = nullptr;  ///< posed for this frame
  const SkyModel* sky = nullptr;
  /// the realtime tier's sky light occluded by the static geometry, lit by `sky`
  /// (render/sky/sky_irradiance_volume.h), or null: then the sky irradiance is unoccluded.
  const SkyIrradianceVolume* sky_volume = nullptr;
  /// the realtime tier's sun shadow rays that the static boxes provably block
  /// (render/sky/sun_occluder_map.h), or null: then every shadow ray is traced.
  const SunOccluderMap* sun_occluders = nullptr;
  const Camera* camera = nullptr;
  const RenderSettings* settings = nullptr;
  /// parts switched off by a bench (render/render_ablation.h), or null: all on.
  const RenderAblation* ablation = nullptr;
  int camera_index = 0;     ///< CameraView::camera_index
  int64_t frame_index = 0;  ///< CameraView::frame_index
  /// adverse conditions of this frame (media, particles, wetness; render/cpu/media_frame.h), or
  /// null in clear conditions (then both tiers render exactly as without effects). `sky`
  /// already is the effects' sky and `lights` carry the effects' light changes.
  const MediaFrame* effects = nullptr;
  /// the renderer's stop request (Renderer::set_stop_request), or null: an integrator that
  /// takes long per pixel reads it before every sample and, once it reads non-zero, leaves the
  /// tile unfinished and sets *stopped.
  const std::atomic<int>* stop_request = nullptr;
  std::atomic<bool>* stopped = nullptr;

  /// stream id of pixel (u, v), sample s: HashKeys(HashKeys(seed, camera), frame, pixel, s)
  /// with pixel = v * width + u.
  uint64_t PixelStream(int u, int v, int s) const {
    const uint64_t pixel = static_cast<uint64_t>(v) * static_cast<uint64_t>(camera->width()) +
                           static_cast<uint64_t>(u);
    return PixelStream(FrameKey(), pixel, s);
  }
  /// the per-frame part of PixelStream, to hoist out of pixel loops:
  /// PixelStream(u, v, s) == PixelStream(FrameKey(), v * width + u, s).
  uint64_t FrameKey() const {
    return HashKeys(HashKeys(settings->seed, static_cast<uint64_t>(camera_index)),
                    static_cast<uint64_t>(frame_index));
  }
  static uint64_t PixelStream(uint64_t frame_key, uint64_t pixel, int s) {
    return HashKeys(HashKeys(frame_key, pixel), static_cast<uint64_t>(s));
  }
};

/// the pixel-centre camera rays of one tile and what they hit, row-major over the tile
/// (index (v - y0) * width + (u - x0)). traced once by the renderer for every tier.
struct PrimaryHits {
  PixelTile tile;
  const Ray* rays = nullptr;         ///< camera ray through the pixel centre (t = z-depth)
  const SurfaceHit* hits = nullptr;  ///< valid where did_hit
  const bool* did_hit = nullptr;
  /// the material of every hit pixel (MaterialEvaluator::EvaluateAndMapNormal over the pixel's
  /// ray cone; `hits` then carry the normal-mapped shading normals), or null when the renderer
  /// did not evaluate them (Integrator::wants_primary_materials).
  const SurfaceMaterial* materials = nullptr;
};

/// full-frame images an integrator writes its tile into.
struct FrameBuffers {
  ImageF* radiance = nullptr;  ///< (H x W x 3) linear radiance, cd/m^2 per channel; required
  /// (H x W x 3) denoiser guides, or null when not wanted: albedo = base colour of the first
  /// visible surface (0 for sky), normal = its unit shading normal in the world frame (0 for sky).
  ImageF* albedo = nullptr;
  ImageF* normal = nullptr;
};

/// estimates pixel radiance for one render tier.
class Integrator {
 public:
  virtual ~Integrator() = default;

  /// renders the pixels of primary.tile into `out`; returns the number of rays it traced
  /// (the primary rays are counted by the renderer). called concurrently for different tiles.
  virtual int64_t RenderTile(const FrameContext& ctx, const PrimaryHits& primary,
                             const FrameBuffers& out) const = 0;

  /// whether the renderer should evaluate the primary hits' materials (PrimaryHits::materials);
  /// else it only applies normal maps to them.
  virtual bool wants_primary_materials() const { return false; }
};

}  // namespace penumbra

#pragma once
// the Embree ray tracer: the Renderer of RenderSettings::Backend::kEmbree (MakeRenderer,
// render/backends/renderer_factory.h).
//
// per frame: pose the RayScene and the lights from the snapshot (the top-level BVH is
// recommitted only when a body moved), split the image into kTileSize x kTileSize tiles spread
// over a thread pool, trace the pixel-centre camera ray of every pixel of a tile as one
// coherent Embree ray stream (these hits are the depth and segmentation images: exact, never
// blended), then let the tier estimate the tile's radiance: the realtime tier's Integrator, or
// the pathtraced tier's path chain (PathTiles: render/transport/path_trace.h over Embree, then
// denoised and developed by FinishPathFrame). radiance is exposed, tone mapped and encoded by
// Film. every output is independent of the thread count.

#include <memory>
#include <string>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/cpu/integrator.h"
#include "penumbra/render/cpu/path_tiles.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/film/denoiser.h"
#include "penumbra/render/film/film.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/material/material_eval.h"
#include "penumbra/render/render_ablation.h"
#include "penumbra/render/renderer.h"
#include "penumbra/render/sky/sky_irradiance_volume.h"
#include "penumbra/render/sky/sky_model.h"
#include "penumbra/render/sky/sun_occluder_map.h"

namespace penumbra {

/// the Renderer of both tiers on Embree. one Render at a time (parallel inside).
class EmbreeRenderer final : public Renderer {
 public:
  /// side of the square pixel tiles that threads work on.
  static constexpr int kTileSize = 16;
  // the realtime tier's shared visibility keeps a tile row's pixels in one 32-bit word with two
  // bits to spare on either side (realtime_integrator.cc).
  static_assert(kTileSize <= 28, "tile rows must fit the shared visibility's row words");

  /// copies `scene` and builds its ray scene.
  /// @throws ConfigError for bad settings or sky; Error if Embree fails or the scene refers
  /// to missing meshes, height fields, materials or textures.
  EmbreeRenderer(const SceneDescription& scene, const RenderSettings& settings);

  /// @throws Error if the snapshot does not match the scene (body counts) or a light /
  /// MJCF light id is out of range; ConfigError for bad intrinsics.
  void Render(const WorldSnapshot& snapshot, const EffectsFrame* effects, const CameraView& view,
              RenderedFrame* out) override;
  using Renderer::Render;

  const RayScene& ray_scene() const { return *ray_scene_; }
  const RenderSettings& settings() const { return settings_; }

  /// parts switched off for `penumbra bench render --ablate` (render/render_ablation.h);
  /// from the next Render on.
  void set_ablation(const RenderAblation& ablation) { ablation_ = ablation; }
  const RenderAblation& ablation() const { return ablation_; }

 private:
  const SceneDescription scene_;  // owned copy; everything below refers to it
  const RenderSettings settings_;
  RenderAblation ablation_;  // all parts on unless a bench switches some off
  std::unique_ptr<RayScene> ray_scene_;
  MaterialEvaluator materials_;
  LightSampler lights_;
  SkyModel sky_;
  MediaFrame effects_;              // per-frame effects state (render/cpu/media_frame.h)
  SkyIrradianceVolume sky_volume_;  // realtime tier: occluded sky light, built at the first frame
  SunOccluderMap sun_occluders_;    // realtime tier: sun shadow rays the static boxes block
  Film film_;
  ThreadPool pool_;
  std::unique_ptr<Integrator> integrator_;  // the realtime tier's
  std::unique_ptr<PathTiles> path_;         // the pathtraced tier's
  std::unique_ptr<Denoiser> denoiser_;      // pathtraced with denoise only
};

/// the EmbreeRenderer of `scene` (copied) with `settings`.
/// @throws as the EmbreeRenderer constructor.
std::unique_ptr<Renderer> MakeEmbreeRenderer(const SceneDescription& scene,
                                             const RenderSettings& settings);

}  // namespace penumbra

#pragma once
// the one place that knows the rendering backends: builds the Renderer and the RayQuery of the
// backend RenderSettings::backend names. a new backend adds its enum value
// (render/render_settings.h), a sub-folder next to render/embree/ with its Renderer and
// RayQuery, and a case in each function below; the sensors (LiDAR) and the sky irradiance
// volume only see RayQuery (render/ray_query.h), the rest of the pipeline only Renderer.

#include <memory>
#include <string>

#include "penumbra/render/ray_query.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// whether a CUDA device can be used: cudaGetDeviceCount succeeded with >= 1 device (any error,
/// e.g. "CUDA driver version is insufficient for CUDA runtime version" on a machine without a
/// GPU, means none). probed once per process.
struct CudaDeviceStatus {
  bool available = false;
  std::string name;  ///< the first device's name, when available
  std::string why;   ///< why none is usable, when not available
};
CudaDeviceStatus ProbeCudaDevice();

/// `backend` with kAuto resolved: kCuda when ProbeCudaDevice finds a device, else kEmbree (the
/// first resolution that finds a device says so in one log line, once per process).
RenderSettings::Backend ResolveBackend(RenderSettings::Backend backend);

/// the Renderer of settings.backend over `scene` (copied) with `settings`.
/// backend cuda: the CUDA backend (render/cuda/cuda_renderer.h), which renders every frame on
/// the GPU.
/// @throws ConfigError for bad settings (settings.ValidateOrThrow), or backend cuda without a
/// usable CUDA device; Error if the backend
/// cannot be initialised or the scene refers to missing meshes, height fields, materials or
/// textures.
std::unique_ptr<Renderer> MakeRenderer(const SceneDescription& scene,
                                       const RenderSettings& settings);

/// the RayQuery of `backend` over `scene`, which is referenced, not copied: it must outlive the
/// query (e.g. the LiDAR's scene, posed by the caller with RayQuery::Update).
/// @throws ConfigError for an unknown backend; Error as the backend's constructor.
std::unique_ptr<RayQuery> MakeRayQuery(const SceneDescription& scene,
                                       RenderSettings::Backend backend);

/// the ray queries over a scene's static geoms that a realtime renderer traces its static maps
/// through before its first frame (the sky irradiance volume, render/sky/sky_irradiance_volume.h;
/// the shelter map, render/particles/shelter_map.h): Embree's (RayScene,
/// render/embree/ray_scene.h), as the CPU backend builds them, for every backend, so a CUDA frame's
/// maps are the CPU's bits and take Embree's time (docs/journal/2026-11-26-gpu-speed.md, "The
/// static maps through Embree"). MakeRenderer gives it to the CUDA renderer; a cuda::BatchRenderer
/// whose cameras must equal MakeRenderer's takes it in BatchConfig::statics_query.
RayQueryFactory StaticMapsQueryFactory();

/// the version of `backend`'s ray-tracing library, for run manifests (Embree: its
/// RTC_VERSION_STRING, e.g. "3.13.5").
/// @throws ConfigError for an unknown backend.
std::string RendererVersion(RenderSettings::Backend backend);

}  // namespace penumbra

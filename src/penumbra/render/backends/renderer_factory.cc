#include "penumbra/render/backends/renderer_factory.h"

#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/cpu/embree_renderer.h"
#include "penumbra/render/embree/embree_version.h"
#include "penumbra/render/embree/ray_scene.h"

namespace penumbra {
namespace {

[[noreturn]] void ThrowUnknownBackend(RenderSettings::Backend backend) {
  throw ConfigError(
      "", 0, "render.backend",
      "unknown backend " + std::to_string(static_cast<int>(backend)) + "; expected one of: embree");
}

}  // namespace

std::unique_ptr<Renderer> MakeRenderer(const SceneDescription& scene,
                                       const RenderSettings& settings) {
  settings.ValidateOrThrow();
  switch (settings.backend) {
    case RenderSettings::Backend::kEmbree:
      return MakeEmbreeRenderer(scene, settings);
  }
  ThrowUnknownBackend(settings.backend);
}

std::unique_ptr<RayQuery> MakeRayQuery(const SceneDescription& scene,
                                       RenderSettings::Backend backend) {
  switch (backend) {
    case RenderSettings::Backend::kEmbree:
      return std::make_unique<RayScene>(scene);
  }
  ThrowUnknownBackend(backend);
}

std::string RendererVersion(RenderSettings::Backend backend) {
  switch (backend) {
    case RenderSettings::Backend::kEmbree:
      return EmbreeVersion();
  }
  ThrowUnknownBackend(backend);
}

}  // namespace penumbra

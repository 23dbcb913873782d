#include "penumbra/render/backends/renderer_factory.h"

#include <spdlog/spdlog.h>

#include <mutex>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/cpu/embree_renderer.h"
#include "penumbra/render/embree/embree_version.h"
#include "penumbra/render/embree/ray_scene.h"
#if PENUMBRA_WITH_CUDA
#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/cuda/cuda_ray_query.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#endif

namespace penumbra {
namespace {

[[noreturn]] void ThrowUnknownBackend(RenderSettings::Backend backend) {
  throw ConfigError("", 0, "render.backend",
                    "unknown backend " + std::to_string(static_cast<int>(backend)) +
                        "; expected one of: cpu, cuda, auto");
}

}  // namespace

CudaDeviceStatus ProbeCudaDevice() {
  // probed once per process: the answer does not change while it runs
  static const CudaDeviceStatus status = [] {
    CudaDeviceStatus s;
#if PENUMBRA_WITH_CUDA
    s.available = cuda::ProbeDevice(&s.name, &s.why);
#else
    s.why = "this penumbra was built without CUDA (PENUMBRA_CUDA=OFF or no nvcc)";
#endif
    return s;
  }();
  return status;
}

RenderSettings::Backend ResolveBackend(RenderSettings::Backend backend) {
  if (backend != RenderSettings::Backend::kAuto) return backend;
  const CudaDeviceStatus s = ProbeCudaDevice();
  static std::once_flag told;
  std::call_once(told, [&] {
    if (s.available)
      spdlog::info(
          "renderer: render.backend auto: CUDA device '{}' found, rendering on the GPU "
          "(cuda backend; --backend cpu for the CPU)",
          s.name);
    else  // the CPU, as always without a GPU: only at debug level
      spdlog::debug("renderer: render.backend auto: no CUDA device ({}), rendering on the CPU",
                    s.why);
  });
  return s.available ? RenderSettings::Backend::kCuda : RenderSettings::Backend::kEmbree;
}

namespace {

// the CUDA backend asked for by name: its device must be there
void RequireCuda() {
  const CudaDeviceStatus s = ProbeCudaDevice();
  if (!s.available)
    throw ConfigError("", 0, "render.backend",
                      "cuda needs a CUDA device, and none is usable: " + s.why +
                          "; expected render.backend cpu or auto (docs/gpu.md)");
}

}  // namespace

std::unique_ptr<Renderer> MakeRenderer(const SceneDescription& scene,
                                       const RenderSettings& settings) {
  settings.ValidateOrThrow();
  switch (ResolveBackend(settings.backend)) {
    case RenderSettings::Backend::kEmbree:
      return MakeEmbreeRenderer(scene, settings);
    case RenderSettings::Backend::kCuda: {
      RequireCuda();
#if PENUMBRA_WITH_CUDA
      return std::make_unique<cuda::CudaRenderer>(scene, settings, StaticMapsQueryFactory());
#else
      break;
#endif
    }
    case RenderSettings::Backend::kAuto:
      break;
  }
  ThrowUnknownBackend(settings.backend);
}

RayQueryFactory StaticMapsQueryFactory() { return RaySceneFactory(); }

std::unique_ptr<RayQuery> MakeRayQuery(const SceneDescription& scene,
                                       RenderSettings::Backend backend) {
  switch (ResolveBackend(backend)) {
    case RenderSettings::Backend::kEmbree:
      return std::make_unique<RayScene>(scene);
    case RenderSettings::Backend::kCuda:
      RequireCuda();
#if PENUMBRA_WITH_CUDA
      return std::make_unique<cuda::CudaRayQuery>(scene);
#else
      break;
#endif
    case RenderSettings::Backend::kAuto:
      break;
  }
  ThrowUnknownBackend(backend);
}

std::string RendererVersion(RenderSettings::Backend backend) {
  switch (ResolveBackend(backend)) {
    case RenderSettings::Backend::kEmbree:
      return EmbreeVersion();
    case RenderSettings::Backend::kCuda:
      return "cuda (" + ProbeCudaDevice().name + "), embree " + EmbreeVersion();
    case RenderSettings::Backend::kAuto:
      break;
  }
  ThrowUnknownBackend(backend);
}

}  // namespace penumbra

#include "penumbra/app/backend_flag.h"

#include "penumbra/core/error.h"
#include "penumbra/render/backends/renderer_factory.h"

namespace penumbra {

void BackendFlag::Add(CLI::App* verb, const std::string& without) {
  verb->add_option("--backend", value_,
                   "render backend: cpu, cuda (an NVIDIA GPU) or auto (cuda when a CUDA device "
                   "is present); default: " +
                       without + " (docs/gpu.md)")
      ->check(CLI::IsMember({"cpu", "cuda", "auto"}));
}

std::optional<RenderSettings::Backend> BackendFlag::Resolve() const {
  if (value_.empty()) return std::nullopt;
  const RenderSettings::Backend b = value_ == "cuda"  ? RenderSettings::Backend::kCuda
                                    : value_ == "cpu" ? RenderSettings::Backend::kEmbree
                                                      : RenderSettings::Backend::kAuto;
  if (b == RenderSettings::Backend::kCuda) {
    const CudaDeviceStatus s = ProbeCudaDevice();
    if (!s.available)
      throw ConfigError("", 0, "--backend",
                        "cuda needs a CUDA device, and none is usable here (" + s.why +
                            "); expected --backend cpu or auto on this machine (docs/gpu.md)");
  }
  return b;
}

void BackendFlag::Apply(RenderSettings* render) const {
  if (const std::optional<RenderSettings::Backend> b = Resolve()) render->backend = *b;
}

}  // namespace penumbra

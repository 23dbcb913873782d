#include "penumbra/render/render_settings.h"

#include <charconv>
#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {

namespace {

std::string Num(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

// key paths are those of the world file's `render:` block.
void CheckClosed(const char* key, double v, double lo, double hi) {
  if (!std::isfinite(v) || v < lo || v > hi) {
    throw ConfigError("", 0, std::string("render.") + key,
                      "got " + Num(v) + "; expected [" + Num(lo) + ", " + Num(hi) + "]");
  }
}

}  // namespace

RenderSettings::Backend RenderSettings::BackendFromName(const std::string& name) {
  if (name == "cpu" || name == "embree") return Backend::kEmbree;
  if (name == "cuda") return Backend::kCuda;
  if (name == "auto") return Backend::kAuto;
  throw ConfigError("", 0, "render.backend",
                    "got '" + name + "'; expected one of: cpu, cuda, auto (embree = cpu)");
}

void RenderSettings::ValidateOrThrow() const {
  if (backend != Backend::kEmbree && backend != Backend::kCuda && backend != Backend::kAuto) {
    throw ConfigError("", 0, "render.backend",
                      "unknown backend; expected one of: cpu, cuda, auto (embree = cpu)");
  }
  if (tier != Tier::kRealtime && tier != Tier::kPathtraced) {
    throw ConfigError("", 0, "render.tier", "unknown tier; expected one of: realtime, pathtraced");
  }
  CheckClosed("samples_per_pixel", samples_per_pixel, 1, kMaxSamplesPerPixel);
  CheckClosed("max_bounces", max_bounces, 1, kMaxBounces);
  CheckClosed("threads", threads, 0, kMaxThreads);
  CheckClosed("max_anisotropy", max_anisotropy, 1, kMaxAnisotropy);
  CheckClosed("exposure.ev100", ev100, kMinEv100, kMaxEv100);
  CheckClosed("exposure.compensation_ev", exposure_compensation_ev, -kMaxCompensationEv,
              kMaxCompensationEv);
  if (tone_map != ToneMap::kFilmic && tone_map != ToneMap::kLinear) {
    throw ConfigError("", 0, "render.tone_map",
                      "unknown tone map; expected one of: filmic, linear");
  }
}

}  // namespace penumbra

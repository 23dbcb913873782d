#pragma once
// the version of the Embree library the ray-query wrappers (render/embree/) are built against,
// for run manifests (RendererVersion, render/backends/renderer_factory.h).

#include <string>

namespace penumbra {

/// the version of the Embree library built against (RTC_VERSION_STRING, e.g. "3.13.5").
std::string EmbreeVersion();

}  // namespace penumbra

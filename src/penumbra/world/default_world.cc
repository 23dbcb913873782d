#include "penumbra/world/default_world.h"

#include <filesystem>

#include "penumbra/core/build_info.h"

namespace penumbra {

std::string DefaultWorldPath() {
  const std::filesystem::path installed =
      std::filesystem::path(PENUMBRA_SOURCE_DIR) / "worlds" / "default.yaml";
  if (std::filesystem::exists(installed)) return installed.string();
  return "worlds/default.yaml";
}

}  // namespace penumbra

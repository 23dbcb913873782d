#pragma once
// where the tests find MuJoCo Menagerie's robots as mjlab 1.6.0 vendors them (Unitree Go1,
// Unitree G1, i2rt YAM: MJCF for MuJoCo 3 with meshes), installed into the project venv by
// scripts/install-deps.sh (scripts/requirements-models.txt). tests skip when it is absent.

#include <filesystem>
#include <string>

namespace penumbra::testing {

/// the venv's mjlab/asset_zoo/robots folder (any python3.x of the venv), or "" when mjlab is
/// not installed.
inline std::string MjlabRobotsDir() {
  const std::filesystem::path lib = std::filesystem::path(PENUMBRA_SOURCE_DIR) / ".venv/lib";
  std::error_code ec;
  for (const auto& e : std::filesystem::directory_iterator(lib, ec)) {
    const auto zoo = e.path() / "site-packages/mjlab/asset_zoo/robots";
    if (std::filesystem::is_directory(zoo)) return zoo.string();
  }
  return "";
}

}  // namespace penumbra::testing

// every bundled world file (worlds/**/*.yaml) loads, validates, composes, binds its effects
// and agents, and steps: the examples in the README and worlds/effects stay runnable.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "penumbra/bench/preset_scene.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

std::vector<std::string> BundledWorlds() {
  std::vector<std::string> out;
  const fs::path root = fs::path(PENUMBRA_SOURCE_DIR) / "worlds";
  for (const auto& e : fs::recursive_directory_iterator(root)) {
    if (!e.is_regular_file() || e.path().extension() != ".yaml") continue;
    if (e.path().parent_path().filename() == "adversity") continue;  // preset files
    out.push_back(e.path().string());
  }
  std::sort(out.begin(), out.end());
  return out;
}

TEST(BundledWorlds, EveryWorldLoadsBindsItsEffectsAndSteps) {
  const std::vector<std::string> worlds = BundledWorlds();
  int effect_worlds = 0;
  for (const std::string& file : worlds) {
    SCOPED_TRACE(file);
    const WorldConfig world = LoadWorldFile(file);
    if (file.find("/effects/") != std::string::npos) ++effect_worlds;
    PresetScene p = LoadPresetScene(world, "");
    if (file.find("/effects/") != std::string::npos) {
      EXPECT_GT(p.session->effects().effects().size() + p.session->effects().agents().size(), 0u);
    }
    for (int i = 0; i < 20; ++i) p.session->sim().Step();
    const WorldSnapshot snap = p.session->sim().Snapshot();
    const auto frame = p.session->effects().Evaluate(snap, Eigen::Vector3d(0, 0, 1));
    EXPECT_EQ(frame != nullptr, !p.session->effects().effects().empty());
  }
  EXPECT_GE(effect_worlds, 13);
}

}  // namespace
}  // namespace penumbra

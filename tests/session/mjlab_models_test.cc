// the Menagerie-derived robots that mjlab 1.6.0 vendors (docs/robots/menagerie.md) load
// unmodified as bare models, as `penumbra run FILE.xml` loads them, and simulate: Unitree Go1,
// Unitree G1 and i2rt YAM, each as mjlab ships it (no actuators: passive bodies). Skipped when
// mjlab is not installed in the project's .venv.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>

#include "common/mjlab_assets.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

const std::string kMjlabRobots = testing::MjlabRobotsDir();

struct Expected {
  const char* file;
  int joints;  // including the free joint of a floating base
  int bodies;  // including the world
};

TEST(MjlabModels, LoadUnmodifiedAsBareModelsAndSimulate) {
  int loaded = 0;
  for (const Expected& e :
       {Expected{"unitree_go1/xmls/go1.xml", 13, 14}, Expected{"unitree_g1/xmls/g1.xml", 30, 31},
        Expected{"i2rt_yam/xmls/yam.xml", 8, 16}}) {
    const std::string path = kMjlabRobots + "/" + e.file;
    if (!std::filesystem::exists(path)) continue;
    SCOPED_TRACE(path);
    SessionOptions options;
    options.build_renderer = false;
    Session session(WorldForBareModel(path), options);
    Simulation& sim = session.sim();
    EXPECT_EQ(sim.model_info().joints.size(), static_cast<size_t>(e.joints));
    EXPECT_EQ(sim.model_info().body_names.size(), static_cast<size_t>(e.bodies));
    EXPECT_TRUE(sim.model_info().actuators.empty());  // mjlab adds them in Python
    while (sim.time() < 0.5 - 1e-9) sim.Step();
    for (double q : sim.qpos()) EXPECT_TRUE(std::isfinite(q));
    ++loaded;
  }
  if (loaded == 0)
    GTEST_SKIP() << "mjlab 1.6.0 is not installed in " << kMjlabRobots
                 << " (scripts/install-deps.sh installs it)";
  EXPECT_EQ(loaded, 3);
}

}  // namespace
}  // namespace penumbra

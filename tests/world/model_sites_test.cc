// robots and models take `sites:` (name + body or geom + pose) and
// `initial_keyframe:`; bad entries name the world file's line.
#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

class ModelSitesTest : public ::testing::Test {
 protected:
  void SetUp() override { dir_.Write("dog.xml", "<mujoco/>\n"); }
  std::string Robot(const std::string& extra) const {
    return dir_.Write("world.yaml", "robots:\n  - name: dog\n    file: dog.xml\n" + extra);
  }
  penumbra::testing::TempDir dir_;
};

TEST_F(ModelSitesTest, SitesAndInitialKeyframeAreRead) {
  const WorldConfig w = LoadWorldFile(
      Robot("    initial_keyframe: stand\n"
            "    sites:\n"
            "      - {name: FR_tip, geom: FR_foot}\n"
            "      - {name: tcp, body: hand, pose: {xyz: [0, 0, 0.1], rpy_deg: [0, 90, 0]}}\n"));
  ASSERT_EQ(w.models.size(), 1u);
  const ModelConfig& m = w.models[0];
  EXPECT_EQ(m.key, "robots[0]");
  EXPECT_EQ(m.initial_keyframe, "stand");
  ASSERT_EQ(m.sites.size(), 2u);
  EXPECT_EQ(m.sites[0].name, "FR_tip");
  EXPECT_EQ(m.sites[0].geom, "FR_foot");
  EXPECT_TRUE(m.sites[0].body.empty());
  EXPECT_EQ(m.sites[1].body, "hand");
  EXPECT_EQ(m.sites[1].pose.xyz, Eigen::Vector3d(0, 0, 0.1));
  EXPECT_EQ(m.sites[1].pose.rpy_deg, Eigen::Vector3d(0, 90, 0));
}

TEST_F(ModelSitesTest, BadEntriesNameTheLine) {
  const auto error = [&](const std::string& extra) {
    try {
      LoadWorldFile(Robot(extra));
    } catch (const ConfigError& e) {
      return std::to_string(e.line()) + " " + e.key() + ": " + e.problem();
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("    sites:\n      - {name: a}\n")
                .rfind("5 robots[0].sites[0]: expected exactly "
                       "one of body",
                       0),
            0u)
      << error("    sites:\n      - {name: a}\n");
  EXPECT_EQ(error("    sites:\n      - {name: a, body: b, geom: g}\n").substr(0, 22),
            "5 robots[0].sites[0]: ");
  EXPECT_EQ(error("    sites:\n      - {name: a/b, body: b}\n").substr(0, 27),
            "5 robots[0].sites[0].name: ");
  EXPECT_NE(error("    sites:\n      - {name: a, body: b}\n      - {name: a, body: c}\n")
                .find("6 robots[0].sites[1].name: duplicate site 'a'"),
            std::string::npos);
  EXPECT_EQ(error("    initial_keyframe: ''\n").substr(0, 36),
            "4 robots[0].initial_keyframe: empty;");
}

}  // namespace
}  // namespace penumbra

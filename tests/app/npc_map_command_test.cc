// `penumbra npc-map --out FILE` never overwrites: an existing file or symbolic link at --out is
// refused (before the world is loaded) unless --force, which replaces it (a link replaced, its
// target untouched). npc-map replaced an existing --out without being asked.

#include "penumbra/app/npc_map_command.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

class NpcMapCommandTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_.Write("m.xml", R"(<mujoco><worldbody>
  <geom name="floor" type="plane" size="3 3 0.1"/>
  <body name="base" pos="0 0 0.2"><freejoint/><geom type="box" size="0.2 0.2 0.1"/></body>
  </worldbody></mujoco>)");
    options_.world_file = tmp_.Write("w.yaml",
                                     "robots:\n"
                                     "  - name: r\n"
                                     "    file: m.xml\n"
                                     "mjcf_cameras: {enabled: false}\n");
  }

  // the problem of the ConfigError WriteNpcMap throws (key --out), or "" when it writes
  std::string OutRefusal() {
    try {
      WriteNpcMap(options_);
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), "--out");
      return e.problem();
    }
    return "";
  }

  testing::TempDir tmp_;
  NpcMapOptions options_;
};

TEST_F(NpcMapCommandTest, AnExistingOutIsRefusedUnlessForceAndALinkIsNeverFollowed) {
  const std::string kept = tmp_.Write("map.png", "mine");
  options_.out = kept;
  EXPECT_EQ(OutRefusal(), "'" + kept +
                              "' exists; expected a new file (never overwritten; --force "
                              "replaces it)");
  EXPECT_EQ(testing::ReadAll(kept), "mine");

  // a link at --out, to a file of the user's: refused, the target untouched
  const std::string target = tmp_.Write("precious.txt", "keep me");
  const fs::path link = tmp_.path() / "link.png";
  fs::create_symlink(target, link);
  options_.out = link.string();
  EXPECT_NE(OutRefusal().find("exists; expected a new file"), std::string::npos);
  EXPECT_TRUE(fs::is_symlink(link));
  EXPECT_EQ(testing::ReadAll(target), "keep me");

  // --force replaces both: the link by a file, never writing through it
  options_.force = true;
  EXPECT_EQ(OutRefusal(), "");
  EXPECT_FALSE(fs::is_symlink(link));
  EXPECT_EQ(testing::ReadAll(link).substr(0, 4), "\x89PNG");
  EXPECT_EQ(testing::ReadAll(target), "keep me");
  options_.out = kept;
  EXPECT_EQ(OutRefusal(), "");
  EXPECT_EQ(testing::ReadAll(kept).substr(0, 4), "\x89PNG");

  // a new --out is written without --force, and nothing else is left beside it
  options_.force = false;
  options_.out = (tmp_.path() / "new.png").string();
  EXPECT_EQ(OutRefusal(), "");
  EXPECT_EQ(testing::ReadAll(options_.out).substr(0, 4), "\x89PNG");
  int entries = 0;
  for (const auto& e : fs::directory_iterator(tmp_.path())) entries += e.path().empty() ? 0 : 1;
  EXPECT_EQ(entries, 6);  // m.xml w.yaml map.png precious.txt link.png new.png
}

}  // namespace
}  // namespace penumbra

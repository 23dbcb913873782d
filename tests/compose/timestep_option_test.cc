// issue 15 point 2: the composer holds the MJCF <option timestep> that decides the composed
// world's step to the range of physics.timestep_sec (scene/scene_limits.h) and names the
// model file and line; a world-file timestep wins and is then the only one checked.

#include <gtest/gtest.h>

#include <string>

#include "common/model_config.h"
#include "common/temp_dir.h"
#include "penumbra/compose/scene_composer.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using testing::Model;

std::string Mjcf(const std::string& timestep) {
  return "<mujoco>\n  <option timestep=\"" + timestep +
         "\"/>\n  <worldbody><geom type=\"plane\" size=\"1 1 0.1\"/></worldbody>\n</mujoco>\n";
}

TEST(TimestepOption, ModelTimestepIsCheckedWithItsFileAndLine) {
  penumbra::testing::TempDir dir;
  for (const std::string bad : {"0", "-0.01", "1", "1e-300"}) {
    const std::string file = dir.Write("bad.xml", Mjcf(bad));
    try {
      ComposeWorld({Model("m", file)}, {});
      ADD_FAILURE() << "no ConfigError for timestep " << bad;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.file(), file);
      EXPECT_EQ(e.line(), 2);
      EXPECT_EQ(e.key(), "option.timestep");
      EXPECT_NE(std::string(e.what()).find("'" + bad + "' is not a usable physics timestep"),
                std::string::npos)
          << e.what();
    }
  }
  // the first model with an <option> decides; a later one is not used and not checked
  const std::string good = dir.Write("good.xml", Mjcf("0.004"));
  const std::string later = dir.Write("later.xml", Mjcf("0"));
  const ComposedScene s = ComposeWorld({Model("a", good), Model("b", later)}, {});
  EXPECT_NE(s.Xml().find("timestep=\"0.004\""), std::string::npos);
}

TEST(TimestepOption, WorldTimestepWins) {
  penumbra::testing::TempDir dir;
  const std::string file = dir.Write("zero.xml", Mjcf("0"));
  ComposeOptions o;
  o.timestep_sec = 0.002;
  const ComposedScene s = ComposeWorld({Model("m", file)}, o);
  EXPECT_NE(s.Xml().find("timestep=\"0.002\""), std::string::npos);
  o.timestep_sec = 1e-300;
  EXPECT_THROW(ComposeWorld({Model("m", file)}, o), ConfigError);
}

}  // namespace
}  // namespace penumbra

// MuJoCo's load error for a world names the model file and line the bad element was written on,
// not a line of the generated composed.xml (each model is compiled alone while composing).
#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

TEST(ModelLoadError, NamesTheModelFileAndLineOfTheElementMujocoRejected) {
  const penumbra::testing::TempDir dir;
  dir.Write("floor.xml",
            "<mujoco>\n  <worldbody>\n"
            "    <geom name=\"ground\" type=\"plane\" size=\"5 5 0.1\"/>\n"
            "  </worldbody>\n</mujoco>\n");
  // a compiler error (range without limited, with autolimits explicitly off), reported by
  // MuJoCo as "line N"
  const std::string robot = dir.Write("robot.xml",
                                      "<mujoco>\n"
                                      "  <compiler autolimits=\"false\"/>\n"
                                      "  <worldbody>\n"
                                      "    <body name=\"base\" pos=\"0 0 1\">\n"
                                      "      <geom size=\"0.1\"/>\n"
                                      "      <joint name=\"j\" type=\"hinge\" range=\"-1 1\"/>\n"
                                      "    </body>\n"
                                      "  </worldbody>\n"
                                      "</mujoco>\n");
  const std::string world = dir.Write("world.yaml",
                                      "duration_sec: 0.02\n"
                                      "models:\n"
                                      "  - {name: floor, file: floor.xml}\n"
                                      "  - {name: r, file: robot.xml}\n");
  SessionOptions options;
  options.composed_xml_path = (dir.path() / "composed.xml").string();
  options.build_renderer = false;
  try {
    Session session(LoadWorldFile(world), options);
    ADD_FAILURE() << "MuJoCo loaded a joint with range but no limited";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), robot) << e.what();
    EXPECT_EQ(e.line(), 6) << e.what();
    EXPECT_NE(std::string(e.what()).find("has `range` but not `limited`"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace penumbra

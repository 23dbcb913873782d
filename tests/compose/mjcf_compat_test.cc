// issue 17 point 5: MJCF keywords of MuJoCo 3 are rewritten for MuJoCo 2.2.2 with a warning
// naming the model file and line, or rejected there with the usual replacement; MuJoCo's own
// load errors, which name a line of the composed text, are restated with the model file and
// line the element came from.

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <string>

#include "common/model_config.h"
#include "common/temp_dir.h"
#include "penumbra/compose/scene_composer.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using testing::Model;

// MuJoCo 2.2.2's verdict on `xml` (written to `dir`): "" when it loads, else its error
std::string MujocoError(const penumbra::testing::TempDir& dir, const std::string& xml) {
  const std::string path = dir.Write("composed.xml", xml);
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
  if (m == nullptr) return error[0] ? error : "load failed";
  mj_deleteModel(m);
  return "";
}

bool Contains(const std::string& text, const std::string& part) {
  return text.find(part) != std::string::npos;
}

TEST(MjcfCompat, NewerKeywordsAreRewrittenWithWarningsNamingFileAndLine) {
  penumbra::testing::TempDir dir;
  const std::string file = dir.Write("robot.xml",
                                     "<mujoco>\n"
                                     "  <option integrator=\"implicitfast\">\n"
                                     "    <flag eulerdamp=\"disable\"/>\n"
                                     "  </option>\n"
                                     "  <visual><global ellipsoidinertia=\"true\"/></visual>\n"
                                     "  <worldbody>\n"
                                     "    <light type=\"directional\" dir=\"0 0 -1\"/>\n"
                                     "    <body><freejoint/><geom size=\"0.1\"/></body>\n"
                                     "  </worldbody>\n"
                                     "</mujoco>\n");
  const ComposedScene s = ComposeWorld({Model("r", file)}, {});
  const std::string xml = s.Xml();
  EXPECT_TRUE(Contains(xml, "integrator=\"implicit\"")) << xml;
  EXPECT_FALSE(Contains(xml, "ellipsoidinertia")) << xml;
  EXPECT_FALSE(Contains(xml, "eulerdamp")) << xml;
  EXPECT_TRUE(Contains(xml, "directional=\"true\"")) << xml;
  EXPECT_EQ(MujocoError(dir, xml), "");
  std::string all;
  for (const std::string& w : s.warnings) all += w + "\n";
  EXPECT_TRUE(Contains(all, file + ":2: <option integrator=\"implicitfast\"> is newer than "
                                   "MuJoCo 2.2.2; using \"implicit\""))
      << all;
  EXPECT_TRUE(Contains(all, file + ":3: <flag eulerdamp=\"disable\">")) << all;
  EXPECT_TRUE(Contains(all, file + ":5: <global ellipsoidinertia=\"true\">")) << all;
  EXPECT_TRUE(Contains(all, file + ":7: <light type=\"directional\">")) << all;
}

TEST(MjcfCompat, KeywordsWithoutA222FormAreRejectedWithTheReplacement) {
  penumbra::testing::TempDir dir;
  // in an included file and in a default class: the error names that file and line
  dir.Write("actuators.xml",
            "<mujoco>\n"
            "  <default>\n"
            "    <position kp=\"20\" kv=\"1\"/>\n"
            "  </default>\n"
            "</mujoco>\n");
  const std::string file = dir.Write("robot.xml",
                                     "<mujoco>\n"
                                     "  <include file=\"actuators.xml\"/>\n"
                                     "  <worldbody><body><joint name=\"j\"/><geom size=\"0.1\"/>"
                                     "</body></worldbody>\n"
                                     "  <actuator><position joint=\"j\"/></actuator>\n"
                                     "</mujoco>\n");
  try {
    ComposeWorld({Model("r", file)}, {});
    ADD_FAILURE() << "position kv accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), (dir.path() / "actuators.xml").string());
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.key(), "position.kv");
    EXPECT_TRUE(Contains(e.what(), "newer than MuJoCo 2.2.2")) << e.what();
    EXPECT_TRUE(Contains(e.what(), "biasprm=\"0 -KP -KV\"")) << e.what();
  }
  const std::string frame = dir.Write("frame.xml",
                                      "<mujoco>\n  <worldbody>\n"
                                      "    <frame pos=\"0 0 1\"><geom size=\"0.1\"/></frame>\n"
                                      "  </worldbody>\n</mujoco>\n");
  try {
    ComposeWorld({Model("f", frame)}, {});
    ADD_FAILURE() << "<frame> accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.line(), 3);
    EXPECT_TRUE(Contains(e.what(), "<frame> is newer than MuJoCo 2.2.2")) << e.what();
  }
}

TEST(MjcfCompat, MujocoErrorsNameTheModelFileAndLine) {
  penumbra::testing::TempDir dir;
  // two models, so that composed lines differ from each model's lines
  const std::string floor =
      dir.Write("floor.xml",
                "<mujoco>\n  <worldbody>\n"
                "    <geom name=\"ground\" type=\"plane\" size=\"5 5 0.1\"/>\n"
                "  </worldbody>\n</mujoco>\n");
  const std::string robot = dir.Write("robot.xml",
                                      "<mujoco>\n"
                                      "  <worldbody>\n"
                                      "    <body name=\"base\" pos=\"0 0 1\">\n"
                                      "      <joint name=\"j\" type=\"hinge\"/>\n"
                                      "      <geom size=\"0.1\" futureattr=\"1\"/>\n"
                                      "    </body>\n"
                                      "  </worldbody>\n"
                                      "</mujoco>\n");
  const ComposedScene s = ComposeWorld({Model("floor", floor), Model("r", robot)}, {});
  const std::string message = MujocoError(dir, s.Xml());
  ASSERT_TRUE(Contains(message, "unrecognized attribute: 'futureattr'")) << message;
  // MuJoCo's error as the physics module reports it: the composed file and MuJoCo's line
  const int composed_line = std::stoi(message.substr(message.rfind("line ") + 5));
  ASSERT_GT(composed_line, 0);
  const ConfigError mujoco(dir.str() + "/composed.xml", composed_line, "",
                           "MuJoCo could not load the model: " + message);
  const ConfigError mapped = LocateComposedError(s, mujoco);
  EXPECT_EQ(mapped.file(), robot);
  EXPECT_EQ(mapped.line(), 5);
  EXPECT_TRUE(Contains(mapped.what(), "composed.xml line " + std::to_string(composed_line)))
      << mapped.what();
  EXPECT_TRUE(Contains(mapped.what(), "may come from a newer MuJoCo")) << mapped.what();

  // a copy of the scene maps its own elements
  const ComposedScene copy = s;
  const auto where = copy.SourceOfLine(composed_line);
  ASSERT_TRUE(where.has_value());
  EXPECT_EQ(where->file, robot);
  EXPECT_EQ(where->line, 5);
}

}  // namespace
}  // namespace penumbra

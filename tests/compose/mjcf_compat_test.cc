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

namespace penumbra {
namespace {

// a stand-in of the Z1/Spot pattern (models written for MuJoCo 3, whose autolimits defaults to
// true): ranges without limited on joints (one through a default class, one through a body's
// childclass), a tendon and actuators (ctrlrange from a default class, forcerange, actrange)
constexpr char kAutolimitsRobot[] = R"(<mujoco>
  <compiler angle="radian"/>
  <default>
    <default class="leg">
      <joint range="-1 1"/>
      <motor ctrlrange="-5 5"/>
    </default>
    <default class="arm"><joint axis="0 1 0" range="-2 2"/></default>
  </default>
  <worldbody>
    <body name="base" pos="0 0 1">
      <freejoint/>
      <geom size="0.1"/>
      <body name="thigh" childclass="arm">
        <joint name="hip"/>
        <geom type="capsule" size="0.05" fromto="0 0 0 0 0 -0.2"/>
        <body name="calf" pos="0 0 -0.2">
          <joint name="knee" class="leg"/>
          <joint name="twist" axis="0 0 1" range="-0.5 0.5" limited="false"/>
          <geom type="capsule" size="0.04" fromto="0 0 0 0 0 -0.2"/>
        </body>
      </body>
      <body name="tail" pos="-0.2 0 0">
        <joint name="wag" type="hinge" range="-0.3 0.3"/>
        <joint name="free_spin" type="hinge" axis="1 0 0"/>
        <geom size="0.02"/>
      </body>
    </body>
  </worldbody>
  <tendon><fixed name="sum" range="-1 1"><joint joint="hip" coef="1"/><joint joint="knee" coef="1"/></fixed></tendon>
  <actuator>
    <motor name="m_knee" joint="knee" class="leg"/>
    <motor name="m_hip" joint="hip" forcerange="-3 3"/>
    <general name="g_wag" joint="wag" dyntype="integrator" actrange="-1 1"/>
  </actuator>
</mujoco>
)";

int JointId(const mjModel* m, const char* name) { return mj_name2id(m, mjOBJ_JOINT, name); }
int ActuatorId(const mjModel* m, const char* name) { return mj_name2id(m, mjOBJ_ACTUATOR, name); }

// issue 38: MuJoCo 2.2.2 refuses this ("joint has `range` but not `limited`") one element per
// run; the MuJoCo-3 defaults layer limits every one of them, as MuJoCo 3 would, and says so in
// one warning
TEST(MjcfAutolimits, RangesWithoutLimitedAreLimitedAsMujoco3DoesWithOneWarning) {
  penumbra::testing::TempDir dir;
  const std::string file = dir.Write("robot.xml", kAutolimitsRobot);
  {
    char error[1000] = "";
    mjModel* raw = mj_loadXML(file.c_str(), nullptr, error, sizeof(error));
    EXPECT_EQ(raw, nullptr);
    EXPECT_TRUE(Contains(error, "but not `limited`")) << error;
    if (raw) mj_deleteModel(raw);
  }
  const ComposedScene s = ComposeWorld({Model("r", file)}, {});
  const std::string path = dir.Write("composed.xml", s.Xml());
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
  ASSERT_NE(m, nullptr) << error;
  for (const char* j : {"r/hip", "r/knee", "r/wag"}) {
    ASSERT_GE(JointId(m, j), 0) << j;
    EXPECT_EQ(m->jnt_limited[JointId(m, j)], 1) << j;
  }
  EXPECT_EQ(m->jnt_range[2 * JointId(m, "r/hip") + 1], 2);
  EXPECT_EQ(m->jnt_range[2 * JointId(m, "r/knee") + 1], 1);
  EXPECT_EQ(m->jnt_limited[JointId(m, "r/twist")], 0);  // limited="false" stays
  EXPECT_EQ(m->jnt_limited[JointId(m, "r/free_spin")], 0);
  EXPECT_EQ(m->tendon_limited[0], 1);
  EXPECT_EQ(m->actuator_ctrllimited[ActuatorId(m, "r/m_knee")], 1);
  EXPECT_EQ(m->actuator_ctrlrange[2 * ActuatorId(m, "r/m_knee") + 1], 5);
  EXPECT_EQ(m->actuator_forcelimited[ActuatorId(m, "r/m_hip")], 1);
  EXPECT_EQ(m->actuator_ctrllimited[ActuatorId(m, "r/m_hip")], 0);
  EXPECT_EQ(m->actuator_actlimited[ActuatorId(m, "r/g_wag")], 1);
  mj_deleteModel(m);
  std::string all;
  int lines = 0;
  for (const std::string& w : s.warnings) {
    if (!Contains(w, "autolimits")) continue;
    all += w;
    ++lines;
  }
  EXPECT_EQ(lines, 1) << all;
  EXPECT_TRUE(Contains(all, file + ": <compiler> does not set autolimits")) << all;
  EXPECT_TRUE(Contains(all, "3 joints: limited (hip, knee, wag)")) << all;
  EXPECT_TRUE(Contains(all, "1 tendons: limited (sum)")) << all;
  EXPECT_TRUE(Contains(all, "1 actuators: ctrllimited (m_knee)")) << all;
  EXPECT_TRUE(Contains(all, "1 actuators: forcelimited (m_hip)")) << all;
  EXPECT_TRUE(Contains(all, "1 actuators: actlimited (g_wag)")) << all;

  // a model that sets autolimits itself is left to MuJoCo (no warning, nothing written)
  std::string own = kAutolimitsRobot;
  own.replace(own.find("<compiler angle=\"radian\"/>"), 26,
              "<compiler angle=\"radian\" autolimits=\"true\"/>");
  const ComposedScene o = ComposeWorld({Model("r", dir.Write("own.xml", own))}, {});
  for (const std::string& w : o.warnings) EXPECT_FALSE(Contains(w, "autolimits")) << w;
  EXPECT_EQ(MujocoError(dir, o.Xml()), "");
}

// Spot's case: several keywords without a 2.2.2 form are reported in one error, not one a run
TEST(MjcfAutolimits, EveryKeywordWithoutA222FormIsReportedInOneError) {
  penumbra::testing::TempDir dir;
  const std::string file = dir.Write("spot.xml",
                                     "<mujoco>\n"
                                     "  <worldbody>\n"
                                     "    <body name=\"b\" gravcomp=\"1\">\n"
                                     "      <joint name=\"j\" actuatorfrcrange=\"-1 1\"/>\n"
                                     "      <geom size=\"0.1\"/>\n"
                                     "    </body>\n"
                                     "  </worldbody>\n"
                                     "  <actuator>\n"
                                     "    <position joint=\"j\" kp=\"10\" kv=\"1\"/>\n"
                                     "    <position joint=\"j\" kp=\"10\" dampratio=\"1\"/>\n"
                                     "  </actuator>\n"
                                     "</mujoco>\n");
  try {
    ComposeWorld({Model("s", file)}, {});
    ADD_FAILURE() << "accepted";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.line(), 3) << what;
    EXPECT_EQ(e.key(), "body.gravcomp") << what;
    EXPECT_TRUE(Contains(what, "(1 of 4 keywords newer than MuJoCo 2.2.2")) << what;
    EXPECT_TRUE(Contains(what, "(2) " + file + ":4: joint.actuatorfrcrange")) << what;
    EXPECT_TRUE(Contains(what, "(3) " + file + ":9: position.kv")) << what;
    EXPECT_TRUE(Contains(what, "(4) " + file + ":10: position.dampratio")) << what;
  }
}

}  // namespace
}  // namespace penumbra

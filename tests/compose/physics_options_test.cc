// issue 17 point 8: the world file's physics options override the composed <option>
// (what MuJoCo 2.2.2 then compiles), and models whose <option> differs only in what the
// world file decides no longer warn; the warning that remains names the attributes and
// points at the world file's physics section.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <string>

#include "common/model_config.h"
#include "common/temp_dir.h"
#include "penumbra/compose/scene_composer.h"

namespace penumbra {
namespace {

using testing::Model;

std::string Mjcf(const std::string& option) {
  return "<mujoco>\n  <option " + option +
         "/>\n  <worldbody><body><freejoint/><geom size=\"0.1\"/></body></worldbody>\n"
         "</mujoco>\n";
}

TEST(PhysicsOptions, WorldOptionsOverrideTheComposedOption) {
  penumbra::testing::TempDir dir;
  const std::string a = dir.Write("a.xml", Mjcf("integrator=\"RK4\" cone=\"pyramidal\""));
  const std::string b = dir.Write("b.xml", Mjcf("integrator=\"Euler\" iterations=\"7\""));
  ComposeOptions o;
  o.physics.integrator = "implicit";
  o.physics.gravity_mps2 = Eigen::Vector3d(0, 0, -1.62);
  o.physics.solver_iterations = 42;
  o.physics.cone = "elliptic";
  const ComposedScene s = ComposeWorld({Model("a", a), Model("b", b)}, o);
  // every differing attribute is decided by the world file: no warning
  EXPECT_TRUE(s.warnings.empty()) << s.warnings.front();

  const std::string path = dir.Write("composed.xml", s.Xml());
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
  ASSERT_NE(m, nullptr) << error;
  EXPECT_EQ(m->opt.integrator, mjINT_IMPLICIT);
  EXPECT_EQ(m->opt.gravity[2], -1.62);
  EXPECT_EQ(m->opt.iterations, 42);
  EXPECT_EQ(m->opt.cone, mjCONE_ELLIPTIC);
  mj_deleteModel(m);
}

TEST(PhysicsOptions, FirstModelWinsWarningNamesTheAttributesAndTheWorldFile) {
  penumbra::testing::TempDir dir;
  const std::string a = dir.Write("a.xml", Mjcf("integrator=\"RK4\" cone=\"pyramidal\""));
  const std::string b = dir.Write("b.xml", Mjcf("integrator=\"Euler\" cone=\"elliptic\""));
  ComposeOptions o;
  o.physics.cone = "elliptic";  // decided; the integrator is not
  const ComposedScene s = ComposeWorld({Model("a", a), Model("b", b)}, o);
  ASSERT_EQ(s.warnings.size(), 1u);
  const std::string& w = s.warnings[0];
  EXPECT_NE(w.find("(integrator)"), std::string::npos) << w;
  EXPECT_NE(w.find("physics section decides"), std::string::npos) << w;
  EXPECT_NE(s.Xml().find("integrator=\"RK4\""), std::string::npos);
}

}  // namespace
}  // namespace penumbra

// the composition step through MuJoCo's model-editing API: a user's modern MJCF composes in a
// world file, composed.xml is MuJoCo's own text and loads in stock MuJoCo 4 with the same
// physics, world-file options win over the models', and Menagerie-derived models (mjlab 1.6.0)
// run unmodified next to a floor.
#include "penumbra/session/world_composer.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>

#include "common/mjlab_assets.h"
#include "common/model_config.h"
#include "common/modern_mjcf.h"
#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

using testing::Model;

using testing::kModernMjcf;

constexpr const char* kComposerFloor =
    "<mujoco><worldbody><geom name=\"floor\" type=\"plane\" size=\"0 0 0.05\"/></worldbody>"
    "</mujoco>\n";

SessionOptions HeadlessComposed() {
  SessionOptions options;
  options.build_renderer = false;
  options.add_controllers = false;
  return options;
}

int ComposedBodyIndex(const Simulation& sim, const std::string& name) {
  const auto& names = sim.model_info().body_names;
  const auto it = std::find(names.begin(), names.end(), name);
  EXPECT_NE(it, names.end()) << name;
  return static_cast<int>(it - names.begin());
}

TEST(WorldComposer, ModernMjcfComposesAndItsKeyPlacesAnUnnamedFreeJoint) {
  penumbra::testing::TempDir dir;
  dir.Write("modern.xml", kModernMjcf);
  dir.Write("floor.xml", kComposerFloor);
  const std::string world = dir.Write(
      "world.yaml",
      "models:\n  - {name: floor, file: floor.xml}\n"
      "robots:\n  - {name: r, file: modern.xml, pose: {xyz: [1, 2, 0], rpy_deg: [0, 0, 90]},\n"
      "      initial_keyframe: stand}\n"
      "  - {name: s, file: modern.xml, pose: {xyz: [-1, 0, 0]}}\n");
  SessionOptions options = HeadlessComposed();
  options.composed_xml_path = (dir.path() / "out/composed.xml").string();
  std::filesystem::create_directories(dir.path() / "out");
  Session session(LoadWorldFile(world), options);
  const Simulation& sim = session.sim();
  const WorldSnapshot snap = sim.Snapshot();
  // the key's height, at the model's pose; the other copy at its body pos
  const Eigen::Vector3d p_r = snap.X_WB[ComposedBodyIndex(sim, "r/base")].translation();
  EXPECT_NEAR(p_r.x(), 1, 1e-12);
  EXPECT_NEAR(p_r.y(), 2, 1e-12);
  EXPECT_NEAR(p_r.z(), 0.27, 1e-12);
  EXPECT_NEAR(snap.X_WB[ComposedBodyIndex(sim, "s/base")].translation().z(), 0.445, 1e-12);
  // the body turned by the pose's yaw
  EXPECT_NEAR(snap.X_WB[ComposedBodyIndex(sim, "r/base")].linear()(1, 0), 1, 1e-12);
  // <replicate> and the default class's mesh
  const auto& geoms = sim.scene().geoms;
  for (const char* name : {"r/stud0", "r/stud3", "s/shell"}) {
    EXPECT_TRUE(std::any_of(geoms.begin(), geoms.end(), [&](const Geom& g) {
      return g.name == name;
    })) << name;
  }

  // composed.xml loads in stock MuJoCo 4 and steps as the session's model does
  char error[1024] = "";
  mjModel* m = mj_loadXML(options.composed_xml_path.c_str(), nullptr, error, sizeof(error));
  ASSERT_NE(m, nullptr) << error;
  mjData* d = mj_makeData(m);
  const int k = mj_name2id(m, mjOBJ_KEY, "r/stand");
  ASSERT_GE(k, 0);
  mj_resetDataKeyframe(m, d, k);
  Session again(LoadWorldFile(world), HeadlessComposed());
  Simulation& live = again.sim();
  for (int i = 0; i < 200; ++i) {
    mj_step(m, d);
    live.Step();
  }
  const SimState s = live.GetState();
  ASSERT_EQ(static_cast<int>(s.qpos.size()), m->nq);
  for (int i = 0; i < m->nq; ++i) EXPECT_EQ(s.qpos[i], d->qpos[i]) << i;
  mj_deleteData(d);
  mj_deleteModel(m);
}

TEST(WorldComposer, ModelErrorsNameTheModelFileAndLine) {
  penumbra::testing::TempDir dir;
  const std::string bad = dir.Write(
      "bad.xml",
      "<mujoco>\n<worldbody>\n<body name=\"b\">\n<joint name=\"j\"/>\n<geom size=\"0.1\"/>\n"
      "</body>\n</worldbody>\n<actuator>\n<motor joint=\"nosuch\"/>\n</actuator>\n</mujoco>\n");
  try {
    ComposeWorld({Model("m", bad)}, {});
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), bad);
    EXPECT_EQ(e.line(), 9) << e.problem();
  }
  ModelConfig twice = Model("m", bad);
  EXPECT_THROW(ComposeWorld({twice, twice}, {}), ConfigError);
  EXPECT_THROW(ComposeWorld({Model("a/b", bad)}, {}), ConfigError);
}

std::string ComposerOptionModel(const std::string& option) {
  return "<mujoco>\n  <option " + option +
         "/>\n  <worldbody><body><freejoint/><geom size=\"0.1\"/></body></worldbody>\n"
         "</mujoco>\n";
}

TEST(WorldComposer, WorldOptionsOverrideTheModelsAndTimestepsAreChecked) {
  penumbra::testing::TempDir dir;
  const std::string a =
      dir.Write("a.xml", ComposerOptionModel("integrator=\"RK4\" timestep=\"0.004\""));
  const std::string b =
      dir.Write("b.xml", ComposerOptionModel("integrator=\"implicit\" iterations=\"7\""));
  ComposeOptions o;
  o.physics.integrator = "implicit";
  o.physics.gravity_mps2 = Eigen::Vector3d(0, 0, -1.62);
  o.physics.solver_iterations = 42;
  o.physics.cone = "elliptic";
  o.timestep_sec = 0.001;
  const std::string path =
      dir.Write("composed.xml", ComposeWorld({Model("a", a), Model("b", b)}, o).Xml());
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
  ASSERT_NE(m, nullptr) << error;
  EXPECT_EQ(m->opt.integrator, mjINT_IMPLICIT);
  EXPECT_EQ(m->opt.gravity[2], -1.62);
  EXPECT_EQ(m->opt.iterations, 42);
  EXPECT_EQ(m->opt.cone, mjCONE_ELLIPTIC);
  EXPECT_EQ(m->opt.timestep, 0.001);
  mj_deleteModel(m);

  // without the world's options the first model decides and the second's differences warn
  const ComposedScene first = ComposeWorld({Model("a", a), Model("b", b)}, {});
  ASSERT_EQ(first.warnings.size(), 1u);
  EXPECT_NE(first.warnings[0].find("(integrator, iterations)"), std::string::npos)
      << first.warnings[0];
  EXPECT_NE(first.Xml().find("integrator=\"RK4\""), std::string::npos);

  // without the world's timestep the deciding model's must be usable
  const std::string zero = dir.Write("zero.xml", ComposerOptionModel("timestep=\"0\""));
  try {
    ComposeWorld({Model("z", zero), Model("a", a)}, {});
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), zero);
    EXPECT_EQ(e.key(), "option.timestep");
  }
  ComposeOptions world_timestep;
  world_timestep.timestep_sec = 0.002;
  EXPECT_NO_THROW(ComposeWorld({Model("z", zero)}, world_timestep));
  world_timestep.timestep_sec = 1e-300;
  EXPECT_THROW(ComposeWorld({Model("z", zero)}, world_timestep), ConfigError);
}

TEST(WorldComposer, AMeshFormatMuJoCoCannotReadIsConvertedWhileComposing) {
  penumbra::testing::TempDir dir;
  dir.Write("tet.ply",
            "ply\nformat ascii 1.0\nelement vertex 4\nproperty float x\nproperty float y\n"
            "property float z\nelement face 4\nproperty list uchar int vertex_indices\n"
            "end_header\n0 0 0\n0.1 0 0\n0 0.1 0\n0 0 0.1\n3 0 2 1\n3 0 1 3\n3 0 3 2\n"
            "3 1 2 3\n");
  const std::string model =
      dir.Write("m.xml",
                "<mujoco><asset><mesh name=\"tet\" file=\"tet.ply\"/></asset><worldbody><body "
                "pos=\"0 0 0.5\"><freejoint/><geom type=\"mesh\" mesh=\"tet\"/></body></worldbody>"
                "</mujoco>\n");
  const std::filesystem::path out = dir.path() / "out";
  std::filesystem::create_directories(out);
  SessionOptions options = HeadlessComposed();
  options.composed_xml_path = (out / "composed.xml").string();
  Session session(WorldForBareModel(model), options);
  // the .msh beside composed.xml, named there by its absolute path
  int msh = 0;
  for (const auto& f : std::filesystem::directory_iterator(out / "meshes"))
    msh += f.path().extension() == ".msh" ? 1 : 0;
  EXPECT_EQ(msh, 1);
  const std::string xml = session.composed_xml();
  EXPECT_NE(xml.find((out / "meshes").string()), std::string::npos);
  EXPECT_EQ(session.sim().scene().meshes.size(), 1u);
}

TEST(WorldComposer, MenagerieModelsRunUnmodifiedNextToAFloor) {
  const std::filesystem::path zoo = testing::MjlabRobotsDir();
  if (zoo.empty()) GTEST_SKIP() << "mjlab (pip mjlab==1.6.0) is not in the project venv";
  for (const char* rel :
       {"unitree_go1/xmls/go1.xml", "unitree_g1/xmls/g1.xml", "i2rt_yam/xmls/yam.xml"}) {
    SCOPED_TRACE(rel);
    penumbra::testing::TempDir dir;
    dir.Write("floor.xml", kComposerFloor);
    const std::string world = dir.Write("world.yaml",
                                        "models:\n  - {name: floor, file: floor.xml}\n"
                                        "robots:\n  - {name: r, file: " +
                                            (zoo / rel).string() + ", pose: {xyz: [0, 0, 0.1]}}\n");
    Session session(LoadWorldFile(world), HeadlessComposed());
    Simulation& sim = session.sim();
    while (sim.time() < 0.1) sim.Step();
    for (double q : sim.GetState().qpos) EXPECT_TRUE(std::isfinite(q));
    // the same file as a bare model (`penumbra run FILE.xml`)
    Session bare(WorldForBareModel((zoo / rel).string()), HeadlessComposed());
    while (bare.sim().time() < 0.1) bare.sim().Step();
  }
}

}  // namespace
}  // namespace penumbra

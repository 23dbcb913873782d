// composition through MjSpec: modern MJCF composes, the saved text is MuJoCo's own and
// compiles to the same physics, keys and sites are placed, errors name the model file and line.

#include "penumbra/physics/model_spec_composer.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <filesystem>
#include <memory>

#include "common/mjlab_assets.h"
#include "common/modern_mjcf.h"
#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

constexpr const char* kFloor =
    "<mujoco><worldbody><geom name=\"floor\" type=\"plane\" size=\"0 0 1\"/></worldbody>"
    "</mujoco>";

using testing::kModernMjcf;

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;

ModelPtr LoadXml(const std::string& xml) {
  char error[1024] = "";
  mjSpec* spec = mj_parseXMLString(xml.c_str(), nullptr, error, sizeof(error));
  EXPECT_NE(spec, nullptr) << error;
  if (spec == nullptr) return nullptr;
  mjModel* m = mj_compile(spec, nullptr);
  EXPECT_NE(m, nullptr) << mjs_getError(spec);
  mj_deleteSpec(spec);
  return ModelPtr(m);
}

SpecModel Model(const std::string& name, const std::string& file, std::array<double, 3> pos = {},
                std::array<double, 4> quat = {1, 0, 0, 0}) {
  SpecModel m;
  m.name = name;
  m.file = file;
  m.pos = pos;
  m.quat = quat;
  return m;
}

// qpos after `steps` steps from the model's reference configuration
std::vector<double> Trajectory(const mjModel* m, int steps, int key = -1) {
  mjData* d = mj_makeData(m);
  if (key >= 0) mj_resetDataKeyframe(m, d, key);
  for (int i = 0; i < steps; ++i) mj_step(m, d);
  std::vector<double> q(d->qpos, d->qpos + m->nq);
  mj_deleteData(d);
  return q;
}

TEST(ModelSpecComposer, ModernMjcfComposesAtItsPose) {
  testing::TempDir dir;
  const std::string file = dir.Write("modern.xml", kModernMjcf);
  ModelSpecComposer c(kFloor, false);
  c.Attach(Model("a", file, {1, 2, 0}, {std::cos(M_PI / 4), 0, 0, std::sin(M_PI / 4)}));
  c.Attach(Model("b", file, {-1, 0, 0}));
  const ModelPtr m(c.Compile({}));
  ASSERT_TRUE(m);
  // every element of both copies, prefixed: 4 replicated studs each, the default-class mesh
  for (const char* name : {"a/torso", "a/shell", "a/stud0", "a/stud3", "b/stud3"})
    EXPECT_GE(mj_name2id(m.get(), mjOBJ_GEOM, name), 0) << name;
  EXPECT_EQ(m->geom_type[mj_name2id(m.get(), mjOBJ_GEOM, "a/shell")], mjGEOM_MESH);
  EXPECT_GE(mj_name2id(m.get(), mjOBJ_ACTUATOR, "b/hinge"), 0);
  // degrees became radians: the hinge range is +-pi/2
  const int j = mj_name2id(m.get(), mjOBJ_JOINT, "a/hinge");
  EXPECT_NEAR(m->jnt_range[2 * j + 1], M_PI / 2, 1e-12);
  // the free body starts at the model pose plus its pos
  const int qa = m->jnt_qposadr[m->body_jntadr[mj_name2id(m.get(), mjOBJ_BODY, "a/base")]];
  EXPECT_NEAR(m->qpos0[qa + 0], 1, 1e-12);
  EXPECT_NEAR(m->qpos0[qa + 1], 2, 1e-12);
  EXPECT_NEAR(m->qpos0[qa + 2], 0.445, 1e-12);

  // key "a/stand": model a from its key, placed by a's pose (0.27 m, turned 90 degrees);
  // model b at its reference configuration
  const int k = mj_name2id(m.get(), mjOBJ_KEY, "a/stand");
  ASSERT_GE(k, 0);
  const double* q = m->key_qpos + k * m->nq;
  EXPECT_NEAR(q[qa + 0], 1, 1e-12);
  EXPECT_NEAR(q[qa + 1], 2, 1e-12);
  EXPECT_NEAR(q[qa + 2], 0.27, 1e-12);
  EXPECT_NEAR(q[qa + 3], std::cos(M_PI / 4), 1e-12);
  EXPECT_NEAR(q[qa + 6], std::sin(M_PI / 4), 1e-12);
  EXPECT_NEAR(q[qa + 7], 0.5, 1e-12);
  const int qb = m->jnt_qposadr[m->body_jntadr[mj_name2id(m.get(), mjOBJ_BODY, "b/base")]];
  for (int i = 0; i < 8; ++i) EXPECT_EQ(q[qb + i], m->qpos0[qb + i]) << i;
  const int ua = mj_name2id(m.get(), mjOBJ_ACTUATOR, "a/hinge");
  const int ub = mj_name2id(m.get(), mjOBJ_ACTUATOR, "b/hinge");
  EXPECT_EQ(m->key_ctrl[k * m->nu + ua], 0.5);
  EXPECT_EQ(m->key_ctrl[k * m->nu + ub], 0.0);
}

TEST(ModelSpecComposer, SavedXmlCompilesToTheSamePhysics) {
  testing::TempDir dir;
  const std::string file = dir.Write("modern.xml", kModernMjcf);
  // an asset file relative to its model's folder, with a compiler meshdir
  dir.Write("sub/assets/box.obj",
            "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n");
  const std::string meshy = dir.Write(
      "sub/meshy.xml",
      "<mujoco><compiler meshdir=\"assets\"/><asset><mesh file=\"box.obj\"/></asset>"
      "<worldbody><body pos=\"0 0 1\"><freejoint/><geom type=\"mesh\" mesh=\"box\"/></body>"
      "</worldbody></mujoco>");
  ModelSpecComposer c(kFloor, false);
  c.Attach(Model("a", file, {0, 0, 0.2}, {std::cos(0.3), 0, 0, std::sin(0.3)}));
  c.Attach(Model("m", meshy, {1, 0, 0}));
  const ModelPtr in_memory(c.Compile({}));
  const std::string xml = c.SaveXml({});
  // the saved file names the mesh by an absolute path: it loads from any folder
  const ModelPtr saved = LoadXml(xml);
  ASSERT_TRUE(in_memory && saved);
  ASSERT_EQ(saved->nq, in_memory->nq);
  EXPECT_EQ(Trajectory(saved.get(), 200), Trajectory(in_memory.get(), 200));
  EXPECT_EQ(Trajectory(saved.get(), 200, 0), Trajectory(in_memory.get(), 200, 0));
}

TEST(ModelSpecComposer, SitesAtBodiesAndGeomCentres) {
  testing::TempDir dir;
  const std::string file =
      dir.Write("legs.xml",
                "<mujoco><default><default class=\"foot\"><geom type=\"capsule\" size=\"0.01\" "
                "fromto=\"0 0 0 0 0 -0.2\"/></default></default><worldbody><body name=\"leg\" "
                "pos=\"0 0 1\"><joint type=\"slide\" axis=\"0 0 1\"/><geom name=\"shin\" "
                "class=\"foot\"/></body></worldbody></mujoco>");
  SpecModel model = Model("r", file, {2, 0, 0});
  SpecSite tip;
  tip.name = "tip";
  tip.geom = "shin";
  tip.pos = {0, 0, -0.05};
  SpecSite top;
  top.name = "top";
  top.body = "leg";
  top.pos = {0, 0, 0.1};
  model.sites = {tip, top};
  ModelSpecComposer c(kFloor, false);
  c.Attach(model);
  const ModelPtr m(c.Compile({}));
  ASSERT_TRUE(m);
  const int s = mj_name2id(m.get(), mjOBJ_SITE, "r/tip");
  ASSERT_GE(s, 0);
  // the capsule's centre (from its default class's fromto) plus the offset
  EXPECT_NEAR(m->site_pos[3 * s + 2], -0.1 - 0.05, 1e-12);
  EXPECT_EQ(m->site_bodyid[s], mj_name2id(m.get(), mjOBJ_BODY, "r/leg"));
  EXPECT_EQ(m->site_group[s], 4);
  const int t = mj_name2id(m.get(), mjOBJ_SITE, "r/top");
  EXPECT_NEAR(m->site_pos[3 * t + 2], 0.1, 1e-12);

  SpecModel bad = Model("q", file);
  SpecSite nowhere;
  nowhere.name = "x";
  nowhere.geom = "calf";
  bad.sites = {nowhere};
  bad.key = "robots[1]";
  try {
    c.Attach(bad);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "robots[1].sites[0].geom");
    EXPECT_NE(e.problem().find("no geom 'calf'"), std::string::npos) << e.problem();
  }
}

TEST(ModelSpecComposer, ErrorsNameTheModelFileAndLine) {
  testing::TempDir dir;
  const std::string schema =
      dir.Write("schema.xml",
                "<mujoco>\n<worldbody>\n<body>\n<geom size=\"0.1\" foo=\"1\"/>\n</body>\n"
                "</worldbody>\n</mujoco>\n");
  const std::string undefined = dir.Write(
      "undefined.xml",
      "<mujoco>\n<worldbody>\n<body name=\"b\">\n<joint name=\"j\"/>\n<geom size=\"0.1\"/>\n"
      "</body>\n</worldbody>\n<actuator>\n<motor joint=\"nosuch\"/>\n</actuator>\n</mujoco>\n");
  for (const auto& [file, line] : {std::pair{schema, 4}, std::pair{undefined, 9}}) {
    ModelSpecComposer c(kFloor, false);
    try {
      c.Attach(Model("m", file));
      FAIL() << "expected ConfigError for " << file;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.file(), file);
      EXPECT_EQ(e.line(), line) << e.problem();
    }
  }
  ModelSpecComposer c(kFloor, false);
  EXPECT_THROW(c.Attach(Model("m", dir.str() + "/missing.xml")), ConfigError);
  SpecModel mjcf = Model("m", dir.Write("ok.xml", kFloor));
  mjcf.floating_base = true;
  EXPECT_THROW(c.Attach(mjcf), ConfigError);
}

TEST(ModelSpecComposer, UrdfFloatingBaseIsAFreeJointOnTheRootLink) {
  testing::TempDir dir;
  const std::string urdf = dir.Write("bot.urdf", R"(<?xml version="1.0"?>
<robot name="bot">
  <mujoco><compiler discardvisual="false" fusestatic="false"/></mujoco>
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><cylinder radius="0.02" length="0.3"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
</robot>
)");
  SpecModel model = Model("u", urdf, {0, 0, 1});
  model.from_urdf = true;
  model.floating_base = true;
  ModelSpecComposer c(kFloor, false);
  c.Attach(model);
  const ModelPtr m(c.Compile({}));
  ASSERT_TRUE(m);
  const int j = mj_name2id(m.get(), mjOBJ_JOINT, "u/floating_base");
  ASSERT_GE(j, 0);
  EXPECT_EQ(m->jnt_type[j], mjJNT_FREE);
  EXPECT_EQ(m->jnt_bodyid[j], mj_name2id(m.get(), mjOBJ_BODY, "u/base"));
  EXPECT_NEAR(m->qpos0[m->jnt_qposadr[j] + 2], 1, 1e-12);
  // it falls
  EXPECT_LT(Trajectory(m.get(), 100)[m->jnt_qposadr[j] + 2], 0.99);
}

TEST(ModelSpecComposer, WorldOptionsOverrideTheModels) {
  testing::TempDir dir;
  const std::string a = dir.Write(
      "a.xml",
      "<mujoco><option timestep=\"0.004\" integrator=\"RK4\"/><worldbody><body><freejoint/>"
      "<geom size=\"0.1\"/></body></worldbody></mujoco>");
  ModelSpecComposer c(kFloor, false);
  c.Attach(Model("a", a));
  const ModelPtr adopted(c.Compile({}));
  EXPECT_EQ(adopted->opt.timestep, 0.004);
  EXPECT_EQ(adopted->opt.integrator, mjINT_RK4);
  SpecOptionOverrides o;
  o.timestep_sec = 0.001;
  o.integrator = "implicitfast";
  o.gravity_mps2 = std::array<double, 3>{0, 0, -1.62};
  const ModelPtr m(c.Compile(o));
  EXPECT_EQ(m->opt.timestep, 0.001);
  EXPECT_EQ(m->opt.integrator, mjINT_IMPLICITFAST);
  EXPECT_EQ(m->opt.gravity[2], -1.62);
}

TEST(ModelSpecComposer, KeysPlaceMocapBodiesByThePose) {
  testing::TempDir dir;
  const std::string file =
      dir.Write("mocap.xml",
                "<mujoco><worldbody><body name=\"target\" mocap=\"true\" pos=\"1 0 0\"><geom "
                "size=\"0.05\" contype=\"0\" conaffinity=\"0\"/></body></worldbody><keyframe><key "
                "name=\"k\" mpos=\"2 0 0.5\" mquat=\"1 0 0 0\"/></keyframe></mujoco>");
  ModelSpecComposer c(kFloor, false);
  c.Attach(Model("m", file, {0, 1, 0}, {std::cos(M_PI / 4), 0, 0, std::sin(M_PI / 4)}));
  const ModelPtr m(c.Compile({}));
  ASSERT_TRUE(m);
  const int k = mj_name2id(m.get(), mjOBJ_KEY, "m/k");
  ASSERT_GE(k, 0);
  // (2, 0, 0.5) turned 90 degrees about z and moved by (0, 1, 0)
  const double* p = m->key_mpos + 3 * k * m->nmocap;
  EXPECT_NEAR(p[0], 0, 1e-12);
  EXPECT_NEAR(p[1], 3, 1e-12);
  EXPECT_NEAR(p[2], 0.5, 1e-12);
  const double* q = m->key_mquat + 4 * k * m->nmocap;
  EXPECT_NEAR(q[0], std::cos(M_PI / 4), 1e-12);
  EXPECT_NEAR(q[3], std::sin(M_PI / 4), 1e-12);
}

TEST(ModelSpecComposer, MenagerieModelsComposeUnmodified) {
  const std::filesystem::path zoo = testing::MjlabRobotsDir();
  if (zoo.empty()) GTEST_SKIP() << "mjlab (pip mjlab==1.6.0) is not in the project venv";
  ModelSpecComposer c(kFloor, false);
  c.Attach(Model("go1", (zoo / "unitree_go1/xmls/go1.xml").string(), {0, 0, 0.45}));
  c.Attach(Model("g1", (zoo / "unitree_g1/xmls/g1.xml").string(), {2, 0, 0.8}));
  c.Attach(Model("yam", (zoo / "i2rt_yam/xmls/yam.xml").string(), {-1, 0, 0},
                 {std::cos(M_PI / 4), 0, 0, std::sin(M_PI / 4)}));
  const ModelPtr in_memory(c.Compile({}));
  ASSERT_TRUE(in_memory);
  EXPECT_GE(mj_name2id(in_memory.get(), mjOBJ_SITE, "go1/FR"), 0);
  EXPECT_GE(mj_name2id(in_memory.get(), mjOBJ_BODY, "g1/pelvis"), 0);
  const ModelPtr saved = LoadXml(c.SaveXml({}));
  ASSERT_TRUE(saved);
  EXPECT_EQ(Trajectory(saved.get(), 200), Trajectory(in_memory.get(), 200));
}

}  // namespace
}  // namespace penumbra

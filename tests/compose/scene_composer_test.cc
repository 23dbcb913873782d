#include "penumbra/compose/scene_composer.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <memory>
#include <sstream>
#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/core/pose.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// ---------------------------------------------------------------------------------------
// helpers

struct ModelDeleter {
  void operator()(mjModel* m) const { mj_deleteModel(m); }
};
struct DataDeleter {
  void operator()(mjData* d) const { mj_deleteData(d); }
};
using ModelPtr = std::unique_ptr<mjModel, ModelDeleter>;
using DataPtr = std::unique_ptr<mjData, DataDeleter>;

using penumbra::testing::TempDir;

// changes the working directory for the lifetime of the object
class ScopedCwd {
 public:
  explicit ScopedCwd(const std::string& dir) : old_(fs::current_path()) { fs::current_path(dir); }
  ~ScopedCwd() { fs::current_path(old_); }

 private:
  fs::path old_;
};

ModelPtr LoadFile(const std::string& path, std::string* error = nullptr) {
  char err[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, err, sizeof(err));
  if (error) *error = err;
  return ModelPtr(m);
}

// MuJoCo's URDF converter, as the physics module provides it
std::string UrdfToMjcf(const std::string& urdf_path) {
  char err[1000] = "";
  mjModel* m = mj_loadXML(urdf_path.c_str(), nullptr, err, sizeof(err));
  if (!m) throw ConfigError(urdf_path, 0, "", std::string("MuJoCo: ") + err);
  const std::string out =
      (fs::temp_directory_path() / ("penumbra_urdf_" + std::to_string(getpid()) + ".xml")).string();
  const int ok = mj_saveLastXML(out.c_str(), m, err, sizeof(err));
  mj_deleteModel(m);
  if (!ok) throw ConfigError(urdf_path, 0, "", std::string("MuJoCo save: ") + err);
  std::stringstream ss;
  ss << std::ifstream(out).rdbuf();
  fs::remove(out);
  return ss.str();
}

ModelConfig Model(const std::string& name, const std::string& file,
                  Eigen::Vector3d xyz = Eigen::Vector3d::Zero(),
                  Eigen::Vector3d rpy_deg = Eigen::Vector3d::Zero()) {
  ModelConfig m;
  m.name = name;
  m.file = file;
  m.pose.xyz = xyz;
  m.pose.rpy_deg = rpy_deg;
  return m;
}

ComposeOptions Options() {
  ComposeOptions o;
  o.urdf_to_mjcf = UrdfToMjcf;
  return o;
}

// composes, writes composed.xml into `dir` and loads it with MuJoCo (failing the test if
// MuJoCo rejects it)
ModelPtr ComposeAndLoad(const std::vector<ModelConfig>& models, const TempDir& dir,
                        ComposedScene* scene_out = nullptr, ComposeOptions opt = Options()) {
  const ComposedScene scene = ComposeWorld(models, opt);
  const std::string path = dir.str() + "/composed.xml";
  WriteComposedScene(scene, path);
  std::string err;
  ModelPtr m = LoadFile(path, &err);
  EXPECT_TRUE(m) << "MuJoCo rejected the composed model: " << err << "\n" << scene.Xml();
  if (scene_out) *scene_out = scene;
  return m;
}

int Id(const mjModel* m, mjtObj type, const std::string& name) {
  return mj_name2id(m, type, name.c_str());
}

std::string Name(const mjModel* m, mjtObj type, int id) {
  const char* n = mj_id2name(m, type, id);
  return n ? n : "";
}

Eigen::Vector3d V3(const mjtNum* v) { return Eigen::Vector3d(v[0], v[1], v[2]); }
Eigen::Quaterniond Q(const mjtNum* q) { return Eigen::Quaterniond(q[0], q[1], q[2], q[3]); }

void ExpectSameRotation(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b,
                        const std::string& what) {
  EXPECT_GT(std::abs(a.normalized().dot(b.normalized())), 1 - 1e-10)
      << what << ": " << a.coeffs().transpose() << " vs " << b.coeffs().transpose();
}

void ExpectNear3(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double tol,
                 const std::string& what) {
  EXPECT_LT((a - b).norm(), tol) << what << ": " << a.transpose() << " vs " << b.transpose();
}

// compares model `alone` (loaded by itself) with its copy in `comp` (names prefixed by
// `prefix`, placed by X_WM). top-level bodies and world geoms are compared after placement;
// world geoms of the copy start at `world_geom_offset` in `comp`.
void ExpectSameModel(const mjModel* comp, const std::string& prefix, const mjModel* alone,
                     const Pose& X_WM, int world_geom_offset) {
  const Eigen::Quaterniond q_WM(X_WM.linear());
  for (int b = 1; b < alone->nbody; ++b) {
    const std::string name = Name(alone, mjOBJ_BODY, b);
    ASSERT_FALSE(name.empty()) << "test models name every body";
    const int cb = Id(comp, mjOBJ_BODY, prefix + name);
    ASSERT_GE(cb, 0) << "body " << prefix + name << " missing";
    const bool top = alone->body_parentid[b] == 0;
    Eigen::Vector3d pos = V3(alone->body_pos + 3 * b);
    Eigen::Quaterniond quat = Q(alone->body_quat + 4 * b);
    if (top) {
      pos = X_WM * pos;
      quat = q_WM * quat;
    } else {
      EXPECT_EQ(Name(comp, mjOBJ_BODY, comp->body_parentid[cb]),
                prefix + Name(alone, mjOBJ_BODY, alone->body_parentid[b]));
    }
    ExpectNear3(V3(comp->body_pos + 3 * cb), pos, 1e-9, "body_pos " + name);
    ExpectSameRotation(Q(comp->body_quat + 4 * cb), quat, "body_quat " + name);
    EXPECT_NEAR(comp->body_mass[cb], alone->body_mass[b], 1e-9) << name;
    ExpectNear3(V3(comp->body_ipos + 3 * cb), V3(alone->body_ipos + 3 * b), 1e-9,
                "body_ipos " + name);
    // inertia tensors (principal axes are ambiguous for repeated eigenvalues)
    const auto tensor = [](const mjtNum* iquat, const mjtNum* diag) {
      const Eigen::Matrix3d r = Q(iquat).normalized().toRotationMatrix();
      return Eigen::Matrix3d(r * V3(diag).asDiagonal() * r.transpose());
    };
    EXPECT_LT((tensor(comp->body_iquat + 4 * cb, comp->body_inertia + 3 * cb) -
               tensor(alone->body_iquat + 4 * b, alone->body_inertia + 3 * b))
                  .norm(),
              1e-9)
        << "inertia " << name;
    EXPECT_EQ(comp->body_mocapid[cb] >= 0, alone->body_mocapid[b] >= 0) << name;
    // geoms of this body, in order
    ASSERT_EQ(comp->body_geomnum[cb], alone->body_geomnum[b]) << name;
    for (int k = 0; k < alone->body_geomnum[b]; ++k) {
      const int g = alone->body_geomadr[b] + k;
      const int cg = comp->body_geomadr[cb] + k;
      const std::string what = "geom " + std::to_string(k) + " of " + name;
      EXPECT_EQ(Name(comp, mjOBJ_GEOM, cg),
                Name(alone, mjOBJ_GEOM, g).empty() ? "" : prefix + Name(alone, mjOBJ_GEOM, g));
      EXPECT_EQ(comp->geom_type[cg], alone->geom_type[g]) << what;
      ExpectNear3(V3(comp->geom_pos + 3 * cg), V3(alone->geom_pos + 3 * g), 1e-9, what);
      ExpectSameRotation(Q(comp->geom_quat + 4 * cg), Q(alone->geom_quat + 4 * g), what);
      ExpectNear3(V3(comp->geom_size + 3 * cg), V3(alone->geom_size + 3 * g), 1e-9, what);
      for (int i = 0; i < 4; ++i)
        EXPECT_EQ(comp->geom_rgba[4 * cg + i], alone->geom_rgba[4 * g + i]);
      EXPECT_EQ(comp->geom_contype[cg], alone->geom_contype[g]) << what;
      EXPECT_EQ(comp->geom_condim[cg], alone->geom_condim[g]) << what;
      EXPECT_EQ(comp->geom_friction[3 * cg], alone->geom_friction[3 * g]) << what;
      EXPECT_EQ(comp->geom_matid[cg] >= 0, alone->geom_matid[g] >= 0) << what;
      if (alone->geom_matid[g] >= 0) {
        EXPECT_EQ(Name(comp, mjOBJ_MATERIAL, comp->geom_matid[cg]),
                  prefix + Name(alone, mjOBJ_MATERIAL, alone->geom_matid[g]));
      }
    }
  }
  // geoms of the world body (placed)
  for (int k = 0; k < alone->body_geomnum[0]; ++k) {
    const int g = alone->body_geomadr[0] + k;
    const int cg = comp->body_geomadr[0] + world_geom_offset + k;
    ASSERT_LT(cg, comp->body_geomadr[0] + comp->body_geomnum[0]);
    const std::string what = "world geom " + std::to_string(k);
    EXPECT_EQ(comp->geom_type[cg], alone->geom_type[g]) << what;
    ExpectNear3(V3(comp->geom_pos + 3 * cg), X_WM * V3(alone->geom_pos + 3 * g), 1e-9, what);
    ExpectSameRotation(Q(comp->geom_quat + 4 * cg), q_WM * Q(alone->geom_quat + 4 * g), what);
    ExpectNear3(V3(comp->geom_size + 3 * cg), V3(alone->geom_size + 3 * g), 1e-9, what);
  }
  // joints
  for (int j = 0; j < alone->njnt; ++j) {
    const std::string name = Name(alone, mjOBJ_JOINT, j);
    if (name.empty()) continue;
    const int cj = Id(comp, mjOBJ_JOINT, prefix + name);
    ASSERT_GE(cj, 0) << "joint " << prefix + name;
    EXPECT_EQ(comp->jnt_type[cj], alone->jnt_type[j]) << name;
    EXPECT_EQ(comp->jnt_limited[cj], alone->jnt_limited[j]) << name;
    EXPECT_NEAR(comp->jnt_range[2 * cj], alone->jnt_range[2 * j], 1e-12) << name;
    EXPECT_NEAR(comp->jnt_range[2 * cj + 1], alone->jnt_range[2 * j + 1], 1e-12) << name;
    ExpectNear3(V3(comp->jnt_axis + 3 * cj), V3(alone->jnt_axis + 3 * j), 1e-12, name);
    EXPECT_EQ(comp->dof_damping[comp->jnt_dofadr[cj]], alone->dof_damping[alone->jnt_dofadr[j]]);
    EXPECT_EQ(comp->jnt_stiffness[cj], alone->jnt_stiffness[j]) << name;
    if (alone->jnt_type[j] == mjJNT_HINGE || alone->jnt_type[j] == mjJNT_SLIDE) {
      EXPECT_NEAR(comp->qpos0[comp->jnt_qposadr[cj]], alone->qpos0[alone->jnt_qposadr[j]], 1e-12)
          << name;
      EXPECT_NEAR(comp->qpos_spring[comp->jnt_qposadr[cj]],
                  alone->qpos_spring[alone->jnt_qposadr[j]], 1e-12)
          << name;
    }
  }
  // actuators: same parameters, transmission on the prefixed target
  for (int a = 0; a < alone->nu; ++a) {
    const std::string name = Name(alone, mjOBJ_ACTUATOR, a);
    ASSERT_FALSE(name.empty()) << "test models name every actuator";
    const int ca = Id(comp, mjOBJ_ACTUATOR, prefix + name);
    ASSERT_GE(ca, 0) << prefix + name;
    EXPECT_EQ(comp->actuator_trntype[ca], alone->actuator_trntype[a]);
    EXPECT_EQ(comp->actuator_dyntype[ca], alone->actuator_dyntype[a]);
    for (int i = 0; i < 3; ++i) {
      EXPECT_EQ(comp->actuator_gainprm[mjNGAIN * ca + i], alone->actuator_gainprm[mjNGAIN * a + i]);
      EXPECT_EQ(comp->actuator_biasprm[mjNBIAS * ca + i], alone->actuator_biasprm[mjNBIAS * a + i]);
    }
    EXPECT_EQ(comp->actuator_gear[6 * ca], alone->actuator_gear[6 * a]);
    EXPECT_EQ(comp->actuator_ctrlrange[2 * ca + 1], alone->actuator_ctrlrange[2 * a + 1]);
    const mjtObj trn_obj = alone->actuator_trntype[a] == mjTRN_TENDON ? mjOBJ_TENDON
                           : alone->actuator_trntype[a] == mjTRN_SITE ? mjOBJ_SITE
                           : alone->actuator_trntype[a] == mjTRN_BODY ? mjOBJ_BODY
                                                                      : mjOBJ_JOINT;
    EXPECT_EQ(Name(comp, trn_obj, comp->actuator_trnid[2 * ca]),
              prefix + Name(alone, trn_obj, alone->actuator_trnid[2 * a]))
        << "transmission of " << name;
  }
  // sensors: same type, object prefixed
  for (int s = 0; s < alone->nsensor; ++s) {
    const std::string name = Name(alone, mjOBJ_SENSOR, s);
    if (name.empty()) continue;
    const int cs = Id(comp, mjOBJ_SENSOR, prefix + name);
    ASSERT_GE(cs, 0) << prefix + name;
    EXPECT_EQ(comp->sensor_type[cs], alone->sensor_type[s]);
    const mjtObj t = static_cast<mjtObj>(alone->sensor_objtype[s]);
    const std::string obj = Name(alone, t, alone->sensor_objid[s]);
    if (!obj.empty()) {
      EXPECT_EQ(Name(comp, t, comp->sensor_objid[cs]), prefix + obj);
    }
  }
  // cameras keep their field of view (always degrees in MJCF)
  for (int c = 0; c < alone->ncam; ++c) {
    const int cc = Id(comp, mjOBJ_CAMERA, prefix + Name(alone, mjOBJ_CAMERA, c));
    ASSERT_GE(cc, 0);
    EXPECT_EQ(comp->cam_fovy[cc], alone->cam_fovy[c]);
  }
  EXPECT_EQ(comp->opt.timestep > 0, true);
}

// ---------------------------------------------------------------------------------------
// test models

// a tetrahedron in OBJ format
constexpr const char* kTetraObj =
    "v 0 0 0\nv 0.1 0 0\nv 0 0.1 0\nv 0 0 0.1\nf 1 3 2\nf 1 2 4\nf 1 4 3\nf 2 3 4\n";

// MuJoCo's custom height-field format: int32 nrow, int32 ncol, float32 data[nrow*ncol]
std::string HFieldBin() {
  std::string s;
  const int32_t rows = 3, cols = 4;
  s.append(reinterpret_cast<const char*>(&rows), 4);
  s.append(reinterpret_cast<const char*>(&cols), 4);
  for (int i = 0; i < rows * cols; ++i) {
    const float v = 0.1f * static_cast<float>(i % 5);
    s.append(reinterpret_cast<const char*>(&v), 4);
  }
  return s;
}

// a small robot that uses most of what MJCF names: degree angles, euler, default classes,
// mesh/hfield files under meshdir, tendons, actuators, sensors, contact, equality, keys
constexpr const char* kRobot = R"(
<mujoco model="robot">
  <compiler angle="degree" meshdir="assets" autolimits="true"/>
  <option timestep="0.004"/>
  <default>
    <geom rgba="0.2 0.6 0.2 1" friction="0.8 0.005 0.0001"/>
    <joint damping="0.5"/>
    <default class="arm">
      <joint damping="2" range="-90 90" armature="0.01"/>
      <geom type="capsule" size="0.03" rgba="0.9 0.1 0.1 1"/>
      <default class="wrist">
        <joint type="slide" range="-0.1 0.2"/>
      </default>
    </default>
    <motor ctrlrange="-1 1" gear="5"/>
  </default>
  <asset>
    <mesh name="tetra" file="tetra.obj"/>
    <hfield name="ground" file="ground.bin" size="1 1 0.1 0.05"/>
    <texture name="checker" type="2d" builtin="checker" width="32" height="32" rgb1="1 1 1" rgb2="0 0 0"/>
    <material name="mat" texture="checker" rgba="1 1 1 1"/>
  </asset>
  <worldbody>
    <geom name="terrain" type="hfield" hfield="ground" pos="0 0 -0.2"/>
    <light name="lamp" pos="0 0 3" dir="0 0 -1" directional="true"/>
    <camera name="overview" pos="2 0 1" euler="0 60 90" fovy="50"/>
    <body name="base" pos="0 0 0.5" euler="0 0 30">
      <freejoint name="root"/>
      <geom name="torso" type="box" size="0.1 0.1 0.05" material="mat"/>
      <geom name="deco" type="mesh" mesh="tetra" pos="0 0 0.05" euler="90 0 0" contype="0" conaffinity="0"/>
      <site name="imu" pos="0 0 0.05"/>
      <site name="anchor" pos="0.1 0 0"/>
      <body name="upper" pos="0.1 0 0" childclass="arm">
        <joint name="shoulder" axis="0 1 0" ref="10" springref="20"/>
        <geom name="upper_geom" fromto="0 0 0 0.2 0 0"/>
        <site name="upper_site" pos="0.2 0 0"/>
        <body name="lower" pos="0.2 0 0" axisangle="0 0 1 45">
          <joint name="elbow" axis="0 1 0" range="-120 5"/>
          <joint name="extend" class="wrist" axis="1 0 0"/>
          <geom name="lower_geom" fromto="0 0 0 0.15 0 0"/>
          <camera name="wrist_cam" pos="0.15 0 0" euler="0 -90 0" fovy="70"/>
        </body>
      </body>
      <body name="ball_link" pos="-0.1 0 0">
        <joint name="ball" type="ball" range="0 60"/>
        <geom name="ball_geom" type="sphere" size="0.03"/>
      </body>
    </body>
  </worldbody>
  <contact>
    <exclude name="no_self" body1="base" body2="upper"/>
    <pair name="p" geom1="lower_geom" geom2="terrain"/>
  </contact>
  <equality>
    <joint name="couple" joint1="elbow" joint2="shoulder" polycoef="0 0.5 0 0 0" active="false"/>
    <weld name="pin" body1="ball_link" body2="world" active="false"/>
  </equality>
  <custom>
    <numeric name="gains" data="1 2 3"/>
    <text name="note" data="hello"/>
    <tuple name="links">
      <element objtype="body" objname="upper" prm="1"/>
      <element objtype="joint" objname="elbow" prm="2"/>
    </tuple>
  </custom>
  <tendon>
    <fixed name="sum">
      <joint joint="shoulder" coef="1"/>
      <joint joint="elbow" coef="1"/>
    </fixed>
    <spatial name="cable" width="0.005">
      <site site="anchor"/>
      <site site="upper_site"/>
    </spatial>
  </tendon>
  <actuator>
    <motor name="m_shoulder" joint="shoulder"/>
    <position name="p_elbow" joint="elbow" kp="10"/>
    <motor name="m_sum" tendon="sum" gear="2"/>
    <general name="g_site" site="imu" refsite="anchor" gear="0 0 1 0 0 0"/>
    <general name="g_extend" joint="extend" dyntype="filter" dynprm="0.1"/>
  </actuator>
  <sensor>
    <jointpos name="s_shoulder" joint="shoulder"/>
    <touch name="s_touch" site="imu"/>
    <framepos name="s_frame" objtype="body" objname="lower"/>
    <tendonpos name="s_sum" tendon="sum"/>
    <actuatorfrc name="s_act" actuator="m_shoulder"/>
    <subtreecom name="s_com" body="base"/>
    <framequat name="s_rel" objtype="site" objname="imu" reftype="body" refname="upper"/>
  </sensor>
  <keyframe>
    <key name="home" qpos="0.3 0 0.6 1 0 0 0  0.2 -0.4 0.05  1 0 0 0" ctrl="0.1 0.2 0.3 0.35 0.4" act="0.5"/>
  </keyframe>
</mujoco>
)";

std::string WriteRobot(const TempDir& dir, const std::string& folder = "robot") {
  dir.Write(folder + "/assets/tetra.obj", kTetraObj);
  dir.Write(folder + "/assets/ground.bin", HFieldBin());
  return dir.Write(folder + "/robot.xml", kRobot);
}

// ---------------------------------------------------------------------------------------
// tests

TEST(SceneComposerTest, TwoCopiesOfARobotComposeAndMatchTheRobotAlone) {
  TempDir dir;
  const std::string robot = WriteRobot(dir);
  ModelPtr alone = LoadFile(robot);
  ASSERT_TRUE(alone);

  const Pose X_b = PoseFromXyzRpyDeg({2, 1, 0}, {0, 0, 90});
  ComposedScene scene;
  ModelPtr m =
      ComposeAndLoad({Model("a", robot), Model("b", robot, {2, 1, 0}, {0, 0, 90})}, dir, &scene);
  ASSERT_TRUE(m);
  EXPECT_EQ(scene.model_names, (std::vector<std::string>{"a", "b"}));
  // deterministic text
  EXPECT_EQ(
      ComposeWorld({Model("a", robot), Model("b", robot, {2, 1, 0}, {0, 0, 90})}, Options()).Xml(),
      scene.Xml());
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings[0];

  // everything doubled
  EXPECT_EQ(m->nbody, 2 * (alone->nbody - 1) + 1);
  EXPECT_EQ(m->ngeom, 2 * alone->ngeom);
  EXPECT_EQ(m->njnt, 2 * alone->njnt);
  EXPECT_EQ(m->nu, 2 * alone->nu);
  EXPECT_EQ(m->na, 2 * alone->na);
  EXPECT_EQ(m->nsensor, 2 * alone->nsensor);
  EXPECT_EQ(m->ntendon, 2 * alone->ntendon);
  EXPECT_EQ(m->neq, 2 * alone->neq);
  EXPECT_EQ(m->nexclude, 2 * alone->nexclude);
  EXPECT_EQ(m->npair, 2 * alone->npair);
  EXPECT_EQ(m->nmesh, 2 * alone->nmesh);
  EXPECT_EQ(m->nhfield, 2 * alone->nhfield);
  EXPECT_EQ(m->nmat, 2 * alone->nmat);
  EXPECT_EQ(m->ntex, 2 * alone->ntex);
  EXPECT_EQ(m->ncam, 2 * alone->ncam);
  EXPECT_EQ(m->nlight, 2 * alone->nlight);
  EXPECT_EQ(m->nkey, 2 * alone->nkey);
  EXPECT_EQ(m->opt.timestep, 0.004);

  // names are prefixed
  for (const char* name : {"base", "upper", "lower", "ball_link"}) {
    EXPECT_GE(Id(m.get(), mjOBJ_BODY, std::string("a/") + name), 0) << name;
    EXPECT_GE(Id(m.get(), mjOBJ_BODY, std::string("b/") + name), 0) << name;
    EXPECT_LT(Id(m.get(), mjOBJ_BODY, name), 0) << name;
  }
  for (const auto& [type, name] :
       std::vector<std::pair<mjtObj, std::string>>{{mjOBJ_JOINT, "shoulder"},
                                                   {mjOBJ_GEOM, "terrain"},
                                                   {mjOBJ_SITE, "imu"},
                                                   {mjOBJ_CAMERA, "wrist_cam"},
                                                   {mjOBJ_LIGHT, "lamp"},
                                                   {mjOBJ_MESH, "tetra"},
                                                   {mjOBJ_HFIELD, "ground"},
                                                   {mjOBJ_TEXTURE, "checker"},
                                                   {mjOBJ_MATERIAL, "mat"},
                                                   {mjOBJ_TENDON, "cable"},
                                                   {mjOBJ_ACTUATOR, "g_extend"},
                                                   {mjOBJ_SENSOR, "s_frame"},
                                                   {mjOBJ_EQUALITY, "couple"},
                                                   {mjOBJ_EXCLUDE, "no_self"},
                                                   {mjOBJ_PAIR, "p"},
                                                   {mjOBJ_KEY, "home"}}) {
    EXPECT_GE(Id(m.get(), type, "a/" + name), 0) << name;
    EXPECT_GE(Id(m.get(), type, "b/" + name), 0) << name;
  }

  // each copy matches the robot alone (degree angles, defaults, euler all preserved)
  ExpectSameModel(m.get(), "a/", alone.get(), Pose::Identity(), 0);
  ExpectSameModel(m.get(), "b/", alone.get(), X_b, alone->body_geomnum[0]);

  // b's actuators drive b's joints and tendons
  for (int a = 0; a < m->nu; ++a) {
    const std::string act = Name(m.get(), mjOBJ_ACTUATOR, a);
    const mjtObj t = m->actuator_trntype[a] == mjTRN_TENDON ? mjOBJ_TENDON
                     : m->actuator_trntype[a] == mjTRN_SITE ? mjOBJ_SITE
                                                            : mjOBJ_JOINT;
    EXPECT_EQ(act.substr(0, 2), Name(m.get(), t, m->actuator_trnid[2 * a]).substr(0, 2)) << act;
  }
  // contact exclude and equality refer to the own copy
  const int ex = Id(m.get(), mjOBJ_EXCLUDE, "b/no_self");
  // signature: (body1 + 1) << 16 | (body2 + 1); compare relative to the robot alone
  const int sig = m->exclude_signature[ex], sig_alone = alone->exclude_signature[0];
  EXPECT_EQ((sig >> 16) - Id(m.get(), mjOBJ_BODY, "b/base"),
            (sig_alone >> 16) - Id(alone.get(), mjOBJ_BODY, "base"));
  EXPECT_EQ((sig & 0xFFFF) - Id(m.get(), mjOBJ_BODY, "b/upper"),
            (sig_alone & 0xFFFF) - Id(alone.get(), mjOBJ_BODY, "upper"));
  const int eq = Id(m.get(), mjOBJ_EQUALITY, "b/couple");
  EXPECT_EQ(m->eq_obj1id[eq], Id(m.get(), mjOBJ_JOINT, "b/elbow"));
  EXPECT_EQ(m->eq_obj2id[eq], Id(m.get(), mjOBJ_JOINT, "b/shoulder"));
  // weld to the world body, sensor reference frame, site transmission, custom tuple
  const int pin = Id(m.get(), mjOBJ_EQUALITY, "b/pin");
  EXPECT_EQ(m->eq_obj1id[pin], Id(m.get(), mjOBJ_BODY, "b/ball_link"));
  EXPECT_EQ(m->eq_obj2id[pin], 0);
  const int rel = Id(m.get(), mjOBJ_SENSOR, "b/s_rel");
  EXPECT_EQ(m->sensor_refid[rel], Id(m.get(), mjOBJ_BODY, "b/upper"));
  const int gs = Id(m.get(), mjOBJ_ACTUATOR, "b/g_site");
  EXPECT_EQ(m->actuator_trnid[2 * gs], Id(m.get(), mjOBJ_SITE, "b/imu"));
  EXPECT_EQ(m->actuator_trnid[2 * gs + 1], Id(m.get(), mjOBJ_SITE, "b/anchor"));
  EXPECT_EQ(m->nnumeric, 2);
  EXPECT_EQ(m->ntext, 2);
  const int tup = Id(m.get(), mjOBJ_TUPLE, "b/links");
  ASSERT_GE(tup, 0);
  EXPECT_EQ(m->tuple_objid[m->tuple_adr[tup]], Id(m.get(), mjOBJ_BODY, "b/upper"));
  EXPECT_EQ(m->tuple_objid[m->tuple_adr[tup] + 1], Id(m.get(), mjOBJ_JOINT, "b/elbow"));
  EXPECT_GE(Id(m.get(), mjOBJ_NUMERIC, "b/gains"), 0);
  EXPECT_GE(Id(m.get(), mjOBJ_TEXT, "a/note"), 0);
  // top-level light direction is rotated with the model (90 deg about z keeps -z)
  const int lamp = Id(m.get(), mjOBJ_LIGHT, "b/lamp");
  ExpectNear3(V3(m->light_pos + 3 * lamp), X_b * Eigen::Vector3d(0, 0, 3), 1e-12, "lamp pos");
  ExpectNear3(V3(m->light_dir + 3 * lamp), Eigen::Vector3d(0, 0, -1), 1e-12, "lamp dir");

  // the composed file has no relative asset paths and loads from another folder
  TempDir elsewhere;
  const std::string moved = elsewhere.str() + "/scene.xml";
  WriteComposedScene(scene, moved);
  ScopedCwd cwd(elsewhere.str());
  std::string err;
  EXPECT_TRUE(LoadFile("scene.xml", &err)) << err;
}

TEST(SceneComposerTest, KeyframesCoverAllModelsAndArePlaced) {
  TempDir dir;
  const std::string robot = WriteRobot(dir);
  ModelPtr alone = LoadFile(robot);
  ASSERT_TRUE(alone);
  const Pose X_b = PoseFromXyzRpyDeg({2, 1, 0}, {0, 0, 90});
  ModelPtr m = ComposeAndLoad({Model("a", robot), Model("b", robot, {2, 1, 0}, {0, 0, 90})}, dir);
  ASSERT_TRUE(m);
  ASSERT_EQ(m->nq, 2 * alone->nq);
  DataPtr d(mj_makeData(m.get()));
  DataPtr da(mj_makeData(alone.get()));

  // key "b/home": b's slice is the key placed by b's pose, a stays at qpos0
  const int kb = Id(m.get(), mjOBJ_KEY, "b/home");
  ASSERT_GE(kb, 0);
  mj_resetDataKeyframe(m.get(), d.get(), kb);
  mj_resetDataKeyframe(alone.get(), da.get(), 0);
  mj_forward(m.get(), d.get());
  mj_forward(alone.get(), da.get());
  for (int i = 0; i < alone->nq; ++i) EXPECT_EQ(d->qpos[i], m->qpos0[i]) << i;
  for (int i = 7; i < alone->nq; ++i) EXPECT_NEAR(d->qpos[alone->nq + i], da->qpos[i], 1e-12);
  for (int i = 0; i < alone->nu; ++i) {
    const std::string act = Name(alone.get(), mjOBJ_ACTUATOR, i);
    EXPECT_EQ(d->ctrl[Id(m.get(), mjOBJ_ACTUATOR, "a/" + act)], 0) << act;
    EXPECT_EQ(d->ctrl[Id(m.get(), mjOBJ_ACTUATOR, "b/" + act)], da->ctrl[i]) << act;
  }
  EXPECT_EQ(d->act[1], da->act[0]);
  // every body of b is where the key puts the robot alone, moved by b's pose
  for (int b = 1; b < alone->nbody; ++b) {
    const int cb = Id(m.get(), mjOBJ_BODY, "b/" + Name(alone.get(), mjOBJ_BODY, b));
    ExpectNear3(V3(d->xpos + 3 * cb), X_b * V3(da->xpos + 3 * b), 1e-9, "xpos");
  }
}

TEST(SceneComposerTest, DefaultsOfOneModelDoNotLeakIntoAnother) {
  TempDir dir;
  const std::string a = dir.Write("a.xml", R"(
<mujoco>
  <default>
    <geom type="box" size="0.3 0.3 0.3" rgba="1 0 0 1" euler="0 0 45"/>
    <joint type="slide" damping="7"/>
    <default class="x"><geom rgba="0 1 0 1"/></default>
  </default>
  <worldbody>
    <geom name="floor_a" type="plane" size="1 1 0.1"/>
    <body name="box" pos="0 0 1"><joint name="j"/><geom name="g"/><geom name="gx" class="x"/></body>
  </worldbody>
</mujoco>)");
  const std::string b = dir.Write("b.xml", R"(
<mujoco>
  <default><default class="x"><geom rgba="0 0 1 1" size="0.05"/></default></default>
  <worldbody>
    <geom name="floor_b" type="plane" size="2 2 0.1"/>
    <body name="ball" pos="0 0 1"><joint name="j"/><geom name="g" size="0.1"/><geom name="gx" class="x"/></body>
  </worldbody>
</mujoco>)");
  ModelPtr ma = LoadFile(a);
  ModelPtr mb = LoadFile(b);
  ASSERT_TRUE(ma && mb);
  ModelPtr m = ComposeAndLoad({Model("a", a), Model("b", b, {3, 0, 0})}, dir);
  ASSERT_TRUE(m);
  ExpectSameModel(m.get(), "a/", ma.get(), Pose::Identity(), 0);
  ExpectSameModel(m.get(), "b/", mb.get(), PoseFromXyzRpyDeg({3, 0, 0}, {0, 0, 0}), 1);
  // explicitly: b's geoms are MuJoCo-default spheres, b's joint a damping-free hinge
  const int g = Id(m.get(), mjOBJ_GEOM, "b/g");
  EXPECT_EQ(m->geom_type[g], mjGEOM_SPHERE);
  EXPECT_FLOAT_EQ(m->geom_rgba[4 * g], 0.5f);
  const int j = Id(m.get(), mjOBJ_JOINT, "b/j");
  EXPECT_EQ(m->jnt_type[j], mjJNT_HINGE);
  EXPECT_EQ(m->dof_damping[m->jnt_dofadr[j]], 0);
  EXPECT_EQ(m->geom_rgba[4 * Id(m.get(), mjOBJ_GEOM, "b/gx") + 2], 1);  // b's own class x
  EXPECT_EQ(m->geom_rgba[4 * Id(m.get(), mjOBJ_GEOM, "a/gx") + 1], 1);  // a's own class x
  EXPECT_EQ(m->geom_type[Id(m.get(), mjOBJ_GEOM, "a/g")], mjGEOM_BOX);
}

TEST(SceneComposerTest, DegreeAndRadianModelsWithDifferentEulerSequencesAgree) {
  TempDir dir;
  // the same model written in degrees with intrinsic xyz and in radians with extrinsic ZYX
  const std::string deg = dir.Write("deg.xml", R"(
<mujoco>
  <compiler angle="degree" eulerseq="xyz" autolimits="true"/>
  <default><geom euler="10 20 30" size="0.05"/><joint range="-30 60"/></default>
  <worldbody>
    <body name="b" pos="0 0 1" euler="30 -20 60">
      <joint name="hinge" ref="15" springref="-5"/>
      <joint name="slide" type="slide" range="-0.5 0.25" axis="1 0 0"/>
      <geom name="g1" type="box" size="0.1 0.1 0.1"/>
      <geom name="g2" type="box" size="0.1 0.2 0.1" axisangle="1 1 0 75"/>
      <inertial pos="0 0 0" mass="1" diaginertia="0.1 0.2 0.3" euler="0 90 0"/>
      <body name="c" pos="0.1 0 0">
        <joint name="ball" type="ball" range="0 45"/>
        <geom name="g3" type="capsule" size="0.02 0.1" quat="0 1 0 0"/>
        <site name="s" euler="0 0 90"/>
        <camera name="cam" euler="45 0 0" fovy="30"/>
      </body>
    </body>
  </worldbody>
</mujoco>)");
  const std::string rad = dir.Write("rad.xml", R"(
<mujoco>
  <compiler angle="radian" eulerseq="ZYX" autolimits="true"/>
  <default><joint range="-0.5 1"/></default>
  <worldbody>
    <body name="b" pos="0 0 1" euler="1 0.5 -0.25">
      <joint name="hinge" ref="0.3" springref="0.1"/>
      <joint name="slide" type="slide" range="-0.5 0.25" axis="1 0 0"/>
      <geom name="g1" type="box" size="0.1 0.1 0.1" euler="0.1 0.2 0.3"/>
      <body name="c" pos="0.1 0 0">
        <joint name="ball" type="ball" range="0 0.7"/>
        <geom name="g3" type="capsule" size="0.02 0.1" axisangle="0 1 0 1.2"/>
      </body>
    </body>
  </worldbody>
</mujoco>)");
  ModelPtr md = LoadFile(deg);
  ModelPtr mr = LoadFile(rad);
  ASSERT_TRUE(md && mr);
  ModelPtr m = ComposeAndLoad({Model("d", deg), Model("r", rad)}, dir);
  ASSERT_TRUE(m);
  ExpectSameModel(m.get(), "d/", md.get(), Pose::Identity(), 0);
  ExpectSameModel(m.get(), "r/", mr.get(), Pose::Identity(), 0);
  // spot checks against hand-computed values
  const int h = Id(m.get(), mjOBJ_JOINT, "d/hinge");
  EXPECT_NEAR(m->jnt_range[2 * h + 1], M_PI / 3, 1e-12);
  EXPECT_NEAR(m->qpos0[m->jnt_qposadr[h]], 15 * M_PI / 180, 1e-12);
  const int s = Id(m.get(), mjOBJ_JOINT, "d/slide");
  EXPECT_EQ(m->jnt_range[2 * s], -0.5);  // metres, not converted
  const int c = Id(m.get(), mjOBJ_CAMERA, "d/cam");
  EXPECT_EQ(m->cam_fovy[c], 30);  // always degrees
  const int site = Id(m.get(), mjOBJ_SITE, "d/s");
  ExpectSameRotation(Q(m->site_quat + 4 * site),
                     Eigen::Quaterniond(Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ())),
                     "site");
}

TEST(SceneComposerTest, PosePlacesFreeBodiesGeomsAndFromto) {
  TempDir dir;
  const std::string f = dir.Write("free.xml", R"(
<mujoco>
  <worldbody>
    <geom name="floor" type="plane" size="1 1 0.1"/>
    <geom name="rod" type="capsule" fromto="0 0 0 1 0 0" size="0.01"/>
    <site name="mark" pos="1 0 0"/>
    <body name="box" pos="0.5 0 1" quat="1 0 0 0">
      <freejoint name="free"/>
      <geom type="box" size="0.1 0.1 0.1"/>
    </body>
  </worldbody>
</mujoco>)");
  const Pose X = PoseFromXyzRpyDeg({1, 2, 3}, {0, 0, 90});
  ModelPtr m = ComposeAndLoad({Model("m", f, {1, 2, 3}, {0, 0, 90})}, dir);
  ASSERT_TRUE(m);
  DataPtr d(mj_makeData(m.get()));
  mj_forward(m.get(), d.get());
  const int box = Id(m.get(), mjOBJ_BODY, "m/box");
  // (1,2,3) + Rz(90) (0.5, 0, 1) = (1, 2.5, 4)
  ExpectNear3(V3(d->xpos + 3 * box), Eigen::Vector3d(1, 2.5, 4), 1e-12, "free body xpos");
  ExpectSameRotation(Q(d->xquat + 4 * box), Eigen::Quaterniond(X.linear()), "free body xquat");
  // the free joint is still a top-level free joint (qpos = world pose)
  EXPECT_EQ(m->jnt_type[0], mjJNT_FREE);
  EXPECT_NEAR(d->qpos[1], 2.5, 1e-12);
  // the plane rotates with the model, the rod's fromto is moved
  const int floor = Id(m.get(), mjOBJ_GEOM, "m/floor");
  ExpectNear3(V3(d->geom_xpos + 3 * floor), Eigen::Vector3d(1, 2, 3), 1e-12, "floor");
  const int rod = Id(m.get(), mjOBJ_GEOM, "m/rod");
  ExpectNear3(V3(d->geom_xpos + 3 * rod), Eigen::Vector3d(1, 2.5, 3), 1e-12, "rod centre");
  Eigen::Map<const Eigen::Matrix<mjtNum, 3, 3, Eigen::RowMajor>> rod_mat(d->geom_xmat + 9 * rod);
  ExpectNear3(rod_mat.col(2).cwiseAbs(), Eigen::Vector3d(0, 1, 0), 1e-12, "rod axis");
  const int mark = Id(m.get(), mjOBJ_SITE, "m/mark");
  ExpectNear3(V3(d->site_xpos + 3 * mark), Eigen::Vector3d(1, 3, 3), 1e-12, "site");
  // after a second of falling the body is still above its start in x, y
  for (int i = 0; i < 100; ++i) mj_step(m.get(), d.get());
  EXPECT_NEAR(d->xpos[3 * box], 1, 1e-6);
  EXPECT_NEAR(d->xpos[3 * box + 1], 2.5, 1e-6);
}

TEST(SceneComposerTest, IncludesAndMeshdirResolveFromTheirFiles) {
  TempDir dir;
  dir.Write("proj/meshes/tetra.obj", kTetraObj);
  dir.Write("proj/parts/arm.xml", R"(
<mujoco>
  <body name="arm" pos="0 0 0.5">
    <joint name="j"/>
    <geom name="arm_mesh" type="mesh" mesh="tetra"/>
  </body>
  <include file="hand.xml"/>
</mujoco>)");
  // included from parts/arm.xml: resolved relative to the including file
  dir.Write("proj/parts/hand.xml", R"(
<mujoco><body name="hand" pos="0 0 1"><geom name="hand_geom" size="0.05"/></body></mujoco>)");
  dir.Write("proj/assets.xml", R"(
<mujoco><asset><mesh name="tetra" file="tetra.obj" scale="2 2 2"/></asset></mujoco>)");
  const std::string main = dir.Write("proj/main.xml", R"(
<mujoco>
  <compiler meshdir="meshes/"/>
  <include file="assets.xml"/>
  <worldbody>
    <include file="parts/arm.xml"/>
  </worldbody>
</mujoco>)");
  ModelPtr m = ComposeAndLoad({Model("x", main), Model("y", main, {0, 1, 0})}, dir);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->nmesh, 2);
  EXPECT_GE(Id(m.get(), mjOBJ_GEOM, "y/arm_mesh"), 0);
  EXPECT_GE(Id(m.get(), mjOBJ_BODY, "y/hand"), 0);
  EXPECT_EQ(m->geom_dataid[Id(m.get(), mjOBJ_GEOM, "y/arm_mesh")],
            Id(m.get(), mjOBJ_MESH, "y/tetra"));

  // composed text: absolute mesh path, no include left
  const ComposedScene scene = ComposeWorld({Model("x", main)}, Options());
  EXPECT_EQ(scene.Xml().find("<include"), std::string::npos);
  EXPECT_NE(scene.Xml().find(fs::canonical(dir.str()).string() + "/proj/meshes/tetra.obj"),
            std::string::npos)
      << scene.Xml();
}

TEST(SceneComposerTest, HumanoidSampleComposesTwice) {
  const std::string humanoid = "/usr/share/mujoco/model/humanoid/humanoid.xml";
  if (!fs::exists(humanoid)) GTEST_SKIP() << "MuJoCo samples not installed";
  TempDir dir;
  ModelPtr alone = LoadFile(humanoid);
  ASSERT_TRUE(alone);
  const Pose X_b = PoseFromXyzRpyDeg({0, 3, 0.1}, {0, 0, 180});
  ModelPtr m =
      ComposeAndLoad({Model("h1", humanoid), Model("h2", humanoid, {0, 3, 0.1}, {0, 0, 180})}, dir);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->nbody, 2 * alone->nbody - 1);
  EXPECT_EQ(m->njnt, 2 * alone->njnt);
  EXPECT_EQ(m->nu, 2 * alone->nu);
  EXPECT_EQ(m->nq, 2 * alone->nq);
  ExpectSameModel(m.get(), "h1/", alone.get(), Pose::Identity(), 0);
  ExpectSameModel(m.get(), "h2/", alone.get(), X_b, alone->body_geomnum[0]);
  // the spotlight of h2 still targets h2's torso
  const int light = Id(m.get(), mjOBJ_LIGHT, "h2/spotlight");
  EXPECT_EQ(m->light_targetbodyid[light], Id(m.get(), mjOBJ_BODY, "h2/torso"));
  // it simulates
  DataPtr d(mj_makeData(m.get()));
  for (int i = 0; i < 20; ++i) mj_step(m.get(), d.get());
  for (int i = 0; i < m->nq; ++i) ASSERT_TRUE(std::isfinite(d->qpos[i]));
}

// every MuJoCo sample that loads by itself composes with a second copy of itself
TEST(SceneComposerTest, MuJoCoSamplesComposeWithThemselves) {
  const std::vector<std::string> samples = {
      "/usr/share/mujoco/model/slider_crank/slider_crank.xml",
      "/usr/share/mujoco/model/tendon_arm/arm26.xml",
      "/usr/share/mujoco/model/mug/mug.xml",
      "/usr/share/mujoco/model/adhesion/active_adhesion.xml",
      "/usr/share/mujoco/model/hammock/hammock.xml",
      "/usr/share/mujoco/model/composite/rope.xml",
  };
  for (const std::string& sample : samples) {
    if (!fs::exists(sample)) continue;
    SCOPED_TRACE(sample);
    TempDir dir;
    ModelPtr alone = LoadFile(sample);
    ASSERT_TRUE(alone);
    ComposedScene scene;
    ModelPtr m = ComposeAndLoad({Model("p", sample), Model("q", sample, {5, 0, 0})}, dir, &scene);
    ASSERT_TRUE(m);
    EXPECT_EQ(m->nbody, 2 * alone->nbody - 1);
    EXPECT_EQ(m->ngeom, 2 * alone->ngeom);
    EXPECT_EQ(m->njnt, 2 * alone->njnt);
    EXPECT_EQ(m->nu, 2 * alone->nu);
    EXPECT_EQ(m->nsensor, 2 * alone->nsensor);
    EXPECT_EQ(m->ntendon, 2 * alone->ntendon);
    EXPECT_EQ(m->nmesh, 2 * alone->nmesh);
  }
}

TEST(SceneComposerTest, KeyframesAreDroppedWithAWarningWhenSizesAreUnknown) {
  const std::string rope = "/usr/share/mujoco/model/composite/rope.xml";
  if (!fs::exists(rope)) GTEST_SKIP() << "MuJoCo samples not installed";
  TempDir dir;
  const std::string robot = WriteRobot(dir);
  ComposedScene scene;
  ModelPtr m = ComposeAndLoad({Model("robot", robot), Model("rope", rope, {3, 0, 0})}, dir, &scene);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->nkey, 0);
  int dropped = 0;
  for (const std::string& w : scene.warnings) {
    if (w.find("keyframes dropped") == std::string::npos) continue;
    ++dropped;
    EXPECT_NE(w.find("composite"), std::string::npos) << w;
    EXPECT_NE(w.find("rope.xml"), std::string::npos) << w;
  }
  EXPECT_EQ(dropped, 1);
}

TEST(SceneComposerTest, UrdfGoesThroughTheConverter) {
  TempDir dir;
  dir.Write("urdf/meshes/tetra.obj", kTetraObj);
  const std::string urdf = dir.Write("urdf/arm.urdf", R"(
<robot name="arm">
  <link name="base"/>
  <link name="link1">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><mesh filename="package://arm/meshes/tetra.obj"/></geometry></collision>
  </link>
  <joint name="j1" type="revolute"><parent link="base"/><child link="link1"/>
    <origin xyz="0 0 0.1" rpy="0 0 0"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="1" velocity="1"/></joint>
</robot>)");
  // meshes resolve against the URDF's folder through its <mujoco><compiler meshdir>
  const std::string with_meshdir = dir.Write("urdf/arm2.urdf", R"(
<robot name="arm2">
  <mujoco><compiler meshdir="meshes"/></mujoco>
  <link name="base"/>
  <link name="link1">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <collision><geometry><mesh filename="package://arm/meshes/tetra.obj"/></geometry></collision>
  </link>
  <joint name="j1" type="continuous"><parent link="base"/><child link="link1"/><axis xyz="0 0 1"/></joint>
</robot>)");
  dir.Write("urdf/tetra.obj", kTetraObj);  // strippath: arm.urdf finds tetra.obj beside it
  ModelPtr alone = LoadFile(with_meshdir);
  ASSERT_TRUE(alone);
  ModelPtr m = ComposeAndLoad({Model("u", urdf), Model("v", with_meshdir, {1, 0, 0})}, dir);
  ASSERT_TRUE(m);
  EXPECT_GE(Id(m.get(), mjOBJ_JOINT, "u/j1"), 0);
  EXPECT_GE(Id(m.get(), mjOBJ_JOINT, "v/j1"), 0);
  EXPECT_NEAR(m->jnt_range[2 * Id(m.get(), mjOBJ_JOINT, "u/j1") + 1], 1, 1e-12);
  ExpectSameModel(m.get(), "v/", alone.get(), PoseFromXyzRpyDeg({1, 0, 0}, {0, 0, 0}), 0);

  // without a converter a URDF is a clear error
  ComposeOptions none;
  try {
    ComposeWorld({Model("u", urdf)}, none);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("arm.urdf"), std::string::npos) << e.what();
  }
}

// ---------------------------------------------------------------------------------------
// errors

std::string ComposeError(const std::vector<ModelConfig>& models) {
  try {
    ComposeWorld(models, Options());
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(SceneComposerTest, ErrorsNameTheFileLineAndWhatWasExpected) {
  TempDir dir;
  const std::string good =
      dir.Write("good.xml", "<mujoco><worldbody><geom size='1'/></worldbody></mujoco>");

  std::string e = ComposeError({Model("a", dir.str() + "/missing.xml")});
  EXPECT_NE(e.find("missing.xml"), std::string::npos) << e;
  EXPECT_NE(e.find("not found"), std::string::npos) << e;

  const std::string broken =
      dir.Write("broken.xml", "<mujoco>\n<worldbody>\n<geom size='1'>\n</mujoco>\n");
  e = ComposeError({Model("a", broken)});
  EXPECT_NE(e.find("broken.xml:"), std::string::npos) << e;
  EXPECT_NE(e.find("syntax"), std::string::npos) << e;

  const std::string unknown_joint = dir.Write("unknown.xml", R"(<mujoco>
  <worldbody><body name="b"><joint name="j"/><geom size="1"/></body></worldbody>
  <actuator>
    <motor name="m" joint="nope"/>
  </actuator>
</mujoco>)");
  e = ComposeError({Model("a", unknown_joint)});
  EXPECT_NE(e.find("unknown.xml:4"), std::string::npos) << e;
  EXPECT_NE(e.find("actuator.motor[m].joint"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown joint 'nope'"), std::string::npos) << e;

  const std::string unknown_class = dir.Write("class.xml", R"(<mujoco>
  <worldbody><geom class="nope" size="1"/></worldbody>
</mujoco>)");
  e = ComposeError({Model("a", unknown_class)});
  EXPECT_NE(e.find("class.xml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("default class 'nope'"), std::string::npos) << e;

  e = ComposeError({Model("a", good), Model("a", good)});
  EXPECT_NE(e.find("duplicate model name 'a'"), std::string::npos) << e;
  e = ComposeError({Model("a/b", good)});
  EXPECT_NE(e.find("'/'"), std::string::npos) << e;

  const std::string no_mesh = dir.Write("nomesh.xml", R"(<mujoco>
  <asset><mesh name="m" file="nowhere.stl"/></asset>
  <worldbody><geom type="mesh" mesh="m"/></worldbody>
</mujoco>)");
  e = ComposeError({Model("a", no_mesh)});
  EXPECT_NE(e.find("nomesh.xml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("nowhere.stl"), std::string::npos) << e;

  const std::string no_include = dir.Write("noinc.xml", R"(<mujoco>
  <include file="gone.xml"/>
</mujoco>)");
  e = ComposeError({Model("a", no_include)});
  EXPECT_NE(e.find("noinc.xml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("gone.xml"), std::string::npos) << e;

  // an error inside an included file names the included file and its line
  dir.Write("inc_bad.xml",
            "<mujoco>\n<worldbody>\n<geom size='1' material='nope'/>\n</worldbody>\n</mujoco>");
  const std::string includes_bad = dir.Write("includes_bad.xml", R"(<mujoco>
  <include file="inc_bad.xml"/>
</mujoco>)");
  e = ComposeError({Model("a", includes_bad)});
  EXPECT_NE(e.find("inc_bad.xml:3"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown material 'nope'"), std::string::npos) << e;

  const std::string cycle = dir.Write("cycle.xml", R"(<mujoco>
  <include file="cycle.xml"/>
</mujoco>)");
  e = ComposeError({Model("a", cycle)});
  EXPECT_NE(e.find("cycle.xml"), std::string::npos) << e;
  EXPECT_NE(e.find("include cycle"), std::string::npos) << e;

  const std::string boundmass = dir.Write("bm.xml", R"(<mujoco>
  <compiler boundmass="0.01"/>
  <worldbody><geom size="1"/></worldbody>
</mujoco>)");
  e = ComposeError({Model("a", good), Model("b", boundmass)});
  EXPECT_NE(e.find("bm.xml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("compiler.boundmass"), std::string::npos) << e;

  const std::string bad_elem =
      dir.Write("elem.xml", "<mujoco>\n<worldbody><body><gem/></body></worldbody></mujoco>");
  e = ComposeError({Model("a", bad_elem)});
  EXPECT_NE(e.find("elem.xml:2"), std::string::npos) << e;
  EXPECT_NE(e.find("<gem>"), std::string::npos) << e;
}

TEST(SceneComposerTest, TimestepOverrideAndCompilerReconciliation) {
  TempDir dir;
  const std::string a = dir.Write("a.xml", R"(<mujoco>
  <compiler inertiafromgeom="true"/>
  <option timestep="0.01" gravity="0 0 -5"/>
  <worldbody><body name="b"><freejoint/><inertial pos="0 0 0" mass="100" diaginertia="1 1 1"/>
    <geom size="0.1" mass="1"/></body></worldbody>
</mujoco>)");
  const std::string b = dir.Write("b.xml", R"(<mujoco>
  <compiler autolimits="true"/>
  <option timestep="0.002"/>
  <worldbody><body name="b"><joint name="j" range="0 1"/><inertial pos="0 0 0" mass="2" diaginertia="1 1 1"/>
    <geom size="0.1" mass="1"/></body></worldbody>
</mujoco>)");
  ModelPtr ma = LoadFile(a);
  ModelPtr mb = LoadFile(b);
  ASSERT_TRUE(ma && mb);
  ComposeOptions opt = Options();
  opt.timestep_sec = 0.001;
  ComposedScene scene;
  ModelPtr m = ComposeAndLoad({Model("a", a), Model("b", b)}, dir, &scene, opt);
  ASSERT_TRUE(m);
  EXPECT_EQ(m->opt.timestep, 0.001);
  EXPECT_EQ(m->opt.gravity[2], -5);
  // b's option differs only in the timestep, which the world file decides: no warning
  // (issue 17 point 8); without the world's timestep it warns, naming the attribute
  EXPECT_TRUE(scene.warnings.empty()) << scene.warnings.front();
  const ComposedScene unset = ComposeWorld({Model("a", a), Model("b", b)}, Options());
  ASSERT_EQ(unset.warnings.size(), 1u);
  EXPECT_NE(unset.warnings[0].find("'b'"), std::string::npos);
  EXPECT_NE(unset.warnings[0].find("(timestep)"), std::string::npos) << unset.warnings[0];
  // a's inertia from geoms (inertiafromgeom="true"), b's from its <inertial>
  EXPECT_NEAR(m->body_mass[Id(m.get(), mjOBJ_BODY, "a/b")], 1, 1e-12);
  EXPECT_NEAR(m->body_mass[Id(m.get(), mjOBJ_BODY, "b/b")], 2, 1e-12);
  EXPECT_EQ(m->jnt_limited[Id(m.get(), mjOBJ_JOINT, "b/j")], 1);
}

}  // namespace
}  // namespace penumbra

// issue 17 point 7: the world file's `sites:` add frames a model lacks (feet, TCP) to its
// bodies, on a body at a pose or at a geom's centre; bad names are errors naming the key.
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/compose/scene_composer.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

const char* kArm =
    "<mujoco>\n"
    "  <worldbody><body name=\"link\" pos=\"0 0 1\" euler=\"0 0 90\">\n"
    "    <joint name=\"j\" type=\"hinge\"/>\n"
    "    <geom name=\"finger\" type=\"capsule\" fromto=\"0.1 0 0 0.3 0 0\" size=\"0.01\"/>\n"
    "    <geom name=\"pad\" type=\"box\" pos=\"0 0.2 0\" size=\"0.01 0.01 0.01\"/>\n"
    "    <site name=\"existing\"/>\n"
    "  </body></worldbody>\n"
    "</mujoco>\n";

ModelConfig Arm(const std::string& file) {
  ModelConfig m;
  m.name = "arm";
  m.file = file;
  m.key = "robots[0]";
  m.pose.xyz = Eigen::Vector3d(1, 0, 0);
  return m;
}

SiteConfig Site(const std::string& name, const std::string& body, const std::string& geom,
                const Eigen::Vector3d& xyz) {
  SiteConfig s;
  s.name = name;
  s.body = body;
  s.geom = geom;
  s.pose.xyz = xyz;
  return s;
}

TEST(WorldSites, AddedOnBodiesAndAtGeomCentres) {
  penumbra::testing::TempDir dir;
  ModelConfig m = Arm(dir.Write("arm.xml", kArm));
  m.sites = {Site("tcp", "link", "", {0, 0, -0.1}), Site("tip", "", "finger", {0, 0, 0}),
             Site("pad_top", "", "pad", {0, 0, 0.01})};
  const ComposedScene s = ComposeWorld({m}, {});
  const std::string path = dir.Write("composed.xml", s.Xml());
  char error[1000] = "";
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
  ASSERT_NE(model, nullptr) << error;
  mjData* d = mj_makeData(model);
  mj_forward(model, d);
  const auto site = [&](const char* name) {
    const int id = mj_name2id(model, mjOBJ_SITE, name);
    EXPECT_GE(id, 0) << name;
    return Eigen::Vector3d(d->site_xpos[3 * id], d->site_xpos[3 * id + 1],
                           d->site_xpos[3 * id + 2]);
  };
  // link at (1, 0, 1) in the world, rotated 90 deg about z: body x -> world y
  EXPECT_TRUE(site("arm/tcp").isApprox(Eigen::Vector3d(1, 0, 0.9), 1e-12)) << site("arm/tcp");
  EXPECT_TRUE(site("arm/tip").isApprox(Eigen::Vector3d(1, 0.2, 1), 1e-12)) << site("arm/tip");
  EXPECT_TRUE(site("arm/pad_top").isApprox(Eigen::Vector3d(0.8, 0, 1.01), 1e-12))
      << site("arm/pad_top");
  mj_deleteData(d);
  mj_deleteModel(model);
}

TEST(WorldSites, BadNamesAreErrorsNamingTheKey) {
  penumbra::testing::TempDir dir;
  const std::string file = dir.Write("arm.xml", kArm);
  const auto error = [&](const SiteConfig& site) -> std::pair<std::string, std::string> {
    ModelConfig m = Arm(file);
    m.sites = {Site("ok", "link", "", {0, 0, 0}), site};
    try {
      ComposeWorld({m}, {});
    } catch (const ConfigError& e) {
      return {e.key(), e.what()};
    }
    return {"", "no error"};
  };
  auto [key, what] = error(Site("foot", "lnk", "", {0, 0, 0}));
  EXPECT_EQ(key, "robots[0].sites[1].body");
  EXPECT_NE(what.find("model 'arm' has no body 'lnk'; expected one of its bodies: link"),
            std::string::npos)
      << what;
  std::tie(key, what) = error(Site("foot", "", "toe", {0, 0, 0}));
  EXPECT_EQ(key, "robots[0].sites[1].geom");
  EXPECT_NE(what.find("expected one of its named geoms: finger, pad"), std::string::npos) << what;
  std::tie(key, what) = error(Site("existing", "link", "", {0, 0, 0}));
  EXPECT_EQ(key, "robots[0].sites[1].name");
  std::tie(key, what) = error(Site("ok", "link", "", {0, 0, 0}));
  EXPECT_EQ(key, "robots[0].sites[1].name");
}

}  // namespace
}  // namespace penumbra

namespace penumbra {
namespace {

// geoms positioned through default classes in every way MJCF allows: a nested class
// (Menagerie's Go2 feet), a body's childclass, a fromto set by a class, a geom's own pos over
// its class's, a class of the second model (composed classes are prefixed)
const char* kDefaultsModel =
    "<mujoco>\n"
    "  <default>\n"
    "    <default class=\"collision\">\n"
    "      <geom group=\"3\"/>\n"
    "      <default class=\"foot\"><geom type=\"sphere\" size=\"0.02\" pos=\"-0.002 0 -0.213\"/>"
    "</default>\n"
    "      <default class=\"rod\"><geom type=\"capsule\" size=\"0.01\" "
    "fromto=\"0 0 0 0.2 0 0.1\"/></default>\n"
    "    </default>\n"
    "    <default class=\"limb\"><geom type=\"box\" size=\"0.01 0.01 0.01\" pos=\"0 0.05 0\"/>"
    "</default>\n"
    "  </default>\n"
    "  <worldbody><body name=\"calf\" pos=\"0 0 1\" euler=\"0 30 0\" childclass=\"limb\">\n"
    "    <joint name=\"knee\" type=\"hinge\"/>\n"
    "    <geom name=\"FR\" class=\"foot\"/>\n"
    "    <geom name=\"shin\"/>\n"
    "    <geom name=\"rod\" class=\"rod\"/>\n"
    "    <geom name=\"own\" class=\"foot\" pos=\"0.01 0 -0.1\"/>\n"
    "  </body></worldbody>\n"
    "</mujoco>\n";

TEST(WorldSites, GeomCentresComeFromDefaultClassesAsMujocoCompilesThem) {
  penumbra::testing::TempDir dir;
  const std::string file = dir.Write("dog.xml", kDefaultsModel);
  std::vector<ModelConfig> models;
  for (const char* name : {"a", "b"}) {
    ModelConfig m;
    m.name = name;
    m.file = file;
    m.key = std::string("robots[") + name + "]";
    m.pose.xyz = Eigen::Vector3d(name[0] == 'a' ? 0 : 2, 0, 0);
    for (const char* g : {"FR", "shin", "rod", "own"})
      m.sites.push_back(Site(std::string(g) + "_site", "", g, {0, 0, 0}));
    models.push_back(m);
  }
  const ComposedScene s = ComposeWorld(models, {});
  const std::string path = dir.Write("composed.xml", s.Xml());
  char error[1000] = "";
  mjModel* model = mj_loadXML(path.c_str(), nullptr, error, sizeof(error));
  ASSERT_NE(model, nullptr) << error;
  mjData* d = mj_makeData(model);
  mj_forward(model, d);
  for (const char* m : {"a/", "b/"}) {
    for (const char* g : {"FR", "shin", "rod", "own"}) {
      const int geom = mj_name2id(model, mjOBJ_GEOM, (std::string(m) + g).c_str());
      const int site = mj_name2id(model, mjOBJ_SITE, (std::string(m) + g + "_site").c_str());
      ASSERT_GE(geom, 0) << m << g;
      ASSERT_GE(site, 0) << m << g;
      // the site sits where MuJoCo compiled the geom (primitive geoms: the centre)
      for (int k = 0; k < 3; ++k)
        EXPECT_NEAR(d->site_xpos[3 * site + k], d->geom_xpos[3 * geom + k], 1e-9) << m << g;
    }
  }
  // and the foot is not on the knee axis (what reading only the geom's own pos gave)
  const int foot = mj_name2id(model, mjOBJ_SITE, "a/FR_site");
  EXPECT_NEAR(model->site_pos[3 * foot + 2], -0.213, 1e-12);
  mj_deleteData(d);
  mj_deleteModel(model);
}

}  // namespace
}  // namespace penumbra

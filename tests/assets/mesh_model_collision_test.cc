// `collision: coacd` on a world-file mesh model (convex decomposition in the world
// file): the model collides as CoACD's convex parts, so a ball dropped into a U-shaped mesh
// lands between its posts, where MuJoCo's single convex hull of the mesh would hold it on an
// invisible lid; the parts come from the on-disk cache the second time; bad input is named.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cstdlib>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/assets/mesh_model.h"
#include "penumbra/core/error.h"
#include "penumbra/decompose/solid_mesh.h"
#include "penumbra/decompose/test_shapes.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

// the solid as OBJ text (m), triangles 1-based
std::string ObjText(const SolidMesh& mesh, size_t drop_triangles = 0) {
  std::string s;
  for (const Eigen::Vector3d& v : mesh.vertices)
    s += fmt::format("v {:.9g} {:.9g} {:.9g}\n", v.x(), v.y(), v.z());
  for (size_t t = drop_triangles; t < mesh.triangles.size(); ++t)
    s += fmt::format("f {} {} {}\n", mesh.triangles[t][0] + 1, mesh.triangles[t][1] + 1,
                     mesh.triangles[t][2] + 1);
  return s;
}

// the U's outline lies in the file's x-y plane (posts x in [0, 0.3] and [0.7, 1], base
// y in [0, 0.3], height 1) extruded 0.4 along z; with up_axis y the world sees the posts
// standing up (world z = file y) and the extrusion along -y (world y in [-0.4, 0])
constexpr double kBall = 0.08;

struct Imported {
  ImportedModel model;
  std::string xml_file;
};

Imported Import(const std::string& world_file, const std::string& mesh_dir) {
  WorldConfig world = LoadWorldFile(world_file);
  std::vector<ImportedModel> models = ImportMeshModels(&world.models, mesh_dir, world.file);
  EXPECT_EQ(models.size(), 1u);
  return {models.at(0), world.models.at(0).file};
}

// the ball's centre height after 2 s dropped from 1.5 m over the U's slot
double DropBall(const testing::TempDir& dir, const std::string& model_xml) {
  std::string xml = testing::ReadAll(model_xml);
  xml.replace(xml.find("</worldbody>"), 0,
              fmt::format("<geom type=\"plane\" size=\"3 3 0.1\"/><body name=\"ball\" "
                          "pos=\"0.5 -0.2 1.5\"><freejoint/><geom type=\"sphere\" size=\"{}\" "
                          "mass=\"0.3\"/></body>",
                          kBall));
  const std::string path = dir.Write("drop.xml", xml);
  char error[1000] = "";
  mjModel* m = mj_loadXML(path.c_str(), nullptr, error, sizeof error);
  EXPECT_NE(m, nullptr) << error;
  if (!m) return 0;
  mjData* d = mj_makeData(m);
  while (d->time < 2.0) mj_step(m, d);
  const double z = d->qpos[2];
  mj_deleteData(d);
  mj_deleteModel(m);
  return z;
}

TEST(MeshModelCollision, CoacdPartsHoldABallBetweenTheUsPostsAndComeFromTheCacheNextTime) {
  testing::TempDir dir;
  ASSERT_EQ(setenv("PENUMBRA_CACHE_DIR", (dir.path() / "cache").c_str(), 1), 0);
  dir.Write("u.obj", ObjText(MakeUShape()));
  const std::string world = dir.Write(
      "w.yaml",
      "models:\n  - {name: u, file: u.obj, up_axis: y, collision: coacd, max_parts: 8}\n");

  const Imported first = Import(world, (dir.path() / "models").string());
  EXPECT_FALSE(first.model.decomposition_cache_hit);
  EXPECT_GE(first.model.collision_parts, 3);  // base and two posts
  EXPECT_LE(first.model.collision_parts, 8);
  EXPECT_LE(first.model.relative_max_concavity, 0.025);
  EXPECT_GE(first.model.hull_volume_ratio, 1 - 1e-9);
  EXPECT_LE(first.model.hull_volume_ratio, 1.02);
  const std::string xml = testing::ReadAll(first.xml_file);
  EXPECT_NE(xml.find("<geom name=\"collision_part_0\" type=\"mesh\" mesh=\"collision_part_0\" "
                     "group=\"3\"/>"),
            std::string::npos)
      << xml;
  EXPECT_NE(xml.find("contype=\"0\" conaffinity=\"0\""), std::string::npos)
      << "the visual mesh must not collide";

  // between the posts on the base (top at z 0.3), not on the hull's lid at z 1
  const double z = DropBall(dir, first.xml_file);
  EXPECT_NEAR(z, 0.3 + kBall, 0.01);

  // a second load reads the same parts from the cache: the same generated file
  const Imported second = Import(world, (dir.path() / "models").string());
  EXPECT_TRUE(second.model.decomposition_cache_hit);
  EXPECT_EQ(second.model.collision_parts, first.model.collision_parts);
  EXPECT_EQ(second.xml_file, first.xml_file);
  std::printf("U: %d parts, decomposed in %.2f s, cached load %.3f s\n",
              first.model.collision_parts, first.model.decompose_sec, second.model.decompose_sec);

  // MuJoCo's hull of the whole mesh (collision: hull) holds the ball on the lid
  const std::string hull_world =
      dir.Write("hull.yaml", "models:\n  - {name: u, file: u.obj, up_axis: y}\n");
  const Imported hull = Import(hull_world, (dir.path() / "models").string());
  EXPECT_EQ(hull.model.collision_parts, 0);
  EXPECT_NEAR(DropBall(dir, hull.xml_file), 1.0 + kBall, 0.01);
  unsetenv("PENUMBRA_CACHE_DIR");
}

std::string ErrorOf(const std::string& world_file, const std::string& mesh_dir) {
  try {
    Import(world_file, mesh_dir);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(MeshModelCollision, CoacdKeysAndOpenMeshesGiveErrorsNamingTheEntry) {
  testing::TempDir dir;
  ASSERT_EQ(setenv("PENUMBRA_CACHE_DIR", (dir.path() / "cache").c_str(), 1), 0);
  dir.Write("u.obj", ObjText(MakeUShape()));
  dir.Write("open.obj", ObjText(MakeUShape(), 1));  // one triangle missing: not closed
  const std::string models = (dir.path() / "models").string();

  // the decomposition keys need collision: coacd and stay in range
  for (const auto& [entry, key] : std::vector<std::pair<std::string, std::string>>{
           {"{name: u, file: u.obj, max_parts: 4}", "models[0].max_parts"},
           {"{name: u, file: u.obj, collision: hull, concavity_threshold: 0.05}",
            "models[0].concavity_threshold"},
           {"{name: u, file: u.obj, collision: coacd, concavity_threshold: 0}",
            "models[0].concavity_threshold"},
           {"{name: u, file: u.obj, collision: coacd, max_parts: 0}", "models[0].max_parts"},
           {"{name: u, file: u.obj, collision: convex}", "models[0].collision"}}) {
    const std::string w = dir.Write("bad.yaml", "models:\n  - " + entry + "\n");
    try {
      LoadWorldFile(w);
      ADD_FAILURE() << "no error for " << entry;
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find(key), std::string::npos) << e.what();
    }
  }

  // an open mesh cannot be decomposed: the error names the entry, the mesh file and the edge
  const std::string open = dir.Write(
      "open.yaml", "models:\n  - {name: u, file: open.obj, up_axis: y, collision: coacd}\n");
  const std::string e = ErrorOf(open, models);
  EXPECT_NE(e.find("models[0].collision"), std::string::npos) << e;
  EXPECT_NE(e.find("open.obj"), std::string::npos) << e;
  EXPECT_NE(e.find("closed"), std::string::npos) << e;
  unsetenv("PENUMBRA_CACHE_DIR");
}

}  // namespace
}  // namespace penumbra

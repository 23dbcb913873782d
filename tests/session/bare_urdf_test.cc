// a bare URDF (`penumbra run robot.urdf`) gets a ground plane, as a bare
// model gets lights and a camera; URDF meshes MuJoCo cannot read are converted next
// to the composed model.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

const char* kUrdf =
    "<robot name=\"bot\">\n"
    "  <link name=\"base\">\n"
    "    <inertial><mass value=\"2\"/>\n"
    "      <inertia ixx=\"0.02\" iyy=\"0.03\" izz=\"0.04\" ixy=\"0\" ixz=\"0\" iyz=\"0\"/>"
    "</inertial>\n"
    "    <collision><origin xyz=\"0 0 0.05\"/><geometry><box size=\"0.4 0.3 0.1\"/></geometry>"
    "</collision>\n"
    "  </link>\n"
    "</robot>\n";

int CountPlanes(const SceneDescription& s) {
  int n = 0;
  for (const Geom& g : s.geoms) n += g.shape == GeomShape::kPlane ? 1 : 0;
  return n;
}

SessionOptions Headless() {
  SessionOptions options;
  options.build_renderer = false;
  options.add_controllers = false;
  return options;
}

TEST(BareUrdf, GetsAGroundPlaneAtZeroWhenItHasNone) {
  penumbra::testing::TempDir dir;
  const WorldConfig world = WorldForBareModel(dir.Write("bot.urdf", kUrdf));
  EXPECT_TRUE(world.ground_plane);
  Session session(world, Headless());
  const SceneDescription& s = session.sim().scene();
  ASSERT_EQ(CountPlanes(s), 1);
  for (const Geom& g : s.geoms) {
    if (g.shape != GeomShape::kPlane) continue;
    EXPECT_EQ(g.name, "ground");
    EXPECT_EQ(g.body, 0);  // the world body, at z = 0
    EXPECT_DOUBLE_EQ(g.X_BG.translation().z(), 0.0);
  }
}

TEST(BareUrdf, BareMjcfAndModelsWithAPlaneGetNoExtraGround) {
  penumbra::testing::TempDir dir;
  const std::string mjcf = dir.Write(
      "box.xml",
      "<mujoco><worldbody><geom type=\"box\" size=\"0.1 0.1 0.1\"/></worldbody></mujoco>\n");
  const WorldConfig bare_mjcf = WorldForBareModel(mjcf);
  EXPECT_FALSE(bare_mjcf.ground_plane);
  EXPECT_EQ(CountPlanes(Session(bare_mjcf, Headless()).sim().scene()), 0);

  // a model with its own floor keeps it alone
  WorldConfig with_floor = WorldForBareModel(dir.Write(
      "floor.xml",
      "<mujoco><worldbody><body><geom type=\"plane\" size=\"1 1 0.1\"/></body></worldbody>"
      "</mujoco>\n"));
  with_floor.ground_plane = true;
  const Session session(with_floor, Headless());
  EXPECT_EQ(CountPlanes(session.sim().scene()), 1);
}

TEST(BareUrdf, DaeMeshesAreConvertedBesideTheComposedModel) {
  penumbra::testing::TempDir dir;
  // a tetrahedron COLLADA visual in millimetres (MuJoCo refuses meshes of fewer than 4 vertices)
  dir.Write("meshes/tri.dae",
            R"(<?xml version="1.0"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<asset><unit meter="0.001"/><up_axis>Z_UP</up_axis></asset>
<library_geometries><geometry id="g"><mesh>
<source id="p"><float_array id="pa" count="12">0 0 0 100 0 0 0 100 0 0 0 50</float_array>
<technique_common><accessor source="#pa" count="4" stride="3"><param name="X" type="float"/>
<param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="4"><input semantic="VERTEX" source="#v" offset="0"/><p>0 2 1 0 1 3 0 3 2 1 2 3</p>
</triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s"><node id="n"><instance_geometry url="#g"/></node>
</visual_scene></library_visual_scenes><scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
)");
  std::string urdf = kUrdf;
  urdf.insert(urdf.find("    <collision>"),
              "    <visual><geometry><mesh filename=\"meshes/tri.dae\"/></geometry></visual>\n");
  const WorldConfig world = WorldForBareModel(dir.Write("bot.urdf", urdf));
  SessionOptions options = Headless();
  options.composed_xml_path = (dir.path() / "out" / "composed.xml").string();
  Session session(world, options);
  ASSERT_EQ(session.sim().scene().meshes.size(), 1u);
  int stl = 0;
  for (const auto& f : fs::directory_iterator(dir.path() / "out" / "meshes")) {
    EXPECT_EQ(f.path().extension(), ".stl");
    ++stl;
  }
  EXPECT_EQ(stl, 1);
}

}  // namespace
}  // namespace penumbra

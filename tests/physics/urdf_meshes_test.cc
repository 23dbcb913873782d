// URDF meshes MuJoCo cannot read (COLLADA) converted to STL through assimp.

#include "penumbra/physics/urdf_meshes.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cstdint>
#include <cstring>
#include <filesystem>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/physics/urdf_converter.h"

namespace penumbra {
namespace {

using penumbra::testing::TempDir;

// a COLLADA box from (0,0,0) to (sx,sy,sz) in the document's units, with the given
// <unit meter> and <up_axis>
std::string DaeBox(double sx, double sy, double sz, const std::string& meter,
                   const std::string& up_axis) {
  std::string p;
  for (int i = 0; i < 8; ++i) {
    p += std::to_string((i & 1) ? sx : 0) + " " + std::to_string((i & 2) ? sy : 0) + " " +
         std::to_string((i & 4) ? sz : 0) + " ";
  }
  // 12 triangles, outward (counter-clockwise seen from outside)
  const std::string tris =
      "0 2 1 1 2 3 4 5 6 5 7 6 0 1 4 1 5 4 2 6 3 3 6 7 0 4 2 2 4 6 1 3 5 3 7 5";
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="u" meter=")" +
         meter + R"("/><up_axis>)" + up_axis + R"(</up_axis></asset>
  <library_geometries><geometry id="box"><mesh>
    <source id="pos"><float_array id="pos-a" count="24">)" +
         p + R"(</float_array>
      <technique_common><accessor source="#pos-a" count="8" stride="3">
        <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/>
      </accessor></technique_common></source>
    <vertices id="v"><input semantic="POSITION" source="#pos"/></vertices>
    <triangles count="12"><input semantic="VERTEX" source="#v" offset="0"/><p>)" +
         tris + R"(</p></triangles>
  </mesh></geometry></library_geometries>
  <library_visual_scenes><visual_scene id="s"><node id="n">
    <instance_geometry url="#box"/></node></visual_scene></library_visual_scenes>
  <scene><instance_visual_scene url="#s"/></scene>
</COLLADA>
)";
}

// per-axis max - min of a binary STL's vertices
std::array<float, 3> StlExtent(const std::string& stl) {
  EXPECT_GE(stl.size(), 84u);
  uint32_t n = 0;
  std::memcpy(&n, stl.data() + 80, 4);
  EXPECT_EQ(stl.size(), 84u + 50u * n);
  std::array<float, 3> lo{1e9f, 1e9f, 1e9f}, hi{-1e9f, -1e9f, -1e9f};
  for (uint32_t t = 0; t < n; ++t) {
    for (int v = 1; v <= 3; ++v) {
      float xyz[3];
      std::memcpy(xyz, stl.data() + 84 + 50 * t + 12 * v, 12);
      for (int k = 0; k < 3; ++k) {
        lo[k] = std::min(lo[k], xyz[k]);
        hi[k] = std::max(hi[k], xyz[k]);
      }
    }
  }
  return {hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]};
}

TEST(UrdfMeshes, ColladaUnitAndUpAxisAreApplied) {
  TempDir dir;
  // millimetres, z up (the ROS convention): coordinates kept, scaled to metres
  const std::string z_up = MeshFileToStl(dir.Write("z.dae", DaeBox(10, 20, 40, "0.001", "Z_UP")));
  const auto ez = StlExtent(z_up);
  EXPECT_NEAR(ez[0], 0.01f, 1e-6f);
  EXPECT_NEAR(ez[1], 0.02f, 1e-6f);
  EXPECT_NEAR(ez[2], 0.04f, 1e-6f);
  // y up: the document's up (+y) becomes +z
  const auto ey = StlExtent(MeshFileToStl(dir.Write("y.dae", DaeBox(1, 2, 4, "1", "Y_UP"))));
  EXPECT_NEAR(ey[0], 1.0f, 1e-6f);
  EXPECT_NEAR(ey[1], 4.0f, 1e-6f);
  EXPECT_NEAR(ey[2], 2.0f, 1e-6f);
  // 12 triangles, same bytes every time
  uint32_t n = 0;
  std::memcpy(&n, z_up.data() + 80, 4);
  EXPECT_EQ(n, 12u);
  EXPECT_EQ(MeshFileToStl((dir.path() / "z.dae").string()), z_up);
  EXPECT_NE(z_up.compare(0, 5, "solid"), 0);  // binary STL, not mistaken for ASCII
}

TEST(UrdfMeshes, MujocoReadsOnlyStlObjMsh) {
  EXPECT_TRUE(MujocoReadsMeshFile("package://p/meshes/a.STL"));
  EXPECT_TRUE(MujocoReadsMeshFile("a.obj"));
  EXPECT_TRUE(MujocoReadsMeshFile("a.msh"));
  EXPECT_FALSE(MujocoReadsMeshFile("package://p/meshes/a.dae"));
  EXPECT_FALSE(MujocoReadsMeshFile("a.ply"));
}

constexpr const char* kDaeUrdf = R"(<?xml version="1.0"?>
<robot name="bot">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><mesh filename="package://bot_description/meshes/box.dae" scale="2 2 2"/></geometry></visual>
    <collision><geometry><box size="0.1 0.1 0.1"/></geometry></collision>
  </link>
</robot>
)";

// sorted per-axis extent of a mesh's vertices (MuJoCo re-aligns meshes to their
// principal axes, which may permute them)
std::array<float, 3> SortedExtent(const TriangleMesh& mesh) {
  Eigen::Vector3f lo = mesh.vertices.front(), hi = lo;
  for (const Eigen::Vector3f& v : mesh.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
  std::array<float, 3> e{hi.x() - lo.x(), hi.y() - lo.y(), hi.z() - lo.z()};
  std::sort(e.begin(), e.end());
  return e;
}

TEST(UrdfMeshes, UrdfWithDaeVisualLoadsAtItsScale) {
  TempDir dir;
  // the ROS package layout: bot_description/urdf/bot.urdf, bot_description/meshes/box.dae
  dir.Write("bot_description/meshes/box.dae", DaeBox(10, 20, 40, "0.001", "Z_UP"));
  const std::string urdf = dir.Write("bot_description/urdf/bot.urdf", kDaeUrdf);
  const std::string mesh_dir = (dir.path() / "out" / "meshes").string();
  const std::string mjcf = ConvertUrdfToMjcfInto(urdf, mesh_dir);
  Simulation sim = Simulation::LoadFromString(mjcf);
  ASSERT_EQ(sim.scene().meshes.size(), 1u);
  const auto e = SortedExtent(sim.scene().meshes[0]);
  // 10 x 20 x 40 mm, scale 2
  EXPECT_NEAR(e[0], 0.02f, 1e-5f);
  EXPECT_NEAR(e[1], 0.04f, 1e-5f);
  EXPECT_NEAR(e[2], 0.08f, 1e-5f);
  // the STL lies in mesh_dir and the MJCF names it there; converting again gives the
  // same text
  int stl_files = 0;
  for (const auto& f : std::filesystem::directory_iterator(mesh_dir)) {
    EXPECT_EQ(f.path().extension(), ".stl");
    EXPECT_NE(mjcf.find(f.path().string()), std::string::npos) << mjcf;
    ++stl_files;
  }
  EXPECT_EQ(stl_files, 1);
  EXPECT_EQ(ConvertUrdfToMjcfInto(urdf, mesh_dir), mjcf);
}

TEST(UrdfMeshes, UnreadableMeshNamesUrdfLinkAndMesh) {
  TempDir dir;
  dir.Write("bot_description/meshes/box.dae", "this is not COLLADA");
  const std::string urdf = dir.Write("bot_description/urdf/bot.urdf", kDaeUrdf);
  try {
    ConvertUrdfToMjcfInto(urdf, (dir.path() / "meshes").string());
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.file(), urdf);
    EXPECT_EQ(e.line(), 5);
    EXPECT_NE(what.find("link 'base'"), std::string::npos) << what;
    EXPECT_NE(what.find("package://bot_description/meshes/box.dae"), std::string::npos) << what;
    EXPECT_NE(what.find("assimp"), std::string::npos) << what;
  }
  // a missing file lists where it was looked for
  std::filesystem::remove(dir.path() / "bot_description/meshes/box.dae");
  try {
    ConvertUrdfToMjcfInto(urdf, (dir.path() / "meshes").string());
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("not found"), std::string::npos) << what;
    EXPECT_NE(what.find("bot_description/meshes/box.dae"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace penumbra

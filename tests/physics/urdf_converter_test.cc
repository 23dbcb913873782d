// URDF -> MJCF through MuJoCo's importer: links, joints and visual geoms survive.

#include "penumbra/physics/urdf_converter.h"

#include <gtest/gtest.h>

#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

constexpr const char* kUrdf = R"(<?xml version="1.0"?>
<robot name="bot">
  <link name="base">
    <inertial><mass value="1"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><box size="0.2 0.2 0.1"/></geometry>
      <material name="red"><color rgba="1 0 0 1"/></material></visual>
    <collision><geometry><box size="0.2 0.2 0.1"/></geometry></collision>
  </link>
  <link name="arm">
    <inertial><mass value="0.5"/><inertia ixx="0.01" iyy="0.01" izz="0.01" ixy="0" ixz="0" iyz="0"/></inertial>
    <visual><geometry><cylinder radius="0.02" length="0.3"/></geometry></visual>
  </link>
  <link name="tool"/>
  <joint name="j1" type="revolute"><parent link="base"/><child link="arm"/>
    <origin xyz="0 0 0.1"/><axis xyz="0 0 1"/><limit lower="-1" upper="1" effort="10" velocity="1"/></joint>
  <joint name="tool_mount" type="fixed"><parent link="arm"/><child link="tool"/><origin xyz="0 0 0.3"/></joint>
</robot>
)";

std::string Write(const std::string& name, const std::string& text) {
  const std::string path = penumbra::testing::ProcessTempDir() + "/" + name;
  std::ofstream(path) << text;
  return path;
}

TEST(UrdfConverter, ProducesLoadableMjcfKeepingLinksAndVisuals) {
  const std::string mjcf = ConvertUrdfToMjcf(Write("bot.urdf", kUrdf));
  ASSERT_NE(mjcf.find("<mujoco"), std::string::npos) << mjcf;
  Simulation sim = Simulation::LoadFromString(mjcf);
  const SceneDescription& s = sim.scene();
  EXPECT_GE(s.FindBody("base"), 0);
  EXPECT_GE(s.FindBody("arm"), 0);
  EXPECT_GE(s.FindBody("tool"), 0);  // fixed-joint link kept as a body
  const ModelInfo& mi = sim.model_info();
  const int j1 = mi.Find(ModelObject::kJoint, "j1");
  ASSERT_GE(j1, 0);
  EXPECT_TRUE(mi.joints[j1].limited);
  EXPECT_DOUBLE_EQ(mi.joints[j1].range[1], 1.0);
  // base: visual (group 1) + collision (group 0); arm: visual only
  int visual = 0, collision = 0;
  for (const Geom& g : s.geoms) (g.group == 1 ? visual : collision)++;
  EXPECT_EQ(visual, 2);
  EXPECT_EQ(collision, 1);
  const Geom& arm_geom = s.geoms.back();
  EXPECT_EQ(arm_geom.shape, GeomShape::kCylinder);
  EXPECT_NEAR(arm_geom.size.y(), 0.15, 1e-12);  // half length
}

TEST(UrdfConverter, BadUrdfIsAConfigErrorNamingTheFile) {
  const std::string path =
      Write("broken.urdf", "<robot name=\"x\">\n<link name=\"a\">\n</robot>\n");
  try {
    ConvertUrdfToMjcf(path);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), path);
  }
  EXPECT_THROW(ConvertUrdfToMjcf("/nonexistent/robot.urdf"), ConfigError);
}

}  // namespace
}  // namespace penumbra

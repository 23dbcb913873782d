// spatial tendons: the scene lists the visible spatial tendons with their
// width and colour, and every snapshot carries their wrap-point paths in the world frame.

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

// a box hanging from a spatial tendon between a world site and a site on the box (the Robotiq
// scene's cube in small), a second tendon with a pulley, an invisible one (group 3) and a fixed
// tendon (no path).
constexpr const char* kTendonXml = R"(
<mujoco>
  <worldbody>
    <site name="anchor" pos="0 0 2"/>
    <site name="anchor2" pos="1 0 2"/>
    <site name="anchor3" pos="2 0 2"/>
    <body name="box" pos="0 0 1">
      <joint name="slide" type="slide" axis="0 0 1"/>
      <geom type="box" size="0.1 0.1 0.1" mass="1"/>
      <site name="hook" pos="0 0 0.1"/>
    </body>
  </worldbody>
  <tendon>
    <spatial name="rope" width="0.02" rgba="1 0.5 0 1" limited="true" range="0 1">
      <site site="anchor"/>
      <site site="hook"/>
    </spatial>
    <spatial name="pulleyed" width="0.01">
      <site site="anchor2"/>
      <site site="hook"/>
      <pulley divisor="2"/>
      <site site="anchor3"/>
      <site site="hook"/>
    </spatial>
    <spatial name="hidden" group="3">
      <site site="anchor"/>
      <site site="hook"/>
    </spatial>
    <fixed name="coupling">
      <joint joint="slide" coef="1"/>
    </fixed>
  </tendon>
</mujoco>)";

TEST(TendonPathTest, SceneListsVisibleSpatialTendonsWithWidthAndColour) {
  const Simulation sim = Simulation::LoadFromString(kTendonXml);
  const SceneDescription& s = sim.scene();
  ASSERT_EQ(s.tendons.size(), 2u);
  EXPECT_EQ(s.tendons[0].name, "rope");
  EXPECT_EQ(s.tendons[0].id, 0);
  EXPECT_DOUBLE_EQ(s.tendons[0].width_m, 0.02);
  const Material& m = s.materials.at(s.tendons[0].material);
  // sRGB-decoded rgba, as geoms (physics/scene_extractor.h)
  EXPECT_FLOAT_EQ(m.base_color.x(), 1.0f);
  EXPECT_NEAR(m.base_color.y(), 0.214f, 1e-3);
  EXPECT_FLOAT_EQ(m.base_color.z(), 0.0f);
  EXPECT_EQ(s.tendons[1].name, "pulleyed");
}

TEST(TendonPathTest, SnapshotsCarryTheWrapPointsInTheWorldFrame) {
  Simulation sim = Simulation::LoadFromString(kTendonXml);
  for (const auto content :
       {Simulation::SnapshotContent::kPoses, Simulation::SnapshotContent::kFull}) {
    const WorldSnapshot snap = sim.Snapshot(content);
    // rope: one run anchor -> hook; pulleyed: two runs split at the pulley
    ASSERT_EQ(snap.tendon_paths.size(), 3u);
    EXPECT_EQ(snap.tendon_paths[0].tendon, 0);
    ASSERT_EQ(snap.tendon_paths[0].p_W.size(), 2u);
    EXPECT_TRUE(snap.tendon_paths[0].p_W[0].isApprox(Eigen::Vector3d(0, 0, 2)));
    EXPECT_TRUE(snap.tendon_paths[0].p_W[1].isApprox(Eigen::Vector3d(0, 0, 1.1)));
    EXPECT_EQ(snap.tendon_paths[1].tendon, 1);
    EXPECT_TRUE(snap.tendon_paths[1].p_W[0].isApprox(Eigen::Vector3d(1, 0, 2)));
    EXPECT_EQ(snap.tendon_paths[2].tendon, 1);
    EXPECT_TRUE(snap.tendon_paths[2].p_W[0].isApprox(Eigen::Vector3d(2, 0, 2)));
  }
  // the hook moves with the box
  for (int i = 0; i < 100; ++i) sim.Step();
  const WorldSnapshot later = sim.Snapshot(Simulation::SnapshotContent::kPoses);
  const double hook_z = later.X_WB[1].translation().z() + 0.1;
  EXPECT_NEAR(later.tendon_paths[0].p_W[1].z(), hook_z, 1e-9);
  EXPECT_LT(hook_z, 1.1 - 1e-3);
}

TEST(TendonPathTest, ModelsWithoutTendonsHaveNoPaths) {
  const Simulation sim = Simulation::LoadFromString(
      "<mujoco><worldbody><geom type='sphere' size='0.1'/></worldbody></mujoco>");
  EXPECT_TRUE(sim.scene().tendons.empty());
  EXPECT_TRUE(sim.Snapshot().tendon_paths.empty());
}

}  // namespace
}  // namespace penumbra

// a sphere dropped into the decomposed bowl (MuJoCo, one convex mesh geom per part) comes to
// rest inside it, near the bottom; dropped onto the plain convex hull of the same bowl it
// rests on the hull's lid above the rim. this is what convex decomposition is for.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include "penumbra/decompose/decomposition.h"
#include "penumbra/decompose/mesh_io.h"
#include "penumbra/decompose/test_shapes.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

constexpr double kOuter = 0.5, kInner = 0.45, kBall = 0.08;
constexpr double kBowlZ = kOuter;  // body origin at the rim; bottom touches the floor

// the ball's resting height (m) after 3 s
double RestingHeight(const Decomposition& d) {
  const PartsMjcf parts = PartsToMjcf(d, "bowl", "rgba=\"0.7 0.6 0.5 1\"");
  const std::string xml = fmt::format(R"(<mujoco model="bowl_drop">
  <option timestep="0.002"/>
  <asset>
{}  </asset>
  <worldbody>
    <geom type="plane" size="2 2 0.1"/>
    <body name="bowl" pos="0 0 {}">
{}    </body>
    <body name="ball" pos="0.06 0.03 1.3">
      <freejoint/>
      <geom type="sphere" size="{}" mass="0.3"/>
    </body>
  </worldbody>
</mujoco>
)",
                                      parts.assets, kBowlZ, parts.geoms, kBall);
  Simulation sim = Simulation::LoadFromString(xml);
  while (sim.time() < 3.0) sim.Step();
  EXPECT_LT(std::abs(sim.qvel()[2]), 0.05) << "the ball should be at rest";
  return sim.qpos()[2];
}

TEST(BowlPhysics, SphereRestsInsideTheDecomposedBowlNotOnItsHull) {
  const SolidMesh bowl = MakeBowl(kOuter, kInner);
  DecompositionOptions options;
  const Decomposition parts = DecomposeMesh(bowl, options, "bowl");
  const double inside = RestingHeight(parts);
  // inner bottom at kBowlZ - kInner; the parts may fill the bottom by at most the threshold
  const double bottom = kBowlZ - kInner + kBall;
  EXPECT_GT(inside, bottom - 0.01);
  EXPECT_LT(inside, bottom + options.concavity_threshold * 2 * kOuter + 0.01);
  EXPECT_LT(inside + kBall, kBowlZ) << "the ball must be below the rim, inside the bowl";

  options.method = DecompositionMethod::kHull;
  const double on_hull = RestingHeight(DecomposeMesh(bowl, options, "bowl"));
  EXPECT_NEAR(on_hull, kBowlZ + kBall, 0.01) << "on the hull the ball lies on the lid";
}

}  // namespace
}  // namespace penumbra

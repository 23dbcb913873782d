// the world file's physics section sets integrator, gravity, solver iterations and friction
// cone beside timestep_sec; bad values name the file and line.
#include <gtest/gtest.h>

#include <string>

#include "penumbra/core/error.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

const std::string kWorld = "/tmp/physics_options_world.yaml";

TEST(PhysicsSection, ReadFromThePhysicsSection) {
  const WorldConfig w = ParseWorld(
      "physics:\n"
      "  timestep_sec: 0.002\n"
      "  integrator: implicit\n"
      "  gravity_mps2: [0, 0, -1.62]\n"
      "  solver_iterations: 50\n"
      "  cone: elliptic\n",
      kWorld);
  EXPECT_EQ(w.timestep_sec, 0.002);
  EXPECT_EQ(w.physics.integrator, "implicit");
  ASSERT_TRUE(w.physics.gravity_mps2.has_value());
  EXPECT_EQ(*w.physics.gravity_mps2, Eigen::Vector3d(0, 0, -1.62));
  EXPECT_EQ(w.physics.solver_iterations, 50);
  EXPECT_EQ(w.physics.cone, "elliptic");
  EXPECT_TRUE(ParseWorld("physics: {timestep_sec: 0.01}\n", kWorld).physics.empty());
  // MuJoCo 3's integrator, the one Menagerie's robots are tuned with
  EXPECT_EQ(ParseWorld("physics: {integrator: implicitfast}\n", kWorld).physics.integrator,
            "implicitfast");
}

void ExpectError(const std::string& yaml, int line, const std::string& key,
                 const std::string& part) {
  try {
    ParseWorld(yaml, kWorld);
    ADD_FAILURE() << "no ConfigError for:\n" << yaml;
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), kWorld) << e.what();
    EXPECT_EQ(e.line(), line) << e.what();
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

TEST(PhysicsSection, BadValuesNameTheLine) {
  ExpectError("physics:\n  integrator: rk4\n", 2, "physics.integrator",
              "expected one of: Euler, RK4, implicit, implicitfast");
  ExpectError("physics:\n  cone: round\n", 2, "physics.cone",
              "expected one of: pyramidal, elliptic");
  ExpectError("physics:\n  timestep_sec: 0.001\n  solver_iterations: 0\n", 3,
              "physics.solver_iterations", "expected [1, 10000]");
  ExpectError("physics:\n  gravity_mps2: [0, 0, -1e9]\n", 2, "physics.gravity_mps2", "component 2");
  ExpectError("physics:\n  gravity_mps2: [0, -9.81]\n", 2, "physics.gravity_mps2", "3 numbers");
}

}  // namespace
}  // namespace penumbra

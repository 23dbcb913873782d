// a degenerate physics timestep, from the MJCF <option timestep> or from the
// override (physics.timestep_sec), is refused at load. timestep="0" used to loop forever,
// "-0.01" ran backwards, "1" overran short runs and 1e-300 never finished. the checks run at
// load, so these tests cannot hang whatever Simulation::Step does.

#include <gtest/gtest.h>

#include <string>

#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

std::string Model(const std::string& timestep) {
  return "<mujoco><option timestep=\"" + timestep +
         "\"/><worldbody><body><freejoint/><geom size=\"0.1\"/></body></worldbody></mujoco>";
}

void ExpectTimestepError(const std::string& model, std::optional<double> override_sec,
                         const std::string& key, const std::string& text) {
  try {
    Simulation::LoadFromString(model, override_sec);
    ADD_FAILURE() << "no ConfigError for " << model;
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), key) << e.what();
    EXPECT_NE(std::string(e.what()).find(text), std::string::npos) << e.what();
  }
}

TEST(TimestepLimits, ModelTimestepOutsideTheRangeIsRefused) {
  ExpectTimestepError(Model("0"), std::nullopt, "option.timestep",
                      "the model's timestep is 0 s; expected seconds in [1e-06, 0.1]");
  ExpectTimestepError(Model("-0.01"), std::nullopt, "option.timestep", "is -0.01 s");
  ExpectTimestepError(Model("1"), std::nullopt, "option.timestep", "is 1 s");
  ExpectTimestepError(Model("1e-300"), std::nullopt, "option.timestep", "is 1e-300 s");
  EXPECT_NO_THROW(Simulation::LoadFromString(Model("0.002")));
  EXPECT_NO_THROW(Simulation::LoadFromString(Model("0.1")));
}

TEST(TimestepLimits, OverrideWinsAndIsCheckedToo) {
  // the override (world file) wins over the model's own value, bad or not
  Simulation sim = Simulation::LoadFromString(Model("0"), 0.004);
  EXPECT_EQ(sim.timestep(), 0.004);
  sim.Step();
  EXPECT_DOUBLE_EQ(sim.time(), 0.004);
  ExpectTimestepError(Model("0.002"), 1e-300, "timestep_sec", "expected seconds in [1e-06, 0.1]");
  ExpectTimestepError(Model("0.002"), 0.5, "timestep_sec", "got 0.5");
  ExpectTimestepError(Model("0.002"), -0.01, "timestep_sec", "got -0.01");
}

}  // namespace
}  // namespace penumbra

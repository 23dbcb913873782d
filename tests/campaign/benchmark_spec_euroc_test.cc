// a benchmark whose method reads EuRoC needs one IMU in every world: told when the spec loads,
// at the method's `dataset`, before any route is recorded

#include <gtest/gtest.h>

#include <string>

#include "common/temp_dir.h"
#include "penumbra/campaign/benchmark_spec.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using testing::TempDir;

// a spec over `world` (a file in `dir`) with one EuRoC method
std::string EurocSpec(const std::string& world) {
  return "name: t\nworlds:\n  - name: w\n    file: " + world +
         "\n    camera: {name: cam, attach: m/rig, width: 32, height: 24, rate_hz: 10}\n"
         "conditions: [none]\ntrials: 1\nmethods:\n"
         "  - name: vio\n    dataset: euroc\n    command: \"run {dataset}\"\n";
}

constexpr char kModel[] =
    "<mujoco><worldbody><body name=\"rig\" pos=\"0 0 1\"><freejoint/>"
    "<geom type=\"box\" size=\"0.1 0.1 0.1\"/></body></worldbody></mujoco>";

std::string World(const std::string& sensors) {
  return "models:\n  - {name: m, file: m.xml}\n" + sensors;
}

std::string ImuEntry(const std::string& name) {
  return "  - {name: " + name + ", type: imu, body: m/rig, preset: consumer_mems}\n";
}

std::string ErrorOf(const TempDir& dir, const std::string& sensors) {
  dir.Write("m.xml", kModel);
  dir.Write("world.yaml", World(sensors));
  try {
    LoadBenchmarkSpec(dir.Write("spec.yaml", EurocSpec("world.yaml")));
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(BenchmarkSpecEuroc, AWorldWithoutAnImuIsRefusedAtTheMethodsDataset) {
  TempDir dir;
  const std::string e = ErrorOf(dir, "");
  EXPECT_NE(e.find("spec.yaml:10"), std::string::npos) << e;  // the `dataset: euroc` line
  EXPECT_NE(e.find("methods[0].dataset"), std::string::npos) << e;
  EXPECT_NE(e.find("EuRoC needs an IMU (imu0) and world 'w'"), std::string::npos) << e;
  EXPECT_NE(e.find("world.yaml) has none"), std::string::npos) << e;
}

TEST(BenchmarkSpecEuroc, TwoImusAreRefusedOneLoads) {
  TempDir dir;
  const std::string e = ErrorOf(dir, "sensors:\n" + ImuEntry("a") + ImuEntry("b"));
  EXPECT_NE(e.find("has 2 IMUs (a, b)"), std::string::npos) << e;
  EXPECT_EQ(ErrorOf(dir, "sensors:\n" + ImuEntry("a")), "");
}

// a TUM method does not need an IMU
TEST(BenchmarkSpecEuroc, TumNeedsNoImu) {
  TempDir dir;
  dir.Write("m.xml", kModel);
  dir.Write("world.yaml", World(""));
  std::string spec = EurocSpec("world.yaml");
  spec.replace(spec.find("euroc"), 5, "tum");
  EXPECT_NO_THROW(LoadBenchmarkSpec(dir.Write("spec.yaml", spec)));
}

}  // namespace
}  // namespace penumbra

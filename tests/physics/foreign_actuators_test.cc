// trot_gait on a quadruped whose legs have position servos (as Menagerie's
// Go1 has stock <position> actuators) drives them through their kp/kv and walks as with
// torque motors; actuators whose force cannot be set are refused with an error naming the
// actuator and its type instead of being misread.
#include <gtest/gtest.h>

#include <fstream>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/config/yaml_document.h"
#include "penumbra/core/error.h"
#include "quadruped_test_util.h"

namespace penumbra {
namespace {

using namespace quadruped_test;  // NOLINT(build/namespaces)

std::string Config(const std::string& commands, const std::string& legs) {
  return "base_body: trunk\n" + legs + "commands: " + commands + "\n";
}

// worlds/models/quadruped.xml with its leg motors replaced by `replacement` (a tag start with
// attributes, e.g. "<position kp=\"100\""), written to a scratch folder; returns the folder
std::string ModelWithActuators(const std::string& replacement, const std::string& dir) {
  std::ifstream f(kModelsDir + "/quadruped.xml");
  std::stringstream ss;
  ss << f.rdbuf();
  std::string xml = ss.str();
  int n = 0;
  for (size_t p = xml.find("<motor name="); p != std::string::npos;
       p = xml.find("<motor name=", p)) {
    xml.replace(p, 6, replacement);
    ++n;
  }
  EXPECT_EQ(n, 12);
  std::ofstream(dir + "/quadruped.xml") << xml;
  return dir;
}

Rig LoadRig(const std::string& dir, const std::string& config) {
  Rig rig{Simulation::LoadFromString(SceneXml("quadruped", Ground::kFlat), std::nullopt, dir)};
  ControllerConfig cfg{"trot_gait", ParseYaml(config), 1};
  rig.sim.AddController(MakeController(cfg, "", "test.yaml"));
  rig.trunk = rig.sim.scene().FindBody("trunk");
  return rig;
}

double ForwardDistance(Rig* rig, double t_sec) {
  const double x0 = Trunk(*rig).translation().x();
  RunUntil(rig, t_sec);
  return Trunk(*rig).translation().x() - x0;
}

TEST(ForeignActuators, TrotGaitDrivesPositionServosLikeMotors) {
  const std::string config = Config("[{t: 0, vx: 0.5}]", LegsYaml());
  Rig motors{
      Simulation::LoadFromString(SceneXml("quadruped", Ground::kFlat), std::nullopt, kModelsDir)};
  motors.sim.AddController(MakeController({"trot_gait", ParseYaml(config), 1}, "", "test.yaml"));
  motors.trunk = motors.sim.scene().FindBody("trunk");
  const double reference = ForwardDistance(&motors, 3.0);

  // Menagerie Go1 style: <position kp> (ctrl = joint target), force-limited like the motors,
  // and a <general> servo with damping (biasprm 0 -kp -kv)
  const std::string dir = penumbra::testing::ProcessTempDir();
  for (const std::string& servo :
       {std::string("<position kp=\"100\""),
        std::string("<general gainprm=\"80\" biastype=\"affine\" biasprm=\"0 -80 -2\"")}) {
    Rig rig = LoadRig(ModelWithActuators(servo, dir), config);
    const double d = ForwardDistance(&rig, 3.0);
    std::printf("[ measured ] 3 s at 0.5 m/s: %.3f m with motors, %.3f m with %s\n", reference, d,
                servo.c_str());
    EXPECT_GT(reference, 1.2);
    EXPECT_NEAR(d, reference, 0.15 * reference) << servo;
    EXPECT_GT(Trunk(rig).linear()(2, 2), 0.95) << servo;  // upright
  }
}

TEST(ForeignActuators, OtherActuatorsAreRefusedNamingTheType) {
  const std::string dir = penumbra::testing::ProcessTempDir();
  // a bias that is neither a position nor a velocity servo's
  ModelWithActuators("<general gainprm=\"20\" biastype=\"affine\" biasprm=\"0 -50 0\"", dir);
  Simulation sim =
      Simulation::LoadFromString(SceneXml("quadruped", Ground::kFlat), std::nullopt, dir);
  ControllerConfig cfg{"trot_gait", ParseYaml(Config("[{t: 0, vx: 0.5}]", LegsYaml())), 3};
  try {
    sim.AddController(MakeController(cfg, "", "test.yaml"));
    ADD_FAILURE() << "trot_gait accepted actuators it cannot drive";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_NE(what.find("legs.FR.actuators[0]"), std::string::npos) << what;
    EXPECT_NE(what.find("actuator 'FR_hip' is a general actuator (biastype"), std::string::npos)
        << what;
    EXPECT_NE(what.find("expected a motor, position servo"), std::string::npos) << what;
  }
}

}  // namespace
}  // namespace penumbra

// the world file's physics options reach the composed model that MuJoCo compiles and that
// composed.xml holds (a replay loads that file): MuJoCo 3's implicitfast integrator included.
#include <gtest/gtest.h>

#include <fstream>
#include <memory>
#include <sstream>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

// a session of a box on a plane under the world file's `physics: {...}` (composed.xml kept in
// `dir`); returns the composed text
std::string PoComposedXml(penumbra::testing::TempDir& dir, const std::string& physics,
                          std::unique_ptr<Session>* session) {
  dir.Write("box.xml",
            "<mujoco><worldbody><geom type=\"plane\" size=\"2 2 0.1\"/>"
            "<body pos=\"0 0 0.5\"><freejoint/><geom type=\"box\" size=\"0.1 0.1 0.1\"/></body>"
            "</worldbody></mujoco>\n");
  const std::string world = dir.Write("world.yaml", "physics: " + physics +
                                                        "\nmodels:\n"
                                                        "  - name: box\n"
                                                        "    file: box.xml\n");
  SessionOptions options;
  options.build_renderer = false;
  options.composed_xml_path = dir.str() + "/composed.xml";
  *session = std::make_unique<Session>(LoadWorldFile(world), options);
  std::ifstream in(options.composed_xml_path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

TEST(PhysicsOptionsSession, ImplicitfastFromTheWorldFileIsTheComposedModelsIntegrator) {
  penumbra::testing::TempDir dir;
  std::unique_ptr<Session> session;
  const std::string xml =
      PoComposedXml(dir, "{integrator: implicitfast, cone: elliptic}", &session);
  EXPECT_NE(xml.find("integrator=\"implicitfast\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("cone=\"elliptic\""), std::string::npos) << xml;
  // and it steps: the box falls onto the plane and rests there
  Simulation& sim = session->sim();
  while (sim.time() < 1.0) sim.Step();
  EXPECT_NEAR(sim.Snapshot().X_WB.back().translation().z(), 0.1, 0.01);
}

TEST(PhysicsOptionsSession, NoslipAndSpeculativeContactsFromTheWorldFileReachComposedXml) {
  penumbra::testing::TempDir dir;
  std::unique_ptr<Session> session;
  const std::string xml =
      PoComposedXml(dir, "{noslip_iterations: 10, speculative: true}", &session);
  EXPECT_NE(xml.find("noslip_iterations=\"10\""), std::string::npos) << xml;
  EXPECT_NE(xml.find("speculative=\"enable\""), std::string::npos) << xml;
  // out of range: the key and the range
  const std::string bad = dir.Write("bad.yaml",
                                    "physics: {noslip_iterations: 5000}\n"
                                    "models:\n"
                                    "  - {name: box, file: box.xml}\n");
  try {
    LoadWorldFile(bad);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("physics.noslip_iterations"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace penumbra

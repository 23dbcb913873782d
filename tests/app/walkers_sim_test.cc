// articulated NPC agents in the physics and every output: a person's limbs and a vehicle's
// wheels are mocap bodies with real geoms, posed every step from the walking cycle or the
// wheels' spin; a ray hits a leg at its height, the camera labels limb pixels `person`, the
// appearance follows the seed, and a restart from a saved state repeats the limb poses.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/compose/agent_bodies.h"
#include "penumbra/session/world_composer.h"
#include "penumbra/effects/agent_animation.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/ray_query.h"
#include "penumbra/render/renderer.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/session/effects_stage.h"

namespace penumbra {
namespace {

// a floor and two walls far to the sides (static bounds of +-6 m)
const char* kWalkersArena = R"(<mujoco model="arena">
  <option timestep="0.002"/>
  <worldbody>
    <geom name="floor" type="plane" size="10 10 0.1"/>
    <geom name="wall_n" type="box" pos="0 6 1" size="6 0.1 1"/>
    <geom name="wall_s" type="box" pos="0 -6 1" size="6 0.1 1"/>
  </worldbody>
</mujoco>)";

WorldConfig WalkersWorld(const std::vector<AgentConfig>& agents, uint64_t seed = 1) {
  const auto dir = std::filesystem::path(penumbra::testing::ProcessTempDir());
  std::filesystem::create_directories(dir);
  const auto path = dir / "walkers_arena.xml";
  std::ofstream(path) << kWalkersArena;
  WorldConfig world;
  world.seed = seed;
  ModelConfig m;
  m.name = "arena";
  m.file = path.string();
  world.models.push_back(m);
  world.agents = agents;
  return world;
}

// a loaded world: the composed document, the effects stage and the simulation (attached)
struct WalkersSim {
  explicit WalkersSim(const WorldConfig& w)
      : world(w),
        composed(ComposeWorld(world.models, ComposeOptions{})),
        stage(world, &composed),
        sim(Simulation::LoadFromString(composed.Xml())) {
    stage.Attach(&sim);
  }
  WorldConfig world;
  ComposedScene composed;
  EffectsStage stage;
  Simulation sim;
};

// a person of 1.75 m walking along +x from (x0, 0), or standing there (speed 0: a long delay)
AgentConfig WalkersPerson(const std::string& name, double x0, double speed) {
  AgentConfig a;
  a.name = name;
  a.waypoints = {{x0, 0}, {x0 + 5, 0}};
  a.speed_m_s = speed > 0 ? speed : 1.0;
  a.start_delay_sec = speed > 0 ? 0 : 3600;
  a.route = AgentRoute::kOnce;
  a.height_m = 1.75;
  a.height_given = true;
  return a;
}

double WalkersAngleAboutY(const Eigen::Matrix3d& R) { return std::atan2(R(0, 2), R(0, 0)); }

TEST(Walkers, LimbBodiesAreMocapGeomsThatSwingAtTheStrideFrequency) {
  WalkersSim w(WalkersWorld({WalkersPerson("walker", -6.5, 1.3)}));  // walks to x = -1.5
  const SceneDescription scene = w.stage.Bind(w.sim.scene());
  const int root = scene.FindBody("agents/walker");
  ASSERT_GE(root, 0);
  // every part is a body with colliding geoms of class person
  for (const std::string& part : AgentPartNames(AgentKind::kPerson)) {
    const int b = scene.FindBody("agents/walker/" + part);
    ASSERT_GE(b, 0) << part;
    int geoms = 0;
    for (const Geom& g : scene.geoms)
      if (g.body == b) {
        ++geoms;
        EXPECT_EQ(g.semantic_class, kSemanticClassPerson) << g.name;
      }
    EXPECT_GE(geoms, 1) << part;
  }
  const int thigh = scene.FindBody("agents/walker/thigh_l");
  const AgentPath path(w.world.agents[0]);
  AgentAnimator expected(AgentKind::kPerson, 1.75, [&path](double t) { return path.X_WA(t); });
  std::vector<double> crossings;
  double prev = 0, worst = 0;
  while (w.sim.time() < 4.0 - 1e-9) {
    w.sim.Step();
    const WorldSnapshot s = w.sim.Snapshot(Simulation::SnapshotContent::kPoses);
    const double t = s.time_sec;
    const double flexion =
        -WalkersAngleAboutY(s.X_WB[root].linear().transpose() * s.X_WB[thigh].linear());
    if (t > 0.8 && t < 3.8 && prev < 0 && flexion >= 0) crossings.push_back(t);
    prev = flexion;
    worst = std::max(worst, (s.X_WB[thigh].matrix() - expected.Poses(t)[1].matrix()).norm());
  }
  ASSERT_GE(crossings.size(), 3u);
  const double hz = (crossings.size() - 1) / (crossings.back() - crossings.front());
  const double model_hz = WalkerStrideFrequency(1.3, 0.530 * 1.75);
  std::printf("thigh in the physics: %zu cycles, %.4f Hz (model %.4f Hz), pose error %.2g\n",
              crossings.size() - 1, hz, model_hz, worst);
  EXPECT_NEAR(hz, model_hz, 0.01 * model_hz);
  EXPECT_LT(worst, 1e-6) << "the body follows the animator at every step";
}

TEST(Walkers, ARayHitsTheLegAtItsHeightAndPassesBetweenTheLegs) {
  // a standing 1.75 m person at x = 3 facing +x: hips (and legs) at y = +-0.0875 m, shins r
  // 0.0525 m from the knee (0.499 m) down, thighs r 0.07 m from the hip (0.9275 m) down
  AgentConfig standing = WalkersPerson("p", 3, 0);
  standing.waypoints[1] = Eigen::Vector2d(4, 0);  // facing +x, inside the arena
  WalkersSim w(WalkersWorld({standing}));
  const SceneDescription scene = w.stage.Bind(w.sim.scene());
  std::unique_ptr<RayQuery> rays = MakeRayQuery(scene, RenderSettings::Backend::kEmbree);
  rays->Update(w.sim.Snapshot(Simulation::SnapshotContent::kPoses));
  const auto cast = [&](double y, double z) {
    Ray r;
    r.o = Eigen::Vector3f(0, static_cast<float>(y), static_cast<float>(z));
    r.d = Eigen::Vector3f(1, 0, 0);
    SurfaceHit hit;
    bool did = false;
    rays->Intersect(std::span<const Ray>(&r, 1), std::span<SurfaceHit>(&hit, 1),
                    std::span<bool>(&did, 1));
    return std::pair<bool, SurfaceHit>(did, hit);
  };
  const auto [shin_hit, shin] = cast(0.0875, 0.3);
  ASSERT_TRUE(shin_hit);
  EXPECT_EQ(scene.geoms[shin.geom].name, "agents/p/shin_l");
  EXPECT_EQ(scene.geoms[shin.geom].semantic_class, kSemanticClassPerson);
  EXPECT_NEAR(shin.t, 3 - 0.03 * 1.75, 1e-4);
  EXPECT_NEAR(shin.p_W.z(), 0.3, 1e-5);
  const auto [thigh_hit, thigh] = cast(-0.0875, 0.7);
  ASSERT_TRUE(thigh_hit);
  EXPECT_EQ(scene.geoms[thigh.geom].name, "agents/p/thigh_r");
  EXPECT_NEAR(thigh.t, 3 - 0.04 * 1.75, 1e-4);
  // between the shins (gap |y| < 0.035 m) the ray passes the person
  const auto [gap_hit, gap] = cast(0.0, 0.3);
  EXPECT_TRUE(!gap_hit || scene.geoms[gap.geom].name.rfind("agents/", 0) != 0)
      << scene.geoms[gap.geom].name;
  std::printf("rays at 0.3 m: shin hit at %.4f m, between the legs: %s\n", shin.t,
              gap_hit ? scene.geoms[gap.geom].name.c_str() : "miss");
}

TEST(Walkers, TheCameraLabelsLimbPixelsPerson) {
  AgentConfig walker = WalkersPerson("p", 3, 1.0);
  walker.waypoints = {{3, 0}, {3, 4}};  // walks across the view (+y)
  WalkersSim w(WalkersWorld({walker}));
  while (w.sim.time() < 0.8 - 1e-9) w.sim.Step();  // mid-stride
  const SceneDescription scene = w.stage.Bind(w.sim.scene());
  RenderSettings rs;
  rs.tier = RenderSettings::Tier::kRealtime;
  auto renderer = MakeRenderer(scene, rs);
  CameraView view;
  view.X_WO.linear() = RotationBodyFromOptical();
  view.X_WO.translation() = Eigen::Vector3d(0, 0.8, 0.9);
  view.intrinsics = CameraIntrinsics::FromFovy(120, 160, 70);
  view.outputs[ImageKind::kRgb] = false;
  view.outputs[ImageKind::kSemanticSegmentation] = view.outputs[ImageKind::kInstanceSegmentation] =
      true;
  RenderedFrame f;
  renderer->Render(w.sim.Snapshot(), view, &f);
  std::map<std::string, int> limb_pixels;
  int person = 0, limb_not_person = 0;
  for (int v = 0; v < 160; ++v)
    for (int u = 0; u < 120; ++u) {
      const int body = *f.body_id.at(u, v);
      const int cls = *f.semantic_class.at(u, v);
      person += cls == kSemanticClassPerson;
      if (body < 0) continue;
      const std::string& name = scene.bodies[body].name;
      if (name.rfind("agents/p/", 0) != 0) continue;
      ++limb_pixels[name.substr(9)];
      limb_not_person += cls != kSemanticClassPerson;
    }
  for (const auto& [part, n] : limb_pixels) std::printf("%s: %d px\n", part.c_str(), n);
  EXPECT_EQ(limb_not_person, 0);
  for (const char* part : {"thigh_l", "thigh_r", "shin_l", "shin_r"})
    EXPECT_GT(limb_pixels[part], 10) << part;
  EXPECT_GT(person, 500);
}

TEST(Walkers, HeightsAndColoursFollowTheSeed) {
  AgentConfig a = WalkersPerson("p0", 0, 1.0);
  a.height_given = false;
  AgentConfig b = a;
  b.name = "p1";
  const std::vector<MocapBodySpec> s1 = AgentBodySpecs({a, b}, 11);
  const std::vector<MocapBodySpec> again = AgentBodySpecs({a, b}, 11);
  const std::vector<MocapBodySpec> s2 = AgentBodySpecs({a, b}, 12);
  for (size_t i = 0; i < 2; ++i) {
    EXPECT_EQ(s1[i].height_m, again[i].height_m);
    EXPECT_EQ(s1[i].shirt_rgb, again[i].shirt_rgb);
    EXPECT_EQ(s1[i].trousers_rgb, again[i].trousers_rgb);
    EXPECT_NE(s1[i].height_m, s2[i].height_m);
  }
  EXPECT_NE(s1[0].height_m, s1[1].height_m);
  // the composed document is the same for the same seed, and the head top is at the height
  WalkersSim x(WalkersWorld({a, b}, 11)), y(WalkersWorld({a, b}, 11));
  EXPECT_EQ(x.composed.Xml(), y.composed.Xml());
  const SceneDescription scene = x.sim.scene();
  const int root = scene.FindBody("agents/p0");
  int heads = 0;
  for (const Geom& g : scene.geoms) {
    if (g.body != root || g.name != "agents/p0/head") continue;
    ++heads;
    EXPECT_NEAR(g.X_BG.translation().z() + g.size[0], s1[0].height_m, 1e-9);
  }
  EXPECT_EQ(heads, 1);
  // a given height wins
  a.height_given = true;
  a.height_m = 1.9;
  EXPECT_EQ(AgentBodySpecs({a}, 11)[0].height_m, 1.9);
}

TEST(Walkers, WheelsSpinByDistanceOverRadiusInThePhysics) {
  AgentConfig lift = WalkersPerson("lift", -4, 2.0);
  lift.kind = AgentKind::kForklift;
  WalkersSim w(WalkersWorld({lift}));
  const int root = w.sim.scene().FindBody("agents/lift");
  const int wheel = w.sim.scene().FindBody("agents/lift/wheel_fl");
  ASSERT_GE(wheel, 0);
  while (w.sim.time() < 1.5 - 1e-9) w.sim.Step();
  const WorldSnapshot s = w.sim.Snapshot(Simulation::SnapshotContent::kPoses);
  const double distance = s.X_WB[root].translation().x() + 4;
  const double angle =
      WalkersAngleAboutY(s.X_WB[root].linear().transpose() * s.X_WB[wheel].linear());
  std::printf("forklift after %.3f m: wheel at %.4f rad, distance / radius %.4f rad\n", distance,
              angle, distance / 0.25);
  EXPECT_NEAR(distance, 3.0, 1e-6);
  EXPECT_NEAR(std::remainder(angle - distance / 0.25, 2 * M_PI), 0, 1e-6);
}

TEST(Walkers, ARestartFromASavedStateRepeatsTheLimbPoses) {
  AgentConfig a = WalkersPerson("p", -3, 1.4);
  a.waypoints = {{-3, 0}, {2, 0}, {2, 3}};
  a.route = AgentRoute::kPingPong;
  a.pause_sec = 0.3;
  WalkersSim w(WalkersWorld({a}));
  while (w.sim.time() < 1.0 - 1e-9) w.sim.Step();
  const SimState saved = w.sim.GetState();
  std::vector<std::vector<Pose>> first;
  while (w.sim.time() < 3.0 - 1e-9) {
    w.sim.Step();
    first.push_back(w.sim.Snapshot(Simulation::SnapshotContent::kPoses).X_WB);
  }
  // back in time on the same simulation: the drivers' animators restart and repeat
  w.sim.SetState(saved);
  for (const std::vector<Pose>& want : first) {
    w.sim.Step();
    const std::vector<Pose> got = w.sim.Snapshot(Simulation::SnapshotContent::kPoses).X_WB;
    ASSERT_EQ(got.size(), want.size());
    for (size_t b = 0; b < got.size(); ++b)
      ASSERT_TRUE(got[b].matrix() == want[b].matrix()) << "body " << b << " at " << w.sim.time();
  }
}

}  // namespace
}  // namespace penumbra

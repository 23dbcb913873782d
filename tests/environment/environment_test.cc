// generated environments (environment/): the same seed gives the same bytes and another seed
// another layout; every colliding geom keeps the walkway's half width for many seeds (read
// back from the MJCF text, independently of the generator's own check); the generated file
// is written once and reused; the bundled worlds route their robot along the walkway and the
// quadruped walks it without touching anything but the floor.

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <map>
#include <regex>
#include <set>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/environment/environment_generator.h"
#include "penumbra/environment/environment_model.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

EnvironmentConfig Config(const std::string& type, uint64_t seed, int resolution = 64) {
  EnvironmentConfig c;
  c.type = type;
  c.seed = seed;
  c.texture_resolution = resolution;
  return c;
}

// a geom of the MJCF text: name, plan bounding rectangle, top height, whether it collides
struct PlanGeom {
  std::string name;
  double x0, y0, x1, y1, z0, z1;
  bool collides;
};

std::vector<double> Numbers(const std::string& s) {
  std::vector<double> v;
  std::istringstream in(s);
  for (double x; in >> x;) v.push_back(x);
  return v;
}

std::string Attribute(const std::string& element, const std::string& name) {
  const std::regex re(" " + name + "=\"([^\"]*)\"");
  std::smatch m;
  return std::regex_search(element, m, re) ? m[1].str() : "";
}

// the geoms of the generated MJCF in the model frame (a static body's pos added to its geoms')
std::vector<PlanGeom> GeomsOf(const std::string& mjcf) {
  std::vector<PlanGeom> out;
  std::istringstream lines(mjcf);
  std::vector<double> body_pos = {0, 0, 0};
  for (std::string e; std::getline(lines, e);) {
    if (e.find("<body ") != std::string::npos) body_pos = Numbers(Attribute(e, "pos"));
    if (e.find("</body>") != std::string::npos) body_pos = {0, 0, 0};
    if (e.find("<geom ") == std::string::npos) continue;
    PlanGeom g;
    g.name = Attribute(e, "name");
    g.collides = Attribute(e, "contype") != "0";
    const std::string type = Attribute(e, "type");
    const std::vector<double> size = Numbers(Attribute(e, "size"));
    std::vector<double> pos = Numbers(Attribute(e, "pos"));
    for (int k = 0; k < 3; ++k) pos[k] += body_pos[k];
    const std::vector<double> euler = Numbers(Attribute(e, "euler"));
    const double yaw = euler.size() == 3 ? euler[2] * M_PI / 180 : 0;
    double hx = 0, hy = 0, hz = 0;
    if (type == "box") {
      // the plan extent of the turned box
      hx = std::abs(std::cos(yaw)) * size[0] + std::abs(std::sin(yaw)) * size[1];
      hy = std::abs(std::sin(yaw)) * size[0] + std::abs(std::cos(yaw)) * size[1];
      hz = size[2];
    } else if (type == "cylinder") {
      hx = hy = size[0];
      hz = size[1];
    } else if (type == "sphere") {
      hx = hy = hz = size[0];
    } else {
      continue;  // planes
    }
    g.x0 = pos[0] - hx, g.x1 = pos[0] + hx, g.y0 = pos[1] - hy, g.y1 = pos[1] + hy;
    g.z0 = pos[2] - hz, g.z1 = pos[2] + hz;
    out.push_back(g);
  }
  return out;
}

// distance from the rectangle to the polyline, sampled every 1 cm along it
double DistanceToWalkway(const PlanGeom& g, const Walkway& w) {
  double best = 1e9;
  for (size_t i = 0; i + 1 < w.points.size(); ++i) {
    const Eigen::Vector2d a = w.points[i], b = w.points[i + 1];
    const int n = static_cast<int>((b - a).norm() / 0.01) + 1;
    for (int k = 0; k <= n; ++k) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(k) / n);
      const double dx = std::max({g.x0 - p.x(), 0.0, p.x() - g.x1});
      const double dy = std::max({g.y0 - p.y(), 0.0, p.y() - g.y1});
      best = std::min(best, std::hypot(dx, dy));
    }
  }
  return best;
}

TEST(EnvironmentGenerator, SameSeedSameBytesAnotherSeedAnotherLayout) {
  for (const std::string type : {"house", "warehouse", "outdoor"}) {
    SCOPED_TRACE(type);
    const GeneratedEnvironment a = GenerateEnvironment(Config(type, 3));
    const GeneratedEnvironment b = GenerateEnvironment(Config(type, 3));
    const GeneratedEnvironment c = GenerateEnvironment(Config(type, 4));
    EXPECT_EQ(a.mjcf, b.mjcf);
    ASSERT_EQ(a.files.size(), b.files.size());
    for (size_t i = 0; i < a.files.size(); ++i) EXPECT_EQ(a.files[i].bytes, b.files[i].bytes);
    ASSERT_EQ(a.materials.size(), b.materials.size());
    for (size_t i = 0; i < a.materials.size(); ++i) {
      EXPECT_EQ(a.materials[i].config.seed, b.materials[i].config.seed);
      EXPECT_EQ(a.materials[i].config.color, b.materials[i].config.color);
    }
    EXPECT_NE(a.mjcf, c.mjcf);
    // another layout, not only other material seeds: the geoms' positions differ
    std::set<std::string> pa, pc;
    for (const PlanGeom& g : GeomsOf(a.mjcf))
      pa.insert(g.name + std::to_string(std::lround(g.x0 * 100)));
    for (const PlanGeom& g : GeomsOf(c.mjcf))
      pc.insert(g.name + std::to_string(std::lround(g.x0 * 100)));
    EXPECT_NE(pa, pc);
    EXPECT_NE(a.materials.front().config.seed, c.materials.front().config.seed);
    EXPECT_GT(a.furniture, 10);
    if (type != "outdoor") {
      EXPECT_GE(a.lights.size(), 8u);
    }
    EXPECT_EQ(a.geoms, static_cast<int>(GeomsOf(a.mjcf).size()) + 1);  // + the ground plane
  }
}

TEST(EnvironmentGenerator, EveryCollidingGeomKeepsClearOfTheWalkway) {
  for (const std::string type : {"house", "warehouse", "outdoor"}) {
    for (uint64_t seed = 0; seed < 12; ++seed) {
      SCOPED_TRACE(type + " seed " + std::to_string(seed));
      const GeneratedEnvironment env = GenerateEnvironment(Config(type, seed));
      ASSERT_EQ(env.walkways.size(), 1u);
      const Walkway& w = env.walkways.front();
      int checked = 0;
      for (const PlanGeom& g : GeomsOf(env.mjcf)) {
        // the building itself (floors, walls and the door jambs in them) and what hangs
        // above a robot's reach (> 0.6 m up) may be near the walkway
        if (g.name.rfind("floor_", 0) == 0 || g.name.rfind("wall_", 0) == 0) continue;
        if (g.z0 > 0.6) continue;
        ++checked;
        if (!g.collides) continue;
        EXPECT_GE(DistanceToWalkway(g, w), w.half_width_m - 1e-3) << g.name;
      }
      EXPECT_GT(checked, 20);
    }
  }
}

TEST(EnvironmentGenerator, OnlyTheWarehouseSaysWhereVehiclesMayDrive) {
  // vehicles belong in the warehouse's zones and aisle; no room of the house, no outdoor trail
  for (const std::string type : {"house", "outdoor"})
    EXPECT_TRUE(GenerateEnvironment(Config(type, 1)).drivable.empty()) << type;
  const GeneratedEnvironment w = GenerateEnvironment(Config("warehouse", 1));
  EXPECT_FALSE(w.drivable.empty());
  for (const std::string& name : w.drivable) {
    const bool room =
        std::any_of(w.rooms.begin(), w.rooms.end(), [&](const auto& r) { return r.first == name; });
    const bool walkway = std::any_of(w.walkways.begin(), w.walkways.end(),
                                     [&](const Walkway& k) { return k.name == name; });
    EXPECT_TRUE(room || walkway) << name << " is neither a zone nor a walkway";
  }
}

TEST(EnvironmentGenerator, ItLoadsInMujocoWithItsMaterials) {
  for (const std::string type : {"house", "warehouse"}) {
    SCOPED_TRACE(type);
    const GeneratedEnvironment env = GenerateEnvironment(Config(type, 5));
    const Simulation sim = Simulation::LoadFromString(env.mjcf, std::nullopt);
    const SceneDescription& scene = sim.scene();
    EXPECT_EQ(static_cast<int>(scene.geoms.size()), env.geoms);
    for (const ProceduralMaterialEntry& e : env.materials)
      EXPECT_GE(scene.FindMaterial(e.material), 0) << e.material;
  }
}

TEST(EnvironmentModel, WritesTheModelOnceAndPrefixesLampsAndMaterials) {
  testing::TempDir dir;
  std::vector<ModelConfig> models(2);
  models[0].name = "robot";
  models[0].file = "/some/robot.xml";
  models[1].name = "home";
  models[1].environment = Config("house", 2);
  models[1].pose.xyz = {10, 0, 0};
  const GeneratedModels a = GenerateEnvironmentModels(&models, dir.path().string());
  EXPECT_EQ(models[0].file, "/some/robot.xml");
  ASSERT_EQ(a.models.size(), 1u);
  EXPECT_EQ(models[1].file, a.models[0].file);
  EXPECT_TRUE(fs::is_regular_file(models[1].file));
  const auto written = fs::last_write_time(models[1].file);
  ASSERT_FALSE(a.lights.empty());
  EXPECT_EQ(a.lights[0].name.rfind("home/", 0), 0u);
  EXPECT_NEAR(a.lights[0].position.x(), a.models[0].environment.lights[0].position.x() + 10, 1e-12);
  EXPECT_EQ(a.materials.front().material.rfind("home/", 0), 0u);
  // a second load finds the file and leaves it as it was
  models[1].file.clear();
  const GeneratedModels b = GenerateEnvironmentModels(&models, dir.path().string());
  EXPECT_EQ(b.models[0].file, a.models[0].file);
  EXPECT_EQ(fs::last_write_time(models[1].file), written);
}

TEST(EnvironmentWorldFile, EnvironmentEntriesAreChecked) {
  testing::TempDir dir;
  const auto load = [&](const std::string& models) {
    return LoadWorldFile(dir.Write("w.yaml", "models:\n" + models));
  };
  const WorldConfig ok = load("  - {name: h, environment: {type: warehouse, seed: 9}}\n");
  ASSERT_TRUE(ok.models[0].environment.has_value());
  EXPECT_EQ(ok.models[0].environment->seed, 9u);
  try {
    load("  - {name: h, environment: {type: castle}}\n");
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.line(), 2);
    EXPECT_NE(std::string(e.what()).find("models[0].environment.type"), std::string::npos)
        << e.what();
  }
  EXPECT_THROW(load("  - {name: h, file: x.xml, environment: {type: house}}\n"), ConfigError);
  EXPECT_THROW(load("  - {name: h, environment: {type: house, texture_resolution: 8}}\n"),
               ConfigError);
  EXPECT_THROW(load("  - {name: h}\n"), ConfigError);
  EXPECT_THROW(load("  - {name: h, environment: {type: house}, units: cm}\n"), ConfigError);
}

// the bundled worlds: the robot's waypoints are the walkway's points, and the quadruped walks
// the whole route touching nothing but the floor
void WalkTheRoute(const std::string& world_name, double min_distance_m) {
  WorldConfig world = LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/" + world_name);
  const ModelConfig* robot = nullptr;
  const ModelConfig* building = nullptr;
  for (const ModelConfig& m : world.models) {
    if (m.is_robot) robot = &m;
    if (m.environment) building = &m;
  }
  ASSERT_NE(robot, nullptr);
  ASSERT_NE(building, nullptr);
  const GeneratedEnvironment env = GenerateEnvironment(*building->environment);
  const Walkway& walkway = env.walkways.front();
  const ConfigValue waypoints = robot->controller.params["waypoints"];
  ASSERT_EQ(waypoints.size() + 1, walkway.points.size());
  EXPECT_NEAR(robot->pose.xyz.x(), walkway.points[0].x(), 1e-9);
  EXPECT_NEAR(robot->pose.xyz.y(), walkway.points[0].y(), 1e-9);
  for (size_t i = 0; i < waypoints.size(); ++i) {
    double x = 0, y = 0;
    ASSERT_TRUE(waypoints[i][0].ToDouble(&x) && waypoints[i][1].ToDouble(&y));
    EXPECT_NEAR(x, walkway.points[i + 1].x(), 1e-9);
    EXPECT_NEAR(y, walkway.points[i + 1].y(), 1e-9);
  }

  SessionOptions options;
  options.build_renderer = false;
  Session session(world, options);
  Simulation& sim = session.sim();
  const SceneDescription& scene = session.scene();
  std::map<int, std::string> geom_names;
  for (const Geom& g : scene.geoms) geom_names[g.id] = g.name;
  const std::string robot_prefix = robot->name + "/", building_prefix = building->name + "/";
  const auto is_robot_body = [&](int body) {
    return scene.bodies[body].name.rfind(robot_prefix, 0) == 0;
  };
  int trunk = -1;
  for (size_t i = 0; i < scene.bodies.size(); ++i)
    if (scene.bodies[i].name == robot_prefix + "trunk") trunk = static_cast<int>(i);
  ASSERT_GE(trunk, 0);

  const int steps = static_cast<int>(world.duration_sec / sim.timestep());
  std::set<std::string> touched;
  std::string first_touch;
  double min_up = 1;  // the trunk's z axis's vertical component: < cos 45 deg = fallen over
  WorldSnapshot snap;
  for (int i = 0; i < steps; ++i) {
    sim.Step();
    if (i % 25 != 0) continue;  // every 50 ms
    sim.Snapshot(&snap);
    min_up = std::min(min_up, snap.X_WB[trunk].linear()(2, 2));
    for (const WorldSnapshot::Contact& c : snap.contacts) {
      const bool r1 = is_robot_body(c.body1), r2 = is_robot_body(c.body2);
      if (r1 == r2) continue;
      const std::string other = geom_names[r1 ? c.geom2 : c.geom1];
      if (other.rfind(building_prefix + "floor_", 0) == 0) continue;
      if (touched.empty())
        first_touch =
            fmt::format("{} at t = {:.2f} s, trunk at ({:.2f}, {:.2f})", other, snap.time_sec,
                        snap.X_WB[trunk].translation().x(), snap.X_WB[trunk].translation().y());
      touched.insert(other);
    }
  }
  EXPECT_TRUE(touched.empty()) << "the robot touched " << first_touch << " and "
                               << touched.size() - 1 << " more";
  // it reached the end of the route and stayed on its feet
  const Eigen::Vector3d end = snap.X_WB[trunk].translation();
  EXPECT_LT((end.head<2>() - walkway.points.back()).norm(), min_distance_m) << end.transpose();
  EXPECT_GT(min_up, std::cos(M_PI / 4));
}

TEST(EnvironmentWorlds, TheQuadrupedWalksTheHouseWithoutCollisions) {
  WalkTheRoute("house.yaml", 0.5);
}

TEST(EnvironmentWorlds, TheQuadrupedWalksTheWarehouseWithoutCollisions) {
  WalkTheRoute("warehouse.yaml", 0.5);
}

TEST(EnvironmentWorlds, TheQuadrupedTrotsTheOutdoorTrailWithoutCollisions) {
  // the route's waypoint tolerance is 0.5 m there (worlds/outdoor.yaml)
  WalkTheRoute("outdoor.yaml", 0.8);
}

TEST(EnvironmentModel, TheOutdoorTerrainIsAHeightFieldFileMujocoLoads) {
  testing::TempDir dir;
  std::vector<ModelConfig> models(1);
  models[0].name = "land";
  models[0].environment = Config("outdoor", 3);
  const GeneratedModels g = GenerateEnvironmentModels(&models, dir.str());
  const std::string mjcf = testing::ReadAll(models[0].file);
  EXPECT_EQ(mjcf.find('@'), std::string::npos);  // every placeholder replaced
  const Simulation sim = Simulation::LoadFromFile(models[0].file);
  ASSERT_EQ(sim.scene().hfields.size(), 1u);
  EXPECT_EQ(sim.scene().hfields[0].rows, 241);
  EXPECT_EQ(sim.scene().hfields[0].cols, 241);
  EXPECT_NEAR(sim.scene().hfields[0].size_x, 30, 1e-6);
}

}  // namespace
}  // namespace penumbra

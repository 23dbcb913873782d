// the bundled default world (a Go1-class quadruped trotting a loop of waypoints through the
// furnished room): it loads, runs, the robot walks at its speed without falling, the loop
// keeps clear of the furniture, and the output is deterministic across render threads.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <limits>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/run/runner.h"
#include "penumbra/session/world_composer.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/control/trot_gait.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

const char kDefaultWorld[] = PENUMBRA_SOURCE_DIR "/worlds/default.yaml";
const std::string kRobot = "go1";

using testing::ReadAll;

// rows of trajectory.csv (step, time_sec, qpos...) as numbers
std::vector<std::vector<double>> ReadTrajectory(const fs::path& csv) {
  std::ifstream f(csv);
  std::string line;
  std::getline(f, line);  // header
  std::vector<std::vector<double>> rows;
  while (std::getline(f, line)) {
    std::vector<double> v;
    std::stringstream ss(line);
    std::string cell;
    while (std::getline(ss, cell, ',')) v.push_back(std::stod(cell));
    rows.push_back(std::move(v));
  }
  return rows;
}

const ModelConfig& RobotConfig(const WorldConfig& world) {
  for (const ModelConfig& m : world.models)
    if (m.is_robot && m.name == kRobot) return m;
  throw std::runtime_error("no robot '" + kRobot + "' in the default world");
}

TEST(DefaultWorldTest, TheQuadrupedWalksAndTheRunIsDeterministic) {
  const fs::path dir =
      fs::temp_directory_path() / ("penumbra_default_world_" + std::to_string(::getpid()));
  fs::remove_all(dir);
  WorldConfig world = LoadWorldFile(kDefaultWorld);
  ASSERT_FALSE(world.cameras.empty());
  ASSERT_EQ(world.models.front().name, kRobot);  // robots are composed first
  ASSERT_EQ(RobotConfig(world).controller.type, "trot_gait");
  RunOptions options;
  options.progress = false;
  options.duration_sec = 2.5;
  // keep the images small: the test is about the pipeline, not resolution
  for (CameraConfig& c : world.cameras) {
    c.width = 160;
    c.height = 120;
  }
  world.render.threads = 1;
  options.out_dir = (dir / "a").string();
  const RunSummary a = RunWorld(world, options);
  world.render.threads = 2;
  options.out_dir = (dir / "b").string();
  RunWorld(world, options);

  const std::string cam = world.cameras.front().name;
  EXPECT_EQ(a.frames_per_camera.at(cam), 26);  // 10 Hz over 2.5 s, both ends
  for (const char* file : {"trajectory.csv", "composed.xml"})
    EXPECT_TRUE(ReadAll(dir / "a" / file) == ReadAll(dir / "b" / file)) << file;
  int images = 0;
  for (const auto& e : fs::recursive_directory_iterator(dir / "a" / cam)) {
    if (!e.is_regular_file()) continue;
    const fs::path rel = fs::relative(e.path(), dir / "a");
    EXPECT_TRUE(ReadAll(e.path()) == ReadAll(dir / "b" / rel)) << rel;
    ++images;
  }
  EXPECT_GE(images, 3 * 26);  // rgb, depth and segmentation of every frame

  // the robot's free joint is the first qpos block (robots are composed before models):
  // columns 2..4 are the trunk origin x, y, z. from standing at the start pose it
  // accelerates (1.5 m/s^2 slew limit) to the 0.45 m/s cruise towards the first waypoint,
  // 1.57 m ahead, so after 2.5 s it has walked about 0.45 (2.5 - 0.15) = 1.06 m along a
  // straight line; a trot's speed oscillates within each stride, hence the band.
  const std::vector<std::vector<double>> rows = ReadTrajectory(dir / "a" / "trajectory.csv");
  ASSERT_EQ(rows.size(), 1250u);
  const Eigen::Vector2d p0(-0.2, -1.45);  // start pose of the world file
  const Eigen::Vector2d p1(rows.back()[2], rows.back()[3]);
  const Eigen::Vector2d heading(std::cos(17 * M_PI / 180), std::sin(17 * M_PI / 180));
  const double along = (p1 - p0).dot(heading);
  const double across = std::abs(heading.x() * (p1 - p0).y() - heading.y() * (p1 - p0).x());
  double min_z = 1e9, max_z = 0;
  for (const auto& r : rows) {
    min_z = std::min(min_z, r[4]);
    max_z = std::max(max_z, r[4]);
  }
  std::printf(
      "[ measured ] 2.5 s: %.3f m along the start heading, %.3f m across; trunk z in "
      "[%.3f, %.3f] m\n",
      along, across, min_z, max_z);
  EXPECT_GT(along, 0.85) << "walked too little for 0.45 m/s";
  EXPECT_LT(along, 1.2) << "walked faster than its 0.45 m/s cruise";
  EXPECT_LT(across, 0.1);
  // standing, the trunk origin is 0.285 m up; trotting it stays near the gait's target height
  // (the height at the start; its belly is 0.055 m below the origin)
  EXPECT_GT(min_z, 0.25);
  EXPECT_LT(max_z, 0.33);
  fs::remove_all(dir);
}

// ---------------------------------------------------------------------------------------
// clearance of the loop, in plan view: every geom of the robot (collision and visual) against
// every other geom that reaches into the robot's height band, while it walks one full lap.

// a plan-view obstacle: an upright box (rectangle) or an upright round shape (disc)
struct Obstacle {
  std::string name;
  bool is_box = true;
  Eigen::Vector2d centre = Eigen::Vector2d::Zero();
  Eigen::Matrix2d axes = Eigen::Matrix2d::Identity();  // columns: the box's x and y axes
  Eigen::Vector2d half = Eigen::Vector2d::Zero();      // box half sizes, or (r, r)

  double Distance(const Eigen::Vector2d& p) const {
    const Eigen::Vector2d d = p - centre;
    if (!is_box) return d.norm() - half.x();
    const Eigen::Vector2d local = axes.transpose() * d;
    const Eigen::Vector2d out = (local.cwiseAbs() - half).cwiseMax(0.0);
    const double inside = std::min(0.0, (local.cwiseAbs() - half).maxCoeff());
    return out.norm() + inside;
  }
};

// a point of the robot in plan view, padded by a radius
struct Sample {
  Eigen::Vector2d p;
  double radius = 0;
};

// z range of a geom in the world (m)
std::pair<double, double> ZRange(const Geom& g, const Pose& X_WG) {
  const Eigen::Matrix3d& R = X_WG.linear();
  const double cz = X_WG.translation().z();
  double h = 0;
  switch (g.shape) {
    case GeomShape::kBox:
      for (int j = 0; j < 3; ++j) h += std::abs(R(2, j)) * g.size[j];
      break;
    case GeomShape::kSphere:
      h = g.size[0];
      break;
    case GeomShape::kCapsule:
    case GeomShape::kCylinder: {
      const double az = std::abs(R(2, 2));
      h = az * g.size[1] + g.size[0] * std::sqrt(std::max(0.0, 1 - az * az)) +
          (g.shape == GeomShape::kCapsule ? g.size[0] : 0.0);
      break;
    }
    case GeomShape::kEllipsoid:
      h = std::sqrt(std::pow(R(2, 0) * g.size[0], 2) + std::pow(R(2, 1) * g.size[1], 2) +
                    std::pow(R(2, 2) * g.size[2], 2));
      break;
    default:
      return {-std::numeric_limits<double>::infinity(), std::numeric_limits<double>::infinity()};
  }
  return {cz - h, cz + h};
}

// plan-view samples of a robot geom: box edges every <= 1 cm (the projected box's outline
// lies on them), capsule and cylinder axes every <= 1 cm padded by the radius, spheres and
// ellipsoids as padded centres
void AddSamples(const Geom& g, const Pose& X_WG, std::vector<Sample>* out) {
  auto segment = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, double r) {
    const int n = 1 + static_cast<int>(std::ceil((b - a).norm() / 0.01));
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector3d p = a + (b - a) * (static_cast<double>(i) / n);
      out->push_back({p.head<2>(), r});
    }
  };
  const Eigen::Vector3d& s = g.size;
  switch (g.shape) {
    case GeomShape::kBox:
      for (int axis = 0; axis < 3; ++axis) {
        const int u = (axis + 1) % 3, v = (axis + 2) % 3;
        for (int su : {-1, 1})
          for (int sv : {-1, 1}) {
            Eigen::Vector3d a, b;
            a[axis] = -s[axis];
            b[axis] = s[axis];
            a[u] = b[u] = su * s[u];
            a[v] = b[v] = sv * s[v];
            segment(X_WG * a, X_WG * b, 0);
          }
      }
      break;
    case GeomShape::kCapsule:
    case GeomShape::kCylinder:
      segment(X_WG * Eigen::Vector3d(0, 0, -s[1]), X_WG * Eigen::Vector3d(0, 0, s[1]), s[0]);
      break;
    case GeomShape::kSphere:
      out->push_back({X_WG.translation().head<2>(), s[0]});
      break;
    case GeomShape::kEllipsoid:
      out->push_back({X_WG.translation().head<2>(), s.maxCoeff()});
      break;
    default:
      ADD_FAILURE() << "robot geom '" << g.name << "' has a shape this test cannot sample";
  }
}

// the robot's height band: obstacles overlapping it count
constexpr double kBandLowM = 0.01, kBandHighM = 0.5;

TEST(DefaultWorldTest, TheLoopKeepsClearOfTheFurniture) {
  const WorldConfig world = LoadWorldFile(kDefaultWorld);
  ComposeOptions compose;
  compose.timestep_sec = world.timestep_sec;
  const ComposedScene composed = ComposeWorld(world.models, compose);
  Simulation sim = Simulation::LoadFromString(composed.Xml(), world.timestep_sec);
  const ModelConfig& robot = RobotConfig(world);
  std::unique_ptr<Controller> c = MakeController(robot.controller, robot.name, world.file);
  const TrotGait* gait = dynamic_cast<const TrotGait*>(c.get());
  ASSERT_NE(gait, nullptr);
  sim.AddController(std::move(c));
  const SceneDescription& scene = sim.scene();
  const int trunk = scene.FindBody(kRobot + "/trunk");
  ASSERT_GE(trunk, 0);
  auto is_robot = [&](int body) { return scene.bodies[body].name.rfind(kRobot + "/", 0) == 0; };

  const int n_waypoints = static_cast<int>(gait->route()->waypoints().size());
  WorldSnapshot snap;
  double clearance = 1e9, centre_clearance = 1e9, min_z = 1e9;
  std::string closest;
  double lap_start = -1, lap_end = -1, lap_path = 0;
  Eigen::Vector2d last(0, 0);
  std::vector<Sample> samples;
  std::vector<Obstacle> obstacles;
  // one lap: from reaching the first waypoint to reaching it again
  while (lap_end < 0 && sim.time() < 60.0) {
    sim.Step();
    const int64_t reached = gait->route()->reached();
    if (reached >= 1 && lap_start < 0) lap_start = sim.time();
    if (reached >= 1 + n_waypoints) lap_end = sim.time();
    if (sim.step_count() % 10 != 0 && lap_end < 0) continue;
    sim.Snapshot(&snap);
    const Eigen::Vector3d p = snap.X_WB[trunk].translation();
    min_z = std::min(min_z, p.z());
    // path length sampled every 0.1 s (without the trot's sway within each stride)
    if (sim.step_count() % 50 == 0 || lap_end > 0) {
      if (lap_start >= 0) lap_path += (p.head<2>() - last).norm();
      last = p.head<2>();
    }
    samples.clear();
    obstacles.clear();
    for (const Geom& g : scene.geoms) {
      const Pose X_WG = snap.X_WB[g.body] * g.X_BG;
      if (is_robot(g.body)) {
        AddSamples(g, X_WG, &samples);
        continue;
      }
      if (g.shape == GeomShape::kPlane) continue;
      const auto [z0, z1] = ZRange(g, X_WG);
      if (z1 < kBandLowM || z0 > kBandHighM) continue;
      // the room's furniture stands upright
      ASSERT_GT(std::abs(X_WG.linear()(2, 2)), 0.999) << g.name << " is tilted";
      Obstacle o;
      o.name = g.name;
      o.centre = X_WG.translation().head<2>();
      if (g.shape == GeomShape::kBox) {
        o.axes = X_WG.linear().topLeftCorner<2, 2>();
        o.half = g.size.head<2>();
      } else {
        ASSERT_TRUE(g.shape == GeomShape::kCylinder || g.shape == GeomShape::kEllipsoid ||
                    g.shape == GeomShape::kSphere)
            << g.name;
        o.is_box = false;
        o.half.setConstant(g.size.head<2>().maxCoeff());
      }
      obstacles.push_back(o);
    }
    for (const Obstacle& o : obstacles) {
      centre_clearance = std::min(centre_clearance, o.Distance(p.head<2>()));
      for (const Sample& s : samples) {
        const double d = o.Distance(s.p) - s.radius;
        if (d < clearance) {
          clearance = d;
          closest = o.name;
        }
      }
    }
  }
  std::printf(
      "[ measured ] one lap: %.2f s, trunk path %.2f m (%.2f m/s); robot-to-furniture "
      "clearance %.3f m (at %s), trunk origin %.3f m; trunk z >= %.3f m; %zu obstacles\n",
      lap_end - lap_start, lap_path, lap_path / (lap_end - lap_start), clearance, closest.c_str(),
      centre_clearance, min_z, obstacles.size());
  ASSERT_GT(lap_end, 0) << "no full lap in 60 s; reached " << gait->route()->reached();
  EXPECT_GT(obstacles.size(), 20u);  // walls, shelves, crates, barrels, table, chair, ...
  EXPECT_GE(clearance, 0.4);
  EXPECT_GT(min_z, 0.25);
  // about 12 m at 0.45 m/s with slower corners
  EXPECT_GT(lap_path, 10.0);
  EXPECT_LT(lap_path, 13.0);
  EXPECT_LT(lap_end - lap_start, 40.0);
}

}  // namespace
}  // namespace penumbra

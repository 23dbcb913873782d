// height fields from ray casts (render/geometry/height_field_sampling.h) written as MuJoCo hfield
// models (assets/height_field_model.h): a terrain mesh z = f(x, y) sampled from above matches f at
// the samples and, between them, within one cell's slope error; MuJoCo places the written hfield
// where the samples say (a ball dropped on it rests at f + r); a quadruped trots across.

#include "penumbra/assets/height_field_model.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/config/yaml_document.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/geometry/height_field_sampling.h"
#include "penumbra/render/geometry/static_geometry.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

// the terrain: 0.12 sin(1.2 x) cos(0.9 y), slope at most 0.12 * hypot(1.2, 0.9) = 0.18
double F(double x, double y) { return 0.12 * std::sin(1.2 * x) * std::cos(0.9 * y); }
constexpr double kMaxSlope = 0.18;

// an OBJ of f over [-h, h]^2 with vertices every `step` (z up)
std::string TerrainObj(double h, double step) {
  const int n = static_cast<int>(std::lround(2 * h / step)) + 1;
  std::string s;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const double x = -h + i * step, y = -h + j * step;
      s += fmt::format("v {:.6f} {:.6f} {:.6f}\n", x, y, F(x, y));
    }
  for (int j = 0; j + 1 < n; ++j)
    for (int i = 0; i + 1 < n; ++i) {
      const int a = j * n + i + 1, b = a + 1, c = a + n, d = c + 1;
      s += fmt::format("f {} {} {}\nf {} {} {}\n", a, b, d, a, d, c);
    }
  return s;
}

struct Sampled {
  SampledHeightField field;
  HeightFieldError error;
};

Sampled SampleTerrain(const testing::TempDir& dir, double cell_m, double half_m) {
  dir.Write("terrain.obj", TerrainObj(3.0, 0.05));
  const std::string world =
      dir.Write("w.yaml", "models:\n  - {name: ground, file: terrain.obj, up_axis: z}\n");
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  Session session(LoadWorldFile(world), so);
  const WorldSnapshot snap = session.sim().Snapshot();
  Eigen::Vector3d lo, hi;
  const SceneDescription statics = StaticGeoms(session.scene(), snap.X_WB, &lo, &hi);
  const std::unique_ptr<RayQuery> q = MakeRayQuery(statics, RenderSettings::Backend::kEmbree);
  q->Update(snap);
  Sampled s;
  s.field = SampleHeightField(*q, {-half_m, -half_m}, {half_m, half_m}, cell_m, hi.z() + 1, lo.z());
  s.error = ErrorAtCellCentres(*q, s.field, hi.z() + 1);
  return s;
}

TEST(HeightField, SamplesMatchTheMeshWithinOneCellsSlopeError) {
  testing::TempDir dir;
  const double cell = 0.1;
  const Sampled s = SampleTerrain(dir, cell, 2.5);
  ASSERT_EQ(s.field.cols, 51);
  ASSERT_EQ(s.field.rows, 51);
  EXPECT_EQ(s.field.misses, 0);
  // at the samples: the mesh's own linear interpolation of f (vertices every 0.05 m) differs
  // from f by at most 0.05^2 / 8 (|fxx| + 2 |fxy| + |fyy|) = 1.7e-4 m
  double worst = 0;
  for (int r = 0; r < s.field.rows; ++r)
    for (int c = 0; c < s.field.cols; ++c) {
      const double x = s.field.x0 + c * cell, y = s.field.y0 + r * cell;
      worst = std::max(worst, std::abs(s.field.z[r * s.field.cols + c] - F(x, y)));
    }
  EXPECT_LT(worst, 3e-4);
  // between them: within one cell's slope error, and in fact within the interpolation bound
  // cell^2 / 8 (|fxx| + 2 |fxy| + |fyy|) = 6.6e-4 m plus the mesh's
  EXPECT_LT(s.error.max_m, cell * kMaxSlope);
  EXPECT_LT(s.error.max_m, 1e-3);
  EXPECT_EQ(s.error.cells, 50 * 50);
}

TEST(HeightField, MujocoPlacesTheWrittenFieldAndAQuadrupedTrotsAcrossIt) {
  testing::TempDir dir;
  const Sampled s = SampleTerrain(dir, 0.1, 2.9);
  const std::string hfield = dir.Write("terrain.hfield", HfieldFileBytes(s.field));
  const std::string model =
      dir.Write("terrain.xml", HeightFieldMjcf("terrain", s.field, hfield, 0.1, {0.5, 0.5, 0.4}));

  // small boxes dropped on the field (friction 2: they do not slide on slopes up to 0.18) rest
  // with their centre 0.03 m (over cos of the slope) above f
  {
    std::string balls;
    const std::vector<Eigen::Vector2d> at = {{1.3, 0.0}, {-1.3, 0.0}, {0.4, 1.7}, {-2.1, -2.3}};
    for (size_t i = 0; i < at.size(); ++i)
      balls += fmt::format(
          R"(<body name="ball{}" pos="{} {} 0.5"><freejoint/><geom type="box" size="0.03 0.03 0.03" friction="2"/></body>)",
          i, at[i].x(), at[i].y());
    std::string xml = testing::ReadAll(model);
    xml.replace(xml.find("</worldbody>"), 0, balls);
    Simulation sim = Simulation::LoadFromString(xml, 0.002);
    for (int i = 0; i < 1500; ++i) sim.Step();
    const WorldSnapshot snap = sim.Snapshot();
    for (size_t i = 0; i < at.size(); ++i) {
      const int b = sim.scene().FindBody("ball" + std::to_string(i));
      ASSERT_GE(b, 0);
      const Eigen::Vector3d p = snap.X_WB[b].translation();
      EXPECT_NEAR(p.head<2>().x(), at[i].x(), 0.01);
      EXPECT_NEAR(p.z(), F(p.x(), p.y()) + 0.03, 0.005) << "box " << i << " at " << p.transpose();
    }
  }

  // the bundled quadruped trots 4.4 m across it
  WorldConfig world = LoadWorldFile(PENUMBRA_SOURCE_DIR "/worlds/default.yaml");
  std::vector<ModelConfig> models;
  for (ModelConfig m : world.models) {
    if (!m.is_robot) continue;
    m.pose.xyz = {-2.2, 0.3, F(-2.2, 0.3)};
    m.pose.rpy_deg = {0, 0, 0};
    m.controller.params = WithEntry(m.controller.params, "waypoints", ParseYaml("[[2.2, 0.3]]"));
    m.controller.params = WithEntry(m.controller.params, "loop", ConfigValue::Scalar("false"));
    models.push_back(m);
  }
  ASSERT_EQ(models.size(), 1u);
  ModelConfig terrain;
  terrain.name = "terrain";
  terrain.file = model;
  models.push_back(terrain);
  world.models = models;
  world.lights.clear();
  world.cameras.clear();
  world.materials.clear();
  SessionOptions so;
  so.build_renderer = false;
  Session session(world, so);
  Simulation& sim = session.sim();
  const int trunk = session.scene().FindBody(models[0].name + "/trunk");
  ASSERT_GE(trunk, 0);
  double min_clearance = 1e9;
  WorldSnapshot snap;
  for (int i = 0; i < static_cast<int>(14.0 / sim.timestep()); ++i) {
    sim.Step();
    if (i % 50) continue;
    sim.Snapshot(&snap);
    const Eigen::Vector3d p = snap.X_WB[trunk].translation();
    min_clearance = std::min(min_clearance, p.z() - F(p.x(), p.y()));
  }
  const Eigen::Vector3d end = snap.X_WB[trunk].translation();
  EXPECT_GT(end.x(), 1.8) << end.transpose();
  EXPECT_NEAR(end.y(), 0.3, 0.3);
  EXPECT_GT(min_clearance, 0.15);  // the trunk never came down to the ground: no fall
}

// the world-file option: a mesh model with `collision: heightfield` collides as the height
// field sampled from it (the mesh itself visual only)
TEST(HeightField, AMeshModelWithCollisionHeightfieldCollidesAsItsSampledField) {
  testing::TempDir dir;
  dir.Write("terrain.obj", TerrainObj(3.0, 0.05));
  const std::string world = dir.Write(
      "w.yaml",
      "models:\n  - {name: ground, file: terrain.obj, up_axis: z, collision: heightfield, "
      "heightfield_cell_m: 0.1}\n");
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  Session session(LoadWorldFile(world), so);
  const SceneDescription& scene = session.scene();
  ASSERT_EQ(scene.hfields.size(), 1u);
  const HeightField& h = scene.hfields[0];
  EXPECT_EQ(h.cols, 61);  // [-3, 3] every 0.1 m
  EXPECT_EQ(h.rows, 61);
  const Geom* hg = nullptr;
  for (const Geom& g : scene.geoms)
    if (g.name == "ground/collision_heightfield") hg = &g;
  ASSERT_NE(hg, nullptr);
  EXPECT_EQ(hg->group, 3);  // not drawn
  // the field's samples are f's heights where the world puts them
  double worst = 0;
  for (int r = 0; r < h.rows; r += 5)
    for (int c = 0; c < h.cols; c += 5) {
      const Eigen::Vector3d p_G(-h.size_x + 2 * h.size_x * c / (h.cols - 1),
                                -h.size_y + 2 * h.size_y * r / (h.rows - 1),
                                h.elevation[r * h.cols + c] * h.size_z);
      const Eigen::Vector3d p_W = hg->X_BG * p_G;
      worst = std::max(worst, std::abs(p_W.z() - F(p_W.x(), p_W.y())));
    }
  EXPECT_LT(worst, 1e-3);
  // the mesh does not collide any more; the field does (MuJoCo's defaults)
  const std::string& xml = session.composed_xml();
  const size_t mesh_at = xml.find("type=\"mesh\"");
  ASSERT_NE(mesh_at, std::string::npos);
  const size_t line_start = xml.rfind('\n', mesh_at) + 1;
  const std::string line = xml.substr(line_start, xml.find('\n', mesh_at) - line_start);
  EXPECT_NE(line.find("mesh=\"ground/"), std::string::npos) << line;
  EXPECT_NE(line.find("contype=\"0\""), std::string::npos) << line;
  EXPECT_NE(line.find("conaffinity=\"0\""), std::string::npos) << line;

  // heightfield_cell_m needs collision: heightfield
  const std::string bad = dir.Write(
      "bad.yaml", "models:\n  - {name: ground, file: terrain.obj, heightfield_cell_m: 0.1}\n");
  try {
    LoadWorldFile(bad);
    FAIL() << "no error";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("models[0].heightfield_cell_m"), std::string::npos)
        << e.what();
  }
}

}  // namespace
}  // namespace penumbra

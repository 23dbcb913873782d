// vdb_smoke: a density grid written with the OpenVDB API is loaded voxel for voxel.
#include "penumbra/effects/vdb_loader.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <filesystem>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/effects/effects_engine.h"

namespace penumbra {
namespace {

float Value(int i, int j, int k) { return 0.01f * (i + 2 * j + 3 * k) + 0.1f; }

std::string WriteVdb(const std::string& name, const std::string& grid_name) {
  openvdb::initialize();
  openvdb::FloatGrid::Ptr grid = openvdb::FloatGrid::create(0.0f);
  grid->setName(grid_name);
  grid->setTransform(openvdb::math::Transform::createLinearTransform(0.1));
  auto acc = grid->getAccessor();
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 4; ++i) acc.setValue(openvdb::Coord(i, j, k), Value(i, j, k));
  const std::string path =
      (std::filesystem::path(penumbra::testing::ProcessTempDir()) / name).string();
  openvdb::io::File file(path);
  openvdb::GridPtrVec grids{grid};
  file.write(grids);
  file.close();
  return path;
}

EffectConfig VdbEffect(const std::string& path) {
  EffectConfig e;
  e.name = "plume";
  e.params = VdbSmokeParams{};
  e.Get<VdbSmokeParams>().file = path;
  return e;
}

TEST(VdbLoaderTest, DensityGridIsCopiedVoxelForVoxel) {
  const std::string path = WriteVdb("penumbra_effects_density.vdb", "density");
  VdbSmokeParams p;
  p.file = path;
  p.density_scale_per_m = 3;
  const GridMedium g = LoadVdbDensity(p, std::nullopt, "effects[0]", "plume");
  ASSERT_EQ(g.nx, 4);
  ASSERT_EQ(g.ny, 6);
  ASSERT_EQ(g.nz, 8);
  // voxel centres at index * 0.1 m: box [-0.05, 0.35] x [-0.05, 0.55] x [-0.05, 0.75]
  EXPECT_NEAR(g.X_WG.translation().x(), 0.15, 1e-9);
  EXPECT_NEAR(g.X_WG.translation().z(), 0.35, 1e-9);
  EXPECT_NEAR(g.half_extents_m.y(), 0.3, 1e-9);
  for (int k = 0; k < 8; ++k)
    for (int j = 0; j < 6; ++j)
      for (int i = 0; i < 4; ++i)
        ASSERT_NEAR((*g.density)[(k * 6 + j) * 4 + i], Value(i, j, k), 1e-5) << i << j << k;
  EXPECT_NEAR(g.max_density, Value(3, 5, 7), 1e-5);
  EXPECT_EQ(g.sigma_t_per_m, Eigen::Vector3f::Constant(3));

  // through the engine, fitted into a region, at the effect's weight
  EffectConfig e = VdbEffect(path);
  e.region = BoxRegion{{1, 1, 0}, {2, 2, 1}};
  EffectsEngine engine({e}, 1, SceneDescription{});
  auto f = engine.Evaluate(0.5, {0, 0, 0});
  ASSERT_EQ(f->grid_media.size(), 1u);
  EXPECT_NEAR(f->grid_media[0].X_WG.translation().x(), 1.5, 1e-9);
  EXPECT_NEAR(f->grid_media[0].half_extents_m.z(), 0.5, 1e-9);
  EXPECT_EQ(*f->grid_media[0].density, *g.density);
}

TEST(VdbLoaderTest, FileWithoutDensityGridIsAConfigError) {
  const std::string path = WriteVdb("penumbra_effects_temperature.vdb", "temperature");
  try {
    EffectsEngine engine({VdbEffect(path)}, 1, SceneDescription{});
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string what = e.what();
    EXPECT_EQ(e.key(), "effects[0].grid");
    EXPECT_NE(what.find("'plume'"), std::string::npos) << what;
    EXPECT_NE(what.find("temperature"), std::string::npos) << what;
    EXPECT_NE(what.find("expected a float grid named 'density'"), std::string::npos) << what;
  }
}

TEST(VdbLoaderTest, MissingOrBrokenFileIsAConfigError) {
  EXPECT_THROW(EffectsEngine({VdbEffect("/nonexistent/x.vdb")}, 1, SceneDescription{}),
               ConfigError);
  const std::string junk =
      (std::filesystem::path(penumbra::testing::ProcessTempDir()) / "junk.vdb").string();
  FILE* fp = std::fopen(junk.c_str(), "wb");
  std::fputs("not a vdb file", fp);
  std::fclose(fp);
  try {
    EffectsEngine engine({VdbEffect(junk)}, 1, SceneDescription{});
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "effects[0].file");
  }
}

}  // namespace
}  // namespace penumbra

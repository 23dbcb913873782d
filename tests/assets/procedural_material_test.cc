// procedural PBR materials, deterministic per seed, at physical scale.
#include "penumbra/assets/procedural_material.h"

#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

ProceduralMaterialConfig Config(const std::string& type, uint64_t seed, int resolution = 128) {
  ProceduralMaterialConfig c;
  c.type = type;
  c.seed = seed;
  c.resolution = resolution;
  return c;
}

TEST(ProceduralMaterial, DiskCacheReturnsTheGeneratedMapsAndSurvivesABadEntry) {
  testing::TempDir dir;
  const std::string cache = (dir.path() / "materials").string();
  const ProceduralMaterialConfig config = Config("wood", 7, 64);
  const ProceduralMaps made = GenerateProceduralMaterial(config);
  bool hit = true;
  const ProceduralMaps first = CachedProceduralMaterial(config, cache, &hit);
  EXPECT_FALSE(hit);
  const ProceduralMaps second = CachedProceduralMaterial(config, cache, &hit);
  EXPECT_TRUE(hit);
  for (const ProceduralMaps* m : {&first, &second}) {
    EXPECT_EQ(m->albedo->rgb_srgb(), made.albedo->rgb_srgb());
    EXPECT_EQ(m->metal_roughness->rgb_srgb(), made.metal_roughness->rgb_srgb());
    EXPECT_EQ(m->normal->rgb_srgb(), made.normal->rgb_srgb());
    EXPECT_EQ(m->albedo->num_levels(), made.albedo->num_levels());
    EXPECT_DOUBLE_EQ(m->size_m, made.size_m);
  }
  // another seed, resolution or colour is another entry.
  ProceduralMaterialConfig other = config;
  other.color = Eigen::Vector3f(0.5f, 0.4f, 0.3f);
  EXPECT_NE(ProceduralMaterialKey(other), ProceduralMaterialKey(config));
  CachedProceduralMaterial(other, cache, &hit);
  EXPECT_FALSE(hit);
  EXPECT_NE(ProceduralMaterialKey(Config("wood", 8, 64)), ProceduralMaterialKey(config));
  EXPECT_NE(ProceduralMaterialKey(Config("wood", 7, 128)), ProceduralMaterialKey(config));
  // a truncated entry is a miss, and is written again.
  std::vector<std::filesystem::path> files;
  for (const auto& e : std::filesystem::directory_iterator(cache)) files.push_back(e.path());
  ASSERT_EQ(files.size(), 2u);
  for (const auto& f : files) std::filesystem::resize_file(f, 100);
  const ProceduralMaps again = CachedProceduralMaterial(config, cache, &hit);
  EXPECT_FALSE(hit);
  EXPECT_EQ(again.normal->rgb_srgb(), made.normal->rgb_srgb());
  CachedProceduralMaterial(config, cache, &hit);
  EXPECT_TRUE(hit);
}

TEST(ProceduralMaterial, SameSeedSameMapsOtherSeedOtherMaps) {
  for (std::string_view type : ProceduralTypes()) {
    SCOPED_TRACE(std::string(type));
    const ProceduralMaps a = GenerateProceduralMaterial(Config(std::string(type), 7));
    const ProceduralMaps b = GenerateProceduralMaterial(Config(std::string(type), 7));
    const ProceduralMaps c = GenerateProceduralMaterial(Config(std::string(type), 8));
    EXPECT_EQ(a.albedo->rgb_srgb(), b.albedo->rgb_srgb());
    EXPECT_EQ(a.metal_roughness->rgb_srgb(), b.metal_roughness->rgb_srgb());
    EXPECT_EQ(a.normal->rgb_srgb(), b.normal->rgb_srgb());
    EXPECT_NE(a.albedo->rgb_srgb(), c.albedo->rgb_srgb());
    EXPECT_DOUBLE_EQ(a.size_m, ProceduralDefaultSize(std::string(type)));
  }
}

// every map varies (features exist), normals point out of the surface, roughness stays in the
// type's physical range.
TEST(ProceduralMaterial, MapsVaryAndStayPlausible) {
  for (std::string_view type : ProceduralTypes()) {
    SCOPED_TRACE(std::string(type));
    const ProceduralMaps m = GenerateProceduralMaterial(Config(std::string(type), 3, 256));
    const std::vector<uint8_t>& a = m.albedo->rgb_srgb();
    const std::vector<uint8_t>& n = m.normal->rgb_srgb();
    const std::vector<uint8_t>& r = m.metal_roughness->rgb_srgb();
    // data maps hold sRGB-encoded values (render/material/material_eval.h, "PBR maps")
    const float* decode = SrgbDecodeTable();
    double mean = 0, sq = 0, lo_r = 1, hi_r = 0;
    int tilted = 0;
    const size_t texels = a.size() / 3;
    for (size_t i = 0; i < texels; ++i) {
      const double l = (a[3 * i] + a[3 * i + 1] + a[3 * i + 2]) / 3.0;
      mean += l;
      sq += l * l;
      lo_r = std::min<double>(lo_r, decode[r[3 * i + 1]]);
      hi_r = std::max<double>(hi_r, decode[r[3 * i + 1]]);
      const double nx = 2 * decode[n[3 * i]] - 1, ny = 2 * decode[n[3 * i + 1]] - 1,
                   nz = 2 * decode[n[3 * i + 2]] - 1;
      EXPECT_GT(nz, 0.3);
      if (std::hypot(nx, ny) > 0.012) ++tilted;  // above the 8-bit step (~0.01)
    }
    mean /= texels;
    const double sd = std::sqrt(std::max(0.0, sq / texels - mean * mean));
    EXPECT_GT(sd, 1.0) << "albedo has no variation";
    EXPECT_GT(tilted, static_cast<int>(texels / 50)) << "normal map has no relief";
    EXPECT_GT(hi_r - lo_r, 0.02) << "roughness has no variation";
    EXPECT_GE(lo_r, 0.1) << "rougher than a polished surface";
  }
}

// tiles: 0.30 m tiles in a 0.6 m image: grout (darker, rough) at 0, 1/2 of the image, tile
// (light, glossy) at 1/4 and 3/4, on both axes: the features sit at their physical size.
TEST(ProceduralMaterial, TileGroutSitsAtTheTileSize) {
  const int n = 240;  // 2.5 mm texels
  const ProceduralMaps m = GenerateProceduralMaterial(Config("tiles", 1, n));
  const std::vector<uint8_t>& a = m.albedo->rgb_srgb();
  const std::vector<uint8_t>& r = m.metal_roughness->rgb_srgb();
  auto lum = [&](int x, int y) { return a[3 * (static_cast<size_t>(y) * n + x)]; };
  auto rough = [&](int x, int y) {
    return SrgbDecodeTable()[r[3 * (static_cast<size_t>(y) * n + x) + 1]];
  };
  for (const int y : {n / 4, 3 * n / 4}) {
    EXPECT_LT(lum(0, y) + 50, lum(n / 4, y));      // grout column at x = 0
    EXPECT_LT(lum(n / 2, y) + 50, lum(n / 4, y));  // and at x = 0.3 m
    EXPECT_GT(rough(n / 2, y), 0.8f);
    EXPECT_LT(rough(3 * n / 4, y), 0.3f);
  }
  // 10 texels (25 mm) from a grout line is tile again
  EXPECT_GT(lum(n / 2 + 10, n / 4), 150);
}

TEST(ProceduralMaterial, ApplyNamesMissingMaterials) {
  SceneDescription scene;
  Material floor;
  floor.name = "room/floor";
  scene.materials.push_back(floor);
  ProceduralMaterialEntry o;
  o.material = "room/floor";
  o.config = Config("wood", 2, 64);
  ApplyProceduralMaterials({o}, "w.yaml", &scene);
  const Material& m = scene.materials[0];
  ASSERT_GE(m.texture, 0);
  EXPECT_EQ(scene.textures[m.texture].name, "room/floor/albedo");
  ASSERT_EQ(scene.textures.size(), 3u);
  EXPECT_EQ(scene.textures[1].name, "room/floor/metallic_roughness");
  EXPECT_EQ(scene.textures[2].name, "room/floor/normal");
  EXPECT_TRUE(m.texuniform);
  EXPECT_NEAR(m.texrepeat.x(), 2 / 1.2, 1e-6);  // MuJoCo: texrepeat / 2 images per metre
  o.material = "room/wall";
  o.line = 12;
  try {
    ApplyProceduralMaterials({o}, "w.yaml", &scene);
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "w.yaml");
    EXPECT_EQ(e.line(), 12);
    EXPECT_EQ(e.key(), "materials.room/wall");
  }
}

}  // namespace
}  // namespace penumbra

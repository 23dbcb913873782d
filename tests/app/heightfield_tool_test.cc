// `penumbra heightfield` bakes what the user asks: by default the ground (not the trees and rocks
// standing on it), else the model, the geoms matching --geoms globs, or with --all everything;
// a selection that matches nothing is refused naming its option.

#include "penumbra/app/heightfield_tool.h"

#include <gtest/gtest.h>

#include <regex>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// a 4 m x 4 m floor (top at z = 0) with a 3 m tree, a rock and a 0.5 m crate on it
const char* kPark = R"(<mujoco>
  <worldbody>
    <geom name="floor_grass" type="box" size="2 2 0.05" pos="0 0 -0.05"/>
    <geom name="tree_trunk" type="cylinder" size="0.2 1.5" pos="0.5 0.5 1.5"/>
    <geom name="rock" type="sphere" size="0.3" pos="-1 -1 0"/>
    <geom name="crate" type="box" size="0.25 0.25 0.25" pos="1 -1 0.25"/>
  </worldbody>
</mujoco>
)";

struct Baked {
  std::string out;  // what the command printed
  double z_min = 0, z_max = 0;
};

Baked Bake(const HeightFieldOptions& o) {
  ::testing::internal::CaptureStdout();
  try {
    RunHeightField(o);
  } catch (...) {
    ::testing::internal::GetCapturedStdout();
    throw;
  }
  Baked b;
  b.out = ::testing::internal::GetCapturedStdout();
  std::smatch m;
  const std::regex z(R"(z \[(-?[0-9.]+), (-?[0-9.]+)\] m)");
  EXPECT_TRUE(std::regex_search(b.out, m, z)) << b.out;
  if (m.size() == 3) b.z_min = std::stod(m[1]), b.z_max = std::stod(m[2]);
  return b;
}

class HeightFieldToolTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_.Write("park.xml", kPark);
    o_.world_file = dir_.Write("world.yaml", "models:\n  - {name: park, file: park.xml}\n");
    o_.out_dir = (dir_.path() / "out").string();
    o_.cell_m = 0.1;
    o_.extent = std::array<double, 4>{-1.9, -1.9, 1.9, 1.9};
  }
  testing::TempDir dir_;
  HeightFieldOptions o_;
};

TEST_F(HeightFieldToolTest, DefaultBakesTheGroundNotWhatStandsOnIt) {
  const Baked b = Bake(o_);
  EXPECT_NEAR(b.z_min, 0.0, 1e-3) << b.out;
  EXPECT_NEAR(b.z_max, 0.0, 1e-3) << b.out;  // the tree, the rock and the crate left out
  EXPECT_NE(b.out.find("sampled 1 static geom(s): park/floor_grass"), std::string::npos) << b.out;
}

TEST_F(HeightFieldToolTest, AllBakesEveryStaticGeom) {
  o_.all = true;
  const Baked b = Bake(o_);
  EXPECT_NEAR(b.z_max, 3.0, 0.01) << b.out;  // the tree's top
  EXPECT_NE(b.out.find("sampled 4 static geom(s)"), std::string::npos) << b.out;
}

TEST_F(HeightFieldToolTest, GeomGlobsSelectByName) {
  o_.geoms = {"park/floor_*", "*/crate"};
  const Baked b = Bake(o_);
  EXPECT_NEAR(b.z_max, 0.5, 0.01) << b.out;  // the crate, not the tree
  EXPECT_NE(b.out.find("sampled 2 static geom(s): park/floor_grass, park/crate"), std::string::npos)
      << b.out;
}

TEST_F(HeightFieldToolTest, ModelBakesAllOfItsGeoms) {
  o_.model = "park";
  EXPECT_NEAR(Bake(o_).z_max, 3.0, 0.01);
}

TEST_F(HeightFieldToolTest, SelectionsThatMatchNothingAreRefusedNamingTheOption) {
  HeightFieldOptions o = o_;
  o.geoms = {"*/bench"};
  try {
    Bake(o);
    FAIL() << "a glob matching nothing was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "--geoms");
    EXPECT_NE(std::string(e.what()).find("park/tree_trunk"), std::string::npos) << e.what();
  }
  o = o_;
  o.model = "garden";
  try {
    Bake(o);
    FAIL() << "an unknown model was accepted";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "--model");
    EXPECT_NE(std::string(e.what()).find("park"), std::string::npos) << e.what();
  }
  o = o_;
  o.all = true;
  o.geoms = {"*"};
  EXPECT_THROW(Bake(o), ConfigError);
  // a world without ground: the default says what it looks for and how to select more
  dir_.Write("park.xml", std::regex_replace(std::string(kPark), std::regex("floor_grass"), "lawn"));
  try {
    Bake(o_);
    FAIL() << "a world without ground was baked";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("*floor*"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("--all"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace penumbra

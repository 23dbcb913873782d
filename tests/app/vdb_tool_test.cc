// `penumbra make-vdb` says what it wrote: the summary agrees with the file as OpenVDB's own
// reader sees it (grid names, active voxel count, voxel size, bounding box), and the command
// prints it

#include "penumbra/app/vdb_tool.h"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include <filesystem>
#include <string>

#include "app/child_process.h"
#include "common/temp_dir.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

TEST(MakeVdb, SummaryMatchesTheFileAsOpenVdbReadsIt) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "puff.vdb").string();
  SmokeVdbOptions o;
  o.voxel_m = 0.1;
  o.radius_m = 0.4;
  o.blobs = 3;
  const SmokeVdbSummary s = MakeSmokeVdb(path, o);
  EXPECT_EQ(s.path, path);
  EXPECT_EQ(s.file_bytes, fs::file_size(path));

  openvdb::initialize();
  openvdb::io::File file(path);
  file.open();
  std::vector<std::string> names;
  for (auto it = file.beginName(); it != file.endName(); ++it) names.push_back(it.gridName());
  ASSERT_EQ(names, std::vector<std::string>{"density"});
  EXPECT_EQ(s.grid, "density");
  const openvdb::FloatGrid::Ptr grid =
      openvdb::gridPtrCast<openvdb::FloatGrid>(file.readGrid("density"));
  file.close();
  ASSERT_TRUE(grid);
  EXPECT_GT(s.active_voxels, 100);
  EXPECT_EQ(s.active_voxels, static_cast<int64_t>(grid->activeVoxelCount()));
  EXPECT_NEAR(grid->voxelSize()[0], 0.1, 1e-9);
  EXPECT_EQ(s.voxel_m, 0.1);
  const openvdb::CoordBBox box = grid->evalActiveVoxelBoundingBox();
  for (int a = 0; a < 3; ++a) {
    EXPECT_EQ(s.index_min[a], box.min()[a]) << a;
    EXPECT_EQ(s.index_max[a], box.max()[a]) << a;
  }
  EXPECT_GE(s.index_min[2], 0);  // nothing below z = 0
  float lo = 0, hi = 0;
  grid->evalMinMax(lo, hi);
  EXPECT_FLOAT_EQ(s.max_density, hi);
  EXPECT_LE(s.max_density, 1.0f);

  const std::string line = DescribeSmokeVdb(s);
  EXPECT_NE(line.find("wrote " + path), std::string::npos) << line;
  EXPECT_NE(line.find("grid 'density'"), std::string::npos) << line;
  EXPECT_NE(line.find(std::to_string(s.active_voxels) + " active voxels of 0.1 m"),
            std::string::npos)
      << line;
}

TEST(MakeVdb, TheCommandSaysWhatItWrote) {
  testing::TempDir dir;
  const std::string path = (dir.path() / "cloud.vdb").string();
  const testing::ProcessResult r =
      testing::RunPenumbra({"make-vdb", path, "--voxel", "0.1", "--radius", "0.4"}, dir.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string said = r.out + r.err;
  EXPECT_NE(said.find("wrote " + path + " ("), std::string::npos) << said;
  EXPECT_NE(said.find("KiB): float grid 'density' (fog volume), "), std::string::npos) << said;
  EXPECT_NE(said.find(" active voxels of 0.1 m"), std::string::npos) << said;
  EXPECT_TRUE(fs::is_regular_file(path));
}

}  // namespace
}  // namespace penumbra

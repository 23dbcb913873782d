#include "penumbra/output/run_manifest.h"

#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include "common/temp_dir.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using testing::ReadAll;
using testing::TempDir;

RunManifest Example() {
  RunManifest m;
  m.world_file = "worlds/default.yaml";
  m.seed = 18446744073709551615ULL;  // largest seed must survive exactly
  m.penumbra_version = "0.1.0";
  m.mujoco_version = "2.2.2";
  m.embree_version = "3.13.5";
  m.command_line = {"penumbra", "run", "worlds/default.yaml", "--out", "out dir"};
  m.sim_duration_sec = 20.0;
  m.frames_per_camera = {{"front", 200}, {"rover/head", 100}};
  m.timings_sec = {{"simulate", 1.5}, {"render", 12.25}, {"load", 0.125}};
  m.peak_resident_memory_mib = 321.5;
  return m;
}

TEST(RunManifest, WritesEveryField) {
  TempDir dir;
  WriteRunManifest((dir.path() / "sub").string(), Example());
  const auto j = nlohmann::json::parse(ReadAll(dir.path() / "sub" / "run.json"));
  EXPECT_EQ(j.at("world_file"), "worlds/default.yaml");
  EXPECT_EQ(j.at("seed").get<uint64_t>(), 18446744073709551615ULL);
  EXPECT_EQ(j.at("penumbra_version"), "0.1.0");
  EXPECT_EQ(j.at("mujoco_version"), "2.2.2");
  EXPECT_EQ(j.at("embree_version"), "3.13.5");
  EXPECT_EQ(j.at("command_line").size(), 5u);
  EXPECT_EQ(j.at("command_line")[4], "out dir");
  EXPECT_DOUBLE_EQ(j.at("sim_duration_sec").get<double>(), 20.0);
  EXPECT_EQ(j.at("frames_per_camera").at("front"), 200);
  EXPECT_EQ(j.at("frames_per_camera").at("rover/head"), 100);
  EXPECT_DOUBLE_EQ(j.at("timings_sec").at("render").get<double>(), 12.25);
  EXPECT_DOUBLE_EQ(j.at("timings_sec").at("load").get<double>(), 0.125);
  EXPECT_DOUBLE_EQ(j.at("peak_resident_memory_mib").get<double>(), 321.5);
}

TEST(RunManifest, KeyOrderIsStable) {
  const std::string text = RunManifestJson(Example());
  EXPECT_EQ(text, RunManifestJson(Example()));
  const auto j = nlohmann::ordered_json::parse(text);
  std::vector<std::string> keys;
  for (const auto& [k, v] : j.items()) keys.push_back(k);
  const std::vector<std::string> expected = {
      "world_file",        "seed",         "penumbra_version",        "mujoco_version",
      "embree_version",    "command_line", "sim_duration_sec",        "interrupted",
      "frames_per_camera", "timings_sec",  "peak_resident_memory_mib"};
  EXPECT_EQ(keys, expected);
  // maps are sorted by name whatever the insertion order
  std::vector<std::string> timing_keys;
  for (const auto& [k, v] : j.at("timings_sec").items()) timing_keys.push_back(k);
  EXPECT_EQ(timing_keys, (std::vector<std::string>{"load", "render", "simulate"}));
  EXPECT_EQ(text.back(), '\n');
}

TEST(RunManifest, UnwritableFolderThrows) {
  TempDir dir;
  const auto file = dir.path() / "a_file";
  std::ofstream(file) << "x";
  EXPECT_THROW(WriteRunManifest((file / "sub").string(), Example()), Error);
}

TEST(PeakResidentMemory, IsPositiveAndGrowsWithTouchedMemory) {
  const double before = PeakResidentMemoryMiB();
  EXPECT_GT(before, 1.0);  // any process holds more than 1 MiB
  // touch 64 MiB more than the current peak
  std::vector<uint8_t> block(static_cast<size_t>(before + 64) * 1024 * 1024);
  for (size_t i = 0; i < block.size(); i += 4096) block[i] = static_cast<uint8_t>(i);
  const double after = PeakResidentMemoryMiB();
  EXPECT_GE(after, before + 32.0) << "touched " << block.size() / (1 << 20) << " MiB";
}

}  // namespace
}  // namespace penumbra

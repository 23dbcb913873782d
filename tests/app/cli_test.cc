// the command-line contract, on the real binary: usage errors exit 2 with the message on
// stderr and nothing on stdout; --help / --version exit 0 on stdout; numbers are strict
// decimal; a seed is any uint64, recorded exactly.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <sstream>

#include "app/child_process.h"
#include "common/temp_dir.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::RunPenumbra;

constexpr char kBoxMjcf[] = R"(<mujoco model="m">
  <option timestep="0.01"/>
  <worldbody>
    <geom name="floor" type="plane" size="2 2 0.1"/>
    <body name="box" pos="0 0 0.5"><freejoint/><geom type="box" size="0.1 0.1 0.1"/></body>
  </worldbody>
</mujoco>)";

using testing::ReadAll;

class CliTest : public ::testing::Test {
 protected:
  void SetUp() override {
    tmp_.Write("m.xml", kBoxMjcf);
    world_ = tmp_.Write("w.yaml",
                        "seed: 18446744073709551615\nduration_sec: 0.05\n"
                        "models: [{name: m, file: m.xml}]\n"
                        "cameras: [{name: c, attach: world, pose: {xyz: [-2, 0, 1]}, width: 8, "
                        "height: 6, rate_hz: 10}]\n");
  }
  testing::TempDir tmp_;
  std::string world_;
};

TEST_F(CliTest, UsageErrorsExit2WithTheMessageOnStderrOnly) {
  struct Case {
    std::vector<std::string> args;
    std::string message;
  };
  const std::string w = world_;
  const std::vector<Case> cases = {
      {{}, "A subcommand is required"},
      {{"run", w, "--bogus"}, "--bogus"},
      {{"run", w, "--threads", "-1"}, "--threads: '-1' is not an integer in [0, 256]"},
      {{"run", w, "--spp", "0"}, "--spp: '0' is not an integer in [1, 65536]"},
      {{"run", w, "--spp", "1e3"}, "--spp: '1e3'"},
      {{"run", w, "--duration", "0"}, "--duration: '0' is out of range"},
      {{"run", w, "--duration", "nan"}, "--duration: 'nan' is not a finite decimal number > 0"},
      {{"run", w, "--duration", "inf"}, "--duration: 'inf'"},
      {{"run", w, "--duration", "0x10"}, "--duration: '0x10' is not a finite decimal number"},
      {{"run", w, "--duration", "1e999"}, "--duration: '1e999'"},
      {{"run", w, "--seed", "-1"}, "--seed: '-1' is negative"},
      {{"run", w, "--seed", "18446744073709551616"}, "--seed: '18446744073709551616'"},
      {{"run", w, "--seed", "0x10"}, "--seed: '0x10'"},
      {{"bench", "render", "--frames", "0"}, "--frames: '0'"},
      {{"bench", "physics", "--seconds", "nan"}, "--seconds: 'nan'"},
      {{"bench", "sensors", "--scans", "0x5"}, "--scans: '0x5'"},
      {{"contact-sheet", "--width", "8"}, "--width: '8' is not an integer in [16, 4096]"},
      {{"make-vdb", "x.vdb", "--blobs", "65"}, "--blobs: '65'"},
      {{"run", w, "--viewer-allow-origin", "http://lab.example:8080"},
       "--viewer-allow-origin: given without --viewer"},
      {{"run", w, "--viewer", "127.0.0.1:0", "--viewer-allow-origin", "ftp://lab.example"},
       "--viewer-allow-origin: 'ftp://lab.example' does not start with http:// or https://"},
      {{"view", w, "--viewer-allow-origin", "http://lab.example/viewer"},
       "--viewer-allow-origin: 'http://lab.example/viewer' holds a path"},
  };
  for (const Case& c : cases) {
    const testing::ProcessResult r = RunPenumbra(c.args, tmp_.path());
    std::string label;
    for (const std::string& a : c.args) label += a + " ";
    EXPECT_EQ(r.exit_code, 2) << label << r.err;
    EXPECT_EQ(r.out, "") << label;
    EXPECT_NE(r.err.find(c.message), std::string::npos) << label << "\nstderr: " << r.err;
  }
}

TEST_F(CliTest, HelpAndVersionExit0OnStdout) {
  for (const std::vector<std::string>& args :
       {std::vector<std::string>{"--help"}, {"--version"}, {"run", "--help"}}) {
    const testing::ProcessResult r = RunPenumbra(args, tmp_.path());
    EXPECT_EQ(r.exit_code, 0) << args.back();
    EXPECT_FALSE(r.out.empty()) << args.back();
    EXPECT_EQ(r.err, "") << args.back();
  }
}

TEST_F(CliTest, BadInputErrorsGoToStderrWithExit2) {
  const std::string missing = (tmp_.path() / "missing.yaml").string();
  const testing::ProcessResult r =
      RunPenumbra({"run", missing, "--out", (tmp_.path() / "o").string()}, tmp_.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("missing.yaml"), std::string::npos) << r.err;
}

TEST_F(CliTest, FullUint64SeedIsRecordedExactlyAndLogsGoToStderr) {
  // the world file's seed: 2^64 - 1
  const fs::path a = tmp_.path() / "a";
  testing::ProcessResult r = RunPenumbra({"run", world_, "--out", a.string(), "-q"}, tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("done:"), std::string::npos) << r.err;
  EXPECT_NE(ReadAll(a / "run.json").find("\"seed\": 18446744073709551615,"), std::string::npos)
      << ReadAll(a / "run.json");
  // --seed overrides it with another full-range value
  const fs::path b = tmp_.path() / "b";
  r = RunPenumbra({"run", world_, "--out", b.string(), "-q", "--seed", "18446744073709551614",
                   "--duration", "0.02"},
                  tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::string manifest = ReadAll(b / "run.json");
  EXPECT_NE(manifest.find("\"seed\": 18446744073709551614,"), std::string::npos) << manifest;
  EXPECT_NE(manifest.find("\"sim_duration_sec\": 0.02"), std::string::npos) << manifest;
}

}  // namespace
}  // namespace penumbra

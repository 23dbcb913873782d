// `penumbra export` against run folders from someone else and against interrupts and full
// disks, on the real binary: a symbolic link in the run folder is refused (nothing
// read through it, nothing exported); a truncated or mis-sized PNG is refused, naming it;
// SIGINT / SIGTERM leave no partial dataset, bag or replay folder and the next export to the
// same place succeeds; a rosbag export to a full 2 MiB tmpfs exits 1 with the system's reason
// (it aborted with SIGABRT: the rosbag library throws from a destructor); and a pathtraced
// replay stops between samples on SIGINT.

#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/mount.h>

#include <cerrno>
#include <chrono>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>
#include <thread>
#include <vector>

#include "app/child_process.h"
#include "common/temp_dir.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ChildProcess;
using testing::ReadAll;
using testing::RunPenumbra;

// a wall in front of a camera on a fixed rig, an IMU beside it
constexpr char kExportSafetyMjcf[] = R"(
<mujoco model="wall">
  <option timestep="0.005"/>
  <worldbody>
    <geom name="wall" type="box" pos="1.55 0 1" size="0.05 3 3" rgba="0.7 0.7 0.7 1"/>
    <body name="rig" pos="0 0 1">
      <geom name="box" type="box" pos="0 0 -0.2" size="0.02 0.02 0.02" contype="0" conaffinity="0"/>
    </body>
  </worldbody>
</mujoco>)";

constexpr char kExportSafetyWorld[] = R"(seed: 5
duration_sec: 0.5
models:
  - {name: scene, file: wall.xml}
lights:
  - {name: sun, type: sun, direction: [0.3, 0.4, -1], illuminance_lux: 20000}
mjcf_cameras: {enabled: false}
cameras:
  - name: front
    attach: scene/rig
    pose: {xyz: [0, 0, 0], rpy_deg: [0, 0, 0]}
    width: 32
    height: 24
    rate_hz: 10
    outputs: [rgb, depth]
)";

// the entries of `dir` whose names start with `prefix` (the output and its temporaries)
std::vector<std::string> ExportSafetyEntries(const fs::path& dir, const std::string& prefix) {
  std::vector<std::string> names;
  if (!fs::exists(dir)) return names;
  for (const auto& e : fs::directory_iterator(dir)) {
    const std::string name = e.path().filename().string();
    if (name.rfind(prefix, 0) == 0) names.push_back(name);
  }
  return names;
}

// PNG files anywhere under the entries of `dir` that start with `prefix`
int ExportSafetyPngsUnder(const fs::path& dir, const std::string& prefix) {
  int n = 0;
  std::error_code ec;
  for (const std::string& name : ExportSafetyEntries(dir, prefix)) {
    if (!fs::is_directory(dir / name, ec)) continue;
    for (auto it = fs::recursive_directory_iterator(dir / name, ec);
         !ec && it != fs::recursive_directory_iterator(); it.increment(ec))
      n += it->path().extension() == ".png";
  }
  return n;
}

class ExportSafetyTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new testing::TempDir();
    dir_->Write("wall.xml", kExportSafetyMjcf);
    const std::string world = dir_->Write("world.yaml", kExportSafetyWorld);
    const testing::ProcessResult r =
        RunPenumbra({"run", world, "--out", (dir_->path() / "run").string(), "--record",
                     (dir_->path() / "run.plog").string(), "--quiet"},
                    dir_->path());
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }

  // a copy of the run folder that the test may change
  fs::path CopyOfRun(const std::string& name) {
    const fs::path copy = tmp_.path() / name;
    fs::copy(dir_->path() / "run", copy, fs::copy_options::recursive);
    return copy;
  }

  // a copy of the run with `frames` frames: frame 0's images hard-linked under new indices,
  // a frames.csv row each, 10 ms apart (long enough an export to interrupt it)
  fs::path BigRun(const std::string& name, int frames) {
    const fs::path run = CopyOfRun(name);
    const std::string csv = ReadAll(run / "front" / "frames.csv");
    const std::string header = csv.substr(0, csv.find('\n') + 1);
    const std::string row0 =
        csv.substr(header.size(), csv.find('\n', header.size()) - header.size());
    const std::string pose = row0.substr(row0.find(',', row0.find(',') + 1));
    for (const auto& e : fs::directory_iterator(run / "front" / "rgb"))
      if (e.path().filename() != "000000.png") fs::remove(e.path());
    for (const auto& e : fs::directory_iterator(run / "front" / "depth"))
      if (e.path().filename() != "000000.png") fs::remove(e.path());
    std::string rows = header;
    for (int i = 0; i < frames; ++i) {
      rows += fmt::format("{},{:.3f}{}\n", i, 0.01 * i, pose);
      if (i == 0) continue;
      for (const char* kind : {"rgb", "depth"})
        fs::create_hard_link(run / "front" / kind / "000000.png",
                             run / "front" / kind / fmt::format("{:06d}.png", i));
    }
    std::ofstream(run / "front" / "frames.csv", std::ios::binary | std::ios::trunc) << rows;
    return run;
  }

  testing::ProcessResult Export(const fs::path& run, const std::string& format,
                                const fs::path& out) {
    return RunPenumbra({"export", run.string(), "--format", format, "--out", out.string()},
                       tmp_.path());
  }

  static testing::TempDir* dir_;
  testing::TempDir tmp_;
};
testing::TempDir* ExportSafetyTest::dir_ = nullptr;

TEST_F(ExportSafetyTest, ASymlinkedFrameIsRefusedAndNothingIsExported) {
  const fs::path secret = tmp_.path() / "secret.txt";
  std::ofstream(secret) << "not a frame: a file outside the run folder\n";
  const fs::path run = CopyOfRun("run_link");
  const fs::path frame = run / "front" / "rgb" / "000002.png";
  fs::remove(frame);
  fs::create_symlink(secret, frame);
  for (const std::string format : {"tum", "kitti"}) {
    const fs::path out = tmp_.path() / ("out_" + format);
    const testing::ProcessResult r = Export(run, format, out);
    EXPECT_EQ(r.exit_code, 2) << format << ": " << r.err;
    EXPECT_NE(r.err.find("000002.png"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("symbolic link"), std::string::npos) << r.err;
    // nothing exported: no output folder and no temporary one beside it
    EXPECT_TRUE(ExportSafetyEntries(tmp_.path(), "out_" + format).empty()) << format;
  }
  // a linked image folder is refused the same way
  const fs::path run2 = CopyOfRun("run_dirlink");
  fs::rename(run2 / "front" / "rgb", tmp_.path() / "elsewhere");
  fs::create_directory_symlink(tmp_.path() / "elsewhere", run2 / "front" / "rgb");
  const testing::ProcessResult r = Export(run2, "tum", tmp_.path() / "out_dir");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("symbolic link"), std::string::npos) << r.err;
  EXPECT_TRUE(ExportSafetyEntries(tmp_.path(), "out_dir").empty());
  // the untouched run exports
  EXPECT_EQ(Export(dir_->path() / "run", "tum", tmp_.path() / "out_ok").exit_code, 0);
  EXPECT_TRUE(fs::exists(tmp_.path() / "out_ok" / "rgb.txt"));
}

TEST_F(ExportSafetyTest, ATruncatedOrMisshapenPngIsRefusedNamingIt) {
  const fs::path run = CopyOfRun("run_cut");
  const fs::path frame = run / "front" / "rgb" / "000001.png";
  const std::string bytes = ReadAll(frame);
  ASSERT_GT(bytes.size(), 100u);
  std::ofstream(frame, std::ios::binary | std::ios::trunc) << bytes.substr(0, bytes.size() / 2);
  testing::ProcessResult r = Export(run, "tum", tmp_.path() / "out_cut");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("000001.png"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("truncated or corrupt"), std::string::npos) << r.err;
  EXPECT_TRUE(ExportSafetyEntries(tmp_.path(), "out_cut").empty());

  // a complete PNG of another format than camera_info.json and the kind say
  const fs::path run2 = CopyOfRun("run_size");
  const std::string other = ReadAll(dir_->path() / "run" / "front" / "depth" / "000000.png");
  std::ofstream(run2 / "front" / "rgb" / "000003.png", std::ios::binary | std::ios::trunc)
      << other;  // 16-bit greyscale where 8-bit RGB belongs
  r = Export(run2, "kitti", tmp_.path() / "out_size");
  EXPECT_EQ(r.exit_code, 2) << r.err;
  EXPECT_NE(r.err.find("000003.png"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("expected an 8-bit RGB PNG of 32 x 24 pixels"), std::string::npos) << r.err;
  EXPECT_TRUE(ExportSafetyEntries(tmp_.path(), "out_size").empty());
}

// SIGINT / SIGTERM while the frames are written: exit 130 / 143 with a message, no dataset
// and no temporary folder left, and the next export to the same folder succeeds
void ExportSafetyInterruptDataset(const fs::path& run, const fs::path& base, int sig,
                                  int expected) {
  const fs::path out = base / "dataset";
  ChildProcess p({"export", run.string(), "--format", "tum", "--out", out.string()}, base);
  bool started = false;
  for (int i = 0; i < 6000 && !started; ++i) {
    started = ExportSafetyPngsUnder(base, "dataset") >= 20;
    if (!started) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(started) << p.err();
  p.Signal(sig);
  EXPECT_EQ(p.Wait(), expected) << p.err();
  EXPECT_NE(p.err().find(sig == SIGINT ? "interrupted by SIGINT" : "interrupted by SIGTERM"),
            std::string::npos)
      << p.err();
  EXPECT_TRUE(ExportSafetyEntries(base, "dataset").empty()) << p.err();
}

TEST_F(ExportSafetyTest, SigintOrSigtermDuringAnExportLeaveNoPartialDataset) {
  constexpr int kFrames = 8000;  // ~1 s of export: ample time to interrupt it
  const fs::path run = BigRun("run_big", kFrames);
  const fs::path base = tmp_.path() / "interrupt";
  fs::create_directories(base);
  ExportSafetyInterruptDataset(run, base, SIGINT, 130);
  ExportSafetyInterruptDataset(run, base, SIGTERM, 143);
  // the next export to that folder succeeds, whole
  const testing::ProcessResult r = RunPenumbra(
      {"export", run.string(), "--format", "tum", "--out", (base / "dataset").string()}, base);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  for (const char* f : {"rgb.txt", "depth.txt", "groundtruth.txt", "associations.txt"})
    EXPECT_TRUE(fs::exists(base / "dataset" / f)) << f;
  EXPECT_EQ(ExportSafetyPngsUnder(base, "dataset"), 2 * kFrames);
  EXPECT_EQ(ExportSafetyEntries(base, "dataset"), std::vector<std::string>{"dataset"});
}

// a run log is replayed before the export: SIGINT during the replay removes the replay folder
TEST_F(ExportSafetyTest, SigintDuringTheReplayOfARunLogLeavesNoReplayFolder) {
  const fs::path base = tmp_.path() / "replay";
  fs::create_directories(base);
  // a slow replay: pathtraced at 4096 samples per pixel
  const std::string slow =
      tmp_.Write("slow.yaml", "render: {tier: pathtraced, samples_per_pixel: 4096}\n");
  const fs::path out = base / "dataset";
  ChildProcess p({"export", (dir_->path() / "run.plog").string(), "--format", "tum", "--out",
                  out.string(), "--world", slow},
                 base);
  bool set_up = false;
  for (int i = 0; i < 6000 && !set_up; ++i) {
    for (const std::string& name : ExportSafetyEntries(base, "dataset"))
      set_up = set_up || fs::exists(base / name / "composed.xml");
    if (!set_up) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(set_up) << p.err();
  p.Signal(SIGINT);
  const int code = p.WaitFor(60);
  if (code < 0) p.Signal(SIGKILL);
  EXPECT_EQ(code, 130) << p.err();
  EXPECT_NE(p.err().find("interrupted by SIGINT"), std::string::npos) << p.err();
  EXPECT_TRUE(ExportSafetyEntries(base, "dataset").empty());
  // and the same export without the slow override succeeds
  const testing::ProcessResult r = RunPenumbra(
      {"export", (dir_->path() / "run.plog").string(), "--format", "tum", "--out", out.string()},
      base);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(out / "associations.txt"));
  EXPECT_EQ(ExportSafetyEntries(base, "dataset"), std::vector<std::string>{"dataset"});
}

// `penumbra replay` of a log at 65536 samples per pixel (minutes per frame): a single SIGINT
// stops the frame between samples; the replay exits 130 soon after (30 s is far more than one
// sample pass of 32 x 24 pixels) with run.json, dropping the unfinished frame
TEST_F(ExportSafetyTest, APathtracedReplayStopsWithinOnePassOnSigint) {
  const std::string slow = tmp_.Write(
      "slower.yaml", "render: {tier: pathtraced, samples_per_pixel: 65536, denoise: false}\n");
  const fs::path out = tmp_.path() / "replayed";
  ChildProcess p({"replay", (dir_->path() / "run.plog").string(), "--out", out.string(), "--world",
                  slow, "-q"},
                 tmp_.path());
  bool set_up = false;
  for (int i = 0; i < 6000 && !set_up; ++i) {
    set_up = fs::exists(out / "composed.xml");
    if (!set_up) std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  ASSERT_TRUE(set_up) << p.err();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // into the first frame
  p.Signal(SIGINT);
  const int code = p.WaitFor(30);
  if (code < 0) p.Signal(SIGKILL);
  ASSERT_EQ(code, 130) << "still running 30 s after SIGINT; " << p.err();
  EXPECT_NE(p.err().find("interrupted at"), std::string::npos) << p.err();
  ASSERT_TRUE(fs::exists(out / "run.json")) << p.err();
  EXPECT_TRUE(nlohmann::json::parse(ReadAll(out / "run.json")).at("interrupted").get<bool>());
}

// a bag on a full disk: a 2 MiB tmpfs (needs the right to mount; skipped where it is missing)
// run.json's world_file is the one path of a run folder that leads outside it: only a world
// file is read there (by its ending, a regular file, no link at its name), and no error quotes
// a line of it (a world_file of /etc/shadow printed that file's first line)
TEST_F(ExportSafetyTest, RunJsonsWorldFileIsReadOnlyAsAWorldAndNeverQuoted) {
  const fs::path run = CopyOfRun("run_world");
  const nlohmann::json manifest = nlohmann::json::parse(ReadAll(run / "run.json"));
  const std::string shadow = tmp_.Write("shadow", "root:$6$SECRETHASH:19000:0:99999:7:::\n");
  const std::string notes = tmp_.Write("notes.yaml", "SECRETKEY: SECRETVALUE\n");
  const fs::path link = tmp_.path() / "link.yaml";
  fs::create_symlink(notes, link);
  for (const std::string& f : {shadow, notes, link.string()}) {
    nlohmann::json j = manifest;
    j["world_file"] = f;
    std::ofstream(run / "run.json", std::ios::trunc) << j.dump();
    const testing::ProcessResult r = Export(run, "rosbag", tmp_.path() / "x.bag");
    if (r.exit_code != 0 && r.err.find("needs ROS 1") != std::string::npos)
      GTEST_SKIP() << "this penumbra was built without ROS 1: " << r.err;
    EXPECT_EQ(r.exit_code, 2) << f << ": " << r.err;
    EXPECT_NE(r.err.find("world_file"), std::string::npos) << r.err;
    EXPECT_EQ(r.err.find("SECRET"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(tmp_.path() / "x.bag"));
  }
}

TEST_F(ExportSafetyTest, ARosbagToAFullDiskExitsOneWithAMessage) {
  const fs::path run = BigRun("run_bag", 1500);
  // the same export to a roomy folder works (and tells whether this build has ROS 1)
  const testing::ProcessResult ok = Export(run, "rosbag", tmp_.path() / "ok.bag");
  if (ok.exit_code != 0 && ok.err.find("needs ROS 1") != std::string::npos)
    GTEST_SKIP() << "this penumbra was built without ROS 1: " << ok.err;
  ASSERT_EQ(ok.exit_code, 0) << ok.err;
  ASSERT_GT(fs::file_size(tmp_.path() / "ok.bag"), 3u << 20);  // larger than the tmpfs
  const fs::path mnt = tmp_.path() / "small";
  fs::create_directories(mnt);
  if (mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=2m") != 0)
    GTEST_SKIP() << "cannot mount a tmpfs here (" << std::strerror(errno)
                 << "); the full-disk path of the rosbag export is not exercised";
  struct Unmount {
    fs::path p;
    ~Unmount() { umount2(p.c_str(), MNT_DETACH); }
  } unmount{mnt};
  const testing::ProcessResult r = Export(run, "rosbag", mnt / "run.bag");
  EXPECT_EQ(r.exit_code, 1) << r.err;  // not 134 (SIGABRT)
  EXPECT_NE(r.err.find("No space left on device"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find((mnt / "run.bag").string()), std::string::npos) << r.err;
  // no bag and no temporary file left on the full disk
  EXPECT_TRUE(fs::is_empty(mnt)) << r.err;
}

}  // namespace
}  // namespace penumbra

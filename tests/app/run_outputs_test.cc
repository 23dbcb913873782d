// `penumbra run` as users run it (the real binary in a child process): interrupts, SIGKILL,
// full disks, the output-folder rule and --outputs. nothing recorded may be lost or left
// partial: every PNG decodes, every CSV ends with a complete row, frames.csv has a row per
// image.

#include <gtest/gtest.h>
#include <sys/mount.h>
#include <sys/resource.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <thread>

#include "app/child_process.h"
#include "common/temp_dir.h"
#include "penumbra/core/output_file.h"
#include "penumbra/output/png_io.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ChildProcess;
using testing::ProcessResult;
using testing::RunPenumbra;

// a falling ball over a checker floor, a hinge (nq = 8 in all), an MJCF camera
constexpr char kBallMjcf[] = R"(<mujoco model="ball">
  <option timestep="0.005"/>
  <asset>
    <texture name="grid" type="2d" builtin="checker" rgb1="0.2 0.3 0.4" rgb2="0.8 0.8 0.8" width="64" height="64"/>
    <material name="grid" texture="grid" texrepeat="8 8"/>
  </asset>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1" material="grid"/>
    <body name="ball" pos="0 0 1">
      <freejoint/>
      <geom name="ball" type="sphere" size="0.2" rgba="0.9 0.3 0.2 1"/>
    </body>
    <body name="arm" pos="1 0 0.5"><joint type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.05"/></body>
    <camera name="overhead" pos="0 -3 2" xyaxes="1 0 0 0 0.6 0.8"/>
  </worldbody>
</mujoco>)";

using testing::ReadAll;

int64_t CountFiles(const fs::path& dir, const std::string& ext) {
  if (!fs::exists(dir)) return 0;
  int64_t n = 0;
  for (const auto& e : fs::directory_iterator(dir))
    if (e.path().extension() == ext && !IsTemporaryOutputName(e.path().filename().string())) ++n;
  return n;
}

int64_t CsvRows(const fs::path& csv) {
  std::ifstream f(csv);
  std::string line;
  int64_t rows = -1;  // header
  while (std::getline(f, line)) ++rows;
  return std::max<int64_t>(rows, 0);
}

// nothing partial anywhere under `out`: every PNG decodes, every CSV is empty or ends with a
// complete row, no temporary and no empty file is left
void ExpectNothingPartial(const fs::path& out, bool allow_temporaries = false) {
  for (const auto& e : fs::recursive_directory_iterator(out)) {
    if (!e.is_regular_file()) continue;
    const std::string name = e.path().filename().string();
    if (IsTemporaryOutputName(name)) {
      EXPECT_TRUE(allow_temporaries) << "temporary file left: " << e.path();
      continue;
    }
    if (e.path().extension() == ".png") {
      EXPECT_NO_THROW(ReadPng(e.path().string())) << e.path();
    } else if (e.path().extension() == ".csv") {
      const std::string text = ReadAll(e.path());
      if (!text.empty()) {
        EXPECT_EQ(text.back(), '\n') << e.path();
      }
      continue;
    }
    EXPECT_GT(fs::file_size(e.path()), 0u) << "empty file: " << e.path();
  }
}

class RunOutputsTest : public ::testing::Test {
 protected:
  void SetUp() override { tmp_.Write("ball.xml", kBallMjcf); }

  // a world with one camera `cam` of the given size, rate and outputs
  std::string World(const std::string& name, int width, int height, double rate_hz,
                    const std::string& outputs, double duration_sec,
                    const std::string& extra = "") {
    return tmp_.Write(
        name, "seed: 3\nduration_sec: " + std::to_string(duration_sec) +
                  "\nmodels: [{name: scene, file: ball.xml}]\n"
                  "mjcf_cameras: {enabled: false}\n"
                  "cameras:\n  - {name: cam, attach: world, pose: {xyz: [-3, 0, 1.5], "
                  "rpy_deg: [0, 20, 0]}, width: " +
                  std::to_string(width) + ", height: " + std::to_string(height) + ", rate_hz: " +
                  std::to_string(rate_hz) + ", outputs: [" + outputs + "]}\n" + extra);
  }

  // waits until `csv` has at least `rows` rows (max 30 s)
  static bool WaitForRows(const fs::path& csv, int64_t rows) {
    for (int i = 0; i < 3000; ++i) {
      if (fs::exists(csv) && CsvRows(csv) >= rows) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  void InterruptAndCheck(int sig, int expected_exit) {
    const fs::path out = tmp_.path() / "out";
    const std::string world = World("w.yaml", 48, 32, 20, "rgb, depth", 60);
    ChildProcess p({"run", world, "--out", out.string(), "-q", "--realtime"}, tmp_.path());
    ASSERT_TRUE(WaitForRows(out / "cam" / "frames.csv", 3)) << p.err();
    p.Signal(sig);
    EXPECT_EQ(p.Wait(), expected_exit) << p.err();
    EXPECT_EQ(p.out(), "");
    EXPECT_NE(p.err().find("interrupted by"), std::string::npos) << p.err();
    ASSERT_TRUE(fs::exists(out / "run.json"));
    const auto j = nlohmann::json::parse(ReadAll(out / "run.json"));
    EXPECT_TRUE(j.at("interrupted").get<bool>());
    const double t = j.at("sim_duration_sec").get<double>();
    EXPECT_GT(t, 0.05);
    EXPECT_LT(t, 30.0);
    // every frame rendered before the stop is written, each with its row
    const int64_t rows = CsvRows(out / "cam" / "frames.csv");
    EXPECT_GE(rows, 3);
    EXPECT_EQ(j.at("frames_per_camera").at("cam").get<int64_t>(), rows);
    EXPECT_EQ(CountFiles(out / "cam" / "rgb", ".png"), rows);
    EXPECT_EQ(CountFiles(out / "cam" / "depth", ".png"), rows);
    // frames at 20 Hz up to the sim time reached
    EXPECT_EQ(rows, static_cast<int64_t>(std::floor(t * 20 + 1e-9)) + 1) << t;
    // the trajectory ends at the sim time reached, on a complete row
    const std::string traj = ReadAll(out / "trajectory.csv");
    ASSERT_EQ(traj.back(), '\n');
    const std::string last = traj.substr(traj.rfind('\n', traj.size() - 2) + 1);
    EXPECT_EQ(std::stod(last.substr(last.find(',') + 1)), t) << last;
    ExpectNothingPartial(out);
  }

  testing::TempDir tmp_;
};

TEST_F(RunOutputsTest, SigintStopsAtAStepBoundaryWritesEverythingAndExits130) {
  InterruptAndCheck(SIGINT, 130);
}

TEST_F(RunOutputsTest, SigtermDoesTheSameAndExits143) { InterruptAndCheck(SIGTERM, 143); }

TEST_F(RunOutputsTest, ASecondSignalExitsAtOnce) {
  // large realtime frames (a pathtraced frame now stops between samples: see below):
  // after the first SIGINT the run renders and writes the queued frames and then run.json;
  // the second SIGINT must end it before that, with 130 and no run.json
  const fs::path out = tmp_.path() / "out";
  const std::string world = World("slow.yaml", 2560, 1920, 20, "rgb", 60);
  ChildProcess p({"run", world, "--out", out.string(), "-q"}, tmp_.path());
  // composed.xml is written once the run is set up, after the handlers are installed
  bool set_up = false;
  for (int i = 0; i < 3000 && !set_up; ++i) {
    set_up = fs::exists(out / "composed.xml");
    if (!set_up) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(set_up) << p.err();
  p.Signal(SIGINT);
  // the second signal only once the first was handled (two pending SIGINTs would merge)
  bool handled = false;
  for (int i = 0; i < 3000 && !handled; ++i) {
    handled = p.err().find("signal again to exit at once") != std::string::npos;
    if (!handled) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(handled) << p.err();
  p.Signal(SIGINT);
  EXPECT_EQ(p.Wait(), 130) << p.err();
  EXPECT_FALSE(fs::exists(out / "run.json"));
  EXPECT_EQ(CountFiles(out / "cam" / "rgb", ".png"), 0);
}

// a pathtraced frame of 4096 samples per pixel takes minutes; a single SIGINT / SIGTERM stops
// it between samples (render/cpu/path_tiles.h): the run exits 130 / 143 soon after (30 s is
// far more than one sample pass of 64 x 48 pixels), writing run.json and the frames finished
// before, and dropping the unfinished one
void PathtracedFrameStopsWithinOnePass(const std::string& world, const fs::path& out, int sig,
                                       int expected) {
  ChildProcess p({"run", world, "--out", out.string(), "-q"}, out.parent_path());
  bool set_up = false;
  for (int i = 0; i < 3000 && !set_up; ++i) {
    set_up = fs::exists(out / "composed.xml");
    if (!set_up) std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  ASSERT_TRUE(set_up) << p.err();
  std::this_thread::sleep_for(std::chrono::milliseconds(300));  // into the first frame
  p.Signal(sig);
  const int code = p.WaitFor(30);
  if (code < 0) p.Signal(SIGKILL);
  ASSERT_EQ(code, expected) << "still running 30 s after the signal; " << p.err();
  EXPECT_NE(p.err().find("interrupted by"), std::string::npos) << p.err();
  ASSERT_TRUE(fs::exists(out / "run.json")) << p.err();
  const auto j = nlohmann::json::parse(ReadAll(out / "run.json"));
  EXPECT_TRUE(j.at("interrupted").get<bool>());
  // what was written is whole: a row per image, none partial
  const int64_t rows = CsvRows(out / "cam" / "frames.csv");
  EXPECT_EQ(CountFiles(out / "cam" / "rgb", ".png"), rows);
  EXPECT_EQ(j.at("frames_per_camera").at("cam").get<int64_t>(), rows);
  ExpectNothingPartial(out);
}

TEST_F(RunOutputsTest, PathtracedFrameStopsWithinOnePassOnSigintOrSigterm) {
  const std::string world =
      World("pt.yaml", 64, 48, 20, "rgb", 60,
            "render: {tier: pathtraced, samples_per_pixel: 4096, denoise: false}\n");
  PathtracedFrameStopsWithinOnePass(world, tmp_.path() / "int", SIGINT, 130);
  PathtracedFrameStopsWithinOnePass(world, tmp_.path() / "term", SIGTERM, 143);
}

TEST_F(RunOutputsTest, SigkillLeavesNoTruncatedPngAndForceClearsTheRest) {
  const fs::path out = tmp_.path() / "out";
  const std::string world = World("w.yaml", 160, 120, 200, "rgb, depth, segmentation", 60);
  {
    ChildProcess p({"run", world, "--out", out.string(), "-q"}, tmp_.path());
    ASSERT_TRUE(WaitForRows(out / "cam" / "frames.csv", 8)) << p.err();
    p.Signal(SIGKILL);
    EXPECT_EQ(p.Wait(), 128 + SIGKILL);
  }
  // images may outnumber rows (written first) but none is partial
  ExpectNothingPartial(out, /*allow_temporaries=*/true);
  EXPECT_GE(CountFiles(out / "cam" / "rgb", ".png"), CsvRows(out / "cam" / "frames.csv"));
  // the killed run's outputs, temporaries included, are Penumbra's: --force clears them
  const ProcessResult r = RunPenumbra(
      {"run", World("short.yaml", 16, 12, 10, "rgb", 0.1), "--out", out.string(), "-q", "--force"},
      tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(CountFiles(out / "cam" / "rgb", ".png"), 2);
  EXPECT_FALSE(fs::exists(out / "cam" / "depth"));
  ExpectNothingPartial(out);
}

TEST_F(RunOutputsTest, ANonEmptyOutputFolderNeedsForceWhichLeavesNoStaleFrames) {
  const fs::path out = tmp_.path() / "out";
  ProcessResult r = RunPenumbra(
      {"run", World("a.yaml", 64, 48, 10, "rgb", 0.5), "--out", out.string(), "-q"}, tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  ASSERT_EQ(CountFiles(out / "cam" / "rgb", ".png"), 6);
  // again into the same folder: refused, nothing touched
  const std::string b = World("b.yaml", 32, 24, 10, "rgb", 0.2);
  r = RunPenumbra({"run", b, "--out", out.string(), "-q"}, tmp_.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("is not empty"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--force"), std::string::npos) << r.err;
  EXPECT_EQ(CountFiles(out / "cam" / "rgb", ".png"), 6);
  // --force: only this run's frames remain
  r = RunPenumbra({"run", b, "--out", out.string(), "-q", "--force"}, tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(CountFiles(out / "cam" / "rgb", ".png"), 3);
  EXPECT_EQ(CsvRows(out / "cam" / "frames.csv"), 3);
  for (const auto& e : fs::directory_iterator(out / "cam" / "rgb"))
    EXPECT_EQ(ReadPng(e.path().string()).width, 32) << e.path();
}

TEST_F(RunOutputsTest, ForceRefusesForeignFilesAndLinksAndTouchesNothing) {
  const fs::path out = tmp_.path() / "out";
  const std::string w = World("a.yaml", 16, 12, 10, "rgb", 0.1);
  ASSERT_EQ(RunPenumbra({"run", w, "--out", out.string(), "-q"}, tmp_.path()).exit_code, 0);
  tmp_.Write("out/notes.txt", "mine");
  ProcessResult r = RunPenumbra({"run", w, "--out", out.string(), "-q", "--force"}, tmp_.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'notes.txt'"), std::string::npos) << r.err;
  EXPECT_EQ(ReadAll(out / "notes.txt"), "mine");
  EXPECT_TRUE(fs::exists(out / "cam" / "rgb" / "000000.png"));
  fs::remove(out / "notes.txt");
  // a link where an output goes is never written through
  const fs::path victim = tmp_.Write("victim.csv", "precious\n");
  fs::remove(out / "trajectory.csv");
  fs::create_symlink(victim, out / "trajectory.csv");
  r = RunPenumbra({"run", w, "--out", out.string(), "-q", "--force"}, tmp_.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'trajectory.csv (a symbolic link)'"), std::string::npos) << r.err;
  EXPECT_EQ(ReadAll(victim), "precious\n");
  EXPECT_TRUE(fs::is_symlink(out / "trajectory.csv"));
}

TEST_F(RunOutputsTest, OutputsFlagForBareModelsAndWorlds) {
  const fs::path bare = tmp_.path() / "bare";
  ProcessResult r = RunPenumbra({"run", (tmp_.path() / "ball.xml").string(), "--out", bare.string(),
                                 "-q", "--duration", "0.05", "--outputs", "depth,normals"},
                                tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // the default camera and the model's own camera both
  for (const fs::path& cam : {bare / "default", bare / "ball" / "overhead"}) {
    EXPECT_GE(CountFiles(cam / "depth", ".png"), 1) << cam;
    EXPECT_GE(CountFiles(cam / "normals", ".png"), 1) << cam;
    EXPECT_FALSE(fs::exists(cam / "rgb")) << cam;
    EXPECT_FALSE(fs::exists(cam / "segmentation")) << cam;
  }
  // a world: overrides the camera's own list
  const fs::path world_out = tmp_.path() / "world";
  r = RunPenumbra({"run", World("w.yaml", 16, 12, 10, "rgb", 0.1), "--out", world_out.string(),
                   "-q", "--outputs", "segmentation,range"},
                  tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(CountFiles(world_out / "cam" / "segmentation", ".png"), 2);
  EXPECT_EQ(CountFiles(world_out / "cam" / "range", ".png"), 2);
  EXPECT_FALSE(fs::exists(world_out / "cam" / "rgb"));
  // bad names: exit 2, the valid ones listed
  r = RunPenumbra({"run", World("w2.yaml", 16, 12, 10, "rgb", 0.1), "--out",
                   (tmp_.path() / "bad").string(), "--outputs", "rgb,infrared"},
                  tmp_.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_EQ(r.out, "");
  EXPECT_NE(r.err.find("--outputs: unknown output 'infrared'; expected a comma-separated list of: "
                       "rgb, depth, segmentation, range, normals, instance_segmentation, "
                       "semantic_segmentation"),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(tmp_.path() / "bad"));
}

// runs the binary with every file it writes limited to `bytes` (RLIMIT_FSIZE; writes past it
// fail with EFBIG as a full disk fails with ENOSPC): a write failure without mounting anything
ProcessResult RunWithFileSizeLimit(const std::vector<std::string>& args, const fs::path& capture,
                                   rlim_t bytes) {
  rlimit old{};
  getrlimit(RLIMIT_FSIZE, &old);
  const sighandler_t old_handler = signal(SIGXFSZ, SIG_IGN);  // inherited: EFBIG, no signal
  rlimit r = old;
  r.rlim_cur = bytes;
  setrlimit(RLIMIT_FSIZE, &r);
  std::unique_ptr<ChildProcess> p;
  try {
    p = std::make_unique<ChildProcess>(args, capture);
  } catch (...) {
  }
  setrlimit(RLIMIT_FSIZE, &old);
  signal(SIGXFSZ, old_handler);
  ProcessResult result;
  if (!p) return result;
  result.exit_code = p->Wait();
  result.out = p->out();
  result.err = p->err();
  return result;
}

// the first "[error]" line of a run's stderr
std::string FirstErrorLine(const std::string& err) {
  const size_t at = err.find("[error]");
  if (at == std::string::npos) return "";
  return err.substr(at, err.find('\n', at) - at);
}

TEST_F(RunOutputsTest, AFailedImageWriteIsTheErrorReportedAndLeavesNoPartialFile) {
  const fs::path out = tmp_.path() / "out";
  // a 256 x 192 frame does not fit in 8 KiB; composed.xml, the JSONs and the trajectory
  // (64 KiB buffer, 100 short rows) do
  const ProcessResult r = RunWithFileSizeLimit(
      {"run", World("w.yaml", 256, 192, 10, "rgb, depth", 0.5), "--out", out.string(), "-q"},
      tmp_.path(), 8192);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_EQ(r.out, "");
  // the first error is an image write of camera `cam` (the writer pool writes frames in
  // parallel, so which frame fails first is not fixed), not a later one such as run.json's
  const std::string first = FirstErrorLine(r.err);
  const std::string cam_dir = (out / "cam").string() + "/";
  EXPECT_NE(first.find("cannot write '" + cam_dir), std::string::npos) << r.err;
  EXPECT_NE(first.find(".png': File too large"), std::string::npos) << r.err;
  // run.json records the same first error
  const auto j = nlohmann::json::parse(ReadAll(out / "run.json"));
  const std::string recorded = j.at("error").get<std::string>();
  EXPECT_FALSE(recorded.empty());
  EXPECT_NE(first.find(recorded), std::string::npos) << first << "\nvs run.json: " << recorded;
  EXPECT_EQ(CountFiles(out / "cam" / "rgb", ".png"), 0);
  EXPECT_EQ(CountFiles(out / "cam" / "depth", ".png"), 0);
  EXPECT_EQ(CsvRows(out / "cam" / "frames.csv"), 0);
  ExpectNothingPartial(out);
}

TEST_F(RunOutputsTest, AFailedTrajectoryWriteIsCutAtARowAndReported) {
  const fs::path out = tmp_.path() / "out";
  // 2 s at 200 Hz: about 60 KiB of trajectory rows, more than the 16 KiB allowed
  const ProcessResult r = RunWithFileSizeLimit(
      {"run", World("w.yaml", 8, 6, 1, "rgb", 2.0), "--out", out.string(), "-q"}, tmp_.path(),
      16384);
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(FirstErrorLine(r.err).find((out / "trajectory.csv").string() + "': File too large"),
            std::string::npos)
      << r.err;
  const std::string traj = ReadAll(out / "trajectory.csv");
  EXPECT_GT(traj.size(), 8000u);
  EXPECT_LE(traj.size(), 16384u);
  EXPECT_EQ(traj.back(), '\n');
  ExpectNothingPartial(out);
}

// a real full disk: a 2 MiB tmpfs (needs the right to mount; skipped where it is missing)
TEST_F(RunOutputsTest, FullDiskReportsTheFirstErrorAndLeavesNoPartialFile) {
  const fs::path mnt = tmp_.path() / "small";
  fs::create_directories(mnt);
  if (mount("tmpfs", mnt.c_str(), "tmpfs", 0, "size=2m") != 0)
    GTEST_SKIP() << "cannot mount a tmpfs here (" << std::strerror(errno)
                 << "); the write failure is covered by the RLIMIT_FSIZE tests";
  struct Unmount {
    fs::path p;
    ~Unmount() { umount2(p.c_str(), MNT_DETACH); }
  } unmount{mnt};
  const fs::path out = mnt / "out";
  const ProcessResult r = RunPenumbra(
      {"run", World("w.yaml", 320, 240, 50, "rgb, depth", 5.0), "--out", out.string(), "-q"},
      tmp_.path());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const std::string first = FirstErrorLine(r.err);
  EXPECT_NE(first.find("No space left on device"), std::string::npos) << r.err;
  EXPECT_NE(first.find(out.string()), std::string::npos) << r.err;
  EXPECT_EQ(first.find("run.json"), std::string::npos) << r.err;
  ExpectNothingPartial(out);
  EXPECT_EQ(CountFiles(out / "cam" / "rgb", ".png"), CsvRows(out / "cam" / "frames.csv"));
  EXPECT_EQ(CountFiles(out / "cam" / "depth", ".png"), CsvRows(out / "cam" / "frames.csv"));
}

TEST_F(RunOutputsTest, FrameTimesAreAtLeastKOverRateAndFloorGivesTheFrame) {
  const fs::path out = tmp_.path() / "out";
  const ProcessResult r =
      RunPenumbra({"run", World("w.yaml", 8, 6, 10, "rgb", 4.0, "physics: {timestep_sec: 0.002}\n"),
                   "--out", out.string(), "-q"},
                  tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  std::ifstream csv(out / "cam" / "frames.csv");
  std::string line;
  std::getline(csv, line);
  int64_t k = 0;
  while (std::getline(csv, line)) {
    const double t = std::strtod(line.c_str() + line.find(',') + 1, nullptr);
    EXPECT_GE(t, static_cast<double>(k) / 10) << line;
    EXPECT_EQ(static_cast<int64_t>(std::floor(t * 10)), k) << line;
    ++k;
  }
  EXPECT_EQ(k, 41);
}

TEST_F(RunOutputsTest, SensorRatesAbovePhysicsFireEveryStepWithAWarning) {
  // rate_hz 1e12 looped once per skipped sample (hours); now one sample per 5 ms step
  const fs::path out = tmp_.path() / "out";
  const ProcessResult r =
      RunPenumbra({"run",
                   World("w.yaml", 8, 6, 10, "rgb", 0.1,
                         "sensors:\n  - {name: imu, type: imu, body: scene/ball, rate_hz: 1e12}\n"
                         "  - {name: gt, type: ground_truth, rate_hz: 1e12, contacts: false}\n"),
                   "--out", out.string(), "-q"},
                  tmp_.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("sensor 'imu' at 1e+12 Hz is faster than the physics rate (200 Hz)"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(CsvRows(out / "imu" / "imu.csv"), 21);  // steps 0 .. 20
  EXPECT_EQ(CsvRows(out / "ground_truth" / "gt.csv"), 21);
}

TEST_F(RunOutputsTest, DivergenceRecordsTheSimTimeReached) {
  // a stiff spring that blows up after a few dozen steps of 10 ms
  tmp_.Write("spring.xml", R"(<mujoco>
  <option timestep="0.01" gravity="0 0 0"/>
  <worldbody>
    <body name="pendulum" pos="0 0 1">
      <joint name="spring" type="hinge" axis="0 1 0" stiffness="1e6" springref="0.1"/>
      <geom type="capsule" fromto="0 0 0 0.5 0 0" size="0.05"/>
    </body>
  </worldbody>
</mujoco>)");
  const std::string world = tmp_.Write(
      "d.yaml",
      "duration_sec: 10\nmodels: [{name: m, file: spring.xml}]\nmjcf_cameras: {enabled: false}\n"
      "cameras: [{name: cam, attach: world, pose: {xyz: [-3, 0, 1]}, width: 8, height: 6, "
      "rate_hz: 1}]\n");
  const fs::path out = tmp_.path() / "out";
  const ProcessResult r = RunPenumbra({"run", world, "--out", out.string(), "-q"}, tmp_.path());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  const size_t at = r.err.find("t = ");
  ASSERT_NE(at, std::string::npos) << r.err;
  const double t_diverged = std::strtod(r.err.c_str() + at + 4, nullptr);
  EXPECT_GT(t_diverged, 0.02) << r.err;
  const auto j = nlohmann::json::parse(ReadAll(out / "run.json"));
  EXPECT_NEAR(j.at("sim_duration_sec").get<double>(), t_diverged, 1e-6 * t_diverged) << r.err;
  EXPECT_NE(j.at("error").get<std::string>().find("diverged"), std::string::npos);
  EXPECT_FALSE(j.at("interrupted").get<bool>());
}

}  // namespace
}  // namespace penumbra

namespace penumbra {
namespace {

// a world with a mesh model writes meshes/<stem>-<hash>.msh and .xml beside
// composed.xml; running it again into the same folder with --force replaces that run (it
// refused them as "files Penumbra did not write")
TEST(RunOutputsMeshes, ForceReplacesARunWhoseWorldHasAMeshModel) {
  testing::TempDir tmp;
  tmp.Write("cube.obj",
            "v -0.1 0 -0.1\nv 0.1 0 -0.1\nv 0.1 0.2 -0.1\nv -0.1 0.2 -0.1\n"
            "v -0.1 0 0.1\nv 0.1 0 0.1\nv 0.1 0.2 0.1\nv -0.1 0.2 0.1\n"
            "f 1 3 2\nf 1 4 3\nf 5 6 7\nf 5 7 8\nf 1 2 6\nf 1 6 5\n"
            "f 2 3 7\nf 2 7 6\nf 3 4 8\nf 3 8 7\nf 4 1 5\nf 4 5 8\n");
  tmp.Write("floor.xml",
            "<mujoco><worldbody><geom name=\"ground\" type=\"plane\" size=\"0 0 0.05\"/>"
            "</worldbody></mujoco>\n");
  const std::string world = tmp.Write("world.yaml",
                                      "duration_sec: 0.02\n"
                                      "models:\n"
                                      "  - {name: floor, file: floor.xml}\n"
                                      "  - {name: crate, file: cube.obj}\n");
  const fs::path out = tmp.path() / "out";
  ProcessResult r = RunPenumbra({"run", world, "--out", out.string(), "-q"}, tmp.path());
  ASSERT_EQ(r.exit_code, 0) << r.err;
  int msh = 0, xml = 0;
  for (const auto& e : fs::directory_iterator(out / "meshes")) {
    msh += e.path().extension() == ".msh";
    xml += e.path().extension() == ".xml";
  }
  ASSERT_GE(msh, 1);
  ASSERT_GE(xml, 1);
  r = RunPenumbra({"run", world, "--out", out.string(), "-q", "--force"}, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("did not write"), std::string::npos) << r.err;
  EXPECT_TRUE(fs::exists(out / "run.json"));
  // the same with a relative --out (the mesh model's MJCF named its .msh files relative to
  // the working folder, which MuJoCo looked for relative to the MJCF: "not found")
  // (the child runs in this process's working folder: a relative path from there)
  const std::string rel = fs::relative(tmp.path() / "rel", fs::current_path()).string();
  ASSERT_FALSE(fs::path(rel).is_absolute());
  r = RunPenumbra({"run", world, "--out", rel, "-q"}, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(tmp.path() / "rel" / "run.json"));
  r = RunPenumbra({"run", world, "--out", rel, "-q", "--force"}, tmp.path());
  EXPECT_EQ(r.exit_code, 0) << r.err;
  // a file of another name in meshes/ is still not Penumbra's
  tmp.Write("out/meshes/mine.xml", "<mujoco/>");
  r = RunPenumbra({"run", world, "--out", out.string(), "-q", "--force"}, tmp.path());
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("'meshes/mine.xml'"), std::string::npos) << r.err;
}

}  // namespace
}  // namespace penumbra

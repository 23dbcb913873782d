// `penumbra run --record` as users run it (the real binary in a child process): the log is
// complete after a normal end and after Ctrl-C, readable to its last complete chunk after
// SIGKILL, run.json reports it, and the run's other outputs are the same bytes as without it.

#include <gtest/gtest.h>
#include <signal.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <thread>

#include "app/child_process.h"
#include "common/temp_dir.h"
#include "penumbra/runlog/run_log_reader.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ChildProcess;
using testing::ReadAll;
using testing::RunPenumbra;

// a ball falling onto a floor next to a hinged arm, 1 ms steps
constexpr char kBallMjcf[] = R"(<mujoco model="ball">
  <option timestep="0.001"/>
  <worldbody>
    <geom name="floor" type="plane" size="3 3 0.1"/>
    <body name="ball" pos="0 0 1">
      <freejoint/>
      <geom name="ball" type="sphere" size="0.2" rgba="0.9 0.3 0.2 1"/>
    </body>
    <body name="arm" pos="1 0 0.5"><joint name="hinge" type="hinge" axis="0 1 0"/><geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.05"/></body>
  </worldbody>
</mujoco>)";

class RecordRunTest : public ::testing::Test {
 protected:
  void SetUp() override { tmp_.Write("ball.xml", kBallMjcf); }

  std::string World(const std::string& extra = "", double duration_sec = 0.5) {
    return tmp_.Write("w.yaml", "seed: 3\nduration_sec: " + std::to_string(duration_sec) +
                                    "\nmodels: [{name: scene, file: ball.xml}]\n"
                                    "mjcf_cameras: {enabled: false}\n"
                                    "cameras:\n  - {name: cam, attach: world, pose: {xyz: [-3, "
                                    "0, 1.5], rpy_deg: [0, 20, 0]}, width: 32, height: 24, "
                                    "rate_hz: 20, outputs: [rgb, depth]}\n" +
                                    extra);
  }

  // waits until the log at `path` reads (recovery mode) up to at least `step` (max 60 s)
  static bool WaitForStep(const std::string& path, int64_t step) {
    for (int i = 0; i < 6000; ++i) {
      if (fs::exists(path)) {
        try {
          if (RunLogReader::Open(path, RunLogReadMode::kRecover).last_step() >= step) return true;
        } catch (const RunLogError&) {
          // the header is not written yet
        }
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    return false;
  }

  testing::TempDir tmp_;
};

TEST_F(RecordRunTest, RecordsEveryStepAndLeavesTheOtherOutputsUnchanged) {
  const std::string world = World();
  const fs::path plain = tmp_.path() / "plain", rec = tmp_.path() / "rec";
  const std::string log = (tmp_.path() / "ball.plog").string();
  auto a = RunPenumbra({"run", world, "--out", plain.string(), "-q"}, tmp_.path());
  ASSERT_EQ(a.exit_code, 0) << a.err;
  auto b = RunPenumbra({"run", world, "--out", rec.string(), "-q", "--record", log}, tmp_.path());
  ASSERT_EQ(b.exit_code, 0) << b.err;

  // steps 0..500 at 1 ms, complete, with the command line and the world text in its header
  RunLogReader r = RunLogReader::Open(log);
  EXPECT_TRUE(r.complete());
  EXPECT_EQ(r.first_step(), 0);
  EXPECT_EQ(r.last_step(), 500);
  EXPECT_EQ(r.header().world_text, ReadAll(world));
  EXPECT_NE(r.header().command_line.find("--record " + log), std::string::npos);
  EXPECT_EQ(r.header().layout.nq, 8);

  const auto j = nlohmann::json::parse(ReadAll(rec / "run.json"));
  EXPECT_EQ(j.at("record").at("file").get<std::string>(), log);
  EXPECT_EQ(j.at("record").at("steps").get<int64_t>(), 501);
  EXPECT_EQ(j.at("record").at("bytes").get<uint64_t>(), fs::file_size(log));
  EXPECT_FALSE(nlohmann::json::parse(ReadAll(plain / "run.json")).contains("record"));

  // the same trajectory, frames and images as the run without the recorder
  for (const char* f : {"trajectory.csv", "cam/frames.csv", "cam/rgb/000005.png",
                        "cam/depth/000009.png", "composed.xml"})
    EXPECT_EQ(ReadAll(plain / f), ReadAll(rec / f)) << f;
}

TEST_F(RecordRunTest, SigkillLeavesALogReadableToItsLastCompleteChunk) {
  const std::string world = World("", 60);
  const std::string log = (tmp_.path() / "killed.plog").string();
  ChildProcess p(
      {"run", world, "--out", (tmp_.path() / "out").string(), "-q", "--realtime", "--record", log},
      tmp_.path());
  // two chunks of 256 steps are on disk, then the recorder dies mid-run
  ASSERT_TRUE(WaitForStep(log, 511)) << p.err();
  p.Signal(SIGKILL);
  EXPECT_EQ(p.Wait(), 128 + SIGKILL);

  try {
    RunLogReader::Open(log);
    FAIL() << "a killed log passed the strict check";
  } catch (const RunLogError& e) {
    EXPECT_NE(std::string(e.what()).find("log ends at chunk "), std::string::npos) << e.what();
  }
  RunLogReader r = RunLogReader::Open(log, RunLogReadMode::kRecover);
  EXPECT_FALSE(r.complete());
  ASSERT_TRUE(r.damage());
  // "log ends at chunk N (step S): ..." naming the last complete chunk and its last step
  const RunLogChunkInfo& last = r.chunks().back();
  EXPECT_NE(r.damage()->find("log ends at chunk " + std::to_string(last.index) + " (step " +
                             std::to_string(r.last_step()) + "):"),
            std::string::npos)
      << *r.damage();
  // every step up to there, in order; whole chunks of 256 steps
  EXPECT_GE(r.last_step(), 511);
  EXPECT_EQ((r.last_step() + 1) % 256, 0) << r.last_step();
  StepRecord s;
  int64_t n = 0;
  while (r.NextStep(&s)) {
    ASSERT_EQ(s.step, n);
    ASSERT_EQ(s.qpos.size(), 8u);
    ++n;
  }
  EXPECT_EQ(n, r.last_step() + 1);
}

TEST_F(RecordRunTest, CtrlCClosesTheLogCompletely) {
  const std::string world = World("", 60);
  const std::string log = (tmp_.path() / "int.plog").string();
  const fs::path out = tmp_.path() / "out";
  ChildProcess p({"run", world, "--out", out.string(), "-q", "--realtime", "--record", log},
                 tmp_.path());
  ASSERT_TRUE(WaitForStep(log, 255)) << p.err();
  p.Signal(SIGINT);
  EXPECT_EQ(p.Wait(), 130) << p.err();
  RunLogReader r = RunLogReader::Open(log);  // strict: no damage
  EXPECT_TRUE(r.complete());
  const auto j = nlohmann::json::parse(ReadAll(out / "run.json"));
  EXPECT_TRUE(j.at("interrupted").get<bool>());
  EXPECT_EQ(j.at("record").at("steps").get<int64_t>(), r.num_steps());
  EXPECT_EQ(j.at("record").at("last_step").get<int64_t>(), r.last_step());
  // the log ends at the step the run stopped at (trajectory.csv's last row)
  const std::string traj = ReadAll(out / "trajectory.csv");
  const std::string last = traj.substr(traj.rfind('\n', traj.size() - 2) + 1);
  EXPECT_EQ(std::stoll(last.substr(0, last.find(','))), r.last_step());
}

TEST_F(RecordRunTest, RecordSensorsStoresTheBytesOfEveryImageAndSensorRow) {
  const std::string world = World(
      "sensors:\n  - {name: imu0, type: imu, body: scene/ball, preset: ideal, rate_hz: 100}\n",
      0.2);
  const fs::path out = tmp_.path() / "out";
  const std::string log = (tmp_.path() / "s.plog").string();
  auto a =
      RunPenumbra({"run", world, "--out", out.string(), "-q", "--record", log, "--record-sensors"},
                  tmp_.path());
  ASSERT_EQ(a.exit_code, 0) << a.err;
  RunLogReader r = RunLogReader::Open(log);
  EXPECT_TRUE(r.header().has_sensor_records);
  const std::vector<SensorRecord> recs = r.SensorRecords();
  // camera at 20 Hz over [0, 0.2] s: frames 0..4, rgb and depth each; IMU at 100 Hz: 21 rows
  int rgb = 0, depth = 0, imu = 0;
  std::string imu_rows;
  for (const SensorRecord& s : recs) {
    if (s.sensor == "cam") {
      const int64_t frame = s.step / 50;  // 1 ms steps, a frame every 50
      EXPECT_EQ(s.step % 50, 0) << s.step;
      char name[32];
      std::snprintf(name, sizeof(name), "%06lld.png", static_cast<long long>(frame));
      if (s.kind == "rgb.png") {
        ++rgb;
        EXPECT_EQ(s.payload, ReadAll(out / "cam" / "rgb" / name)) << name;
      } else {
        EXPECT_EQ(s.kind, "depth.png");
        ++depth;
        EXPECT_EQ(s.payload, ReadAll(out / "cam" / "depth" / name)) << name;
      }
    } else {
      EXPECT_EQ(s.sensor, "imu0");
      EXPECT_EQ(s.kind, "imu.csv");
      ++imu;
      imu_rows += s.payload;
    }
  }
  EXPECT_EQ(rgb, 5);
  EXPECT_EQ(depth, 5);
  EXPECT_EQ(imu, 21);
  const std::string csv = ReadAll(out / "imu" / "imu0.csv");
  EXPECT_EQ(csv.substr(csv.find('\n') + 1), imu_rows);
  EXPECT_EQ(nlohmann::json::parse(ReadAll(out / "run.json")).at("record").at("sensor_records"), 31);
}

TEST_F(RecordRunTest, WorldFileRecordSectionWritesIntoTheOutputFolder) {
  const std::string world = World("record: {file: run.plog}\n");
  const fs::path out = tmp_.path() / "out";
  auto a = RunPenumbra({"run", world, "--out", out.string(), "-q"}, tmp_.path());
  ASSERT_EQ(a.exit_code, 0) << a.err;
  EXPECT_TRUE(RunLogReader::Open((out / "run.plog").string()).complete());
  // a rerun with --force may replace it (a .plog is a Penumbra output)
  auto b = RunPenumbra({"run", world, "--out", out.string(), "-q", "--force"}, tmp_.path());
  EXPECT_EQ(b.exit_code, 0) << b.err;
}

TEST_F(RecordRunTest, BadRecordSettingsAreRefusedNamingTheirSource) {
  auto a = RunPenumbra({"run", World(), "--out", (tmp_.path() / "o1").string(), "-q", "--record",
                        (tmp_.path() / "x.txt").string()},
                       tmp_.path());
  EXPECT_EQ(a.exit_code, 2);
  EXPECT_NE(a.err.find("--record"), std::string::npos) << a.err;
  EXPECT_NE(a.err.find("expected a file name ending in .plog"), std::string::npos) << a.err;

  const std::string w = World("record: {file: run.log}\n");
  auto b = RunPenumbra({"run", w, "--out", (tmp_.path() / "o2").string(), "-q"}, tmp_.path());
  EXPECT_EQ(b.exit_code, 2);
  EXPECT_NE(b.err.find("w.yaml:7: record.file"), std::string::npos) << b.err;

  auto c = RunPenumbra(
      {"run", World(), "--out", (tmp_.path() / "o3").string(), "-q", "--record-sensors"},
      tmp_.path());
  EXPECT_EQ(c.exit_code, 2);
  EXPECT_NE(c.err.find("--record-sensors"), std::string::npos) << c.err;
}

// a world file may come from anyone: its record.file is a new file inside the output folder,
// never an absolute path or one that leaves it (which overwrote another run log)
TEST_F(RecordRunTest, AWorldFilesRecordFileStaysInsideTheOutputFolder) {
  tmp_.Write("victim.plog", "keep");
  for (const std::string& f :
       {std::string("../victim.plog"), (tmp_.path() / "victim.plog").string(),
        std::string("../new.plog"), std::string("a/../../new.plog")}) {
    const std::string w = World("record: {file: '" + f + "'}\n");
    auto r = RunPenumbra({"run", w, "--out", (tmp_.path() / "out").string(), "-q"}, tmp_.path());
    EXPECT_EQ(r.exit_code, 2) << f << ": " << r.err;
    EXPECT_NE(r.err.find("w.yaml:7: record.file"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("inside it"), std::string::npos) << r.err;
  }
  EXPECT_EQ(ReadAll(tmp_.path() / "victim.plog"), "keep");
  EXPECT_FALSE(fs::exists(tmp_.path() / "new.plog"));
}

// --record never overwrites an existing log unless the user passes --force
TEST_F(RecordRunTest, AnExistingLogIsReplacedOnlyWithForce) {
  const std::string log = tmp_.Write("old.plog", "keep");
  auto a = RunPenumbra(
      {"run", World(), "--out", (tmp_.path() / "o1").string(), "-q", "--record", log}, tmp_.path());
  EXPECT_EQ(a.exit_code, 2) << a.err;
  EXPECT_NE(a.err.find("--record: run log '" + log + "' exists"), std::string::npos) << a.err;
  EXPECT_EQ(ReadAll(log), "keep");
  EXPECT_FALSE(fs::exists(tmp_.path() / "o1" / "run.json"));
  auto b = RunPenumbra(
      {"run", World(), "--out", (tmp_.path() / "o2").string(), "-q", "--record", log, "--force"},
      tmp_.path());
  ASSERT_EQ(b.exit_code, 0) << b.err;
  EXPECT_TRUE(RunLogReader::Open(log).complete());
}

// a live run owns its output folder and its log: a second run into either, --force or not,
// fails at start naming the first run's PID, and the first run ends with all its outputs
// (two runs into one log both exited 0 and left a corrupt log; --force into a live run's folder
// removed its outputs and made it fail)
TEST_F(RecordRunTest, ASecondRunIntoALiveRunsFolderOrLogFailsNamingItsPid) {
  const std::string world = World("", 60);
  const fs::path out = tmp_.path() / "out";
  const std::string log = (tmp_.path() / "live.plog").string();
  ChildProcess a({"run", world, "--out", out.string(), "-q", "--realtime", "--record", log},
                 tmp_.path());
  ASSERT_TRUE(WaitForStep(log, 255)) << a.err();
  const std::string pid = "(PID " + std::to_string(a.pid()) + ")";
  const fs::path cap = tmp_.path() / "second";
  fs::create_directories(cap);
  for (const bool force : {false, true}) {
    std::vector<std::string> args = {"run", world,      "--out", (tmp_.path() / "o2").string(),
                                     "-q",  "--record", log};
    if (force) args.push_back("--force");
    auto same_log = RunPenumbra(args, cap);
    EXPECT_EQ(same_log.exit_code, 2) << same_log.err;
    EXPECT_NE(same_log.err.find("is being written by another run " + pid), std::string::npos)
        << same_log.err;
    args = {"run", world, "--out", out.string(), "-q"};
    if (force) args.push_back("--force");
    auto same_out = RunPenumbra(args, cap);
    EXPECT_EQ(same_out.exit_code, 2) << same_out.err;
    EXPECT_NE(same_out.err.find("is in use by another run " + pid), std::string::npos)
        << same_out.err;
  }
  EXPECT_FALSE(fs::exists(tmp_.path() / "o2"));
  a.Signal(SIGINT);
  EXPECT_EQ(a.Wait(), 130) << a.err();
  EXPECT_TRUE(RunLogReader::Open(log).complete());
  EXPECT_TRUE(fs::exists(out / "run.json"));
  EXPECT_TRUE(fs::exists(out / "cam" / "rgb" / "000000.png"));
}

}  // namespace
}  // namespace penumbra

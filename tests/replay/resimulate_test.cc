// ResimulateLog: a recorded run simulated again and checked at every step: bit-exact for the
// recording's own world, the first divergent step, field, entry and values when a model file
// changed since, and command events refused unless the logged ctrl is applied.
#include "penumbra/replay/resimulate.h"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <nlohmann/json.hpp>

#include "common/run_loop.h"
#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/output/recorder_sink.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/runlog/run_log_codec.h"
#include "penumbra/runlog/run_log_reader.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

// a ball dropped next to a motor-driven pendulum (a PD controller writes its ctrl)
constexpr char kModel[] = R"(<mujoco><option timestep="0.002"/><worldbody>
  <geom name="floor" type="plane" size="3 3 0.1"/>
  <body name="ball" pos="0 0 0.5"><freejoint name="free"/><geom type="sphere" size="0.1"/></body>
  <body name="arm" pos="1 0 1"><joint name="hinge" axis="0 1 0"/>
    <geom type="capsule" fromto="0 0 0 0.4 0 0" size="0.03"/></body>
  </worldbody><actuator><motor name="m" joint="hinge"/></actuator></mujoco>)";

class ResimulateTest : public ::testing::Test {
 protected:
  void SetUp() override {
    model_ = tmp_.Write("m.xml", kModel);
    const std::string world =
        tmp_.Write("w.yaml",
                   "robots:\n"
                   "  - name: r\n"
                   "    file: m.xml\n"
                   "    controller: {type: joint_pd, joints: [hinge], actuators: [m], kp: [20],\n"
                   "                 kd: [1], target: [0.8]}\n"
                   "mjcf_cameras: {enabled: false}\n");
    log_ = (tmp_.path() / "r.plog").string();
    SessionOptions o;
    o.build_renderer = false;
    Session session(LoadWorldFile(world), o);
    PhysicsSource physics(&session.sim());
    RecorderSink recorder(log_, MakeRunLogHeader(session, "test", "penumbra run w.yaml"));
    if (with_command_) recorder.writer().RecordEvent(10, 0.02, "command", command_);
    ASSERT_FALSE(testing::RunLoop(&physics, {&recorder}, duration_sec_).error);
  }

  testing::TempDir tmp_;
  std::string model_, log_;
  bool with_command_ = false;
  std::string command_ = R"({"v": 1})";
  double duration_sec_ = 0.4;
};

TEST_F(ResimulateTest, TheRecordingsOwnWorldIsBitExactInBothModes) {
  ResimulateOptions o;
  o.log_path = log_;
  ResimulateReport r = ResimulateLog(o);
  EXPECT_FALSE(r.divergence);
  EXPECT_EQ(r.steps_checked, 201);
  EXPECT_EQ(r.Describe(), "bit-exact (201 steps)");
  o.mode = ResimulateMode::kCtrl;
  r = ResimulateLog(o);
  EXPECT_EQ(r.Describe(), "bit-exact (201 steps)");
}

TEST_F(ResimulateTest, AChangedModelDivergesAtItsFirstStepNamingFieldEntryAndValues) {
  // lower gravity since the recording: the ball falls slower from the first step on
  std::string changed = kModel;
  changed.replace(changed.find("<option "), 8, "<option gravity=\"0 0 -9.7\" ");
  tmp_.Write("m.xml", changed);
  ResimulateOptions o;
  o.log_path = log_;
  o.mode = ResimulateMode::kCtrl;
  const ResimulateReport r = ResimulateLog(o);
  ASSERT_TRUE(r.divergence);
  EXPECT_EQ(r.divergence->step, 1);
  // qpos is compared first: the free joint's z (its entry 2) is the first to differ
  EXPECT_EQ(r.divergence->field, "qpos");
  EXPECT_EQ(r.divergence->index, 2);
  EXPECT_EQ(r.divergence->what, "joint 'r/free' entry 2");
  EXPECT_LT(r.divergence->logged, r.divergence->simulated);  // it fell faster when recorded
  EXPECT_EQ(r.Describe(),
            fmt::format("diverged at step 1 (t = 0.002 s): qpos[2] (joint 'r/free' entry 2): "
                        "logged {:.17g}, simulated {:.17g}",
                        r.divergence->logged, r.divergence->simulated));
  ASSERT_EQ(r.warnings.size(), 1u);
  EXPECT_NE(r.warnings[0].find("model " + model_ + " changed since the run was recorded"),
            std::string::npos)
      << r.warnings[0];
}

class ResimulateCommandsTest : public ResimulateTest {
 protected:
  void SetUp() override {
    with_command_ = true;
    ResimulateTest::SetUp();
  }
};

TEST_F(ResimulateCommandsTest, CommandEventsAreRefusedUnlessTheLoggedCtrlIsApplied) {
  ResimulateOptions o;
  o.log_path = log_;
  try {
    ResimulateLog(o);
    ADD_FAILURE();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("the log holds 1 command event(s) (the first at step "
                                         "10); re-injecting commands is not supported yet; "
                                         "expected --resimulate ctrl"),
              std::string::npos)
        << e.what();
  }
  o.mode = ResimulateMode::kCtrl;
  EXPECT_EQ(ResimulateLog(o).Describe(), "bit-exact (201 steps)");
}

class ResimulateStateCommandTest : public ResimulateTest {
 protected:
  void SetUp() override {
    with_command_ = true;
    command_ = R"({"cmd": "set_mocap", "body": "target", "xyz": [0, 0, 1]})";
    ResimulateTest::SetUp();
  }
};

TEST_F(ResimulateStateCommandTest, ACommandThatSetsTheStateIsRefusedInBothModesNamingIt) {
  ResimulateOptions o;
  o.log_path = log_;
  EXPECT_THROW(ResimulateLog(o), ConfigError);
  o.mode = ResimulateMode::kCtrl;
  try {
    ResimulateLog(o);
    ADD_FAILURE() << "a set_mocap command was resimulated";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("1 command event(s) that change the state itself (the "
                                         "first, 'set_mocap', at step 10)"),
              std::string::npos)
        << e.what();
  }
}

// `log` with its header's timestep_sec set to `timestep_sec`, the header chunk stored
// uncompressed and every CRC valid again: a crafted log, not a damaged one
void SetLoggedTimestep(const std::string& log, double timestep_sec) {
  namespace codec = runlog_codec;
  std::string bytes;
  {
    std::ifstream in(log, std::ios::binary);
    bytes.assign(std::istreambuf_iterator<char>(in), {});
  }
  codec::ChunkHeader h;
  ASSERT_EQ(codec::DecodeChunkHeader(
                reinterpret_cast<const uint8_t*>(bytes.data() + codec::kPreambleBytes), &h),
            "");
  const size_t body_at = codec::kPreambleBytes + codec::kChunkHeaderBytes;
  const std::string stored = bytes.substr(body_at, h.stored_size);
  const std::string text =
      h.codec == codec::kCodecZstd ? codec::ZstdDecompress(stored, h.raw_size) : stored;
  nlohmann::json j = nlohmann::json::parse(text);
  j["timestep_sec"] = timestep_sec;
  const std::string body = j.dump();
  codec::ChunkHeader nh = h;
  nh.codec = codec::kCodecNone;
  nh.raw_size = nh.stored_size = body.size();
  std::string chunk = codec::EncodeChunkHeader(nh) + body;
  codec::PutU32(&chunk, codec::Crc32(body.data(), body.size()));
  bytes = bytes.substr(0, codec::kPreambleBytes) + chunk +
          bytes.substr(body_at + h.stored_size + codec::kChunkTrailerBytes);
  std::ofstream(log, std::ios::binary | std::ios::trunc) << bytes;
}

TEST_F(ResimulateTest, AHeaderTimestepOfZeroIsRefusedAsReplayRefusesItNeverBitExact) {
  SetLoggedTimestep(log_, 0.0);
  for (ResimulateMode mode : {ResimulateMode::kControllers, ResimulateMode::kCtrl}) {
    ResimulateOptions o;
    o.log_path = log_;
    o.mode = mode;
    try {
      const ResimulateReport r = ResimulateLog(o);
      ADD_FAILURE() << "a timestep of 0 s was resimulated: " << r.Describe();
    } catch (const RunLogError& e) {
      EXPECT_EQ(std::string(e.what()),
                log_ +
                    ": damaged run log header: header chunk: timestep_sec is 0 s; expected a "
                    "physics timestep in [1e-06, 0.1] s");
    }
  }
}

TEST_F(ResimulateTest, AHeaderTimestepOtherThanTheModelsIsRefusedNamingBoth) {
  SetLoggedTimestep(log_, 0.001);
  ResimulateOptions o;
  o.log_path = log_;
  try {
    const ResimulateReport r = ResimulateLog(o);
    ADD_FAILURE() << "a log recorded at another timestep was resimulated: " << r.Describe();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.problem(),
              "the replay model's timestep is 0.002 s; the log was recorded at 0.001 s; expected "
              "the recorded physics unchanged");
  }
}

// a log of 401 steps: two steps chunks (256 + 145 steps)
class ResimulateDamagedTest : public ResimulateTest {
 protected:
  void SetUp() override {
    duration_sec_ = 0.8;
    ResimulateTest::SetUp();
  }
};

TEST_F(ResimulateDamagedTest, AFlippedByteInAStepsChunkIsReportedAsDamageNeverBitExact) {
  // one byte in the middle of the second steps chunk's body
  uint64_t at = 0;
  {
    RunLogReader reader = RunLogReader::Open(log_);
    int steps_chunks = 0;
    for (const RunLogChunkInfo& c : reader.chunks())
      if (c.kind == RunLogChunkKind::kSteps && ++steps_chunks == 2)
        at = c.file_offset + runlog_codec::kChunkHeaderBytes + c.compressed_size / 2;
    ASSERT_EQ(steps_chunks, 2);
  }
  {
    std::fstream f(log_, std::ios::in | std::ios::out | std::ios::binary);
    f.seekg(static_cast<std::streamoff>(at));
    char b = 0;
    f.read(&b, 1);
    b = static_cast<char>(b ^ 0x10);
    f.seekp(static_cast<std::streamoff>(at));
    f.write(&b, 1);
  }
  for (ResimulateMode mode : {ResimulateMode::kControllers, ResimulateMode::kCtrl}) {
    ResimulateOptions o;
    o.log_path = log_;
    o.mode = mode;
    const ResimulateReport r = ResimulateLog(o);
    EXPECT_FALSE(r.divergence);
    EXPECT_FALSE(r.bit_exact());
    ASSERT_TRUE(r.damage);
    EXPECT_NE(r.damage->find("CRC mismatch in chunk"), std::string::npos) << *r.damage;
    EXPECT_NE(r.damage->find("steps 256..400"), std::string::npos) << *r.damage;
    // the steps before the damage were checked, and said so; "bit-exact (N steps)" never
    EXPECT_EQ(r.steps_checked, 256);
    EXPECT_EQ(r.Describe().rfind("damaged log, not verified past step 255: log ends at chunk", 0),
              0u)
        << r.Describe();
    EXPECT_EQ(r.Describe().find("bit-exact ("), std::string::npos) << r.Describe();
  }
}

}  // namespace
}  // namespace penumbra

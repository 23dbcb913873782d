// diff_ik's target generation, limit clamping and gripper, keyframe_playback's timeline and
// CSV reader, and both controllers' config errors, against a fake ControlInput
// (tests/control/arm_control_fake.h).

#include <gtest/gtest.h>
#include <sys/stat.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "arm_control_fake.h"
#include "penumbra/control/diff_ik.h"
#include "penumbra/control/keyframe_playback.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using namespace arm_fake;

constexpr double kDeg = M_PI / 180;

std::string ErrorOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::unique_ptr<DiffIkController> MakeIk(const ModelInfo& m, const std::string& extra = "") {
  return Make<DiffIkController>(m, "diff_ik",
                                std::string(kServo) + "site: ee\ngripper_actuator: grip\n" + extra);
}

// a straight move: linear in position, slerp in orientation, minimum-jerk timing whose
// peak speed is the requested one; move_by is relative to the goal; pose jumps
TEST(DiffIk, StraightMovesAndJumps) {
  const ModelInfo m = ArmModel();
  auto ik = MakeIk(m);
  FakeInput in(m);
  in.q_[3] = -1;
  std::vector<double> ctrl(8, 0.0);
  ik->Compute(in, ctrl);  // t = 0: the target starts at the measured pose (identity)
  EXPECT_TRUE(ik->target().isApprox(Pose::Identity()));
  const Pose goal = PoseFromXyzRpyDeg(Eigen::Vector3d(0.3, 0, 0), Eigen::Vector3d(0, 0, 90));
  ik->PushCommand(ArmCommand::MoveTo(goal, 0.1, 90 * kDeg));
  // duration 1.875 max(0.3 m / 0.1 m/s, 90 deg / 90 deg/s) = 5.625 s
  const double T = 5.625;
  in.t_ = 0.01;
  ik->Compute(in, ctrl);  // the move starts here
  EXPECT_TRUE(ik->moving());
  in.t_ = 0.01 + T / 2;
  ik->Compute(in, ctrl);
  EXPECT_NEAR(ik->target().translation().x(), 0.15, 1e-12);
  EXPECT_NEAR(ik->target().translation().y(), 0.0, 1e-12);
  EXPECT_NEAR(Eigen::AngleAxisd(ik->target().linear()).angle(), 45 * kDeg, 1e-12);
  // peak speed: ds/dtau (0.5) = 1.875, times 0.3 m / T = 0.1 m/s
  in.t_ = 0.01 + T / 2 + 1e-4;
  const double x0 = ik->target().translation().x();
  ik->Compute(in, ctrl);
  EXPECT_NEAR((ik->target().translation().x() - x0) / 1e-4, 0.1, 1e-6);
  in.t_ = 0.01 + T;
  ik->Compute(in, ctrl);
  EXPECT_FALSE(ik->moving());
  EXPECT_TRUE(ik->target().isApprox(goal, 1e-12));
  // relative move, from the goal
  ik->PushCommand(
      ArmCommand::MoveBy(PoseFromXyzRpyDeg(Eigen::Vector3d(0, 0, 0.1), Eigen::Vector3d::Zero())));
  in.t_ = 6;
  ik->Compute(in, ctrl);
  EXPECT_TRUE(ik->goal().translation().isApprox(Eigen::Vector3d(0.3, 0, 0.1), 1e-12));
  EXPECT_TRUE(ik->goal().linear().isApprox(goal.linear(), 1e-12));
  // a jump replaces the move at once
  ik->PushCommand(ArmCommand::SetPose(Pose::Identity()));
  in.t_ = 6.1;
  ik->Compute(in, ctrl);
  EXPECT_FALSE(ik->moving());
  EXPECT_TRUE(ik->target().isApprox(Pose::Identity()));
}

TEST(DiffIk, GripperCommandsWriteItsActuator) {
  const ModelInfo m = ArmModel();
  auto ik = MakeIk(m, "gripper_initial: close\n");
  FakeInput in(m);
  std::vector<double> ctrl(8, -1.0);
  ik->Compute(in, ctrl);
  EXPECT_EQ(ctrl[7], 0.0);  // closed = the ctrlrange minimum
  ik->PushCommand(ArmCommand::Gripper(ArmCommand::GripperAction::kOpen));
  in.t_ = 0.1;
  ik->Compute(in, ctrl);
  EXPECT_EQ(ctrl[7], 0.04);
  ik->PushCommand(ArmCommand::Gripper(ArmCommand::GripperAction::kValue, 0.015));
  in.t_ = 0.2;
  ik->Compute(in, ctrl);
  EXPECT_EQ(ctrl[7], 0.015);
  // without a gripper actuator, a gripper command is refused
  auto no_gripper = Make<DiffIkController>(m, "diff_ik", std::string(kServo) + "site: ee\n");
  EXPECT_THROW(no_gripper->PushCommand(ArmCommand::Gripper(ArmCommand::GripperAction::kOpen)),
               Error);
}

// joint 1 drives the site along x (the Jacobian column); the target lies far beyond what
// joint 1's range allows: the reference brakes into the bound and never passes it
TEST(DiffIk, ReferenceStaysInsideTheJointRanges) {
  const ModelInfo m = ArmModel();
  auto ik = MakeIk(m, "max_tracking_error: 10\n");
  FakeInput in(m);
  in.q_ = {1.5, 0, 0, -1, 0, 0, 0, 0};
  in.jacobian_.setZero(6, m.nv);
  in.jacobian_(3, 0) = 1;  // linear x from joint 1
  std::vector<double> ctrl(8, 0.0);
  ik->Compute(in, ctrl);
  ik->PushCommand(
      ArmCommand::SetPose(PoseFromXyzRpyDeg(Eigen::Vector3d(5, 0, 0), Eigen::Vector3d::Zero())));
  double worst = -10;
  for (int k = 1; k <= 2000; ++k) {
    in.t_ = 0.002 * k;
    in.q_[0] = ik->q_ref()[0];  // a perfect servo
    ik->Compute(in, ctrl);
    worst = std::max(worst, ik->q_ref()[0]);
  }
  EXPECT_LE(worst, 2.0 - 0.01);  // range [-2, 2] less the 0.01 rad margin
  EXPECT_GT(ik->q_ref()[0], 2.0 - 0.011);
  for (int i = 1; i < 7; ++i) EXPECT_TRUE(std::isfinite(ik->q_ref()[i]));
}

TEST(DiffIk, ConfigErrors) {
  const ModelInfo m = ArmModel();
  auto error = [&](const std::string& extra) { return ErrorOf([&] { MakeIk(m, extra); }); };
  EXPECT_NE(error("commands: [{t: 0, move_to: {xyz: [0, 0, 1]}, gripper: open}]\n")
                .find("commands[0]: got more than one of move_to / move_by / pose / gripper"),
            std::string::npos);
  EXPECT_NE(error("commands: [{t: 0, gripper: half}]\n")
                .find("commands[0].gripper: got 'half'; expected open, close or a ctrl value"),
            std::string::npos);
  EXPECT_NE(error("commands: [{t: 0, move_by: {}}]\n").find("commands[0].move_by: empty"),
            std::string::npos);
  EXPECT_NE(error("commands: [{t: 0, move_to: {xyz: [0, 1]}}]\n")
                .find("commands[0].move_to.xyz: got a list of 2 items; expected a list of 3 "
                      "numbers (m)"),
            std::string::npos);
  EXPECT_NE(error("commands: [{t: 0, move_to: {xyz: [0, 0, 1], rpy: [0, 0, 0]}}]\n")
                .find("commands[0].move_to.rpy: unknown key(s) 'rpy'"),
            std::string::npos);
  EXPECT_NE(error("damping: 0.2\ndamping_max: 0.1\n").find("damping_max: got 0.1"),
            std::string::npos);
  EXPECT_NE(error("posture: [0, 0]\n").find("posture: got a list of 2 items"), std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              Make<DiffIkController>(m, "diff_ik",
                                     std::string(kServo) + "site: ee\ngripper_open: 0.04\n");
            }).find("gripper_open: given without gripper_actuator"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              Make<DiffIkController>(
                  m, "diff_ik",
                  std::string(kServo) + "site: ee\n" + "commands: [{t: 0, gripper: open}]\n");
            }).find("commands[0].gripper: a gripper command, but no gripper_actuator"),
            std::string::npos);
}

std::unique_ptr<KeyframePlayback> MakeKp(const ModelInfo& m, const std::string& extra,
                                         const std::string& world = "world.yaml") {
  std::unique_ptr<Controller> c =
      MakeController(Block("keyframe_playback", std::string(kServo) + extra), "a", world);
  auto* kp = dynamic_cast<KeyframePlayback*>(c.get());
  if (!kp) return nullptr;
  c.release();
  std::unique_ptr<KeyframePlayback> out(kp);
  out->Initialize(m);
  return out;
}

// the timeline: an implicit start frame at 0 when the first frame is later, linear
// segments, hold at the end, or a loop whose first segment starts from the last frame
TEST(KeyframePlayback, TimelineOfKeysAndJointValues) {
  const ModelInfo m = ArmModel();
  auto kp = MakeKp(m,
                   "gripper_actuator: grip\ngripper_joint: finger\n"
                   "frames:\n"
                   "  - {t: 1, key: home}\n"
                   "  - {t: 3, q: [0, 0, 0, -1, 0, 0, 0], gripper: 0.02}\n"
                   "  - {t: 4, key: bent, gripper: 0.01}\n");
  ASSERT_NE(kp, nullptr);
  Eigen::VectorXd start = Eigen::VectorXd::Constant(7, 0.2), q, qd;
  double g = 0;
  kp->Evaluate(0.5, start, 0.03, &q, &qd, &g);  // halfway from the start to "home"
  EXPECT_NEAR(q[1], 0.5 * (0.2 - 0.5), 1e-12);
  EXPECT_NEAR(qd[1], (-0.5 - 0.2) / 1.0, 1e-12);
  EXPECT_NEAR(g, 0.5 * (0.03 + 0.04), 1e-12);
  kp->Evaluate(2, start, 0.03, &q, &qd, &g);  // halfway from "home" to the q frame
  EXPECT_NEAR(q[3], -1.5, 1e-12);
  EXPECT_NEAR(qd[3], 0.5, 1e-12);
  EXPECT_NEAR(g, 0.03, 1e-12);
  kp->Evaluate(10, start, 0.03, &q, &qd, &g);  // after the end: "bent", gripper overridden
  EXPECT_NEAR(q[0], 1.0, 1e-12);
  EXPECT_NEAR(qd.norm(), 0.0, 1e-12);
  EXPECT_NEAR(g, 0.01, 1e-12);

  auto loop = MakeKp(m,
                     "loop: true\nframes: [{t: 1, q: [1, 0, 0, -1, 0, 0, 0]}, "
                     "{t: 2, q: [0, 0, 0, -1, 0, 0, 0]}]\n");
  loop->Evaluate(0.5, start, 0, &q, &qd, &g);  // first lap: from the start configuration
  EXPECT_NEAR(q[0], 0.6, 1e-12);
  loop->Evaluate(4.5, start, 0, &q, &qd, &g);  // third lap, t = 0.5: from the last frame
  EXPECT_NEAR(q[0], 0.5, 1e-12);
  loop->Evaluate(5.5, start, 0, &q, &qd, &g);
  EXPECT_NEAR(q[0], 0.5, 1e-12);
}

TEST(KeyframePlayback, ConfigErrors) {
  const ModelInfo m = ArmModel();
  auto error = [&](const std::string& extra) { return ErrorOf([&] { MakeKp(m, extra); }); };
  EXPECT_NE(error("").find("frames: missing; expected exactly one of frames"), std::string::npos);
  EXPECT_NE(
      error("frames: [{t: 0, key: home}]\ncsv: x.csv\n").find("csv: given together with frames"),
      std::string::npos);
  EXPECT_NE(error("frames: [{t: 0, key: home, q: [0, 0, 0, 0, 0, 0, 0]}]\n")
                .find("frames[0]: has both key and q"),
            std::string::npos);
  EXPECT_NE(error("frames: [{t: 1, key: home}, {t: 1, key: bent}]\n")
                .find("frames[1].t: equal to the previous frame's time"),
            std::string::npos);
  EXPECT_NE(error("gripper_actuator: grip\ngripper_joint: finger\n"
                  "frames: [{t: 1, q: [0, 0, 0, -1, 0, 0, 0]}]\n")
                .find("frames[0].gripper: missing"),
            std::string::npos);
  EXPECT_NE(
      error("gripper_actuator: grip\nframes: [{t: 1, key: home}]\n").find("gripper_joint: missing"),
      std::string::npos);
  // a key that the model does not have fails at initialisation, listing it
  EXPECT_NE(error("frames: [{t: 1, key: home}, {t: 2, key: wave}]\n")
                .find("frames[1].key: keyframe 'a/wave' (existing keyframe names: 'a/home', "
                      "'a/bent')"),
            std::string::npos);
}

class JointCsv : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = std::filesystem::temp_directory_path() /
           ("penumbra_joint_csv_" +
            std::string(::testing::UnitTest::GetInstance()->current_test_info()->name()));
    std::filesystem::create_directories(dir_);
  }
  void TearDown() override { std::filesystem::remove_all(dir_); }
  std::string Write(const std::string& text) {
    const std::string path = (dir_ / "m.csv").string();
    std::ofstream(path) << text;
    return path;
  }
  std::string Error(const std::string& text) {
    const std::string path = Write(text);
    return ErrorOf([&] { ReadJointCsv(path, {"j1", "j2"}, "finger"); });
  }
  std::filesystem::path dir_;
};

TEST_F(JointCsv, ReadsColumnsByName) {
  const std::string path =
      Write("# comment\ntime_sec, finger, j2, j1\n0, 0.04, 2, 1\n\n0.5, 0, 4, 3\n");
  const auto frames = ReadJointCsv(path, {"j1", "j2"}, "finger");
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[1].time_sec, 0.5);
  EXPECT_EQ(frames[1].q, (std::vector<double>{3, 4}));
  EXPECT_EQ(*frames[0].gripper, 0.04);
}

TEST_F(JointCsv, ErrorsNameTheFileAndLine) {
  const std::string path = (dir_ / "m.csv").string();
  EXPECT_EQ(Error("time_sec,j1\n0,1\n"),
            path +
                ":1: missing column(s) 'j2', 'finger'; expected the header "
                "'time_sec,j1,j2,finger' (joint columns in any order)");
  EXPECT_NE(Error("time_sec,j1,j2,finger,j9\n").find(":1: unknown column(s) 'j9'"),
            std::string::npos);
  EXPECT_NE(Error("t,j1,j2,finger\n").find(":1: first column is 't'; expected time_sec"),
            std::string::npos);
  EXPECT_EQ(Error("time_sec,j1,j2,finger\n0,1,2,0\n\n0.5,1,x,0\n"),
            path + ":4: column 'j2': got 'x'; expected a finite number");
  EXPECT_NE(
      Error("time_sec,j1,j2,finger\n0,1,2,0\n0,1,2,0\n").find(":3: time_sec does not increase"),
      std::string::npos);
  EXPECT_NE(Error("time_sec,j1,j2,finger\n0,1,2\n").find(":2: got 3 values; expected 4"),
            std::string::npos);
  EXPECT_NE(Error("time_sec,j1,j2,finger\n").find("no data rows"), std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              ReadJointCsv((dir_ / "none.csv").string(), {"j1"}, "");
            }).find("CSV file not found"),
            std::string::npos);
}

// a FIFO named as the CSV blocked open() for ever; it is refused at once naming what it is
TEST_F(JointCsv, AFifoOrAFolderIsRefusedWithoutBlocking) {
  const std::string fifo = (dir_ / "fifo.csv").string();
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  EXPECT_NE(ErrorOf([&] {
              ReadJointCsv(fifo, {"j1"}, "");
            }).find("CSV file is not a regular file (a FIFO); expected a regular file"),
            std::string::npos);
  EXPECT_NE(ErrorOf([&] {
              ReadJointCsv(dir_.string(), {"j1"}, "");
            }).find("CSV file is a directory; expected a regular file"),
            std::string::npos);
}

}  // namespace
}  // namespace penumbra

// the waypoint follower's control law against a fake ControlInput, and name
// resolution through Controller::Initialize.

#include "penumbra/control/waypoint_follower.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// model: world, chassis (1); joints: left (0), right (1) hinges; actuators l (0), r (1)
ModelInfo RoverModel() {
  ModelInfo m;
  m.nq = 2;
  m.nv = 2;
  m.nu = 3;
  m.body_names = {"world", "r/chassis"};
  m.body_parent = {-1, 0};
  m.joints.resize(2);
  m.joints[0].name = "r/left_joint";
  m.joints[1].name = "r/right_joint";
  m.joints[0].body = m.joints[1].body = 1;
  m.actuators.resize(3);
  m.actuators[0].name = "r/other";
  m.actuators[1].name = "r/left";
  m.actuators[1].joint = 0;
  m.actuators[2].name = "r/right";
  m.actuators[2].joint = 1;
  return m;
}

// only X_WB of the chassis matters to the follower
class FakeInput final : public ControlInput {
 public:
  explicit FakeInput(const ModelInfo& m) : model_(m) {}
  void Set(double x, double y, double yaw_deg) {
    X_ = PoseFromXyzRpyDeg(Eigen::Vector3d(x, y, 0.05), Eigen::Vector3d(0, 0, yaw_deg));
  }
  double time_sec() const override { return 0; }
  const ModelInfo& model() const override { return model_; }
  std::span<const double> qpos() const override { return {}; }
  std::span<const double> qvel() const override { return {}; }
  std::span<const double> sensordata() const override { return {}; }
  Pose X_WB(int body) const override { return body == 1 ? X_ : Pose::Identity(); }
  Twist V_WB(int) const override { return Twist::Zero(); }
  void Jacobian(int, const Eigen::Vector3d&,
                Eigen::Matrix<double, 6, Eigen::Dynamic>*) const override {}

 private:
  const ModelInfo& model_;
  Pose X_ = Pose::Identity();
};

WaypointFollowerParams Params(std::vector<Eigen::Vector2d> wps, bool loop) {
  WaypointFollowerParams p;
  p.base_body = "r/chassis";
  p.left_actuator = "r/left";
  p.right_actuator = "r/right";
  p.wheel_radius_m = 0.05;
  p.track_width_m = 0.3;
  p.speed_m_s = 0.5;
  p.max_yaw_rate_deg_s = 90;
  p.waypoints = std::move(wps);
  p.loop = loop;
  p.tolerance_m = 0.15;
  return p;
}

class WaypointFollowerTest : public ::testing::Test {
 protected:
  WaypointFollowerTest() : model_(RoverModel()), input_(model_) {}
  std::unique_ptr<WaypointFollower> Make(std::vector<Eigen::Vector2d> wps, bool loop) {
    auto f = std::make_unique<WaypointFollower>(
        Params(std::move(wps), loop), ControllerContext{"w.yaml", 3, "robots[r].controller"});
    f->Initialize(model_);
    return f;
  }
  // runs one update at pose (x, y, yaw) and returns ctrl
  std::vector<double> Run(WaypointFollower& f, double x, double y, double yaw_deg) {
    input_.Set(x, y, yaw_deg);
    std::vector<double> ctrl(3, 7.0);
    f.Compute(input_, ctrl);
    EXPECT_EQ(ctrl[0], 7.0) << "touched another actuator";
    return ctrl;
  }
  ModelInfo model_;
  FakeInput input_;
};

TEST_F(WaypointFollowerTest, StraightAheadDrivesBothWheelsAtCruiseSpeed) {
  auto f = Make({{2, 0}}, false);
  const auto ctrl = Run(*f, 0, 0, 0);
  EXPECT_NEAR(ctrl[1], 0.5 / 0.05, 1e-12);
  EXPECT_NEAR(ctrl[2], 0.5 / 0.05, 1e-12);
  EXPECT_NEAR(f->commanded_yaw_rate(), 0, 1e-12);
}

TEST_F(WaypointFollowerTest, PurePursuitCurvatureAndDifferentialKinematics) {
  auto f = Make({{1, 1}}, false);
  Run(*f, 0, 0, 0);  // alpha = 45 deg, d = sqrt(2): kappa = 2 sin(45) / sqrt(2) = 1 / m
  const double v = f->commanded_speed_m_s(), w = f->commanded_yaw_rate();
  // v kappa = 0.5 rad/s < 90 deg/s: cruise speed kept
  EXPECT_NEAR(v, 0.5, 1e-12);
  EXPECT_NEAR(w, 0.5, 1e-12);
  const auto ctrl = Run(*f, 0, 0, 0);
  EXPECT_NEAR(ctrl[1], (v - w * 0.15) / 0.05, 1e-12);  // left slower when turning left
  EXPECT_NEAR(ctrl[2], (v + w * 0.15) / 0.05, 1e-12);
}

TEST_F(WaypointFollowerTest, YawRateLimitReducesSpeed) {
  auto f = Make({{0.2, 0.2}}, false);  // kappa = 2 sin(45) / 0.283 = 5 / m
  Run(*f, 0, 0, 0);
  EXPECT_NEAR(std::abs(f->commanded_yaw_rate()), M_PI / 2, 1e-9);
  EXPECT_NEAR(f->commanded_speed_m_s(), (M_PI / 2) / 5.0, 1e-9);
}

TEST_F(WaypointFollowerTest, TargetBehindTurnsInPlaceTowardsIt) {
  auto f = Make({{-1, -0.5}}, false);
  auto ctrl = Run(*f, 0, 0, 0);  // target at -153 deg: turn right (clockwise)
  EXPECT_EQ(f->commanded_speed_m_s(), 0);
  EXPECT_NEAR(f->commanded_yaw_rate(), -M_PI / 2, 1e-12);
  EXPECT_NEAR(ctrl[1], -ctrl[2], 1e-12);
  EXPECT_GT(ctrl[1], 0);
  // heading wraps: at yaw 170 deg the target at -153 deg is 37 deg to the left
  Run(*f, 0, 0, 170);
  EXPECT_GT(f->commanded_yaw_rate(), 0);
  EXPECT_GT(f->commanded_speed_m_s(), 0);
}

TEST_F(WaypointFollowerTest, AdvancesStopsAndLoops) {
  auto once = Make({{1, 0}, {1, 1}}, false);
  Run(*once, 0, 0, 0);
  EXPECT_EQ(once->target_index(), 0);
  Run(*once, 0.9, 0.05, 0);  // within 0.15 of (1, 0)
  EXPECT_EQ(once->target_index(), 1);
  EXPECT_EQ(once->waypoints_reached(), 1);
  EXPECT_FALSE(once->finished());
  auto ctrl = Run(*once, 1.0, 0.95, 90);
  EXPECT_TRUE(once->finished());
  EXPECT_EQ(ctrl[1], 0);
  EXPECT_EQ(ctrl[2], 0);
  ctrl = Run(*once, 0, 0, 0);  // stays finished
  EXPECT_EQ(ctrl[1], 0);

  auto looping = Make({{1, 0}, {1, 1}}, true);
  Run(*looping, 0.95, 0, 0);
  Run(*looping, 1.0, 0.95, 90);
  EXPECT_FALSE(looping->finished());
  EXPECT_EQ(looping->target_index(), 0);
  EXPECT_EQ(looping->waypoints_reached(), 2);
  // every waypoint within tolerance: at most one lap per update
  auto tiny = Make({{0, 0}, {0.01, 0}}, true);
  Run(*tiny, 0, 0, 0);
  EXPECT_EQ(tiny->waypoints_reached(), 2);
}

TEST_F(WaypointFollowerTest, TrackingErrorIsTheDistanceFromTheSegmentFollowed) {
  auto f = Make({{2, 0}, {2, 2}}, false);
  ASSERT_EQ(f->tracking_error_labels(),
            (std::vector<std::string>{"cross_track_m", "goal_distance_m"}));
  std::vector<double> e;
  f->AppendTrackingError(&e);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_TRUE(std::isnan(e[0])) << "no update yet";
  // the first segment runs from the start position (0, 0) to (2, 0)
  Run(*f, 0, 0, 0);
  Run(*f, 1, 0.3, 0);
  e.clear();
  f->AppendTrackingError(&e);
  EXPECT_NEAR(e[0], 0.3, 1e-12);
  EXPECT_NEAR(e[1], std::hypot(1.0, 0.3), 1e-12);
  // past the first waypoint: the segment (2, 0) -> (2, 2)
  Run(*f, 1.95, 0.05, 90);
  Run(*f, 1.6, 1.0, 90);
  e.clear();
  f->AppendTrackingError(&e);
  EXPECT_NEAR(e[0], 0.4, 1e-12);
  EXPECT_NEAR(e[1], std::hypot(0.4, 1.0), 1e-12);
}

TEST_F(WaypointFollowerTest, InitializeListsAllMissingNames) {
  WaypointFollowerParams p = Params({{1, 0}}, false);
  p.base_body = "r/base";
  p.right_actuator = "r/rightt";
  WaypointFollower f(p, ControllerContext{"w.yaml", 3, "robots[r].controller"});
  try {
    f.Initialize(model_);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_EQ(e.line(), 3);
    EXPECT_NE(msg.find("base_body: body 'r/base'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("right_actuator: actuator 'r/rightt'"), std::string::npos) << msg;
    EXPECT_EQ(msg.find("'r/left' ("), std::string::npos) << msg;  // present, not reported
    EXPECT_NE(msg.find("'r/right'"), std::string::npos) << msg;   // listed as existing
  }
}

TEST_F(WaypointFollowerTest, ActuatorOnNonHingeIsRejected) {
  model_.joints[1].type = JointInfo::Type::kSlide;
  WaypointFollower f(Params({{1, 0}}, false),
                     ControllerContext{"w.yaml", 3, "robots[r].controller"});
  try {
    f.Initialize(model_);
    FAIL() << "expected ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "robots[r].controller.right_actuator");
  }
}

TEST(WaypointFollowerParams, ValidateOrThrowChecksRanges) {
  WaypointFollowerParams p = Params({{1, 0}}, true);
  const ControllerContext c{"w.yaml", 2, "robots[x].controller"};
  EXPECT_NO_THROW(p.ValidateOrThrow(c));
  p.speed_m_s = 0;
  EXPECT_THROW(p.ValidateOrThrow(c), ConfigError);
  p = Params({}, true);
  EXPECT_THROW(p.ValidateOrThrow(c), ConfigError);
  p = Params({{1, 0}}, true);
  p.waypoints[0].x() = std::nan("");
  EXPECT_THROW(p.ValidateOrThrow(c), ConfigError);
  EXPECT_THROW(WaypointFollower(p, c), ConfigError);
}

TEST(ModelInfo, FindAndNames) {
  const ModelInfo m = RoverModel();
  EXPECT_EQ(m.Find(ModelObject::kBody, "r/chassis"), 1);
  EXPECT_EQ(m.Find(ModelObject::kActuator, "r/right"), 2);
  EXPECT_EQ(m.Find(ModelObject::kJoint, "r/left_joint"), 0);
  EXPECT_EQ(m.Find(ModelObject::kSensor, "x"), -1);
  EXPECT_EQ(m.Find(ModelObject::kBody, ""), -1);
  EXPECT_EQ(m.Names(ModelObject::kActuator),
            (std::vector<std::string>{"r/other", "r/left", "r/right"}));
  EXPECT_STREQ(ModelObjectName(ModelObject::kSite), "site");
}

}  // namespace
}  // namespace penumbra

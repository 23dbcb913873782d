// the bundled quadrotor (worlds/models/quadrotor.xml) flown by the multirotor_pid controller
// from a ground plane, configured through the factory as a world file would.
// acceptance: takeoff to 1.5 m and hold within 3 cm RMS for 10 s (in a steady 5 m/s wind the
// controller does not know about); a 4 m square of waypoints at 1 m/s with cross-track
// error < 0.15 m; bit-identical trajectories on two runs.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>

#include "penumbra/config/yaml_document.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/control/multirotor_pid.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

const std::string kModels = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/models/";

// the bundled model (unprefixed names) over a ground plane at z = 0; `option_attrs` (e.g. a
// wind) go into <option>.
Simulation LoadOnGround(const std::string& option_attrs = "") {
  const std::string xml = R"(<mujoco model="quadrotor_test">
  <option )" + option_attrs +
                          R"(/>
  <include file="quadrotor.xml"/>
  <worldbody>
    <geom name="ground" type="plane" size="20 20 0.1"/>
  </worldbody>
</mujoco>)";
  return Simulation::LoadFromString(xml, std::nullopt, kModels);
}

constexpr const char* kBaseParams = R"(type: multirotor_pid
base_body: base
rotor_actuators: [thrust_fr, thrust_rl, thrust_fl, thrust_rr]
)";

MultirotorPid* AddPid(Simulation* sim, const std::string& extra_yaml) {
  ControllerConfig cfg;
  cfg.type = "multirotor_pid";
  cfg.line = 20;
  cfg.params = ParseYaml(std::string(kBaseParams) + extra_yaml);
  std::unique_ptr<Controller> c = MakeController(cfg, "", "quadrotor.yaml");
  auto* pid = dynamic_cast<MultirotorPid*>(c.get());
  sim->AddController(std::move(c));
  return pid;
}

Eigen::Vector3d BasePosition(const Simulation& sim) {
  // the drone's free joint is the model's only joint: qpos[0..3) = base origin
  return Eigen::Vector3d(sim.qpos()[0], sim.qpos()[1], sim.qpos()[2]);
}

// distance from p to the segment a-b
double DistanceToSegment(const Eigen::Vector3d& p, const Eigen::Vector3d& a,
                         const Eigen::Vector3d& b) {
  const Eigen::Vector3d ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / ab.squaredNorm(), 0.0, 1.0);
  return (p - (a + t * ab)).norm();
}

TEST(QuadrotorFlight, TakesOffAndHoldsPositionInWind) {
  // a steady 5 m/s wind from the south-west, air density 1.225 kg/m^3: MuJoCo's fluid model
  // drags the airframe (about 0.1 N); only the velocity integrators can cancel it
  Simulation sim = LoadOnGround(R"(density="1.225" viscosity="1.8e-5" wind="3.5 3.5 0")");
  MultirotorPid* pid = AddPid(&sim, "commands: [{t: 0, mode: takeoff, altitude_m: 1.5}]\n");
  const Eigen::Vector3d target(0, 0, 1.5);
  double max_z = 0;
  double reached_at = -1;
  while (sim.time() < 8.0) {
    sim.Step();
    const Eigen::Vector3d p = BasePosition(sim);
    max_z = std::max(max_z, p.z());
    if (reached_at < 0 && std::abs(p.z() - 1.5) < 0.05) reached_at = sim.time();
  }
  // hold: 10 s from t = 8 s
  double sum_sq = 0, max_err = 0;
  int n = 0;
  while (sim.time() < 18.0) {
    sim.Step();
    const double e = (BasePosition(sim) - target).norm();
    sum_sq += e * e;
    max_err = std::max(max_err, e);
    ++n;
  }
  const double rms = std::sqrt(sum_sq / n);
  std::printf(
      "takeoff: within 5 cm of 1.5 m at t = %.2f s, overshoot %.1f mm; hold 10 s in wind: "
      "RMS %.2f mm, max %.2f mm\n",
      reached_at, 1000 * (max_z - 1.5), 1000 * rms, 1000 * max_err);
  EXPECT_GT(reached_at, 0);
  EXPECT_LT(reached_at, 4.0);
  EXPECT_LT(max_z, 1.6);
  EXPECT_LT(rms, 0.03);
  EXPECT_EQ(pid->mode(), MultirotorCommand::Mode::kTakeoff);
}

TEST(QuadrotorFlight, FliesAWaypointSquareOnTheLines) {
  Simulation sim = LoadOnGround();
  MultirotorPid* pid = AddPid(&sim, R"(commands:
  - {t: 0, mode: takeoff, altitude_m: 1.5}
  - {t: 5, mode: waypoints, speed_m_s: 1.0,
     waypoints: [[4, 0, 1.5], [4, 4, 1.5], [0, 4, 1.5], [0, 0, 1.5]]}
)");
  const std::vector<Eigen::Vector3d> corners = {
      {0, 0, 1.5}, {4, 0, 1.5}, {4, 4, 1.5}, {0, 4, 1.5}, {0, 0, 1.5}};
  while (sim.time() < 5.0) sim.Step();
  double max_cross = 0, max_speed = 0;
  size_t next = 1;  // next corner to pass within 0.1 m
  std::vector<double> corner_time;
  while (sim.time() < 30.0) {
    sim.Step();
    const Eigen::Vector3d p = BasePosition(sim);
    double cross = 1e9;
    for (size_t k = 0; k + 1 < corners.size(); ++k)
      cross = std::min(cross, DistanceToSegment(p, corners[k], corners[k + 1]));
    max_cross = std::max(max_cross, cross);
    max_speed =
        std::max(max_speed, Eigen::Vector3d(sim.qvel()[0], sim.qvel()[1], sim.qvel()[2]).norm());
    if (next < corners.size() && (p - corners[next]).norm() < 0.1) {
      corner_time.push_back(sim.time());
      ++next;
    }
  }
  std::printf("square: max cross-track %.1f mm, max speed %.3f m/s, corners at", 1000 * max_cross,
              max_speed);
  for (double t : corner_time) std::printf(" %.2f", t);
  std::printf(" s\n");
  ASSERT_EQ(corner_time.size(), 4u);
  EXPECT_LT(max_cross, 0.15);
  EXPECT_GT(max_speed, 0.95);
  EXPECT_LT(max_speed, 1.15);
  EXPECT_TRUE(pid->path_finished());
  EXPECT_LT((BasePosition(sim) - corners[0]).norm(), 0.03);
}

// one flight of takeoff then a waypoint leg with a heading change; every qpos of every step
std::vector<double> RecordFlight(double seconds) {
  Simulation sim = LoadOnGround(R"(density="1.225" viscosity="1.8e-5" wind="2 -1 0")");
  AddPid(&sim, R"(commands:
  - {t: 0, mode: takeoff, altitude_m: 1.2}
  - {t: 3, mode: waypoints, waypoints: [[1, 1, 1.5], [0, 1, 1]], speed_m_s: 1.5, face_path: true}
)");
  std::vector<double> trace;
  while (sim.time() < seconds) {
    sim.Step();
    trace.insert(trace.end(), sim.qpos().begin(), sim.qpos().end());
  }
  return trace;
}

TEST(QuadrotorFlight, TwoRunsAreBitIdentical) {
  const std::vector<double> a = RecordFlight(6.0);
  const std::vector<double> b = RecordFlight(6.0);
  ASSERT_EQ(a.size(), b.size());
  size_t differing = 0;
  for (size_t i = 0; i < a.size(); ++i)
    if (std::memcmp(&a[i], &b[i], sizeof(double)) != 0) ++differing;
  EXPECT_EQ(differing, 0u);
  // it did fly: the last recorded position is up and away from the start
  const size_t last = a.size() - 7;
  EXPECT_GT(a[last + 2], 0.8);
}

TEST(QuadrotorFlight, WrongRotorNamesFailAtLoadListingThem) {
  Simulation sim = LoadOnGround();
  ControllerConfig cfg;
  cfg.type = "multirotor_pid";
  cfg.line = 14;
  cfg.params = ParseYaml(R"(base_body: base
rotor_actuators: [thrust_fr, motor_rl, thrust_fl, motor_rr]
commands: [{t: 0, mode: takeoff, altitude_m: 1.5}]
)");
  std::unique_ptr<Controller> c = MakeController(cfg, "", "quadrotor.yaml");
  try {
    sim.AddController(std::move(c));
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    const std::string msg = e.what();
    EXPECT_NE(msg.find("quadrotor.yaml:14"), std::string::npos) << msg;
    EXPECT_NE(msg.find("2 names not found"), std::string::npos) << msg;
    EXPECT_NE(msg.find("rotor_actuators[1]: actuator 'motor_rl'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("rotor_actuators[3]: actuator 'motor_rr'"), std::string::npos) << msg;
    EXPECT_NE(msg.find("'thrust_rl'"), std::string::npos) << msg;  // existing names as a hint
    EXPECT_EQ(msg.find("'thrust_fr' ("), std::string::npos) << msg;
  }
}

TEST(QuadrotorFlight, BadCommandsFailAtParseNamingTheKey) {
  auto error = [](const std::string& extra, bool base = true) {
    ControllerConfig cfg;
    cfg.type = "multirotor_pid";
    cfg.line = 9;
    cfg.params =
        ParseYaml((base ? std::string(kBaseParams) : std::string("base_body: base\n")) + extra);
    try {
      MakeController(cfg, "drone", "w.yaml");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_EQ(error("commands: [{t: 0, mode: takeoff}]\n"),
            "w.yaml:9: robots[drone].controller.commands[0].altitude_m: missing; expected the "
            "target altitude (world z, m)");
  EXPECT_EQ(error("commands: [{t: 0, mode: loop}]\n"),
            "w.yaml:9: robots[drone].controller.commands[0].mode: got 'loop'; expected one of "
            "idle, takeoff, hover, waypoints, velocity, land");
  EXPECT_EQ(error("commands: [{t: 0, mode: hover, altitude_m: 2}]\n"),
            "w.yaml:9: robots[drone].controller.commands[0].altitude_m: unknown key for mode "
            "hover; expected only: t, mode, position, speed_m_s, yaw_deg");
  EXPECT_EQ(error("commands: [{t: 2, mode: idle}, {t: 1, mode: idle}]\n"),
            "w.yaml:9: robots[drone].controller.commands[1].t: got 1, before the previous "
            "command's t = 2; expected non-decreasing times");
  EXPECT_EQ(error("commands: [{t: 0, mode: waypoints, waypoints: [[1, 2]]}]\n"),
            "w.yaml:9: robots[drone].controller.commands[0].waypoints[0]: got a list of 2 items; "
            "expected [x, y, z] (world, m)");
  EXPECT_EQ(error("max_tilt_deg: 90\n"),
            "w.yaml:9: robots[drone].controller.max_tilt_deg: got 90; expected a number > 0 and "
            "<= 80");
  EXPECT_EQ(
      error("velocity_p_xy: 2\nvelocity_gain: 3\n"),
      "w.yaml:9: robots[drone].controller.velocity_gain: unknown key(s) 'velocity_gain'; "
      "expected only: attitude_p_roll_pitch, attitude_p_yaw, base_body, commands, "
      "derivative_cutoff_hz, gravity_m_s2, land_speed_m_s, leash_m, max_accel_m_s2, "
      "max_climb_m_s, max_descent_m_s, max_jerk_m_s3, max_roll_pitch_rate_deg_s, max_speed_xy_m_s, "
      "max_tilt_deg, "
      "max_yaw_rate_deg_s, position_p_xy, position_p_z, rate_d_roll_pitch, rate_d_yaw, "
      "rate_hz, rate_i_limit_rad_s2, rate_i_roll_pitch, rate_i_yaw, rate_p_roll_pitch, "
      "rate_p_yaw, rotor_actuators, type, velocity_d_xy, velocity_d_z, velocity_i_limit_m_s2, "
      "velocity_i_xy, velocity_i_z, velocity_p_xy, velocity_p_z, yaw_speed_deg_s");
  EXPECT_EQ(error("rotor_actuators: [a, b, c]\n", false),
            "w.yaml:9: robots[drone].controller.rotor_actuators: got a list of 3 items; expected "
            "a list of at least 4 rotor actuator names, e.g. [thrust_fr, thrust_rl, thrust_fl, "
            "thrust_rr]");
  EXPECT_EQ(error("rotor_actuators: [a, b, c, a]\n", false),
            "w.yaml:9: robots[drone].controller.rotor_actuators[3]: actuator 'drone/a' listed "
            "twice; expected each rotor once");
}

TEST(QuadrotorFlight, VelocityModeAndProgrammaticCommands) {
  Simulation sim = LoadOnGround();
  MultirotorPid* pid = AddPid(&sim, "commands: [{t: 0, mode: takeoff, altitude_m: 1.0}]\n");
  while (sim.time() < 3.0) sim.Step();
  // cmd_vel style: 1 m/s forward in the heading frame while turning at 30 deg/s
  MultirotorCommand cmd;
  cmd.mode = MultirotorCommand::Mode::kVelocity;
  cmd.frame = MultirotorCommand::Frame::kHeading;
  cmd.velocity_m_s = {1.0, 0, 0};
  cmd.yaw_rate_deg_s = 30;
  pid->SetCommand(cmd);
  double min_speed = 1e9, max_speed = 0;
  while (sim.time() < 9.0) {
    sim.Step();
    if (sim.time() > 5.0) {
      const double v = Eigen::Vector2d(sim.qvel()[0], sim.qvel()[1]).norm();
      min_speed = std::min(min_speed, v);
      max_speed = std::max(max_speed, v);
    }
  }
  // 6 s at 30 deg/s: the heading turned by 180 deg (from 0 to pi)
  const Eigen::Quaterniond q(sim.qpos()[3], sim.qpos()[4], sim.qpos()[5], sim.qpos()[6]);
  const Eigen::Vector3d nose = q * Eigen::Vector3d::UnitX();
  const double yaw = std::atan2(nose.y(), nose.x());
  std::printf("velocity mode: speed in [%.3f, %.3f] m/s, yaw after 6 s %.1f deg\n", min_speed,
              max_speed, yaw * 180 / M_PI);
  EXPECT_GT(min_speed, 0.95);
  EXPECT_LT(max_speed, 1.05);
  EXPECT_NEAR(std::abs(yaw), M_PI, 2 * M_PI / 180);
  // the body moves along its nose: velocity along the heading
  const Eigen::Vector2d v(sim.qvel()[0], sim.qvel()[1]);
  EXPECT_GT(v.dot(nose.head<2>()) / v.norm(), 0.99);

  // stop: zero velocity holds where the vehicle stopped
  cmd.velocity_m_s.setZero();
  cmd.yaw_rate_deg_s = 0;
  pid->SetCommand(cmd);
  while (sim.time() < 11.0) sim.Step();
  const Eigen::Vector3d stopped = BasePosition(sim);
  while (sim.time() < 14.0) sim.Step();
  EXPECT_LT((BasePosition(sim) - stopped).norm(), 0.01);
  EXPECT_NEAR(BasePosition(sim).z(), 1.0, 0.01);

  // hover at a given position with a heading
  cmd = MultirotorCommand();
  cmd.mode = MultirotorCommand::Mode::kHover;
  cmd.position = Eigen::Vector3d(0, 0, 2.0);
  cmd.yaw_deg = 90;
  cmd.speed_m_s = 2.0;
  pid->SetCommand(cmd);
  while (sim.time() < 24.0) sim.Step();
  EXPECT_LT((BasePosition(sim) - Eigen::Vector3d(0, 0, 2.0)).norm(), 0.01);
  const Eigen::Quaterniond q2(sim.qpos()[3], sim.qpos()[4], sim.qpos()[5], sim.qpos()[6]);
  const Eigen::Vector3d nose2 = q2 * Eigen::Vector3d::UnitX();
  EXPECT_NEAR(std::atan2(nose2.y(), nose2.x()), M_PI / 2, 1e-2);

  // land: 2 m down at 0.5 m/s, touchdown detected, rotors stopped
  cmd = MultirotorCommand();
  cmd.mode = MultirotorCommand::Mode::kLand;
  pid->SetCommand(cmd);
  double landed_at = -1, min_vz = 0;
  while (sim.time() < 32.0) {
    sim.Step();
    min_vz = std::min(min_vz, sim.qvel()[2]);
    if (landed_at < 0 && pid->mode() == MultirotorCommand::Mode::kIdle) landed_at = sim.time();
  }
  std::printf("land: touchdown detected at %.2f s after the command, fastest descent %.3f m/s\n",
              landed_at - 24.0, -min_vz);
  EXPECT_GT(landed_at - 24.0, 3.5);  // 1.9 m at 0.5 m/s
  EXPECT_LT(landed_at - 24.0, 5.5);
  EXPECT_GT(min_vz, -0.6);
  EXPECT_NEAR(BasePosition(sim).z(), 0.085, 0.005);  // standing on its feet
  EXPECT_LT((BasePosition(sim).head<2>()).norm(), 0.02);
  for (double f : pid->rotor_thrust_n()) EXPECT_EQ(f, 0.0);

  // invalid programmatic commands are rejected
  cmd = MultirotorCommand();
  cmd.mode = MultirotorCommand::Mode::kWaypoints;
  EXPECT_THROW(pid->SetCommand(cmd), ConfigError);
}

// a test-only disturbance: from t0 for `duration` it overrides the rotor ctrl written by the
// controllers before it with a violent pattern (one front rotor at full thrust, the others
// off), as a motor glitch would
class RotorGlitch final : public Controller {
 public:
  RotorGlitch(double t0, double duration) : Controller({}), t0_(t0), t1_(t0 + duration) {}
  std::string type() const override { return "rotor_glitch"; }
  double rate_hz() const override { return 0; }
  std::vector<NameRequirement> RequiredNames() const override {
    std::vector<NameRequirement> r;
    for (const char* n : {"thrust_fr", "thrust_rl", "thrust_fl", "thrust_rr"})
      r.push_back({ModelObject::kActuator, n, ""});
    return r;
  }
  void Reset() override {}  // no memory
  void Compute(const ControlInput& input, std::span<double> ctrl) override {
    if (input.time_sec() < t0_ || input.time_sec() >= t1_) return;
    for (size_t i = 0; i < ids_.size(); ++i) ctrl[ids_[i]] = i == 0 ? 7.0 : 0.0;
  }

 protected:
  void OnInitialize(const ModelInfo&, const std::vector<int>& ids) override { ids_ = ids; }

 private:
  double t0_, t1_;
  std::vector<int> ids_;
};

TEST(QuadrotorFlight, RecoversFromAnUpsetWithSaturatedRotors) {
  Simulation sim = LoadOnGround();
  MultirotorPid* pid = AddPid(&sim, "commands: [{t: 0, mode: takeoff, altitude_m: 3.0}]\n");
  sim.AddController(std::make_unique<RotorGlitch>(5.0, 0.25));
  const Eigen::Vector3d hold(0, 0, 3.0);
  double max_tilt = 0, min_z = 10, min_rp_scale = 1, recovered_at = -1, upright_at = -1;
  bool saw_collective_limit = false;
  while (sim.time() < 12.0) {
    sim.Step();
    const Eigen::Quaterniond q(sim.qpos()[3], sim.qpos()[4], sim.qpos()[5], sim.qpos()[6]);
    const double tilt = std::acos(std::clamp((q * Eigen::Vector3d::UnitZ()).z(), -1.0, 1.0));
    const Eigen::Vector3d p = BasePosition(sim);
    if (sim.time() > 5.0) {
      max_tilt = std::max(max_tilt, tilt);
      min_z = std::min(min_z, p.z());
      if (tilt > 10 * M_PI / 180) {
        upright_at = -1;
      } else if (upright_at < 0) {
        upright_at = sim.time();
      }
      min_rp_scale = std::min(min_rp_scale, pid->last_mix().roll_pitch_scale);
      saw_collective_limit |= pid->last_mix().collective_limited;
      if ((p - hold).norm() > 0.05)
        recovered_at = -1;
      else if (recovered_at < 0)
        recovered_at = sim.time();
    }
  }
  std::printf(
      "upset: max tilt %.0f deg, lowest %.2f m, roll/pitch scale down to %.2f, upright "
      "(< 10 deg) %.2f s and back within 5 cm %.2f s after the glitch ended, final error "
      "%.1f mm\n",
      max_tilt * 180 / M_PI, min_z, min_rp_scale, upright_at - 5.25, recovered_at - 5.25,
      1000 * (BasePosition(sim) - hold).norm());
  EXPECT_GT(max_tilt, 90 * M_PI / 180);  // a real upset
  EXPECT_GT(min_z, 1.0);                 // never near the ground
  EXPECT_LT(min_rp_scale, 1.0);          // the mixer had to scale roll/pitch down
  EXPECT_TRUE(saw_collective_limit);     // and move the collective
  EXPECT_GT(upright_at, 5.25);
  EXPECT_LT(upright_at, 6.75);
  EXPECT_GT(recovered_at, 0);
  EXPECT_LT(recovered_at, 10.0);
  EXPECT_LT((BasePosition(sim) - hold).norm(), 0.02);
}

}  // namespace
}  // namespace penumbra

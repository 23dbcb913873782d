// every number a controller reads from a world file has a finite upper bound
// (control/param_limits.h): a speed, gain, rate, time or target of 1e300 (or +-inf, nan) is
// refused at parse with "file:line: key path: got ...; expected ... <range>", for each
// controller type; values at the bounds are accepted.

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/config/yaml_document.h"
#include "penumbra/control/controller_factory.h"
#include "penumbra/control/keyframe_playback.h"
#include "penumbra/control/multirotor_pid.h"
#include "penumbra/control/param_limits.h"
#include "penumbra/control/waypoint_follower.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace param_bounds_test {
namespace {

using Keys = std::vector<std::pair<std::string, std::string>>;

// the keys a controller type needs besides the one under test
Keys Base(const std::string& type) {
  if (type == "waypoint_follower")
    return {{"base_body", "c"},         {"left_actuator", "l"},   {"right_actuator", "r"},
            {"wheel_radius_m", "0.05"}, {"track_width_m", "0.3"}, {"waypoints", "[[1.0, 0.0]]"}};
  if (type == "trot_gait")
    return {{"base_body", "trunk"},
            {"legs",
             "{FR: {hip: FR_h, thigh: FR_t, calf: FR_c, foot: FR_f}, "
             "FL: {hip: FL_h, thigh: FL_t, calf: FL_c, foot: FL_f}, "
             "RR: {hip: RR_h, thigh: RR_t, calf: RR_c, foot: RR_f}, "
             "RL: {hip: RL_h, thigh: RL_t, calf: RL_c, foot: RL_f}}"}};
  if (type == "joint_pd") return {{"joints", "[j1, j2]"}, {"actuators", "[a1, a2]"}};
  if (type == "diff_ik")
    return {{"joints", "[j1, j2]"},
            {"actuators", "[a1, a2]"},
            {"site", "ee"},
            {"gripper_actuator", "grip"}};
  if (type == "keyframe_playback")
    return {{"joints", "[j1, j2]"}, {"actuators", "[a1, a2]"}, {"frames", "[{t: 0, q: [0, 0]}]"}};
  if (type == "multirotor_pid") return {{"base_body", "base"}, {"rotor_actuators", "[a, b, c, d]"}};
  ADD_FAILURE() << type;
  return {};
}

// the base keys with `set` replacing or adding keys, one `key: value` line each
std::string Yaml(const std::string& type, const Keys& set) {
  Keys keys = Base(type);
  for (const auto& [k, v] : set) {
    bool replaced = false;
    for (auto& kv : keys)
      if (kv.first == k) {
        kv.second = v;
        replaced = true;
      }
    if (!replaced) keys.emplace_back(k, v);
  }
  std::string out;
  for (const auto& [k, v] : keys) out += k + ": " + v + "\n";
  return out;
}

std::unique_ptr<Controller> Make(const std::string& type, const std::string& yaml) {
  ControllerConfig c;
  c.type = type;
  c.params = ParseYaml(yaml);
  c.line = 21;
  return MakeController(c, "r", "worlds/w.yaml");
}

// the message of the ConfigError parsing `yaml` throws, or "" when it parses
std::string ErrorOf(const std::string& type, const std::string& yaml) {
  try {
    Make(type, yaml);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

std::string Sub(std::string s, const std::string& value) {
  for (size_t p = s.find('X'); p != std::string::npos; p = s.find('X', p + value.size()))
    s.replace(p, 1, value);
  return s;
}

struct Case {
  std::string type;
  Keys set;           // keys to set; 'X' in a value is the bad value
  std::string path;   // key path of the error, below robots[r].controller
  std::string range;  // text of the range the error names
};

// top-level number keys: (key, range text)
void AddScalars(std::vector<Case>* cases, const std::string& type, const Keys& extra,
                const std::vector<std::pair<std::string, std::string>>& keys) {
  for (const auto& [k, range] : keys) {
    Keys set = extra;
    set.emplace_back(k, "X");
    cases->push_back({type, set, k, range});
  }
}

std::vector<Case> Cases() {
  std::vector<Case> c;
  const std::string kLen = "<= 100000", kSpeed = "<= 100", kAng = "<= 36000", kGain = "<= 1e+06",
                    kRate = "<= 1e+06", kTime = "<= 1e+06";
  AddScalars(&c, "waypoint_follower", {},
             {{"wheel_radius_m", kLen},
              {"track_width_m", kLen},
              {"speed_m_s", kSpeed},
              {"max_yaw_rate_deg_s", kAng},
              {"tolerance_m", kLen},
              {"rate_hz", kRate}});
  c.push_back({"waypoint_follower",
               {{"waypoints", "[[1, 2], [X, 0.0]]"}},
               "waypoints[1]",
               "in [-100000, 100000]"});
  c.push_back({"waypoint_follower", {{"waypoints", "[[0.0, X]]"}}, "waypoints[0]", "100000"});

  // trot_gait, and the twist script it shares with the policy controller
  AddScalars(&c, "trot_gait", {},
             {{"body_height_m", kLen},
              {"max_step_m", kLen},
              {"max_accel_m_s2", "<= 10000"},
              {"max_yaw_accel_rad_s2", "<= 1e+06"},
              {"kp_xy", kGain},
              {"kd_xy", kGain},
              {"kp_z", kGain},
              {"kd_z", kGain},
              {"kp_tilt", kGain},
              {"kd_tilt", kGain},
              {"kp_yaw", kGain},
              {"kd_yaw", kGain},
              {"swing_kp", kGain},
              {"swing_kd", kGain},
              {"stance_kd", kGain},
              {"rate_hz", kRate}});
  AddScalars(&c, "trot_gait", {{"waypoints", "[[1.0, 0.0]]"}},
             {{"speed_m_s", kSpeed}, {"max_yaw_rate_deg_s", kAng}, {"tolerance_m", kLen}});
  c.push_back({"trot_gait", {{"waypoints", "[[X, 0.0]]"}}, "waypoints[0]", "100000"});
  c.push_back({"trot_gait", {{"hold", "{h: X}"}}, "hold.h", "in [-1e+09, 1e+09]"});
  c.push_back({"trot_gait", {{"commands", "[{t: X}]"}}, "commands[0].t", "in [0, 1e+06] (s)"});
  c.push_back(
      {"trot_gait", {{"commands", "[{t: 0, vx: X}]"}}, "commands[0].vx", "in [-100, 100] (m/s)"});
  c.push_back({"trot_gait", {{"commands", "[{t: 0, vy: X}]"}}, "commands[0].vy", "[-100, 100]"});
  c.push_back({"trot_gait",
               {{"commands", "[{t: 0, yaw_rate: X}]"}},
               "commands[0].yaw_rate",
               "in [-628.319, 628.319] (rad/s)"});
  {
    Keys legs = Base("trot_gait");
    std::string l = legs[1].second;
    l.replace(l.find("foot: FR_f"), 10, "foot: FR_f, offsets_rad: [0, X, 0]");
    c.push_back({"trot_gait", {{"legs", l}}, "legs.FR.offsets_rad[1]", "[-100000, 100000]"});
  }

  // joint servos (joint_pd, diff_ik and keyframe_playback share them) and joint_pd
  AddScalars(&c, "joint_pd", {},
             {{"kp", kGain},
              {"kd", kGain},
              {"max_velocity", "<= 10000"},
              {"max_acceleration", "<= 1e+06"},
              {"max_effort", "<= 1e+09"},
              {"limit_margin", kLen},
              {"rate_hz", kRate}});
  c.push_back({"joint_pd", {{"kp", "[1, X]"}}, "kp[1]", kGain});
  c.push_back({"joint_pd", {{"target", "[X, 0]"}}, "target[0]", kLen});
  c.push_back({"joint_pd", {{"commands", "[{t: X, q: [0, 0]}]"}}, "commands[0].t", kTime});
  c.push_back({"joint_pd", {{"commands", "[{t: 0, q: [0, X]}]"}}, "commands[0].q[1]", kLen});
  c.push_back(
      {"joint_pd", {{"commands", "[{t: 0, qd: [X, 0]}]"}}, "commands[0].qd[0]", "<= 10000"});
  c.push_back(
      {"joint_pd", {{"commands", "[{t: 0, tau: [X, 0]}]"}}, "commands[0].tau[0]", "<= 1e+09"});

  AddScalars(&c, "diff_ik", {},
             {{"position_gain", kGain},
              {"orientation_gain", kGain},
              {"damping", kGain},
              {"damping_max", kGain},
              {"manipulability_threshold", kGain},
              {"max_linear_speed_m_s", kSpeed},
              {"max_angular_speed_deg_s", kAng},
              {"speed_m_s", kSpeed},
              {"angular_speed_deg_s", kAng},
              {"posture_gain", kGain},
              {"limit_zone", kLen},
              {"limit_gain", kGain},
              {"max_tracking_error", kLen},
              {"limit_velocity_gain", kGain},
              {"gripper_open", "<= 1e+09"},
              {"gripper_closed", "<= 1e+09"},
              {"rate_hz", kRate}});
  c.push_back({"diff_ik", {{"gripper_initial", "X"}}, "gripper_initial", "[-1e+09, 1e+09]"});
  c.push_back({"diff_ik", {{"posture", "[0, X]"}}, "posture[1]", kLen});
  c.push_back(
      {"diff_ik", {{"commands", "[{t: X, move_to: {xyz: [0, 0, 0]}}]"}}, "commands[0].t", kTime});
  c.push_back({"diff_ik",
               {{"commands", "[{t: 0, move_to: {xyz: [X, 0, 0]}}]"}},
               "commands[0].move_to.xyz[0]",
               kLen});
  c.push_back({"diff_ik",
               {{"commands", "[{t: 0, move_by: {xyz: [0, 0, X]}}]"}},
               "commands[0].move_by.xyz[2]",
               kLen});
  c.push_back({"diff_ik",
               {{"commands", "[{t: 0, pose: {xyz: [0, X, 0]}}]"}},
               "commands[0].pose.xyz[1]",
               kLen});
  c.push_back({"diff_ik",
               {{"commands", "[{t: 0, move_to: {xyz: [0, 0, 0]}, speed_m_s: X}]"}},
               "commands[0].speed_m_s",
               kSpeed});
  c.push_back({"diff_ik",
               {{"commands", "[{t: 0, move_to: {xyz: [0, 0, 0]}, angular_speed_deg_s: X}]"}},
               "commands[0].angular_speed_deg_s",
               kAng});
  c.push_back({"diff_ik", {{"commands", "[{t: 0, gripper: X}]"}}, "commands[0].gripper", "1e+09"});

  AddScalars(&c, "keyframe_playback", {}, {{"rate_hz", kRate}});
  c.push_back({"keyframe_playback", {{"frames", "[{t: X, q: [0, 0]}]"}}, "frames[0].t", kTime});
  c.push_back({"keyframe_playback", {{"frames", "[{t: 0, q: [X, 0]}]"}}, "frames[0].q[0]", kLen});
  c.push_back({"keyframe_playback",
               {{"gripper_actuator", "g"},
                {"gripper_joint", "gj"},
                {"frames", "[{t: 0, q: [0, 0], gripper: X}]"}},
               "frames[0].gripper",
               kLen});

  AddScalars(&c, "multirotor_pid", {},
             {{"rate_hz", kRate},
              {"gravity_m_s2", "<= 10000"},
              {"max_speed_xy_m_s", kSpeed},
              {"max_climb_m_s", kSpeed},
              {"max_descent_m_s", kSpeed},
              {"max_accel_m_s2", "<= 10000"},
              {"max_jerk_m_s3", "<= 1e+06"},
              {"max_roll_pitch_rate_deg_s", kAng},
              {"max_yaw_rate_deg_s", kAng},
              {"yaw_speed_deg_s", kAng},
              {"leash_m", kLen},
              {"land_speed_m_s", kSpeed},
              {"position_p_xy", kGain},
              {"position_p_z", kGain},
              {"velocity_p_xy", kGain},
              {"velocity_i_xy", kGain},
              {"velocity_d_xy", kGain},
              {"velocity_p_z", kGain},
              {"velocity_i_z", kGain},
              {"velocity_d_z", kGain},
              {"velocity_i_limit_m_s2", "<= 10000"},
              {"attitude_p_roll_pitch", kGain},
              {"attitude_p_yaw", kGain},
              {"rate_p_roll_pitch", kGain},
              {"rate_i_roll_pitch", kGain},
              {"rate_d_roll_pitch", kGain},
              {"rate_p_yaw", kGain},
              {"rate_i_yaw", kGain},
              {"rate_d_yaw", kGain},
              {"rate_i_limit_rad_s2", "<= 1e+06"},
              {"derivative_cutoff_hz", kRate}});
  c.push_back({"multirotor_pid", {{"commands", "[{t: X, mode: idle}]"}}, "commands[0].t", kTime});
  c.push_back({"multirotor_pid",
               {{"commands", "[{t: 0, mode: takeoff, altitude_m: X}]"}},
               "commands[0].altitude_m",
               kLen});
  c.push_back({"multirotor_pid",
               {{"commands", "[{t: 0, mode: takeoff, altitude_m: 1, speed_m_s: X}]"}},
               "commands[0].speed_m_s",
               kSpeed});
  c.push_back({"multirotor_pid",
               {{"commands", "[{t: 0, mode: hover, yaw_deg: X}]"}},
               "commands[0].yaw_deg",
               kAng});
  c.push_back({"multirotor_pid",
               {{"commands", "[{t: 0, mode: hover, position: [X, 0, 1]}]"}},
               "commands[0].position[0]",
               kLen});
  c.push_back({"multirotor_pid",
               {{"commands", "[{t: 0, mode: waypoints, waypoints: [[0, 0, 1], [1, X, 1]]}]"}},
               "commands[0].waypoints[1][1]",
               kLen});
  c.push_back({"multirotor_pid",
               {{"commands", "[{t: 0, mode: velocity, velocity_m_s: [0, 0, X]}]"}},
               "commands[0].velocity_m_s[2]",
               kSpeed});
  c.push_back({"multirotor_pid",
               {{"commands", "[{t: 0, mode: velocity, yaw_rate_deg_s: X}]"}},
               "commands[0].yaw_rate_deg_s",
               kAng});
  return c;
}

// every case parses with a small value in place of X (so the refusal below is the value's),
// and 1e300, -1e300, +-inf and nan are refused naming the file, line, key path and range
TEST(ControllerParamBounds, HugeInfiniteAndNanValuesAreRefusedWithFileLineKeyAndRange) {
  const std::vector<Case> cases = Cases();
  ASSERT_GT(cases.size(), 100u);
  for (const Case& k : cases) {
    Keys ok = k.set;
    for (auto& kv : ok) kv.second = Sub(kv.second, "0.5");
    EXPECT_EQ(ErrorOf(k.type, Yaml(k.type, ok)), "") << k.type << " " << k.path;
    for (const std::string bad : {"1e300", "-1e300", ".inf", "-.inf", ".nan"}) {
      Keys set = k.set;
      for (auto& kv : set) kv.second = Sub(kv.second, bad);
      const std::string e = ErrorOf(k.type, Yaml(k.type, set));
      const std::string where = "worlds/w.yaml:21: robots[r].controller." + k.path + ": got ";
      EXPECT_EQ(e.rfind(where, 0), 0u) << k.type << " " << k.path << " = " << bad << ": " << e;
      EXPECT_NE(e.find(k.range), std::string::npos)
          << k.type << " " << k.path << " = " << bad << ": " << e << "\n(no '" << k.range << "')";
    }
  }
}

// the bounds themselves are accepted, just above them refused
TEST(ControllerParamBounds, ValuesAtTheBoundsAreAccepted) {
  auto wf = Make("waypoint_follower", Yaml("waypoint_follower", {{"speed_m_s", "100"},
                                                                 {"max_yaw_rate_deg_s", "36000"},
                                                                 {"rate_hz", "1e6"},
                                                                 {"waypoints", "[[-1e5, 1e5]]"}}));
  const auto& w = dynamic_cast<WaypointFollower&>(*wf).params();
  EXPECT_EQ(w.speed_m_s, kMaxParamSpeedMS);
  EXPECT_EQ(w.waypoints[0], Eigen::Vector2d(-1e5, 1e5));
  EXPECT_NE(ErrorOf("waypoint_follower", Yaml("waypoint_follower", {{"speed_m_s", "100.001"}}))
                .find("speed_m_s: got 100.001; expected a number > 0 and <= 100"),
            std::string::npos);

  auto mr = Make("multirotor_pid",
                 Yaml("multirotor_pid",
                      {{"max_speed_xy_m_s", "100"},
                       {"commands", "[{t: 1e6, mode: hover, position: [1e5, -1e5, 1e5]}]"}}));
  const auto& m = dynamic_cast<MultirotorPid&>(*mr).params();
  EXPECT_EQ(m.max_speed_xy_m_s, 100);
  ASSERT_EQ(m.commands.size(), 1u);
  EXPECT_EQ(m.commands[0].t_sec, kMaxParamTimeSec);
  EXPECT_EQ(ErrorOf("multirotor_pid", Yaml("multirotor_pid", {{"commands",
                                                               "[{t: 0, mode: hover, position: "
                                                               "[100001, 0, 1]}]"}})),
            "worlds/w.yaml:21: robots[r].controller.commands[0].position[0]: got 100001; "
            "expected a number >= -100000 and <= 100000");
}

// a keyframe CSV's times and joint values are bounded like a world file's frames
TEST(ControllerParamBounds, KeyframeCsvValuesAreBounded) {
  const std::filesystem::path dir =
      std::filesystem::temp_directory_path() / "penumbra_param_bounds_csv";
  std::filesystem::create_directories(dir);
  const std::string path = (dir / "m.csv").string();
  auto error = [&](const std::string& text) {
    std::ofstream(path) << text;
    try {
      ReadJointCsv(path, {"j1", "j2"}, "");
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_EQ(error("time_sec,j1,j2\n0,1,2\n1e6,-1e5,1e5\n"), "");
  EXPECT_EQ(error("time_sec,j1,j2\n0,1,2\n1e300,0,0\n"),
            path + ":3: time_sec 1e300 is out of range; expected a time in [0, 1e+06] (s)");
  EXPECT_EQ(error("time_sec,j1,j2\n0,1,2\n1,0,-1e300\n"),
            path +
                ":3: column 'j2': got -1e300; expected a joint value in [-100000, 100000] "
                "(rad or m)");
  std::filesystem::remove_all(dir);
}

}  // namespace
}  // namespace param_bounds_test
}  // namespace penumbra

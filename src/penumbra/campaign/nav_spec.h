#pragma once
// the navigation half of a benchmark spec (`kind: nav`, docs/benchmarks.md "Navigation"):
// point-goal episodes per world, the robot profile the harness judges them with, and the
// harness's metric settings. read by LoadBenchmarkSpec (campaign/benchmark_spec.h).
//
//   kind: nav
//   worlds:
//     - name: target                     # [A-Za-z0-9_-]+, unique
//       file: ../worlds/quadruped_target.yaml
//       robot: quadruped                 # the world's robot (its `robots:` name)
//       profile: quadruped               # quadruped | rover (default quadruped)
//       camera: {name: nav_depth, attach: quadruped/camera_mount, width: 80, height: 60,
//                fovy_deg: 50, rate_hz: 10}  # optional: replaces the world's cameras, as
//                                     # the SLAM spec's camera (rgb + depth, D435 depth model
//                                     # unless `depth_noise` says otherwise)
//       episodes:
//         - name: ahead                  # unique within the world
//           goal: [3.0, 0.0]             # world frame x, y, m
//           start: [0.0, 0.0, 0.0]       # optional: x, y (m), yaw (deg) of the robot
//           radius: 0.5                  # success radius, m (default 0.5)
//           timeout_sec: 30              # sim time limit of the episode (default 60)
//   methods:
//     - {name: penumbra_nav, bundled: penumbra_nav}
//     - {name: my_nav, command: "my_nav --connect {endpoint} --goal {goal_x},{goal_y}",
//        timeout_sec: 600}               # wall-clock limit, s
//   metrics: {debounce_sec: 0.5, min_force_N: 1.0, pose_rate_hz: 50}

#include <string>
#include <vector>

namespace penumbra {

/// one point-goal episode.
struct NavEpisode {
  std::string name;
  double goal_x = 0, goal_y = 0;  ///< world frame, m
  bool has_start = false;         ///< false: the robot starts where the world file puts it
  double start_x = 0, start_y = 0, start_yaw_deg = 0;  ///< world frame: m, m, deg about z
  double radius_m = 0.5;                               ///< success radius, > 0
  double timeout_sec = 60;                             ///< sim time, > 0
  int line = 0;                                        ///< line of the entry in the spec

  /// @throws ConfigError("", 0, field, problem) for a radius or timeout out of (0, 3600] or a
  ///         coordinate that is not finite.
  void ValidateOrThrow() const;
};

/// what the harness knows of a robot model to judge an episode (the navigator's profiles in
/// python/penumbra_nav/robots.py, docs/navigation.md).
struct NavRobotProfile {
  std::string name;       ///< quadruped | rover
  std::string base_body;  ///< model-local base body (trunk, chassis)
  /// model-local geom or body globs in ground contact by design (feet, wheels, caster): their
  /// contacts with the floor are not collisions
  std::vector<std::string> ground_parts;
  double fall_height_m = 0.15;  ///< a fall: the base origin's world z below this, m
  double max_tilt_deg = 45;     ///< ... or |roll| or |pitch| of the base above this, deg
};

/// the profile called `name`. @throws ConfigError("", 0, "profile", ...) for an unknown one.
NavRobotProfile NavProfile(const std::string& name);

/// the names NavProfile knows.
const std::vector<std::string>& NavProfileNames();

/// the harness's metric settings (`metrics:` of a nav spec).
struct NavMetricsConfig {
  /// contact intervals of one (robot body, other body) pair less than this apart are one
  /// collision, s (>= 0)
  double debounce_sec = 0.5;
  /// a pair is in contact when its summed normal force is at least this, N (>= 0)
  double min_force_N = 1.0;
  /// rate of the base pose series the run writes, Hz (0, 1000]
  double pose_rate_hz = 50;
  /// floor geom/body glob (composed names): contacts of ground parts with it are not counted
  std::string floor = "*floor*";

  /// @throws ConfigError("", 0, field, problem) for a value out of range or an empty floor.
  void ValidateOrThrow() const;
};

/// the placeholders a nav method's command may use: {penumbra} {pythonpath} {endpoint}
/// {goal_x} {goal_y} {radius} {timeout_sec} {robot} {robot_name} {out_dir} {workdir} {seed}.
const std::vector<std::string>& NavMethodPlaceholders();

/// the command of the bundled navigator (python/penumbra_nav, run by /usr/bin/python3 with
/// PYTHONPATH={pythonpath}, the source tree's python/ folder, set by /usr/bin/env).
std::string BundledNavCommand();

}  // namespace penumbra

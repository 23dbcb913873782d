#pragma once
// a benchmark specification (`penumbra benchmark SPEC.yaml`, docs/benchmarks.md): which
// worlds (each a recorded route), which adversity conditions, how many trials (seeds), which
// SLAM methods and which metrics. `kind: nav` makes it a navigation benchmark instead: its
// worlds name a robot and point-goal episodes, its methods are closed-loop navigators
// (campaign/nav_spec.h has that half of the format); `kind: slam` is the default. loaded and
// checked as a whole before anything runs; every error names the spec file, the 1-based line and
// the key path.
//
//   name: slam                       # a label for the report
//   worlds:
//     - name: room                   # [A-Za-z0-9_-]+, unique
//       file: ../worlds/default.yaml # a world file, relative to the spec's folder
//       duration_sec: 20             # the recorded route's length (default: the world's)
//       camera: {...}                # one world-file camera (docs/world-file.md `cameras`);
//                                    # outputs become [rgb, depth]; depth_noise defaults to
//                                    # {preset: realsense_d435} (ground-truth depth is refused)
//   conditions:                      # adversity presets: none | minor | major | FILE[#NAME]
//     - none                         # a bare spec is named after the preset
//     - {name: fog, adversity: presets.yaml#fog}
//   trials: 3                        # seeds 1..N; or `seeds: [7, 8, 9]`
//   methods:
//     - {name: rgbd, bundled: opencv_rgbd}   # `penumbra slam` methods (slam/rgbd_odometry.h)
//     - name: orbslam2               # any program: a command template (placeholders below)
//       dataset: tum                 # the exported dataset format: tum | euroc
//       command: "rgbd_tum voc.txt {settings} {dataset} {dataset}/associations.txt"
//       trajectory: CameraTrajectory.txt   # the file it writes, relative to its work folder
//       format: tum                  # tum (s) | tum_ns (timestamps in ns)
//       timeout_sec: 600
//       align: se3                   # se3 | sim3 (monocular) | none
//   metrics: {align: se3, rpe_delta_sec: 1, max_dt_sec: 0.02}
//   render: {threads: 1, tier: realtime}
//   workers: 1                       # local worker processes (--workers overrides)
//   keep_datasets: false             # keep the replayed images and exported datasets
//   slurm: {sbatch: ["#SBATCH --partition=debug", ...], poll_sec: 2}
//
// placeholders of a command: {penumbra} (this binary), {dataset} (the exported dataset's
// folder), {output} (the default trajectory file, {workdir}/trajectory.txt), {workdir} (the
// method's own folder, its current folder), {fx} {fy} {cx} {cy} {width} {height} (the
// camera's pinhole intrinsics, pixels), {camera_info} (the run's camera_info.json), {seed}.
// `{{` and `}}` are literal braces. a command runs without a shell: the template is split
// into words at load (campaign/command_template.h: quotes group, nothing is expanded, shell
// operators are refused) and each value is substituted as plain text inside its word.

#include <cstdint>
#include <string>
#include <vector>

#include "penumbra/campaign/nav_spec.h"
#include "penumbra/eval/umeyama.h"

namespace penumbra {

/// one world (one recorded route).
struct BenchmarkWorld {
  std::string name;
  std::string file;         ///< world file, absolute
  double duration_sec = 0;  ///< 0 = the world's own duration
  std::string camera_name;  ///< the benchmark camera
  std::string camera_yaml;  ///< the camera as a one-line YAML mapping (outputs, depth_noise set)
  int line = 0;             ///< line of the entry in the spec
  // kind: nav only
  std::string robot;                  ///< the world's robot (its `robots:` name)
  std::string profile = "quadruped";  ///< NavProfile name
  std::vector<NavEpisode> episodes;   ///< at least one
};

/// one adversity condition.
struct BenchmarkCondition {
  std::string name;
  std::string adversity;  ///< resolved preset spec (world/adversity_preset.h)
};

/// one SLAM method: a command template over an exported dataset; for a nav spec, a
/// closed-loop navigator's command (NavMethodPlaceholders) and its wall-clock timeout.
struct BenchmarkMethod {
  std::string name;
  std::string dataset = "tum";  ///< tum | euroc
  std::string command;          ///< template (see the file header)
  /// `command` split into words (SplitCommandTemplate), placeholders still in them
  std::vector<std::string> command_words;
  std::string trajectory = "trajectory.txt";  ///< relative to the method's work folder
  std::string format = "tum";                 ///< tum | tum_ns
  double timeout_sec = 600;
  AlignmentModel align = AlignmentModel::kSe3;
  std::string bundled;  ///< the `penumbra slam` method (nav: `penumbra_nav`), "" for a command
};

/// evaluation settings (docs/evaluation.md).
struct BenchmarkMetrics {
  AlignmentModel align = AlignmentModel::kSe3;  ///< default of the methods' `align`
  double rpe_delta_sec = 1.0;
  double max_dt_sec = 0.02;
};

/// a whole spec.
struct BenchmarkSpec {
  std::string file;  ///< the spec file, absolute
  std::string dir;   ///< its folder
  std::string name;
  std::string kind = "slam";  ///< slam | nav
  std::vector<BenchmarkWorld> worlds;
  std::vector<BenchmarkCondition> conditions;
  std::vector<uint64_t> seeds;
  std::vector<BenchmarkMethod> methods;
  BenchmarkMetrics metrics;
  NavMetricsConfig nav_metrics;   ///< kind: nav
  int render_threads = 1;         ///< per job (0 = all cores)
  std::string tier = "realtime";  ///< realtime | pathtraced
  int workers = 1;
  bool keep_datasets = false;
  std::vector<std::string> sbatch_lines;  ///< extra lines of the Slurm batch script header
  double slurm_poll_sec = 2;
};

/// loads and checks a spec file.
/// @throws ConfigError(file, line, key, problem) for unreadable files, YAML syntax errors,
///         unknown keys, wrong types, out-of-range values, duplicate or malformed names,
///         missing worlds / conditions / methods, unknown presets, unknown placeholders,
///         world files that do not exist, and a method with `dataset: euroc` when a world has
///         no IMU or several (at the method's `dataset`).
BenchmarkSpec LoadBenchmarkSpec(const std::string& path);

/// the placeholders a command template may use, in the order of the file header.
const std::vector<std::string>& MethodPlaceholders();

}  // namespace penumbra

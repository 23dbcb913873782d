// the nav benchmark's acceptance, parts (b) and (c), through the real `penumbra benchmark` with a
// `kind: nav` spec: every job starts a real lockstep `penumbra run --zmq` and a real method
// process (the bundled python3 -m penumbra_nav, or tests/campaign/straight_driver.py), and the
// harness judges the episode from the run's own pose and contact series.
//   (b) the baseline navigator reaches a goal 3 m ahead under `none`: success, no collision;
//   (c) a goal inside a closed pen (tests/campaign/data/nav_wall.yaml): the navigator times
//       out honestly (success 0), and a blind method that trots straight into the pen's
//       wall is charged a collision (success 0, SC 0).
// plus the spec checks of the nav format (errors naming file:line and the field).

#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <map>
#include <sstream>

#include "common/temp_dir.h"
#include "penumbra/campaign/benchmark_spec.h"
#include "penumbra/campaign/nav_report.h"
#include "penumbra/core/error.h"
#include "penumbra/world/adversity_preset.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::TempDir;

std::vector<std::map<std::string, std::string>> ReadRows(const fs::path& csv) {
  std::istringstream in(ReadAll(csv.string()));
  std::string line;
  std::getline(in, line);
  std::vector<std::string> head;
  {
    std::istringstream h(line);
    std::string f;
    while (std::getline(h, f, ',')) head.push_back(f);
  }
  std::vector<std::map<std::string, std::string>> rows;
  while (std::getline(in, line)) {
    std::vector<std::string> f;
    std::string cur;
    bool quoted = false;
    for (char c : line) {
      if (c == '"')
        quoted = !quoted;
      else if (c == ',' && !quoted) {
        f.push_back(cur);
        cur.clear();
      } else
        cur += c;
    }
    f.push_back(cur);
    std::map<std::string, std::string> r;
    for (size_t i = 0; i < head.size() && i < f.size(); ++i) r[head[i]] = f[i];
    rows.push_back(r);
  }
  return rows;
}

int RunBenchmarkCli(const std::string& args) {
  const int status = std::system((std::string(PENUMBRA_BINARY) + " benchmark " + args).c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(NavBenchmark, BaselineReachesAGoalThreeMetresAheadWithoutCollision) {
  TempDir dir;
  const std::string spec = dir.Write(
      "nav.yaml", std::string("kind: nav\nname: nav_short\nworlds:\n  - name: target\n    file: ") +
                      PENUMBRA_SOURCE_DIR +
                      "/worlds/quadruped_target.yaml\n    robot: quadruped\n    episodes:\n"
                      "      - {name: ahead, goal: [3, 0], radius: 0.5, timeout_sec: 20}\n"
                      "conditions: [none]\ntrials: 1\nmethods:\n"
                      "  - {name: penumbra_nav, bundled: penumbra_nav, timeout_sec: 120}\n");
  const fs::path out = fs::path(dir.path()) / "out";
  ASSERT_EQ(RunBenchmarkCli(spec + " --out " + out.string() + " --quiet"), 0);
  // the documented columns, in order
  std::string header = ReadAll((out / "results.csv").string());
  header = header.substr(0, header.find('\n'));
  std::string expected;
  for (const std::string& c : NavCsvColumns()) expected += (expected.empty() ? "" : ",") + c;
  EXPECT_EQ(header, expected);
  const auto rows = ReadRows(out / "results.csv");
  ASSERT_EQ(rows.size(), 1u);
  const auto& r = rows[0];
  EXPECT_EQ(r.at("status"), "ok") << r.at("detail");
  EXPECT_EQ(r.at("end"), "method_exit") << r.at("detail");
  EXPECT_EQ(r.at("success"), "1") << r.at("detail");
  EXPECT_EQ(r.at("collisions"), "0");
  EXPECT_EQ(r.at("sc"), "1");
  EXPECT_LE(std::stod(r.at("final_goal_distance_m")), 0.5);
  EXPECT_GT(std::stod(r.at("time_to_goal_sec")), 3.0);  // 2.5 m at <= 0.4 m/s
  EXPECT_LT(std::stod(r.at("time_to_goal_sec")), 20.0);
  // the harness's own judgement agrees with the run's files: the episode JSON of the method
  // is not read, but the run's pose series is there
  const fs::path job = out / "jobs" / "target__ahead__none__penumbra_nav__t1";
  EXPECT_TRUE(fs::is_regular_file(job / "run" / "metrics" / "nav_base.csv"));
  EXPECT_TRUE(fs::is_regular_file(job / "penumbra_nav" / "episode.json"));
  EXPECT_TRUE(fs::is_regular_file(out / "summary.md"));
  EXPECT_NE(ReadAll((out / "summary.md").string())
                .find("| none | penumbra_nav | 1/1 | 1.00 ± 0.00 | 0.00 ± 0.00 |"),
            std::string::npos)
      << ReadAll((out / "summary.md").string());
  EXPECT_TRUE(fs::is_regular_file(out / "plots" / "target_success.png"));
  EXPECT_TRUE(fs::is_regular_file(out / "plots" / "target_sc.png"));
  EXPECT_TRUE(fs::is_regular_file(out / "plots" / "path_target__ahead__none__penumbra_nav.png"));
  EXPECT_TRUE(fs::is_regular_file(out / "report.md"));
}

TEST(NavBenchmark, GoalBehindAWallTimesOutOrCountsCollisions) {
  TempDir dir;
  const std::string src = PENUMBRA_SOURCE_DIR;
  const std::string spec = dir.Write(
      "wall.yaml",
      "kind: nav\nname: wall\nworlds:\n  - name: pen\n    file: " + src +
          "/tests/campaign/data/nav_wall.yaml\n    robot: quadruped\n    episodes:\n"
          "      - {name: inside, goal: [2.5, 0], radius: 0.3, timeout_sec: 8}\n"
          "conditions: [none]\ntrials: 1\nmethods:\n"
          "  - {name: penumbra_nav, bundled: penumbra_nav, timeout_sec: 120}\n"
          "  - {name: straight, command: \"/usr/bin/env PYTHONPATH={pythonpath} /usr/bin/python3 " +
          src +
          "/tests/campaign/straight_driver.py {endpoint}\", timeout_sec: 120}\n"
          "metrics: {debounce_sec: 0.5}\nworkers: 2\n");
  const fs::path out = fs::path(dir.path()) / "out";
  ASSERT_EQ(RunBenchmarkCli(spec + " --out " + out.string() + " --quiet"), 0);
  const auto rows = ReadRows(out / "results.csv");
  ASSERT_EQ(rows.size(), 2u);
  std::map<std::string, std::map<std::string, std::string>> by;
  for (const auto& r : rows) by[r.at("method")] = r;
  const auto& nav = by.at("penumbra_nav");
  // the navigator cannot reach the goal: it is not a success, and the row says why it ended
  EXPECT_EQ(nav.at("success"), "0") << nav.at("detail");
  EXPECT_EQ(nav.at("sc"), "0");
  EXPECT_EQ(nav.at("status"), "ok") << nav.at("detail");
  EXPECT_TRUE(nav.at("end") == "sim_timeout" || std::stoi(nav.at("collisions")) > 0)
      << nav.at("end") << " " << nav.at("collisions");
  EXPECT_GT(std::stod(nav.at("final_goal_distance_m")), 0.3);
  EXPECT_EQ(nav.at("time_to_goal_sec"), "");
  // the blind method walks into the west wall: at least one collision, from the run's
  // contacts (feet on the floor are not counted: the robot trots for 8 s)
  const auto& blind = by.at("straight");
  EXPECT_EQ(blind.at("status"), "ok") << blind.at("detail");
  EXPECT_EQ(blind.at("end"), "sim_timeout");
  EXPECT_EQ(blind.at("success"), "0");
  EXPECT_GE(std::stoi(blind.at("collisions")), 1);
  EXPECT_EQ(blind.at("sc"), "0");
  // it stopped at the wall (west face at x = 1.75; the trunk's centre stays ~0.4 m before it)
  EXPECT_GT(std::stod(blind.at("final_goal_distance_m")), 0.6);
}

std::string NavSpec(const std::string& episodes, const std::string& extra = "",
                    const std::string& methods = "  - {name: nav, bundled: penumbra_nav}\n") {
  return std::string("kind: nav\nworlds:\n  - name: target\n    file: ") + PENUMBRA_SOURCE_DIR +
         "/worlds/quadruped_target.yaml\n    robot: quadruped\n    episodes:\n" + episodes +
         "conditions: [none, minor]\ntrials: 2\nmethods:\n" + methods + extra;
}

std::string ErrorOf(const std::string& text) {
  TempDir dir;
  const std::string file = dir.Write("spec.yaml", text);
  try {
    LoadBenchmarkSpec(file);
  } catch (const ConfigError& e) {
    return e.what();
  }
  return "";
}

TEST(NavBenchmark, SpecLoadsAndPlansOneJobPerEpisodeConditionMethodTrial) {
  TempDir dir;
  const BenchmarkSpec s = LoadBenchmarkSpec(dir.Write(
      "spec.yaml", NavSpec("      - {name: a, goal: [3, 0]}\n"
                           "      - {name: b, goal: [5, 2.5], start: [0.5, 0, 10], radius: 0.4, "
                           "timeout_sec: 30}\n")));
  EXPECT_EQ(s.kind, "nav");
  ASSERT_EQ(s.worlds.size(), 1u);
  ASSERT_EQ(s.worlds[0].episodes.size(), 2u);
  EXPECT_EQ(s.worlds[0].profile, "quadruped");
  EXPECT_DOUBLE_EQ(s.worlds[0].episodes[0].radius_m, 0.5);
  EXPECT_DOUBLE_EQ(s.worlds[0].episodes[0].timeout_sec, 60);
  EXPECT_FALSE(s.worlds[0].episodes[0].has_start);
  EXPECT_TRUE(s.worlds[0].episodes[1].has_start);
  EXPECT_DOUBLE_EQ(s.worlds[0].episodes[1].start_yaw_deg, 10);
  EXPECT_NE(s.methods[0].command.find("-m penumbra_nav --endpoint {endpoint}"), std::string::npos);
  // run without a shell: /usr/bin/env sets PYTHONPATH
  ASSERT_GE(s.methods[0].command_words.size(), 3u);
  EXPECT_EQ(s.methods[0].command_words[0], "/usr/bin/env");
  EXPECT_EQ(s.methods[0].command_words[1], "PYTHONPATH={pythonpath}");
  EXPECT_DOUBLE_EQ(s.nav_metrics.debounce_sec, 0.5);
  const std::vector<BenchmarkJob> jobs = PlanBenchmarkJobs(s);
  ASSERT_EQ(jobs.size(), 2u * 2u * 1u * 2u);
  EXPECT_EQ(jobs[0].id, "target__a__none__nav__t1");
  EXPECT_EQ(jobs[7].id, "target__b__minor__nav__t2");
  // no camera: the world's own
  EXPECT_TRUE(s.worlds[0].camera_yaml.empty());
}

TEST(NavBenchmark, SpecCameraGetsDepthAndTheD435Model) {
  TempDir dir;
  std::string text = NavSpec("      - {name: a, goal: [3, 0]}\n");
  text.replace(text.find("    robot:"), 0,
               "    camera: {name: nav_depth, attach: quadruped/camera_mount, width: 80, "
               "height: 60, fovy_deg: 50, rate_hz: 10}\n");
  const BenchmarkSpec s = LoadBenchmarkSpec(dir.Write("spec.yaml", text));
  ASSERT_EQ(s.worlds.size(), 1u);
  EXPECT_EQ(s.worlds[0].camera_name, "nav_depth");
  EXPECT_NE(s.worlds[0].camera_yaml.find("outputs: [rgb, depth]"), std::string::npos)
      << s.worlds[0].camera_yaml;
  EXPECT_NE(s.worlds[0].camera_yaml.find("realsense_d435"), std::string::npos)
      << s.worlds[0].camera_yaml;
}

TEST(NavBenchmark, SpecErrorsNameFileLineAndField) {
  std::string e = ErrorOf(NavSpec("      - {name: a, goal: [3]}\n"));
  EXPECT_NE(e.find("spec.yaml:7"), std::string::npos) << e;
  EXPECT_NE(e.find("goal"), std::string::npos) << e;
  e = ErrorOf(NavSpec("      - {name: a, goal: [3, 0], radius: -1}\n"));
  EXPECT_NE(e.find("spec.yaml:7"), std::string::npos) << e;
  EXPECT_NE(e.find("radius"), std::string::npos) << e;
  e = ErrorOf(NavSpec("      - {name: a, goal: [3, 0]}\n", "",
                      "  - {name: x, command: \"nav --goal {goal_z}\"}\n"));
  EXPECT_NE(e.find("methods[0].command"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown placeholder '{goal_z}'"), std::string::npos) << e;
  EXPECT_NE(e.find("{endpoint}"), std::string::npos) << e;
  e = ErrorOf(NavSpec("      - {name: a, goal: [3, 0]}\n", "keep_datasets: true\n"));
  EXPECT_NE(e.find("unknown key 'keep_datasets'"), std::string::npos) << e;
  e = ErrorOf(NavSpec("      - {name: a, goal: [3, 0]}\n", "metrics: {debounce_sec: -1}\n"));
  EXPECT_NE(e.find("metrics.debounce_sec"), std::string::npos) << e;
  e = ErrorOf(NavSpec("      - {name: a, goal: [3, 0]}\n      - {name: a, goal: [1, 0]}\n"));
  EXPECT_NE(e.find("spec.yaml:8"), std::string::npos) << e;
  EXPECT_NE(e.find("appears twice"), std::string::npos) << e;
  // the world's robot must exist
  std::string text = NavSpec("      - {name: a, goal: [3, 0]}\n");
  text.replace(text.find("robot: quadruped"), 16, "robot: go2");
  e = ErrorOf(text);
  EXPECT_NE(e.find("spec.yaml:5"), std::string::npos) << e;
  EXPECT_NE(e.find("no robot 'go2'"), std::string::npos) << e;
  EXPECT_NE(e.find("quadruped"), std::string::npos) << e;
  // a SLAM key in a nav spec's world
  text = NavSpec("      - {name: a, goal: [3, 0]}\n");
  text.replace(text.find("    robot:"), 0, "    duration_sec: 5\n");
  e = ErrorOf(text);
  EXPECT_NE(e.find("unknown key 'duration_sec'"), std::string::npos) << e;
  // the navigator's camera is checked as the SLAM spec's: a body the world lacks
  text = NavSpec("      - {name: a, goal: [3, 0]}\n");
  text.replace(text.find("    robot:"), 0,
               "    camera: {name: c, attach: nowhere/mount, width: 80, height: 60}\n");
  e = ErrorOf(text);
  EXPECT_NE(e.find("spec.yaml:5"), std::string::npos) << e;
  EXPECT_NE(e.find("nowhere/mount"), std::string::npos) << e;
  // unknown kind
  e = ErrorOf("kind: rl\n");
  EXPECT_NE(e.find("kind"), std::string::npos) << e;
}

// the bundled navigation benchmark runs levels of its own (benchmarks/nav_presets.yaml), not
// the shared presets calibrated for RGB-D odometry, whose `minor` has no people: each level
// adds people who step into the robot's path and shortens the depth camera's range
TEST(NavBenchmark, BundledSpecRunsItsOwnNavigationLevels) {
  const BenchmarkSpec s =
      LoadBenchmarkSpec(std::string(PENUMBRA_SOURCE_DIR) + "/benchmarks/nav.yaml");
  ASSERT_EQ(s.conditions.size(), 3u);
  EXPECT_EQ(s.conditions[0].name, "none");
  EXPECT_EQ(s.conditions[1].name, "minor");
  EXPECT_EQ(s.conditions[2].name, "major");
  const AdversityPreset none = LoadAdversityPreset(s.conditions[0].adversity);
  const AdversityPreset minor = LoadAdversityPreset(s.conditions[1].adversity);
  const AdversityPreset major = LoadAdversityPreset(s.conditions[2].adversity);
  EXPECT_TRUE(none.empty());
  for (const BenchmarkCondition& c : {s.conditions[1], s.conditions[2]})
    EXPECT_NE(c.adversity.find("benchmarks/nav_presets.yaml#"), std::string::npos) << c.adversity;
  // people in the robot's path: some under minor, more under major
  EXPECT_GE(minor.npc_people, 1);
  EXPECT_GT(major.npc_people, minor.npc_people);
  EXPECT_EQ(minor.npc_behaviour, AgentBehaviour::kBlock);
  EXPECT_EQ(major.npc_behaviour, AgentBehaviour::kBlock);
  // no blocking vehicle (it would drive at the robot)
  EXPECT_EQ(minor.npc_vehicles, 0);
  EXPECT_EQ(major.npc_vehicles, 0);
  // the depth camera's range: fog under both, denser under major, smoke under major only
  ASSERT_TRUE(minor.fog_mor_m.has_value());
  ASSERT_TRUE(major.fog_mor_m.has_value());
  EXPECT_LT(*major.fog_mor_m, *minor.fog_mor_m);
  EXPECT_FALSE(minor.smoke_sigma_t_per_m.has_value());
  EXPECT_TRUE(major.smoke_sigma_t_per_m.has_value());
}

}  // namespace
}  // namespace penumbra

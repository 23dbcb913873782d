#include "penumbra/campaign/benchmark_spec.h"

#include <gtest/gtest.h>

#include <filesystem>

#include "common/temp_dir.h"
#include "penumbra/campaign/benchmark_report.h"
#include "penumbra/campaign/command_template.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using testing::TempDir;

std::string Spec(const std::string& extra,
                 const std::string& methods = "  - {name: rgbd, bundled: opencv_rgbd}\n") {
  return std::string("name: t\nworlds:\n  - name: room\n    file: ") + PENUMBRA_SOURCE_DIR +
         "/worlds/default.yaml\n    duration_sec: 1\n    camera: {name: cam, attach: "
         "go1/camera_mount, width: 160, "
         "height: 120, fovy_deg: 70, rate_hz: 10}\nconditions: [none, major]\ntrials: "
         "2\nmethods:\n" +
         methods + extra;
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

// a YAML tag (`!foo`, `!!binary`) would be dropped silently by yaml-cpp: refused with its line
TEST(BenchmarkSpec, YamlTagsAreRefusedWithTheirLine) {
  const std::string e = ErrorOf(Spec("trials: !foo 3\n"));
  EXPECT_NE(e.find("spec.yaml:11"), std::string::npos) << e;
  EXPECT_NE(e.find("YAML tag '!foo'"), std::string::npos) << e;
}

TEST(BenchmarkSpec, LoadsWithDefaults) {
  TempDir dir;
  const BenchmarkSpec s = LoadBenchmarkSpec(dir.Write("spec.yaml", Spec("")));
  ASSERT_EQ(s.worlds.size(), 1u);
  EXPECT_EQ(s.worlds[0].camera_name, "cam");
  // the benchmark camera writes rgb and depth through the RealSense D435 model
  EXPECT_NE(s.worlds[0].camera_yaml.find("outputs: [rgb, depth]"), std::string::npos)
      << s.worlds[0].camera_yaml;
  EXPECT_NE(s.worlds[0].camera_yaml.find("realsense_d435"), std::string::npos)
      << s.worlds[0].camera_yaml;
  ASSERT_EQ(s.conditions.size(), 2u);
  EXPECT_EQ(s.conditions[1].name, "major");
  EXPECT_EQ(s.seeds, (std::vector<uint64_t>{1, 2}));
  ASSERT_EQ(s.methods.size(), 1u);
  EXPECT_NE(s.methods[0].command.find("slam opencv_rgbd {dataset} {output}"), std::string::npos);
  EXPECT_EQ(s.render_threads, 1);
}

TEST(BenchmarkSpec, ErrorsNameFileLineAndKey) {
  std::string e = ErrorOf(Spec("colour: red\n"));
  EXPECT_NE(e.find("spec.yaml:11"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown key 'colour'"), std::string::npos) << e;
  e = ErrorOf(Spec("", "  - {name: x, command: \"run {datset}\"}\n"));
  EXPECT_NE(e.find("methods[0].command"), std::string::npos) << e;
  EXPECT_NE(e.find("unknown placeholder '{datset}'"), std::string::npos) << e;
  e = ErrorOf(Spec("", "  - {name: x, bundled: orbslam}\n"));
  EXPECT_NE(e.find("methods[0].bundled"), std::string::npos) << e;
  e = ErrorOf(Spec("", "  - {name: x}\n"));
  EXPECT_NE(e.find("exactly one of 'bundled'"), std::string::npos) << e;
  e = ErrorOf(Spec("workers: 0\n"));
  EXPECT_NE(e.find("workers"), std::string::npos) << e;
  e = ErrorOf(
      Spec("", "  - {name: a, bundled: opencv_rgbd}\n  - {name: a, bundled: opencv_icp}\n"));
  EXPECT_NE(e.find("appears twice"), std::string::npos) << e;
  std::string text = Spec("");
  text.replace(text.find("[none, major]"), 13, "[none, heavy]");
  e = ErrorOf(text);
  EXPECT_NE(e.find("unknown preset 'heavy'"), std::string::npos) << e;
  text = Spec("");
  text.replace(text.find("default.yaml"), 12, "nowhere.yaml");
  e = ErrorOf(text);
  EXPECT_NE(e.find("worlds[0].file"), std::string::npos) << e;
  e = ErrorOf(Spec("seeds: [1]\n"));
  EXPECT_NE(e.find("exactly one of 'trials'"), std::string::npos) << e;
  text = Spec("");
  text.replace(text.find("width: 160"), 10, "width: -5");
  e = ErrorOf(text);
  EXPECT_NE(e.find("spec.yaml:6: worlds[0].camera"), std::string::npos) << e;
  EXPECT_NE(e.find("width"), std::string::npos) << e;
  e = ErrorOf("worlds: [\n");
  EXPECT_NE(e.find("YAML syntax error"), std::string::npos) << e;
}

TEST(MethodProcess, TemplatesFillBraces) {
  EXPECT_EQ(FillTemplate("a {x} {{y}} {x}", {{"x", "1"}}), "a 1 {y} 1");
  EXPECT_THROW(FillTemplate("{z}", {{"x", "1"}}), Error);
}

TEST(BenchmarkSpec, CommandsAreSplitAtLoadAndShellSyntaxIsRefusedWithFileLineAndField) {
  TempDir dir;
  const BenchmarkSpec s = LoadBenchmarkSpec(dir.Write(
      "spec.yaml",
      Spec("",
           "  - {name: rgbd, bundled: opencv_rgbd}\n"
           "  - {name: mine, command: \"/opt/x/run 'a b' {dataset}/associations.txt\"}\n")));
  ASSERT_EQ(s.methods.size(), 2u);
  EXPECT_EQ(s.methods[0].command_words,
            (std::vector<std::string>{"{penumbra}", "slam", "opencv_rgbd", "{dataset}", "{output}",
                                      "--intrinsics", "{fx},{fy},{cx},{cy}"}));
  EXPECT_EQ(s.methods[1].command_words,
            (std::vector<std::string>{"/opt/x/run", "a b", "{dataset}/associations.txt"}));
  // the reported template: a value in double quotes beside a command substitution
  std::string e = ErrorOf(Spec("", "  - {name: x, command: 'run \"$(cat {dataset})\"'}\n"));
  EXPECT_NE(e.find("spec.yaml:10: methods[0].command: column 6: '$' inside"), std::string::npos)
      << e;
  e = ErrorOf(Spec("", "  - {name: x, command: \"run {dataset}; touch X\"}\n"));
  EXPECT_NE(e.find("methods[0].command: column 14: ';' separates commands"), std::string::npos)
      << e;
  e = ErrorOf(Spec("", "  - {name: x, command: \"run {dataset} | tee log\"}\n"));
  EXPECT_NE(e.find("'|' makes a pipeline"), std::string::npos) << e;
  e = ErrorOf(Spec("", "  - {name: x, command: \"run {dataset} > log\"}\n"));
  EXPECT_NE(e.find("'>' redirects"), std::string::npos) << e;
  e = ErrorOf(Spec("", "  - {name: x, command: \"sh -c 'run {dataset}'\"}\n"));
  EXPECT_NE(e.find("inside the inline program of 'sh -c'"), std::string::npos) << e;
  e = ErrorOf(Spec("", "  - {name: x, command: \"exec run {dataset}\"}\n"));
  EXPECT_NE(e.find("'exec' is a shell builtin"), std::string::npos) << e;
  // control characters in an extra #SBATCH line
  e = ErrorOf(Spec("slurm: {sbatch: [\"#SBATCH --time=1\\r\"]}\n"));
  EXPECT_NE(e.find("slurm.sbatch[0]"), std::string::npos) << e;
  EXPECT_NE(e.find("without control characters"), std::string::npos) << e;
}

// a template that would paste a value into a shell's or an interpreter's code is refused at
// load, with the spec file, the line, the field, the method and why (slam and nav alike)
TEST(BenchmarkSpec, TemplatesPastingValuesIntoCodeAreRefusedAtLoadNamingTheMethod) {
  std::string e = ErrorOf(Spec("", "  - {name: viash, command: \"sh -c -- 'true {output}'\"}\n"));
  EXPECT_NE(e.find("spec.yaml:10: methods[0].command: column 10: word 4 'true {output}': a "
                   "placeholder inside the inline program of 'sh -c'"),
            std::string::npos)
      << e;
  EXPECT_NE(e.find("(method 'viash')"), std::string::npos) << e;
  // YAML single quotes: '' is one quote
  e = ErrorOf(Spec("",
                   "  - {name: rgbd, bundled: opencv_rgbd}\n"
                   "  - name: timeit\n"
                   "    command: 'python3 -m timeit -s ''import os; "
                   "os.system(\"cat {dataset} > {output}\")'''\n"));
  EXPECT_NE(e.find("spec.yaml:12: methods[1].command: column 22: word 5"), std::string::npos) << e;
  EXPECT_NE(e.find("'python3 -m timeit' runs its arguments as code"), std::string::npos) << e;
  EXPECT_NE(e.find("(method 'timeit')"), std::string::npos) << e;
  TempDir dir;
  const std::string nav =
      std::string("kind: nav\nname: n\nworlds:\n  - name: pen\n    file: ") + PENUMBRA_SOURCE_DIR +
      "/tests/campaign/data/nav_wall.yaml\n    robot: quadruped\n    episodes:\n"
      "      - {name: a, goal: [1, 0], radius: 0.3, timeout_sec: 8}\n"
      "conditions: [none]\ntrials: 1\nmethods:\n"
      "  - {name: drive, command: \"/usr/bin/env X=1 bash -c 'nav {endpoint}'\"}\n";
  try {
    LoadBenchmarkSpec(dir.Write("nav.yaml", nav));
    ADD_FAILURE() << "accepted a nav template with a placeholder in bash -c";
  } catch (const ConfigError& err) {
    const std::string what = err.what();
    EXPECT_NE(what.find("nav.yaml:12: methods[0].command:"), std::string::npos) << what;
    EXPECT_NE(what.find("inside the inline program of 'bash -c'"), std::string::npos) << what;
    EXPECT_NE(what.find("(method 'drive')"), std::string::npos) << what;
  }
}

// every spec under benchmarks/ still loads, and its methods' templates split
TEST(BenchmarkSpec, BundledSpecsLoad) {
  int loaded = 0;
  for (const auto& entry :
       std::filesystem::directory_iterator(std::string(PENUMBRA_SOURCE_DIR) + "/benchmarks")) {
    if (entry.path().extension() != ".yaml") continue;
    // presets files (nav_presets.yaml) are not specs: a spec has methods
    if (testing::ReadAll(entry.path()).find("\nmethods:") == std::string::npos) continue;
    try {
      const BenchmarkSpec s = LoadBenchmarkSpec(entry.path().string());
      ASSERT_FALSE(s.methods.empty()) << entry.path();
      for (const BenchmarkMethod& m : s.methods) EXPECT_FALSE(m.command_words.empty()) << m.name;
      ++loaded;
    } catch (const Error& err) {
      ADD_FAILURE() << entry.path() << ": " << err.what();
    }
  }
  EXPECT_GE(loaded, 3);  // slam.yaml, nav.yaml, calibration.yaml
}

TEST(BenchmarkReport, SummaryIsMeanAndSampleStdOverOkTrials) {
  TempDir dir;
  const BenchmarkSpec s = LoadBenchmarkSpec(dir.Write("spec.yaml", Spec("")));
  std::vector<BenchmarkRow> rows(3);
  for (int i = 0; i < 3; ++i) {
    rows[i].world = "room";
    rows[i].condition = "none";
    rows[i].method = "rgbd";
    rows[i].trial = i + 1;
    rows[i].status = i < 2 ? "ok" : "failed";
    rows[i].ate_rmse_m = i < 2 ? 0.1 * (i + 1) : NAN;
    rows[i].tracked_fraction = i < 2 ? 1.0 : NAN;
  }
  const std::vector<SummaryLine> lines = Summarize(s, rows);
  ASSERT_EQ(lines.size(), 2u);  // none, major
  EXPECT_EQ(lines[0].trials, 3);
  EXPECT_EQ(lines[0].ok, 2);
  EXPECT_NEAR(lines[0].ate_rmse_m.mean, 0.15, 1e-12);
  EXPECT_NEAR(lines[0].ate_rmse_m.std, std::sqrt(0.005), 1e-12);  // (0.05^2 * 2) / (2 - 1)
  EXPECT_NEAR(lines[0].tracked_fraction.mean, 2.0 / 3.0, 1e-12);  // the failed trial counts 0
  EXPECT_EQ(lines[1].trials, 0);
  const std::string csv = BenchmarkCsv(rows);
  EXPECT_EQ(csv.substr(0, csv.find('\n')),
            "world,condition,method,trial,seed,status,frames,poses,ate_rmse_m,ate_mean_m,ate_max_m,"
            "rpe_trans_rmse_m,rpe_rot_rmse_deg,coverage,scaled_ate_m,tracked_fraction,"
            "tracked_path_coverage,tracked_scaled_ate_m,pose_fraction,scale,replay_sec,"
            "export_sec,method_sec,eval_sec,detail");
  EXPECT_NE(csv.find("room,none,rgbd,3,0,failed,0,0,,,,"), std::string::npos) << csv;
}

}  // namespace
}  // namespace penumbra

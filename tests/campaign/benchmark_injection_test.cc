// through the real `penumbra benchmark`: shell text in a value (the output
// folder, hence the dataset, output and work folder paths) reaches the method as one literal
// argument and runs nothing; the command.sh written for people runs the same argument vector;
// a Slurm batch script quotes every value and refuses paths it cannot carry (a newline in
// --out would have become a command line of the script) before anything is written.

#include <gtest/gtest.h>
#include <stdlib.h>

#include <filesystem>
#include <string>
#include <utility>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/campaign/benchmark_runner.h"
#include "penumbra/campaign/child_process.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::TempDir;

std::string InjectionSpec(const std::string& methods) {
  return std::string("name: inj\nworlds:\n  - name: room\n    file: ") + PENUMBRA_SOURCE_DIR +
         "/worlds/default.yaml\n    duration_sec: 0.5\n"
         "    camera: {name: cam, attach: go1/camera_mount, width: 64, height: 48, fovy_deg: 70, "
         "rate_hz: 10}\n"
         "conditions: [none]\ntrials: 1\nmethods:\n" +
         methods + "render: {threads: 1}\nworkers: 1\n";
}

// runs the real binary with `args` (no shell) in `dir`; its exit code (-1 when it ran past
// `limit_sec` and was killed), stderr in *err
int InjectionRun(const std::vector<std::string>& args, const fs::path& dir, double limit_sec,
                 std::string* err) {
  std::vector<std::string> argv = {PENUMBRA_BINARY};
  argv.insert(argv.end(), args.begin(), args.end());
  const fs::path err_file = dir / "cli_stderr.txt";
  ChildProcess p(argv, dir.string(), (dir / "cli_stdout.txt").string(), err_file.string());
  const bool exited = p.WaitFor(limit_sec);
  if (!exited) p.TerminateAndWait(5);
  *err = ReadAll(err_file);
  return exited ? p.exit_code() : -1;
}

// files under `root` whose name begins with `prefix`
std::vector<std::string> InjectedFiles(const fs::path& root, const std::string& prefix) {
  std::vector<std::string> found;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec))
    if (it->path().filename().string().rfind(prefix, 0) == 0) found.push_back(it->path().string());
  return found;
}

std::vector<std::string> SplitNul(const std::string& s) {
  std::vector<std::string> out;
  size_t pos = 0;
  while (pos <= s.size()) {
    const size_t end = std::min(s.find('\0', pos), s.size());
    out.push_back(s.substr(pos, end - pos));
    pos = end + 1;
  }
  return out;
}

TEST(BenchmarkInjection, ShellTextInPathsReachesTheMethodAsOneLiteralArgument) {
  TempDir dir;
  // the reported template: {output} inside double quotes, beside single-quoted and bare values
  const std::string spec = dir.Write("spec.yaml", InjectionSpec(R"X(  - name: argv
    command: >-
      /usr/bin/python3 -c 'import sys; sys.stdout.write("\0".join(sys.argv[1:]))'
      {dataset} "{output}" '{workdir}' x{seed}y {camera_info}
)X"));
  const fs::path out = dir.path() / "o $(touch INJ1) `touch INJ2` ;touch INJ3 'q\" && touch INJ4";
  std::string err;
  ASSERT_EQ(
      InjectionRun({"benchmark", spec, "--out", out.string(), "--quiet"}, dir.path(), 600, &err), 0)
      << err;
  const fs::path job = out / "jobs" / "room__none__t1";
  const fs::path work = job / "argv";
  const std::string printed = ReadAll(work / "stdout.log");
  EXPECT_EQ(SplitNul(printed), (std::vector<std::string>{
                                   (job / "dataset_tum").string(),
                                   (work / "trajectory.txt").string(),
                                   work.string(),
                                   "x1y",
                                   (job / "camera_info.json").string(),
                               }))
      << ReadAll(work / "stderr.log");
  // nothing ran: no file made by an injected command anywhere
  EXPECT_EQ(InjectedFiles(dir.path(), "INJ"), std::vector<std::string>{});
  EXPECT_EQ(InjectedFiles(fs::current_path(), "INJ"), std::vector<std::string>{});
  // the command.sh written for people runs the very same argument vector through /bin/sh
  const std::optional<std::string> again =
      CaptureCommand({"/bin/sh", (work / "command.sh").string()});
  ASSERT_TRUE(again) << ReadAll(work / "command.sh");
  EXPECT_EQ(*again, printed);
  EXPECT_EQ(InjectedFiles(dir.path(), "INJ"), std::vector<std::string>{});
}

// the templates that pasted values into code a shell then parsed: refused before anything runs,
// so an --out holding $(touch ...) creates nothing; the same values given to a shell as its
// positional arguments stay text
TEST(BenchmarkInjection, TemplatesPastingValuesIntoShellCodeAreRefusedAndRunNothing) {
  TempDir dir;
  const fs::path out = dir.path() / "o $(touch INJ1) `touch INJ2`";
  const std::vector<std::pair<std::string, int>> methods = {
      {"  - {name: viash, command: \"sh -c -- 'true {output}'\"}\n", 10},
      {"  - name: timeit\n    command: 'python3 -m timeit -s ''import os; "
       "os.system(\"true {dataset} > {output}\")'' pass'\n",
       11}};
  for (const auto& [method, line] : methods) {
    const std::string spec = dir.Write("spec.yaml", InjectionSpec(method));
    std::string err;
    EXPECT_EQ(
        InjectionRun({"benchmark", spec, "--out", out.string(), "--quiet"}, dir.path(), 600, &err),
        2)
        << err;
    EXPECT_NE(err.find(spec + ":" + std::to_string(line) + ": methods[0].command: column "),
              std::string::npos)
        << err;
    EXPECT_NE(err.find("program text"), std::string::npos) << err;
    EXPECT_EQ(InjectedFiles(dir.path(), "INJ"), std::vector<std::string>{});
    EXPECT_EQ(InjectedFiles(fs::current_path(), "INJ"), std::vector<std::string>{});
  }
  // the shell a method asked for, the values as "$1" and "$2"
  const std::string spec = dir.Write(
      "spec.yaml", InjectionSpec("  - {name: argv, command: \"sh -c -- 'printf \\\"%s\\\\n\\\" "
                                 "\\\"$1\\\" \\\"$2\\\"' sh {dataset} {output}\"}\n"));
  std::string err;
  ASSERT_EQ(
      InjectionRun({"benchmark", spec, "--out", out.string(), "--quiet"}, dir.path(), 600, &err), 0)
      << err;
  const fs::path job = out / "jobs" / "room__none__t1";
  EXPECT_EQ(
      ReadAll(job / "argv" / "stdout.log"),
      (job / "dataset_tum").string() + "\n" + (job / "argv" / "trajectory.txt").string() + "\n")
      << ReadAll(job / "argv" / "stderr.log");
  EXPECT_EQ(InjectedFiles(dir.path(), "INJ"), std::vector<std::string>{});
}

TEST(BenchmarkInjection, SlurmRefusesControlCharactersInOutBeforeWritingAnything) {
  TempDir dir;
  const std::string spec =
      dir.Write("spec.yaml", InjectionSpec("  - {name: rgbd, bundled: opencv_rgbd}\n"));
  for (const std::string name : {"a\nexec touch PWNED\n#", "a\rb",
                                 "a\x01"
                                 "b"}) {
    const fs::path out = dir.path() / name;
    std::string err;
    EXPECT_EQ(InjectionRun({"benchmark", spec, "--out", out.string(), "--slurm", "--quiet"},
                           dir.path(), 600, &err),
              2)
        << err;
    EXPECT_NE(err.find("--out: the output folder"), std::string::npos) << err;
    EXPECT_NE(err.find("control character"), std::string::npos) << err;
    EXPECT_FALSE(fs::exists(out));
  }
  EXPECT_EQ(InjectedFiles(dir.path(), "array.sbatch"), std::vector<std::string>{});
  EXPECT_EQ(InjectedFiles(dir.path(), "PWNED"), std::vector<std::string>{});
}

TEST(BenchmarkInjection, SlurmScriptQuotesEveryValueAndRunsTheWorkerLiterally) {
  TempDir dir;
  BenchmarkSpec spec;
  spec.name = "t";
  spec.file = (dir.path() / "spec $(touch SINJ1) `touch SINJ2` ;touch SINJ3 'x\".yaml").string();
  spec.render_threads = 2;
  spec.sbatch_lines = {"#SBATCH --time=00:10:00"};
  const std::string out = (dir.path() / "out").string();
  const std::string script = SlurmBatchScript(spec, out, "/bin/echo", {0, 2});
  EXPECT_NE(script.find("\n#SBATCH --array=0,2\n"), std::string::npos) << script;
  EXPECT_NE(script.find("\n#SBATCH --output=" + out + "/slurm/%A_%a.out\n"), std::string::npos)
      << script;
  EXPECT_NE(script.find("\n#SBATCH --cpus-per-task=2\n#SBATCH --time=00:10:00\n"),
            std::string::npos)
      << script;
  // the array task's command line, run by bash as Slurm would: every word arrives literally
  const std::string file = dir.Write("array.sbatch", "cd " + dir.str() + "\n" + script);
  setenv("SLURM_ARRAY_TASK_ID", "2", 1);
  const std::optional<std::string> got = CaptureCommand({"/bin/bash", file});
  unsetenv("SLURM_ARRAY_TASK_ID");
  ASSERT_TRUE(got) << script;
  EXPECT_EQ(*got, "benchmark " + spec.file + " --out " + out + " --job 2 --quiet\n");
  EXPECT_EQ(InjectedFiles(dir.path(), "SINJ"), std::vector<std::string>{});
  // an --out with command substitutions (no blank: #SBATCH --output could not carry one)
  // reaches the worker as one literal argument: placeholders are filled there, without a shell
  const std::string odd_out = (dir.path() / "o$(touch${IFS}SINJ4)`touch${IFS}SINJ5`;x").string();
  const std::string odd = dir.Write(
      "odd.sbatch", "cd " + dir.str() + "\n" + SlurmBatchScript(spec, odd_out, "/bin/echo", {1}));
  setenv("SLURM_ARRAY_TASK_ID", "1", 1);
  const std::optional<std::string> odd_got = CaptureCommand({"/bin/bash", odd});
  unsetenv("SLURM_ARRAY_TASK_ID");
  ASSERT_TRUE(odd_got);
  EXPECT_EQ(*odd_got, "benchmark " + spec.file + " --out " + odd_out + " --job 1 --quiet\n");
  EXPECT_EQ(InjectedFiles(dir.path(), "SINJ"), std::vector<std::string>{});
  // a spec without `name:` is named after its file: sbatch would read blanks on the #SBATCH
  // line as the start of more options, so only name characters reach it
  BenchmarkSpec stem = spec;
  stem.name = "a b --chdir=/ x$(y)";
  const std::string stem_script = SlurmBatchScript(stem, out, "/bin/echo", {0});
  EXPECT_NE(stem_script.find("\n#SBATCH --job-name=penumbra-a_b_--chdir___x__y_\n"),
            std::string::npos)
      << stem_script;

  // control characters anywhere, and what an #SBATCH --output line cannot carry, are refused
  for (const std::string bad : {"\n", "\r", "\x01", "\x7f", " ", "#", "%", "\"", "'", "\\"}) {
    try {
      SlurmBatchScript(spec, out + "/a" + bad + "b", "/bin/echo", {0});
      ADD_FAILURE() << "accepted --out with byte " << static_cast<int>(bad[0]);
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), "--out");
    }
  }
  BenchmarkSpec newline_spec = spec;
  newline_spec.file = dir.str() + "/x\nexec touch PWNED\n.yaml";
  try {
    SlurmBatchScript(newline_spec, out, "/bin/echo", {0});
    ADD_FAILURE() << "accepted a spec path with a newline";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.key(), "spec");
    EXPECT_NE(std::string(e.what()).find("control character"), std::string::npos) << e.what();
  }
  EXPECT_THROW(SlurmBatchScript(spec, out, "/bin/ec\nho", {0}), ConfigError);
  BenchmarkSpec cr_line = spec;
  cr_line.sbatch_lines = {"#SBATCH --time=1\rexec touch PWNED"};
  EXPECT_THROW(SlurmBatchScript(cr_line, out, "/bin/echo", {0}), ConfigError);
}

}  // namespace
}  // namespace penumbra

// `penumbra benchmark` interrupted, through the real binary: SIGINT while methods
// run exits 130, every method process is gone, and no job folder is left half-written
// (interrupted jobs are removed, the report holds only finished jobs); SIGTERM while a route
// is being recorded exits 143 at once and keeps no partial recording; SIGINT during a nav
// episode stops its simulator and its method.

#include <gtest/gtest.h>
#include <signal.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/campaign/child_process.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;
using testing::ReadAll;
using testing::TempDir;

std::string InterruptSpec(double duration_sec, const std::string& methods, int trials) {
  return std::string("name: intr\nworlds:\n  - name: room\n    file: ") + PENUMBRA_SOURCE_DIR +
         "/worlds/default.yaml\n    duration_sec: " + std::to_string(duration_sec) +
         "\n    camera: {name: cam, attach: go1/camera_mount, width: 64, height: 48, fovy_deg: "
         "70, rate_hz: 10}\nconditions: [none]\ntrials: " +
         std::to_string(trials) + "\nmethods:\n" + methods + "render: {threads: 1}\nworkers: 2\n";
}

// true when process `pid` exists and is not a zombie
bool ProcessAlive(int pid) {
  if (kill(pid, 0) != 0) return false;
  const std::string stat = ReadAll("/proc/" + std::to_string(pid) + "/stat");
  const size_t paren = stat.rfind(')');
  return paren != std::string::npos && paren + 2 < stat.size() && stat[paren + 2] != 'Z';
}

// polls `done` every 100 ms until it holds or `limit_sec` passes
template <typename F>
bool WaitUntil(double limit_sec, F&& done) {
  const auto until = std::chrono::steady_clock::now() + std::chrono::duration<double>(limit_sec);
  while (!done()) {
    if (std::chrono::steady_clock::now() > until) return false;
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  return true;
}

std::vector<std::string> FilesNamed(const fs::path& root, const std::string& suffix) {
  std::vector<std::string> found;
  std::error_code ec;
  for (auto it = fs::recursive_directory_iterator(root, ec);
       it != fs::recursive_directory_iterator(); it.increment(ec)) {
    const std::string name = it->path().filename().string();
    if (name.size() >= suffix.size() &&
        name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
      found.push_back(it->path().string());
  }
  return found;
}

TEST(BenchmarkInterrupt, SigintStopsWorkersAndMethodsAndLeavesNoPartialJob) {
  TempDir dir;
  // each method records its pid (sh execs sleep: the same process) and hangs
  const std::string spec = dir.Write(
      "spec.yaml",
      InterruptSpec(1, "  - {name: hang, command: \"sh -c 'echo $$ > pid.txt; exec sleep 300'\"}\n",
                    2));
  const fs::path out = dir.path() / "out";
  ChildProcess bench({PENUMBRA_BINARY, "benchmark", spec, "--out", out.string(), "--quiet"},
                     dir.str(), (dir.path() / "stdout.txt").string(),
                     (dir.path() / "stderr.txt").string());
  std::vector<int> methods;
  const bool both_running = WaitUntil(600, [&] {
    if (bench.Exited()) return true;
    methods.clear();
    for (const char* job : {"room__none__t1", "room__none__t2"}) {
      const std::string pid = ReadAll(out / "jobs" / job / "hang" / "pid.txt");
      if (pid.empty() || pid.back() != '\n') return false;
      methods.push_back(std::stoi(pid));
    }
    return true;
  });
  ASSERT_TRUE(both_running) << ReadAll(dir.path() / "stderr.txt");
  ASSERT_FALSE(bench.Exited()) << bench.Describe() << ReadAll(dir.path() / "stderr.txt");
  for (int pid : methods) ASSERT_TRUE(ProcessAlive(pid)) << pid;

  ASSERT_EQ(kill(bench.pid(), SIGINT), 0);
  const bool exited = bench.WaitFor(120);
  if (!exited) bench.TerminateAndWait(5);
  ASSERT_TRUE(exited) << "still running 120 s after SIGINT";
  const std::string err = ReadAll(dir.path() / "stderr.txt");
  EXPECT_EQ(bench.exit_code(), 130) << bench.Describe() << "\n" << err;
  EXPECT_NE(err.find("interrupted by SIGINT"), std::string::npos) << err;
  // the methods (grandchildren, in their own process groups) were stopped
  for (int pid : methods) EXPECT_TRUE(WaitUntil(30, [&] { return !ProcessAlive(pid); })) << pid;
  // no job is marked finished and no interrupted job's folder is left behind
  EXPECT_EQ(FilesNamed(out, "result.json"), std::vector<std::string>{});
  std::error_code ec;
  EXPECT_TRUE(!fs::exists(out / "jobs") || fs::is_empty(out / "jobs", ec))
      << FilesNamed(out / "jobs", "").size() << " entries left in jobs/";
  EXPECT_EQ(FilesNamed(out, ".tmp"), std::vector<std::string>{});
  // the report covers the finished jobs: none
  const std::string csv = ReadAll(out / "results.csv");
  EXPECT_EQ(std::count(csv.begin(), csv.end(), '\n'), 1) << csv;
  EXPECT_TRUE(fs::is_regular_file(out / "report.md"));
}

TEST(BenchmarkInterrupt, SigtermWhileRecordingARouteExits143AndKeepsNoPartialRecording) {
  TempDir dir;
  // an hour of route: the recording is what runs when the signal comes
  const std::string spec =
      dir.Write("spec.yaml", InterruptSpec(3600, "  - {name: rgbd, bundled: opencv_rgbd}\n", 1));
  const fs::path out = dir.path() / "out";
  ChildProcess bench({PENUMBRA_BINARY, "benchmark", spec, "--out", out.string(), "--quiet"},
                     dir.str(), (dir.path() / "stdout.txt").string(),
                     (dir.path() / "stderr.txt").string());
  ASSERT_TRUE(WaitUntil(300, [&] {
    return ReadAll(dir.path() / "stderr.txt").find("recording the route") != std::string::npos ||
           bench.Exited();
  }));
  ASSERT_FALSE(bench.Exited()) << ReadAll(dir.path() / "stderr.txt");
  ASSERT_EQ(kill(bench.pid(), SIGTERM), 0);
  const bool exited = bench.WaitFor(120);
  if (!exited) bench.TerminateAndWait(5);
  ASSERT_TRUE(exited) << "still recording 120 s after SIGTERM";
  const std::string err = ReadAll(dir.path() / "stderr.txt");
  EXPECT_EQ(bench.exit_code(), 143) << bench.Describe() << "\n" << err;
  EXPECT_NE(err.find("interrupted by SIGTERM while recording the route of world 'room'"),
            std::string::npos)
      << err;
  std::error_code ec;
  EXPECT_TRUE(fs::is_empty(out / "recordings", ec)) << FilesNamed(out / "recordings", "").size();
  EXPECT_FALSE(fs::exists(out / "jobs"));
}

// pids of the processes whose command line mentions `text`
std::vector<int> ProcessesMentioning(const std::string& text) {
  std::vector<int> found;
  std::error_code ec;
  for (const auto& e : fs::directory_iterator("/proc", ec)) {
    const std::string name = e.path().filename().string();
    if (name.find_first_not_of("0123456789") != std::string::npos) continue;
    std::string cmdline = ReadAll(e.path() / "cmdline");
    std::replace(cmdline.begin(), cmdline.end(), '\0', ' ');
    if (cmdline.find(text) != std::string::npos && ProcessAlive(std::stoi(name)))
      found.push_back(std::stoi(name));
  }
  return found;
}

TEST(BenchmarkInterrupt, SigintDuringANavEpisodeStopsTheRunAndTheMethod) {
  TempDir dir;
  const std::string spec = dir.Write(
      "nav.yaml", std::string("kind: nav\nname: nav_intr\nworlds:\n  - name: target\n    file: ") +
                      PENUMBRA_SOURCE_DIR +
                      "/worlds/quadruped_target.yaml\n    robot: quadruped\n    episodes:\n"
                      "      - {name: ahead, goal: [3, 0], timeout_sec: 30}\n"
                      "conditions: [none]\ntrials: 1\nmethods:\n"
                      "  - {name: hang, command: \"sh -c 'echo $$ > pid.txt; exec sleep 300'\"}\n");
  const fs::path out = dir.path() / "out";
  ChildProcess bench({PENUMBRA_BINARY, "benchmark", spec, "--out", out.string(), "--quiet"},
                     dir.str(), (dir.path() / "stdout.txt").string(),
                     (dir.path() / "stderr.txt").string());
  const fs::path pid_file = out / "jobs" / "target__ahead__none__hang__t1" / "hang" / "pid.txt";
  ASSERT_TRUE(WaitUntil(300, [&] {
    const std::string pid = ReadAll(pid_file);
    return bench.Exited() || (!pid.empty() && pid.back() == '\n');
  }));
  ASSERT_FALSE(bench.Exited()) << bench.Describe() << ReadAll(dir.path() / "stderr.txt");
  const int method = std::stoi(ReadAll(pid_file));
  // the simulator of the episode runs too (its command line names the job's run folder)
  const std::vector<int> runs = ProcessesMentioning((out / "jobs").string());
  ASSERT_FALSE(runs.empty());

  ASSERT_EQ(kill(bench.pid(), SIGINT), 0);
  const bool exited = bench.WaitFor(120);
  if (!exited) bench.TerminateAndWait(5);
  ASSERT_TRUE(exited) << "still running 120 s after SIGINT";
  EXPECT_EQ(bench.exit_code(), 130) << ReadAll(dir.path() / "stderr.txt");
  EXPECT_TRUE(WaitUntil(30, [&] { return !ProcessAlive(method); })) << method;
  for (int pid : runs) EXPECT_TRUE(WaitUntil(30, [&] { return !ProcessAlive(pid); })) << pid;
  EXPECT_EQ(ProcessesMentioning(out.string()), std::vector<int>{});
  std::error_code ec;
  EXPECT_TRUE(!fs::exists(out / "jobs") || fs::is_empty(out / "jobs", ec));
  EXPECT_EQ(FilesNamed(out, "result.json"), std::vector<std::string>{});
}

}  // namespace
}  // namespace penumbra

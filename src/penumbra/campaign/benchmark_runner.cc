#include "penumbra/campaign/benchmark_runner.h"

#include <fcntl.h>
#include <fmt/format.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <string.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <sstream>
#include <thread>

#include "penumbra/campaign/benchmark_job.h"
#include "penumbra/campaign/benchmark_report.h"
#include "penumbra/campaign/benchmark_text.h"
#include "penumbra/campaign/child_process.h"
#include "penumbra/campaign/nav_job.h"
#include "penumbra/campaign/nav_report.h"
#include "penumbra/campaign/shell_quote.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace fs = std::filesystem;
namespace {

using namespace benchmark_text;  // NOLINT: module-internal helpers

using Clock = std::chrono::steady_clock;

std::string Hms(double sec) {
  const long s = std::lround(std::max(0.0, sec));
  char buf[32];
  if (s >= 3600)
    snprintf(buf, sizeof buf, "%ld:%02ld:%02ld", s / 3600, (s / 60) % 60, s % 60);
  else
    snprintf(buf, sizeof buf, "%ld:%02ld", s / 60, s % 60);
  return buf;
}

bool Finished(const std::string& out, const BenchmarkJob& j) {
  std::error_code ec;
  return fs::is_regular_file(JobResultPath(out, j), ec);
}

// one line of progress: done / all, elapsed, ETA from the mean time of the jobs done here
void Progress(bool on, size_t done, size_t all, size_t done_here, size_t failed,
              Clock::time_point start) {
  if (!on) return;
  const double elapsed = std::chrono::duration<double>(Clock::now() - start).count();
  const std::string eta =
      done_here > 0 && done < all ? ", ETA " + Hms(elapsed / done_here * (all - done)) : "";
  const int width = 30;
  const int filled = all ? static_cast<int>(width * done / all) : width;
  spdlog::info("benchmark [{}{}] {}/{} jobs{}, {} elapsed{}", std::string(filled, '#'),
               std::string(width - filled, '.'), done, all,
               failed ? fmt::format(" ({} failed)", failed) : "", Hms(elapsed), eta);
}

pid_t SpawnWorker(const BenchmarkOptions& o, const std::string& spec_path, const BenchmarkJob& j,
                  const fs::path& log) {
  const pid_t parent = getpid();
  const pid_t pid = fork();
  if (pid < 0) throw Error(std::string("cannot start a worker: ") + strerror(errno));
  if (pid == 0) {
    // its own process group: a terminal's Ctrl-C reaches only the harness, which stops each
    // worker once (SIGTERM); SIGTERM too when the harness dies
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    const int fd = open(log.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
    const int in = open("/dev/null", O_RDONLY | O_CLOEXEC);
    if (fd < 0 || in < 0) _exit(127);
    dup2(in, 0);
    dup2(fd, 1);
    dup2(fd, 2);
    const std::string index = std::to_string(j.index);
    std::vector<const char*> argv = {
        o.penumbra_binary.c_str(), "benchmark", spec_path.c_str(), "--out",
        o.out_dir.c_str(),         "--job",     index.c_str(),     "--quiet"};
    if (!o.backend.empty()) {
      argv.push_back("--backend");
      argv.push_back(o.backend.c_str());
    }
    argv.push_back(nullptr);
    execv(o.penumbra_binary.c_str(), const_cast<char* const*>(argv.data()));
    _exit(127);
  }
  setpgid(pid, pid);
  return pid;
}

// removes the folder of a job that did not finish (no result.json): partial outputs of an
// interrupted job
void RemoveUnfinished(const std::string& out, const BenchmarkJob& j) {
  if (Finished(out, j)) return;
  std::error_code ec;
  fs::remove_all(JobFolder(out, j), ec);
}

int StopSignal(const std::atomic<int>* stop) { return stop ? stop->load() : 0; }

std::string SignalName(int sig) { return sig == SIGTERM ? "SIGTERM" : "SIGINT"; }

// runs the unfinished jobs as local worker processes; returns the ids of jobs whose worker
// failed
std::vector<std::string> RunLocal(const BenchmarkOptions& o, const BenchmarkSpec& spec,
                                  const std::vector<BenchmarkJob>& jobs, int workers,
                                  Clock::time_point start) {
  std::vector<const BenchmarkJob*> pending;
  size_t done = 0;
  for (const BenchmarkJob& j : jobs)
    if (Finished(o.out_dir, j))
      ++done;
    else
      pending.push_back(&j);
  if (done > 0) spdlog::info("{} of {} jobs finished earlier: skipped", done, jobs.size());
  fs::create_directories(fs::path(o.out_dir) / "logs");
  std::map<pid_t, const BenchmarkJob*> running;
  std::vector<std::string> failed;
  size_t next = 0, done_here = 0;
  bool stopping = false;
  Progress(o.progress, done, jobs.size(), 0, 0, start);
  while (next < pending.size() || !running.empty()) {
    if (!stopping && StopSignal(o.stop_request) != 0) {
      stopping = true;
      if (!running.empty())
        spdlog::warn("{}: stopping {} running job(s); their partial folders are removed",
                     SignalName(StopSignal(o.stop_request)), running.size());
      for (const auto& [pid, job] : running) kill(pid, SIGTERM);
    }
    while (!stopping && next < pending.size() && running.size() < static_cast<size_t>(workers)) {
      const BenchmarkJob* j = pending[next++];
      running[SpawnWorker(o, spec.file, *j, fs::path(o.out_dir) / "logs" / (j->id + ".log"))] = j;
    }
    if (stopping && running.empty()) break;
    int status = 0;
    const pid_t pid = waitpid(-1, &status, WNOHANG);
    if (pid <= 0) {
      std::this_thread::sleep_for(std::chrono::milliseconds(50));
      continue;
    }
    const auto it = running.find(pid);
    if (it == running.end()) continue;
    const BenchmarkJob* j = it->second;
    running.erase(it);
    const bool ok = WIFEXITED(status) && WEXITSTATUS(status) == 0 && Finished(o.out_dir, *j);
    if (stopping) RemoveUnfinished(o.out_dir, *j);
    if (!ok && !stopping) {
      failed.push_back(j->id);
      spdlog::error("job {} failed ({}); log: {}", j->id,
                    WIFEXITED(status) ? "exit " + std::to_string(WEXITSTATUS(status))
                                      : "signal " + std::to_string(WTERMSIG(status)),
                    (fs::path(o.out_dir) / "logs" / (j->id + ".log")).string());
    }
    if (ok) ++done;
    ++done_here;
    Progress(o.progress, done, jobs.size(), done_here, failed.size(), start);
  }
  return failed;
}

std::vector<std::string> RunSlurm(const BenchmarkOptions& o, const BenchmarkSpec& spec,
                                  const std::vector<BenchmarkJob>& jobs, Clock::time_point start) {
  std::vector<int> pending;
  for (const BenchmarkJob& j : jobs)
    if (!Finished(o.out_dir, j)) pending.push_back(j.index);
  if (pending.size() < jobs.size())
    spdlog::info("{} of {} jobs finished earlier: not submitted", jobs.size() - pending.size(),
                 jobs.size());
  if (pending.empty()) return {};
  if (FindOnPath("sbatch").empty())
    throw ConfigError("", 0, "--slurm",
                      "sbatch not found; expected Slurm's client commands (slurm-client) on PATH");
  const fs::path dir = fs::path(o.out_dir) / "slurm";
  fs::create_directories(dir);
  const fs::path script = dir / "array.sbatch";
  WriteText(script, SlurmBatchScript(spec, o.out_dir, o.penumbra_binary, pending, o.backend));
  int code = 0;
  const std::optional<std::string> submitted =
      CaptureCommand({"sbatch", "--parsable", script.string()}, /*merge_stderr=*/true, &code);
  if (!submitted)
    throw Error("sbatch " + script.string() + " failed (exit " + std::to_string(code) + ")");
  // --parsable prints "ID" or "ID;CLUSTER" (after any warning lines on stderr): the last line
  // that is one, and only digits reach scancel / squeue
  std::string job_id;
  std::istringstream lines(*submitted);
  for (std::string line; std::getline(lines, line);) {
    const std::string id = line.substr(0, line.find(';'));
    if (!id.empty() && id.find_first_not_of("0123456789") == std::string::npos) job_id = id;
  }
  if (job_id.empty())
    throw Error("sbatch " + script.string() + " answered '" + SanitizeForMessage(*submitted, 200) +
                "'; expected a job id");
  spdlog::info("submitted Slurm job array {} ({} tasks): {}", job_id, pending.size(),
               script.string());
  size_t last = SIZE_MAX;
  for (;;) {
    if (StopSignal(o.stop_request) != 0) {
      CaptureCommand({"scancel", job_id});
      spdlog::warn("{}: Slurm job array {} cancelled", SignalName(StopSignal(o.stop_request)),
                   job_id);
      return {};
    }
    const std::optional<std::string> queued =
        CaptureCommand({"squeue", "-h", "-j", job_id, "-o", "%i"});
    size_t done = 0;
    for (const BenchmarkJob& j : jobs) done += Finished(o.out_dir, j) ? 1 : 0;
    if (done != last)
      Progress(o.progress, done, jobs.size(), done - (jobs.size() - pending.size()), 0, start);
    last = done;
    if (queued && queued->find_first_not_of(" \n") == std::string::npos) break;
    std::this_thread::sleep_for(
        std::chrono::milliseconds(static_cast<int>(spec.slurm_poll_sec * 1000)));
  }
  std::vector<std::string> failed;
  for (int i : pending)
    if (!Finished(o.out_dir, jobs[i])) {
      failed.push_back(jobs[i].id);
      spdlog::error("job {} (array task {}) left no result; log: {}", jobs[i].id, i,
                    (dir / (job_id + "_" + std::to_string(i) + ".out")).string());
    }
  return failed;
}

}  // namespace

void CheckSlurmPaths(const std::string& out_dir, const std::string& spec_file,
                     const std::string& penumbra_binary) {
  const auto check = [](const std::string& key, const std::string& what, const std::string& v) {
    if (const std::optional<size_t> at = FindControlCharacter(v))
      throw ConfigError("", 0, key,
                        what + " '" + SanitizeForMessage(v, 200) +
                            "' holds a control character (byte " + std::to_string(*at) +
                            ": newline, carriage return, NUL, tab or another below 0x20) that a "
                            "Slurm batch script cannot carry; expected a path without control "
                            "characters");
  };
  check("--out", "the output folder", out_dir);
  check("spec", "the spec file", spec_file);
  check("binary", "the penumbra binary", penumbra_binary);
  const size_t bad = out_dir.find_first_of(" \t\"'\\#%");
  if (bad != std::string::npos)
    throw ConfigError("", 0, "--out",
                      "the output folder '" + SanitizeForMessage(out_dir, 200) + "' holds '" +
                          out_dir[bad] + "' (byte " + std::to_string(bad) +
                          "), which the batch script's #SBATCH --output line cannot carry (blanks, "
                          "quotes, \\, # and % have a meaning there); expected another --out for "
                          "--slurm");
}

std::string SlurmBatchScript(const BenchmarkSpec& spec, const std::string& out_dir,
                             const std::string& penumbra_binary, const std::vector<int>& indices,
                             const std::string& backend) {
  std::string array;
  for (int i : indices) {
    if (!array.empty()) array += ',';
    array += std::to_string(i);
  }
  const std::string out = fs::absolute(out_dir).lexically_normal().string();
  CheckSlurmPaths(out, spec.file, penumbra_binary);
  for (const std::string& l : spec.sbatch_lines)
    if (FindControlCharacter(l) || l.rfind("#SBATCH", 0) != 0)
      throw ConfigError(spec.file, 0, "slurm.sbatch",
                        "'" + SanitizeForMessage(l, 200) +
                            "'; expected one '#SBATCH ...' line without control characters");
  // the name is the spec file's stem when it has no `name:`: only name characters reach the
  // #SBATCH line (sbatch splits it at blanks into options)
  std::string job_name = spec.name;
  for (char& c : job_name)
    if (!((c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
          c == '-'))
      c = '_';
  std::string s = fmt::format(
      "#!/bin/bash\n#SBATCH --job-name=penumbra-{}\n#SBATCH --array={}\n#SBATCH "
      "--output={}/slurm/%A_%a.out\n"
      "#SBATCH --cpus-per-task={}\n",
      job_name, array, out, spec.render_threads > 0 ? spec.render_threads : 1);
  for (const std::string& l : spec.sbatch_lines) s += fmt::format("{}\n", l);
  s += "# one benchmark job (world x condition x trial) per array task; docs/benchmarks.md\n";
  s += fmt::format("exec {} benchmark {} --out {} --job \"$SLURM_ARRAY_TASK_ID\" --quiet{}\n",
                   ShellQuote(penumbra_binary), ShellQuote(spec.file), ShellQuote(out),
                   backend.empty() ? "" : " --backend " + ShellQuote(backend));
  return s;
}

int RunBenchmarkWorker(const std::string& spec_path, const std::string& out_dir, int index,
                       const std::string& penumbra_binary, const std::atomic<int>* stop_request,
                       const std::string& backend) {
  const BenchmarkSpec spec = LoadBenchmarkSpec(spec_path);
  const fs::path copy = fs::path(out_dir) / "spec.yaml";
  std::error_code ec;
  if (!fs::is_regular_file(copy, ec) || ReadText(copy) != ReadText(spec.file))
    throw ConfigError(spec.file, 0, "",
                      "differs from " + copy.string() +
                          " (or that is missing); expected the spec the benchmark in '" + out_dir +
                          "' was started with");
  const std::vector<BenchmarkJob> jobs = PlanBenchmarkJobs(spec);
  if (index < 0 || index >= static_cast<int>(jobs.size()))
    throw ConfigError("", 0, "--job",
                      "index " + std::to_string(index) + " out of range; expected 0.." +
                          std::to_string(jobs.size() - 1));
  BenchmarkJobContext context;
  context.out_dir = out_dir;
  context.penumbra_binary = penumbra_binary;
  context.stop_request = stop_request;
  context.backend = backend;
  const BenchmarkJob& job = jobs[index];
  try {
    if (spec.kind == "nav") {
      const NavRow r = RunNavJob(spec, job, context);
      spdlog::info(
          "{} {} {} {} trial {}: {} ({}), success {}, collisions {} (+ {} by agents), goal "
          "distance {} m",
          r.world, r.episode, r.condition, r.method, r.trial, r.status, r.detail, r.success ? 1 : 0,
          r.collisions, r.agent_contacts, r.final_goal_distance_m);
      return 0;
    }
    const std::vector<BenchmarkRow> rows = RunBenchmarkJob(spec, job, context);
    for (const BenchmarkRow& r : rows)
      spdlog::info("{} {} {} trial {}: {} ({}) ATE {}", r.world, r.condition, r.method, r.trial,
                   r.status, r.detail, r.ate_rmse_m);
    return 0;
  } catch (const Error& e) {
    // a stop turns whatever the job was doing into an interruption: its folder goes
    const int sig = StopSignal(stop_request);
    if (sig == 0) throw;
    RemoveUnfinished(out_dir, job);
    spdlog::warn("{}: {}; its folder {} is removed (the same benchmark command runs it again)",
                 SignalName(sig), e.what(), JobFolder(out_dir, job));
    return 128 + sig;
  }
}

int RunBenchmark(const BenchmarkOptions& o) {
  const Clock::time_point start = Clock::now();
  const BenchmarkSpec spec = LoadBenchmarkSpec(o.spec_path);
  if (o.out_dir.empty()) throw ConfigError("", 0, "--out", "expected an output folder");
  // a path the batch script cannot carry is refused before anything is written
  if (o.slurm)
    CheckSlurmPaths(fs::absolute(o.out_dir).lexically_normal().string(), spec.file,
                    o.penumbra_binary);
  const fs::path out(o.out_dir);
  const fs::path copy = out / "spec.yaml";
  std::error_code ec;
  if (o.force)
    for (const char* p : {"spec.yaml", "recordings", "jobs", "logs", "slurm", "plots",
                          "results.csv", "summary.md", "summary.csv", "report.md"})
      fs::remove_all(out / p);
  if (fs::is_regular_file(copy, ec) && ReadText(copy) != ReadText(spec.file))
    throw ConfigError(
        "", 0, "--out",
        "'" + o.out_dir + "' holds the results of another spec (its spec.yaml differs from " +
            spec.file +
            "); expected the same spec to resume, --force to start again, or another folder");
  if (!fs::exists(copy, ec) && fs::exists(out, ec) && !fs::is_empty(out, ec))
    throw ConfigError(
        "", 0, "--out",
        "'" + o.out_dir + "' is not empty and holds no benchmark; expected a new or empty folder");
  fs::create_directories(out / "recordings");
  WriteText(copy, ReadText(spec.file));

  const std::vector<BenchmarkJob> jobs = PlanBenchmarkJobs(spec);
  const bool nav = spec.kind == "nav";
  if (nav)
    spdlog::info(
        "navigation benchmark '{}': {} world(s), {} condition(s), {} method(s), {} trial(s) = {} "
        "jobs (one episode each)",
        spec.name, spec.worlds.size(), spec.conditions.size(), spec.methods.size(),
        spec.seeds.size(), jobs.size());
  else
    spdlog::info(
        "benchmark '{}': {} world(s) x {} condition(s) x {} trial(s) = {} jobs, {} method(s)",
        spec.name, spec.worlds.size(), spec.conditions.size(), spec.seeds.size(), jobs.size(),
        spec.methods.size());
  // 1. the routes, recorded once (SLAM only: navigation runs closed loop)
  for (const BenchmarkWorld& w : spec.worlds) {
    if (nav) break;
    const std::string plog = RecordingPath(o.out_dir, w);
    if (fs::is_regular_file(plog, ec)) continue;
    spdlog::info("recording the route of world '{}' ({})", w.name, w.file);
    const std::string tmp = plog.substr(0, plog.size() - 5) + ".partial.plog";
    fs::remove(tmp, ec);
    try {
      o.record(w, tmp, o.stop_request);
    } catch (const Error&) {
      // a stop during the recording's set-up ends it with an error (the session's
      // SetupInterrupted): then the stop is what happened, reported below
      if (!StopSignal(o.stop_request)) throw;
    }
    if (const int sig = StopSignal(o.stop_request)) {
      fs::remove(tmp, ec);
      spdlog::warn(
          "interrupted by {} while recording the route of world '{}': the partial recording is "
          "removed, no job ran; the same command resumes",
          SignalName(sig), w.name);
      return 128 + sig;
    }
    fs::rename(tmp, plog);
  }
  // 2. the jobs
  const int workers = o.workers > 0 ? o.workers : spec.workers;
  const std::vector<std::string> failed =
      o.slurm ? RunSlurm(o, spec, jobs, start) : RunLocal(o, spec, jobs, workers, start);
  const int stop_signal = StopSignal(o.stop_request);
  // 3. the results of every finished job (also after an interruption)
  size_t n_rows = 0, n_finished = 0;
  for (const BenchmarkJob& j : jobs) n_finished += Finished(o.out_dir, j) ? 1 : 0;
  const double wall = std::chrono::duration<double>(Clock::now() - start).count();
  if (nav) {
    std::vector<NavRow> rows;
    for (const BenchmarkJob& j : jobs)
      if (Finished(o.out_dir, j)) rows.push_back(ReadNavJobResult(JobResultPath(o.out_dir, j)));
    WriteNavReport(spec, o.out_dir, rows, wall);
    n_rows = rows.size();
  } else {
    std::vector<BenchmarkRow> rows;
    for (const BenchmarkJob& j : jobs)
      if (Finished(o.out_dir, j))
        for (BenchmarkRow& r : ReadJobResult(JobResultPath(o.out_dir, j)))
          rows.push_back(std::move(r));
    WriteBenchmarkReport(spec, o.out_dir, rows, wall);
    n_rows = rows.size();
  }
  spdlog::info("{} rows -> {}/results.csv, report.md ({} wall)", n_rows, o.out_dir, Hms(wall));
  if (stop_signal != 0) {
    spdlog::warn(
        "interrupted by {}: the {} finished job(s) are kept and reported, unfinished job folders "
        "removed; the same command resumes",
        SignalName(stop_signal), n_finished);
    return 128 + stop_signal;
  }
  if (!failed.empty()) {
    spdlog::error(
        "{} job(s) failed in the harness (not a method's failure): their rows are missing",
        failed.size());
    return 1;
  }
  return 0;
}

}  // namespace penumbra

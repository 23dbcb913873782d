#include "penumbra/campaign/nav_job.h"

#include <arpa/inet.h>
#include <netinet/in.h>
#include <signal.h>
#include <spdlog/spdlog.h>
#include <sys/socket.h>
#include <unistd.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <memory>
#include <nlohmann/json.hpp>
#include <optional>
#include <random>
#include <sstream>
#include <thread>

#include "penumbra/campaign/benchmark_text.h"
#include "penumbra/campaign/child_process.h"
#include "penumbra/campaign/command_template.h"
#include "penumbra/campaign/method_process.h"
#include "penumbra/campaign/nav_metrics.h"
#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/world/adversity_preset.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra {
namespace fs = std::filesystem;
namespace {

using namespace benchmark_text;  // NOLINT: module-internal helpers

using Clock = std::chrono::steady_clock;

// true when 127.0.0.1:port can be bound now
bool PortFree(int port) {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  if (fd < 0) return false;
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(static_cast<uint16_t>(port));
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const bool ok = bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0;
  close(fd);
  return ok;
}

// a port p with p and p + 1 free on the loopback (the run's command and publish sockets);
// drawn from 20000-59999 by a generator seeded from the pid and the clock, so that workers
// started together rarely try the same one
int FreePortPair() {
  std::mt19937 rng(static_cast<unsigned>(getpid()) * 2654435761u ^
                   static_cast<unsigned>(Clock::now().time_since_epoch().count()));
  std::uniform_int_distribution<int> dist(10000, 29999);
  for (int attempt = 0; attempt < 200; ++attempt) {
    const int p = dist(rng) * 2;
    if (PortFree(p) && PortFree(p + 1)) return p;
  }
  throw Error("no free pair of loopback TCP ports found for the run's ZeroMQ sockets");
}

std::string NavNum(double v) { return FormatNumber(v); }

// the world override: the base's pose series, the robot's contacts (undebounced) and the
// spec's camera, if any
std::string OverrideYaml(const BenchmarkSpec& spec, const BenchmarkWorld& w) {
  const NavRobotProfile profile = NavProfile(w.profile);
  const NavMetricsConfig& m = spec.nav_metrics;
  std::string s = "# written by penumbra benchmark (campaign/nav_job.h)\nmetrics:\n";
  s += "  rate_hz: " + NavNum(m.pose_rate_hz) + "\n  series:\n";
  s += "    - {name: nav_base, type: body_pose, bodies: [\"" + w.robot + "/" + profile.base_body +
       "\"], rate_hz: " + NavNum(m.pose_rate_hz) + "}\n";
  s += "    - name: nav_contacts\n      type: contacts\n";
  s += "      min_force_N: " + NavNum(m.min_force_N) + "\n      debounce_sec: 0\n";
  s += "      between: [{a: \"" + w.robot + "/*\", b: \"*\"}]\n      exclude: [";
  for (size_t i = 0; i < profile.ground_parts.size(); ++i)
    s += std::string(i ? ", " : "") + "{a: \"" + w.robot + "/" + profile.ground_parts[i] +
         "\", b: \"" + m.floor + "\"}";
  s += "]\n      self_contacts: false\n      pair: body\n";
  s += "      rate_hz: " + NavNum(m.pose_rate_hz) + "\n";
  // the spec's camera replaces the world's cameras (the navigator takes the first with depth)
  if (!w.camera_yaml.empty()) s += "cameras:\n  - " + w.camera_yaml + "\n";
  return s;
}

std::vector<std::string> SplitCsv(const std::string& line) {
  std::vector<std::string> f;
  std::string cur;
  for (char c : line) {
    if (c == ',') {
      f.push_back(cur);
      cur.clear();
    } else if (c != '\r') {
      cur += c;
    }
  }
  f.push_back(cur);
  return f;
}

double ToDouble(const std::string& s, const fs::path& file) {
  try {
    size_t n = 0;
    const double v = std::stod(s, &n);
    if (n != s.size()) throw std::invalid_argument(s);
    return v;
  } catch (const std::exception&) {
    throw Error(file.string() + ": '" + s + "' is not a number");
  }
}

std::vector<NavPoseSample> ReadPoses(const fs::path& file, const std::string& body) {
  std::ifstream in(file);
  if (!in) throw Error("the run wrote no " + file.string());
  std::string line;
  std::getline(in, line);
  const std::vector<std::string> head = SplitCsv(line);
  std::map<std::string, size_t> col;
  for (size_t i = 0; i < head.size(); ++i) col[head[i]] = i;
  const std::vector<std::string> keys = {"time_sec",   body + "_x_m", body + "_y_m", body + "_z_m",
                                         body + "_qw", body + "_qx",  body + "_qy",  body + "_qz"};
  std::vector<size_t> idx;
  for (const std::string& k : keys) {
    if (!col.count(k)) throw Error(file.string() + ": no column " + k);
    idx.push_back(col[k]);
  }
  std::vector<NavPoseSample> out;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const std::vector<std::string> f = SplitCsv(line);
    if (f.size() != head.size()) break;  // a cut last row
    double v[8];
    for (int i = 0; i < 8; ++i) v[i] = ToDouble(f[idx[i]], file);
    out.push_back({v[0], v[1], v[2], v[3], v[4], v[5], v[6], v[7]});
  }
  return out;
}

std::vector<ContactInterval> ReadContacts(const fs::path& file) {
  std::ifstream in(file);
  if (!in) throw Error("the run wrote no " + file.string());
  std::string line;
  // episode,a,b,start_sec,end_sec,peak_force_N[,a_speed_toward_b_m_s,b_speed_toward_a_m_s]
  std::getline(in, line);
  const size_t columns = SplitCsv(line).size();
  std::vector<ContactInterval> out;
  while (std::getline(in, line)) {
    if (line.empty()) continue;
    const std::vector<std::string> f = SplitCsv(line);
    if (f.size() != columns || (columns != 6 && columns != 8)) break;
    ContactInterval c{f[1], f[2], ToDouble(f[3], file), ToDouble(f[4], file)};
    if (columns == 8) {
      c.a_toward_b_m_s = ToDouble(f[6], file);
      c.b_toward_a_m_s = ToDouble(f[7], file);
    }
    out.push_back(c);
  }
  return out;
}

nlohmann::json OptNum(double v) {
  return std::isfinite(v) ? nlohmann::json(v) : nlohmann::json(nullptr);
}
double NavNumOf(const nlohmann::json& j) { return j.is_number() ? j.get<double>() : NAN; }

nlohmann::json RowJson(const NavRow& r) {
  nlohmann::json path = nlohmann::json::array();
  for (const auto& [x, y] : r.path_xy) path.push_back({x, y});
  return {{"world", r.world},
          {"episode", r.episode},
          {"condition", r.condition},
          {"method", r.method},
          {"trial", r.trial},
          {"seed", r.seed},
          {"status", r.status},
          {"end", r.end},
          {"detail", r.detail},
          {"goal_x", r.goal_x},
          {"goal_y", r.goal_y},
          {"radius_m", r.radius_m},
          {"timeout_sec", r.timeout_sec},
          {"success", r.success},
          {"collisions", r.collisions},
          {"agent_contacts", r.agent_contacts},
          {"time_to_goal_sec", OptNum(r.time_to_goal_sec)},
          {"final_goal_distance_m", OptNum(r.final_goal_distance_m)},
          {"episode_time_sec", OptNum(r.episode_time_sec)},
          {"path_length_m", OptNum(r.path_length_m)},
          {"sc", r.sc},
          {"fell", r.fell},
          {"method_sec", r.method_sec},
          {"run_sec", r.run_sec},
          {"eval_sec", r.eval_sec},
          {"path_xy", path}};
}

std::string Tail(const fs::path& file, size_t bytes) {
  std::string t = ReadText(file);
  if (t.size() > bytes) t = t.substr(t.size() - bytes);
  for (char& c : t)
    if (c == '\n' || c == '\r') c = ' ';
  return t;
}

}  // namespace

std::string NavPythonPath() { return (fs::path(PENUMBRA_SOURCE_DIR) / "python").string(); }

std::vector<BenchmarkJob> PlanNavJobs(const BenchmarkSpec& spec) {
  std::vector<BenchmarkJob> jobs;
  for (size_t w = 0; w < spec.worlds.size(); ++w)
    for (size_t e = 0; e < spec.worlds[w].episodes.size(); ++e)
      for (size_t c = 0; c < spec.conditions.size(); ++c)
        for (size_t m = 0; m < spec.methods.size(); ++m)
          for (size_t t = 0; t < spec.seeds.size(); ++t) {
            BenchmarkJob j;
            j.index = static_cast<int>(jobs.size());
            j.world = w;
            j.episode = e;
            j.condition = c;
            j.method = m;
            j.trial = t;
            j.seed = spec.seeds[t];
            j.id = spec.worlds[w].name + "__" + spec.worlds[w].episodes[e].name + "__" +
                   spec.conditions[c].name + "__" + spec.methods[m].name + "__t" +
                   std::to_string(t + 1);
            jobs.push_back(j);
          }
  return jobs;
}

NavRow RunNavJob(const BenchmarkSpec& spec, const BenchmarkJob& job,
                 const BenchmarkJobContext& context) {
  const BenchmarkWorld& w = spec.worlds[job.world];
  const NavEpisode& ep = w.episodes[job.episode];
  const BenchmarkCondition& cond = spec.conditions[job.condition];
  const BenchmarkMethod& method = spec.methods[job.method];
  const NavRobotProfile profile = NavProfile(w.profile);
  const fs::path dir = fs::absolute(JobFolder(context.out_dir, job)).lexically_normal();
  fs::remove_all(dir);
  fs::create_directories(dir);
  WriteText(dir / "override.yaml", OverrideYaml(spec, w));
  // a preset whose people block the robot: the same preset with the episode's goal
  // (npcs.block_goal), so that they start near the robot's route to it; the run's command
  // line names that file, so its log (and a replay) carries it
  std::string adversity = cond.adversity;
  if (AdversityPreset preset = LoadAdversityPreset(cond.adversity);
      preset.npc_behaviour == AgentBehaviour::kBlock && preset.npc_people > 0) {
    preset.npc_block_goal = Eigen::Vector2d(ep.goal_x, ep.goal_y);
    WriteText(dir / "adversity.yaml", AdversityPresetFileText(preset));
    adversity = (dir / "adversity.yaml").string() + "#" + preset.name;
  }

  NavRow row;
  row.world = w.name;
  row.episode = ep.name;
  row.condition = cond.name;
  row.method = method.name;
  row.trial = static_cast<int>(job.trial) + 1;
  row.seed = job.seed;
  row.goal_x = ep.goal_x;
  row.goal_y = ep.goal_y;
  row.radius_m = ep.radius_m;
  row.timeout_sec = ep.timeout_sec;

  const fs::path run_dir = dir / "run";
  const fs::path work = dir / method.name;
  fs::create_directories(work);
  std::unique_ptr<ChildProcess> run, proc;
  std::string endpoint;
  const Clock::time_point start = Clock::now();
  bool wall_timeout = false, stopped = false;
  // a port taken between the check and the run's bind makes the run fail at once: try again
  for (int attempt = 0; attempt < 3; ++attempt) {
    const int port = FreePortPair();
    endpoint = "tcp://127.0.0.1:" + std::to_string(port);
    std::vector<std::string> argv = {context.penumbra_binary,
                                     "run",
                                     w.file,
                                     "--out",
                                     run_dir.string(),
                                     "--force",
                                     "--quiet",
                                     "--zmq",
                                     endpoint,
                                     "--lockstep",
                                     "--adversity",
                                     adversity,
                                     "--seed",
                                     std::to_string(job.seed),
                                     "--duration",
                                     NavNum(ep.timeout_sec),
                                     "--threads",
                                     std::to_string(spec.render_threads),
                                     "--override",
                                     (dir / "override.yaml").string()};
    if (!context.backend.empty()) {
      argv.push_back("--backend");
      argv.push_back(context.backend);
    }
    if (ep.has_start) {
      argv.push_back("--start-pose");
      argv.push_back(w.robot + "," + NavNum(ep.start_x) + "," + NavNum(ep.start_y) + "," +
                     NavNum(ep.start_yaw_deg));
    }
    fs::remove_all(run_dir);
    run = std::make_unique<ChildProcess>(argv, dir.string(), (dir / "run.log").string(),
                                         (dir / "run.log").string());
    // a bind failure shows within a moment: the run exits before it waits for a client
    if (run->WaitFor(1.0) &&
        Tail(dir / "run.log", 4000).find("Address already in use") != std::string::npos) {
      spdlog::warn("job {}: port {} taken, trying another", job.id, port);
      continue;
    }
    break;
  }
  // values are plain text inside their words: never read by a shell
  const std::map<std::string, std::string> values = {{"penumbra", context.penumbra_binary},
                                                     {"pythonpath", NavPythonPath()},
                                                     {"endpoint", endpoint},
                                                     {"goal_x", NavNum(ep.goal_x)},
                                                     {"goal_y", NavNum(ep.goal_y)},
                                                     {"radius", NavNum(ep.radius_m)},
                                                     {"timeout_sec", NavNum(ep.timeout_sec)},
                                                     {"robot", w.profile},
                                                     {"robot_name", w.robot},
                                                     {"out_dir", work.string()},
                                                     {"workdir", work.string()},
                                                     {"seed", std::to_string(job.seed)}};
  const std::vector<std::string> argv = ExpandCommandTemplate(method.command_words, values);
  WriteText(work / "command.sh", MethodCommandScript(argv, work.string()));
  proc = std::make_unique<ChildProcess>(argv, work.string(), (work / "stdout.log").string(),
                                        (work / "stderr.log").string(), /*search_path=*/true);
  // the episode: until the method exits, the run ends (sim timeout) or the wall limit
  std::optional<Clock::time_point> run_end;
  for (;;) {
    const bool method_done = proc->Exited();
    const bool run_done = run->Exited();
    if (method_done) break;
    if (run_done && !run_end) run_end = Clock::now();
    if (run_end && Since(*run_end) > 3) {
      proc->TerminateAndWait(2);
      break;
    }
    if (Since(start) > method.timeout_sec) {
      wall_timeout = true;
      proc->TerminateAndWait(2);
      break;
    }
    if (context.stop_request && context.stop_request->load() != 0) {
      stopped = true;
      proc->TerminateAndWait(2);
      break;
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  row.method_sec = proc->wall_sec();
  // the run: stopped (SIGTERM: it finishes its outputs and run.json), killed after 60 s
  run->TerminateAndWait(60);
  row.run_sec = run->wall_sec();
  if (stopped) throw JobInterrupted("job " + job.id + " interrupted during its episode");

  const Clock::time_point eval_start = Clock::now();
  const bool run_ok = NavRunDelivered(run->exit_code(), run->signal(), run_dir.string());
  std::vector<NavPoseSample> poses;
  std::vector<ContactInterval> contacts;
  std::string eval_error;
  try {
    poses = ReadPoses(run_dir / "metrics" / "nav_base.csv", w.robot + "/" + profile.base_body);
    contacts = ReadContacts(run_dir / "metrics" / "nav_contacts_episodes.csv");
    // a collision is the robot's, whichever of its parts touched: the robot is one side, and
    // an agent's limbs and wheels are the agent
    NameContactSides(w.robot, &contacts);
    if (poses.empty()) eval_error = "the run wrote no pose sample";
  } catch (const Error& e) {
    eval_error = e.what();
  }
  row.detail = "method " + proc->Describe() + (wall_timeout ? " (wall-clock timeout)" : "") +
               "; run " + run->Describe();
  if (!run_ok || !eval_error.empty()) {
    row.status = "run_failed";
    row.end = "run_failed";
    row.detail += "; " + (eval_error.empty() ? "" : eval_error + "; ") +
                  "run.log: " + Tail(dir / "run.log", 300);
  } else {
    NavEpisodeTask task;
    task.goal_x = ep.goal_x;
    task.goal_y = ep.goal_y;
    task.radius_m = ep.radius_m;
    task.timeout_sec = ep.timeout_sec;
    task.fall_height_m = profile.fall_height_m;
    task.max_tilt_deg = profile.max_tilt_deg;
    task.debounce_sec = spec.nav_metrics.debounce_sec;
    task.robot = w.robot;
    // first pass: how the episode ended per the ground truth
    const NavEpisodeMetrics probe = EvaluateNavEpisode(poses, contacts, task, true);
    const bool sim_timeout = probe.episode_time_sec >= ep.timeout_sec - 1e-6;
    if (wall_timeout)
      row.status = "timeout";
    else if (proc->signal() != 0 && !(sim_timeout && proc->signal() == SIGTERM))
      row.status = "failed";
    else if (proc->exit_code() != 0 && !sim_timeout && !probe.fell)
      row.status = "failed";
    else
      row.status = "ok";
    const NavEpisodeMetrics m = EvaluateNavEpisode(poses, contacts, task, row.status == "ok");
    row.end = m.fell         ? "fall"
              : sim_timeout  ? "sim_timeout"
              : wall_timeout ? "wall_timeout"
                             : "method_exit";
    row.success = m.success;
    row.collisions = m.collisions;
    row.agent_contacts = m.agent_contacts;
    row.time_to_goal_sec = m.success ? m.time_to_goal_sec : NAN;
    row.final_goal_distance_m = m.final_goal_distance_m;
    row.episode_time_sec = m.episode_time_sec;
    row.path_length_m = m.path_length_m;
    row.sc = m.sc;
    row.fell = m.fell;
    double next = -1;
    for (const NavPoseSample& p : poses)
      if (p.time_sec >= next) {
        row.path_xy.push_back({p.x, p.y});
        next = p.time_sec + 0.1;
      }
  }
  row.eval_sec = Since(eval_start);
  // written last and atomically (WriteText): its presence marks the job finished
  WriteText(JobResultPath(context.out_dir, job), RowJson(row).dump(1) + "\n");
  return row;
}

bool NavRunDelivered(int exit_code, int signal, const std::string& run_dir) {
  if (exit_code == 0 || exit_code == 128 + SIGTERM || exit_code == 128 + SIGINT) return true;
  // the signal's default action: the run had no handler left (it was past its end)
  if (signal != SIGTERM && signal != SIGINT) return false;
  std::error_code ec;
  return fs::is_regular_file(fs::path(run_dir) / "run.json", ec);
}

NavRow ReadNavJobResult(const std::string& path) {
  NavRow r;
  try {
    const nlohmann::json e = nlohmann::json::parse(ReadText(path));
    r.world = e.at("world");
    r.episode = e.at("episode");
    r.condition = e.at("condition");
    r.method = e.at("method");
    r.trial = e.at("trial");
    r.seed = e.at("seed");
    r.status = e.at("status");
    r.end = e.at("end");
    r.detail = e.at("detail");
    r.goal_x = e.at("goal_x");
    r.goal_y = e.at("goal_y");
    r.radius_m = e.at("radius_m");
    r.timeout_sec = e.at("timeout_sec");
    r.success = e.at("success");
    r.collisions = e.at("collisions");
    r.agent_contacts = e.value("agent_contacts", 0);  // results written before it existed
    r.time_to_goal_sec = NavNumOf(e.at("time_to_goal_sec"));
    r.final_goal_distance_m = NavNumOf(e.at("final_goal_distance_m"));
    r.episode_time_sec = NavNumOf(e.at("episode_time_sec"));
    r.path_length_m = NavNumOf(e.at("path_length_m"));
    r.sc = e.at("sc");
    r.fell = e.at("fell");
    r.method_sec = e.at("method_sec");
    r.run_sec = e.at("run_sec");
    r.eval_sec = e.at("eval_sec");
    for (const nlohmann::json& p : e.at("path_xy")) r.path_xy.push_back({p.at(0), p.at(1)});
  } catch (const nlohmann::json::exception& e) {
    throw ConfigError(path, 0, "", std::string("not a nav job result: ") + e.what());
  }
  return r;
}

}  // namespace penumbra

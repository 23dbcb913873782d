#include "penumbra/campaign/benchmark_spec.h"

#include <stdlib.h>
#include <unistd.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "penumbra/campaign/command_template.h"
#include "penumbra/campaign/shell_quote.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/replay/world_override.h"
#include "penumbra/world/adversity_preset.h"
#include "penumbra/world/world_config.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra {
namespace fs = std::filesystem;
namespace {

bool ValidName(const std::string& s) {
  if (s.empty() || s.size() > 64) return false;
  return std::all_of(s.begin(), s.end(), [](char c) {
    return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
           c == '-';
  });
}

std::string Name(const YamlReader& r) {
  const std::string s = r.String();
  if (!ValidName(s))
    r.Fail("'" + SanitizeForMessage(s, 80) + "' is not a name; expected 1-64 of A-Z a-z 0-9 _ -");
  return s;
}

double Positive(const YamlReader& r, double hi) {
  const double v = r.Double();
  if (!(v > 0 && v <= hi))
    r.Fail("out of range; expected a number in (0, " + FormatNumber(hi) + "]");
  return v;
}

AlignmentModel Align(const YamlReader& r) {
  const std::string s = r.Enum({"se3", "sim3", "none"});
  return s == "sim3"   ? AlignmentModel::kSim3
         : s == "none" ? AlignmentModel::kNone
                       : AlignmentModel::kSe3;
}

// checks that every {placeholder} of a template is known; `{{` and `}}` are literal braces
void CheckTemplate(const YamlReader& r, const std::string& text,
                   const std::vector<std::string>& known) {
  for (size_t i = 0; i < text.size(); ++i) {
    if (text[i] == '{' && i + 1 < text.size() && text[i + 1] == '{') {
      ++i;
      continue;
    }
    if (text[i] == '}' && i + 1 < text.size() && text[i + 1] == '}') {
      ++i;
      continue;
    }
    if (text[i] == '}')
      r.Fail("unmatched '}' at column " + std::to_string(i + 1) + "; write '}}' for a brace");
    if (text[i] != '{') continue;
    const size_t end = text.find('}', i);
    if (end == std::string::npos)
      r.Fail("unmatched '{' at column " + std::to_string(i + 1) + "; write '{{' for a brace");
    const std::string key = text.substr(i + 1, end - i - 1);
    if (std::find(known.begin(), known.end(), key) == known.end()) {
      std::string names;
      for (const std::string& k : known) names += (names.empty() ? "{" : ", {") + k + "}";
      r.Fail("unknown placeholder '{" + SanitizeForMessage(key, 40) +
             "}'; expected one of: " + names);
    }
    i = end;
  }
}

// the template split into words (campaign/command_template.h); a refusal names the field and
// the method
std::vector<std::string> SplitAt(const YamlReader& r, const std::string& text,
                                 const std::string& method) {
  try {
    return SplitCommandTemplate(text);
  } catch (const ConfigError& e) {
    r.Fail(e.problem() + " (method '" + method + "')");
  }
}

// a method's `command` template: not blank, only `known` placeholders; its words
void ReadCommand(const YamlReader& c, const std::vector<std::string>& known, BenchmarkMethod* m) {
  m->command = c.String();
  if (m->command.find_first_not_of(" \t") == std::string::npos)
    c.Fail("empty; expected a command line");
  CheckTemplate(c, m->command, known);
  m->command_words = SplitAt(c, m->command, m->name);
}

// a world's `file`: relative to the spec's folder `dir`, canonical; fails at the field when
// no such file exists
std::string WorldFile(const YamlReader& file, const std::string& dir) {
  fs::path p = file.String();
  if (p.is_relative()) p = fs::path(dir) / p;
  std::error_code ec;
  if (!fs::is_regular_file(p, ec))
    file.Fail("world file '" + p.string() + "' not found; expected a world file (.yaml)");
  return fs::weakly_canonical(p).string();
}

void CheckCamera(const BenchmarkWorld& w, const YamlReader& camera);
void ReadCamera(const YamlReader& cam, BenchmarkWorld* world);

BenchmarkWorld ReadWorld(const YamlReader& r, const std::string& dir) {
  r.ExpectMap({"name", "file", "duration_sec", "camera"});
  BenchmarkWorld w;
  w.line = r.line();
  w.name = Name(r.Child("name"));
  w.file = WorldFile(r.Child("file"), dir);
  if (r.Has("duration_sec")) w.duration_sec = Positive(r.Child("duration_sec"), 3600);
  ReadCamera(r.Child("camera"), &w);
  return w;
}

// the benchmark camera `cam` of world `w` (its file set): a world-file camera with rgb and
// depth outputs and, unless it says otherwise, the RealSense D435 depth model.
void ReadCamera(const YamlReader& cam, BenchmarkWorld* world) {
  BenchmarkWorld& w = *world;
  cam.ExpectMapAnyKeys();
  if (!cam.Has("name"))
    cam.Fail("no 'name'; expected a world-file camera with a name (docs/world-file.md)");
  const YamlReader cam_name = cam.Child("name");
  w.camera_name = cam_name.String();
  if (w.camera_name.empty() || w.camera_name.find_first_of(" \t\n{}[],:#") != std::string::npos)
    cam_name.Fail("expected a camera name without spaces or YAML punctuation");
  ConfigValue node = WithEntry(cam.node(), "outputs", ParseYaml("[rgb, depth]", ""));
  if (!node["depth_noise"])
    node = WithEntry(node, "depth_noise", ParseYaml("{preset: realsense_d435}", ""));
  w.camera_yaml = EmitYamlFlow(node);
  CheckCamera(w, cam);
}

BenchmarkCondition ReadCondition(const YamlReader& r, const std::string& dir,
                                 const std::string& file) {
  BenchmarkCondition c;
  if (r.node().IsScalar()) {
    const std::string spec = r.String();
    c.adversity = ResolveAdversitySpec(spec, dir, file, r.line());
    std::string stem = fs::path(spec.substr(0, spec.find('#'))).stem().string();
    if (spec.find('#') != std::string::npos) stem = spec.substr(spec.find('#') + 1);
    c.name = spec.find(".y") == std::string::npos ? spec : stem;
    if (!ValidName(c.name))
      r.Fail("cannot name the condition '" + spec + "'; write {name: NAME, adversity: SPEC}");
    return c;
  }
  r.ExpectMap({"name", "adversity"});
  c.name = Name(r.Child("name"));
  const YamlReader a = r.Child("adversity");
  c.adversity = ResolveAdversitySpec(a.String(), dir, file, a.line());
  LoadAdversityPreset(c.adversity, file, a.line());
  return c;
}

BenchmarkMethod ReadMethod(const YamlReader& r, const BenchmarkMetrics& metrics) {
  r.ExpectMap(
      {"name", "bundled", "dataset", "command", "trajectory", "format", "timeout_sec", "align"});
  BenchmarkMethod m;
  m.name = Name(r.Child("name"));
  m.align = metrics.align;
  if (r.Has("bundled") == r.Has("command"))
    r.Fail("expected exactly one of 'bundled' (a penumbra slam method) and 'command' (a template)");
  if (r.Has("bundled")) {
    m.bundled =
        r.Child("bundled").Enum({"opencv_rgbd", "opencv_icp", "opencv_rgbd_icp", "open3d_rgbd"});
    for (const char* k : {"dataset", "trajectory", "format"})
      if (r.Has(k))
        r.Child(k).Fail("not allowed with 'bundled' (a bundled method reads TUM and writes TUM)");
    m.command =
        "{penumbra} slam " + m.bundled + " {dataset} {output} --intrinsics {fx},{fy},{cx},{cy}";
    m.command_words = SplitCommandTemplate(m.command);
  } else {
    ReadCommand(r.Child("command"), MethodPlaceholders(), &m);
  }
  if (r.Has("dataset")) m.dataset = r.Child("dataset").Enum({"tum", "euroc"});
  if (r.Has("trajectory")) {
    const YamlReader t = r.Child("trajectory");
    m.trajectory = t.String();
    if (m.trajectory.empty() || fs::path(m.trajectory).is_absolute() ||
        m.trajectory.find("..") != std::string::npos)
      t.Fail("expected a file name relative to the method's work folder");
  }
  if (r.Has("format")) m.format = r.Child("format").Enum({"tum", "tum_ns"});
  if (r.Has("timeout_sec")) m.timeout_sec = Positive(r.Child("timeout_sec"), 7 * 24 * 3600.0);
  if (r.Has("align")) m.align = Align(r.Child("align"));
  return m;
}

// a method reading EuRoC gets imu0 from each world's only IMU (a benchmark names none): every
// world must have exactly one, told at the method's `dataset` before anything runs
void CheckEurocImus(const YamlReader& dataset, const std::vector<BenchmarkWorld>& worlds) {
  for (const BenchmarkWorld& w : worlds) {
    std::vector<std::string> imus;
    for (const SensorConfig& c : LoadWorldFile(w.file).sensors)
      if (c.kind() == SensorKind::kImu) imus.push_back(c.name);
    const std::string world = "world '" + w.name + "' (" + w.file + ")";
    if (imus.empty())
      dataset.Fail("EuRoC needs an IMU (imu0) and " + world +
                   " has none; expected an IMU in every world of the benchmark (`type: imu` in "
                   "its `sensors:`, docs/world-file.md), or dataset: tum");
    if (imus.size() > 1) {
      std::string list;
      for (const std::string& n : imus) list += (list.empty() ? "" : ", ") + n;
      dataset.Fail(world + " has " + std::to_string(imus.size()) + " IMUs (" + list +
                   "); the EuRoC export takes a world's only IMU, expected one");
    }
  }
}

// a ConfigError of a Validate call (key = the field) re-raised at the field's line
template <typename F>
void AtLine(const YamlReader& r, F&& f) {
  try {
    f();
  } catch (const ConfigError& e) {
    if (r.Has(e.key())) r.Child(e.key()).Fail(e.problem());
    r.Fail(e.key() + ": " + e.problem());
  }
}

NavEpisode ReadEpisode(const YamlReader& r) {
  r.ExpectMap({"name", "goal", "start", "radius", "timeout_sec"});
  NavEpisode e;
  e.line = r.line();
  e.name = Name(r.Child("name"));
  const YamlReader goal = r.Child("goal");
  const std::vector<YamlReader> g = goal.List();
  if (g.size() != 2) goal.Fail("expected [x, y] in m (world frame)");
  e.goal_x = g[0].Double();
  e.goal_y = g[1].Double();
  if (r.Has("start")) {
    const YamlReader start = r.Child("start");
    const std::vector<YamlReader> s = start.List();
    if (s.size() != 3) start.Fail("expected [x, y, yaw_deg] (m, m, deg; world frame)");
    e.has_start = true;
    e.start_x = s[0].Double();
    e.start_y = s[1].Double();
    e.start_yaw_deg = s[2].Double();
  }
  if (r.Has("radius")) e.radius_m = r.Child("radius").Double();
  if (r.Has("timeout_sec")) e.timeout_sec = r.Child("timeout_sec").Double();
  AtLine(r, [&] { e.ValidateOrThrow(); });
  return e;
}

BenchmarkWorld ReadNavWorld(const YamlReader& r, const std::string& dir) {
  r.ExpectMap({"name", "file", "robot", "profile", "camera", "episodes"});
  BenchmarkWorld w;
  w.line = r.line();
  w.name = Name(r.Child("name"));
  w.file = WorldFile(r.Child("file"), dir);
  if (r.Has("profile")) {
    std::vector<std::string_view> names;
    for (const std::string& n : NavProfileNames()) names.push_back(n);
    w.profile = r.Child("profile").Enum(names);
  }
  const YamlReader robot = r.Child("robot");
  w.robot = robot.String();
  const WorldConfig world = LoadWorldFile(w.file);
  std::string robots;
  bool found = false;
  for (const ModelConfig& m : world.models)
    if (m.is_robot) {
      robots += (robots.empty() ? "" : ", ") + m.name;
      found = found || m.name == w.robot;
    }
  if (!found)
    robot.Fail("the world has no robot '" + SanitizeForMessage(w.robot, 40) +
               "'; expected one of: " + (robots.empty() ? "(none)" : robots));
  std::set<std::string> names;
  const YamlReader episodes = r.Child("episodes");
  for (const YamlReader& e : episodes.List()) {
    w.episodes.push_back(ReadEpisode(e));
    if (!names.insert(w.episodes.back().name).second)
      e.Child("name").Fail("episode name appears twice in this world; expected unique names");
  }
  if (w.episodes.empty()) episodes.Fail("no episodes; expected at least one");
  if (r.Has("camera")) ReadCamera(r.Child("camera"), &w);
  return w;
}

BenchmarkMethod ReadNavMethod(const YamlReader& r) {
  r.ExpectMap({"name", "bundled", "command", "timeout_sec"});
  BenchmarkMethod m;
  m.name = Name(r.Child("name"));
  m.timeout_sec = 600;
  if (r.Has("bundled") == r.Has("command"))
    r.Fail("expected exactly one of 'bundled' (penumbra_nav) and 'command' (a template)");
  if (r.Has("bundled")) {
    m.bundled = r.Child("bundled").Enum({"penumbra_nav"});
    m.command = BundledNavCommand();
    m.command_words = SplitCommandTemplate(m.command);
  } else {
    ReadCommand(r.Child("command"), NavMethodPlaceholders(), &m);
  }
  if (r.Has("timeout_sec")) m.timeout_sec = Positive(r.Child("timeout_sec"), 7 * 24 * 3600.0);
  return m;
}

// the camera as a replay will take it: the world file loaded and the override the jobs write
// applied (world-file camera rules: keys, ranges, attach bodies); errors point at the spec
void CheckCamera(const BenchmarkWorld& w, const YamlReader& camera) {
  WorldConfig world = LoadWorldFile(w.file);
  std::string tmpl = (fs::temp_directory_path() / "penumbra_benchmark_camera_XXXXXX.yaml").string();
  const int fd = mkstemps(tmpl.data(), 5);
  if (fd < 0)
    throw Error("cannot create a temporary file in " + fs::temp_directory_path().string());
  close(fd);
  {
    std::ofstream out(tmpl, std::ios::binary | std::ios::trunc);
    out << "cameras:\n  - " << w.camera_yaml << "\n";
  }
  try {
    ApplyWorldOverride(world, tmpl);
  } catch (const ConfigError& e) {
    std::error_code ec;
    fs::remove(tmpl, ec);
    std::string key = e.key();
    if (key.rfind("cameras[0]", 0) == 0) key = key.substr(10);
    camera.Fail((key.empty() ? "" : key.substr(key[0] == '.' ? 1 : 0) + ": ") + e.problem());
  }
  std::error_code ec;
  fs::remove(tmpl, ec);
}

}  // namespace

const std::vector<std::string>& MethodPlaceholders() {
  static const std::vector<std::string> kKeys = {"penumbra", "dataset", "output",      "workdir",
                                                 "fx",       "fy",      "cx",          "cy",
                                                 "width",    "height",  "camera_info", "seed"};
  return kKeys;
}

BenchmarkSpec LoadBenchmarkSpec(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw ConfigError(path, 0, "", "benchmark spec not found; expected a YAML file");
  BenchmarkSpec s;
  s.file = fs::absolute(path).lexically_normal().string();
  s.dir = fs::path(s.file).parent_path().string();
  const std::string text = ReadInputFile(path, "benchmark spec");
  {
    YamlReader r(ParseYaml(text, s.file), s.file, nullptr);
    if (r.node().IsMap() && r.Has("kind")) s.kind = r.Child("kind").Enum({"slam", "nav"});
    const bool nav = s.kind == "nav";
    if (nav)
      r.ExpectMap({"kind", "name", "worlds", "conditions", "trials", "seeds", "methods", "metrics",
                   "render", "workers", "slurm"});
    else
      r.ExpectMap({"kind", "name", "worlds", "conditions", "trials", "seeds", "methods", "metrics",
                   "render", "workers", "keep_datasets", "slurm"});
    s.name = r.Has("name") ? Name(r.Child("name")) : fs::path(s.file).stem().string();
    if (nav && r.Has("metrics")) {
      const YamlReader m = r.Child("metrics");
      m.ExpectMap({"debounce_sec", "min_force_N", "pose_rate_hz", "floor"});
      if (m.Has("debounce_sec")) s.nav_metrics.debounce_sec = m.Child("debounce_sec").Double();
      if (m.Has("min_force_N")) s.nav_metrics.min_force_N = m.Child("min_force_N").Double();
      if (m.Has("pose_rate_hz")) s.nav_metrics.pose_rate_hz = m.Child("pose_rate_hz").Double();
      if (m.Has("floor")) s.nav_metrics.floor = m.Child("floor").String();
      AtLine(m, [&] { s.nav_metrics.ValidateOrThrow(); });
    } else if (r.Has("metrics")) {
      const YamlReader m = r.Child("metrics");
      m.ExpectMap({"align", "rpe_delta_sec", "max_dt_sec"});
      if (m.Has("align")) s.metrics.align = Align(m.Child("align"));
      if (m.Has("rpe_delta_sec"))
        s.metrics.rpe_delta_sec = Positive(m.Child("rpe_delta_sec"), 3600);
      if (m.Has("max_dt_sec")) s.metrics.max_dt_sec = Positive(m.Child("max_dt_sec"), 10);
    }
    std::set<std::string> names;
    const YamlReader worlds = r.Child("worlds");
    for (const YamlReader& w : worlds.List()) {
      s.worlds.push_back(nav ? ReadNavWorld(w, s.dir) : ReadWorld(w, s.dir));
      if (!names.insert(s.worlds.back().name).second)
        w.Child("name").Fail("world name appears twice; expected unique names");
    }
    if (s.worlds.empty()) worlds.Fail("no worlds; expected at least one");
    names.clear();
    const YamlReader conditions = r.Child("conditions");
    for (const YamlReader& c : conditions.List()) {
      s.conditions.push_back(ReadCondition(c, s.dir, s.file));
      if (!names.insert(s.conditions.back().name).second)
        c.Fail("condition name '" + s.conditions.back().name +
               "' appears twice; expected unique names");
    }
    if (s.conditions.empty()) conditions.Fail("no conditions; expected at least one");
    if (r.Has("trials") == r.Has("seeds"))
      r.Fail("expected exactly one of 'trials' (N: seeds 1..N) and 'seeds' (a list)");
    if (r.Has("trials")) {
      const YamlReader t = r.Child("trials");
      const int n = t.Int();
      if (n < 1 || n > 1000) t.Fail("out of range; expected an integer in [1, 1000]");
      for (int i = 1; i <= n; ++i) s.seeds.push_back(static_cast<uint64_t>(i));
    } else {
      const YamlReader seeds = r.Child("seeds");
      std::set<uint64_t> seen;
      for (const YamlReader& e : seeds.List()) {
        s.seeds.push_back(e.Uint64());
        if (!seen.insert(s.seeds.back()).second)
          e.Fail("seed appears twice; expected distinct seeds");
      }
      if (s.seeds.empty()) seeds.Fail("no seeds; expected at least one");
    }
    names.clear();
    const YamlReader methods = r.Child("methods");
    for (const YamlReader& m : methods.List()) {
      s.methods.push_back(nav ? ReadNavMethod(m) : ReadMethod(m, s.metrics));
      if (!nav && s.methods.back().dataset == "euroc") CheckEurocImus(m.Child("dataset"), s.worlds);
      if (!names.insert(s.methods.back().name).second)
        m.Child("name").Fail("method name appears twice; expected unique names");
    }
    if (s.methods.empty()) methods.Fail("no methods; expected at least one");
    if (r.Has("render")) {
      const YamlReader rr = r.Child("render");
      rr.ExpectMap({"threads", "tier"});
      if (rr.Has("threads")) {
        s.render_threads = rr.Child("threads").Int();
        if (s.render_threads < 0 || s.render_threads > 256)
          rr.Child("threads").Fail("out of range; expected an integer in [0, 256] (0 = all cores)");
      }
      if (rr.Has("tier")) s.tier = rr.Child("tier").Enum({"realtime", "pathtraced"});
    }
    if (r.Has("workers")) {
      s.workers = r.Child("workers").Int();
      if (s.workers < 1 || s.workers > 256)
        r.Child("workers").Fail("out of range; expected an integer in [1, 256]");
    }
    if (!nav && r.Has("keep_datasets")) s.keep_datasets = r.Child("keep_datasets").Bool();
    if (r.Has("slurm")) {
      const YamlReader sl = r.Child("slurm");
      sl.ExpectMap({"sbatch", "poll_sec"});
      if (sl.Has("sbatch"))
        for (const YamlReader& l : sl.Child("sbatch").List()) {
          const std::string line = l.String();
          if (line.rfind("#SBATCH", 0) != 0 || FindControlCharacter(line))
            l.Fail(
                "expected one '#SBATCH ...' line without control characters (newline, "
                "carriage return, tab, ...)");
          s.sbatch_lines.push_back(line);
        }
      if (sl.Has("poll_sec")) s.slurm_poll_sec = Positive(sl.Child("poll_sec"), 600);
    }
  }
  return s;
}

}  // namespace penumbra

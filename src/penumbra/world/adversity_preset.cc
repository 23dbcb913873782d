#include "penumbra/world/adversity_preset.h"

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>

#include "penumbra/config/param_reader.h"
#include "penumbra/config/yaml_document.h"
#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/core/output_path_policy.h"
#include "penumbra/core/text_match.h"
#include "penumbra/world/adversity_edit.h"

namespace fs = std::filesystem;

namespace penumbra {
namespace {

bool IsFileSpec(const std::string& spec) {
  const std::string path = spec.substr(0, spec.find('#'));
  const std::string ext = fs::path(path).extension().string();
  return ext == ".yaml" || ext == ".yml";
}

// reads a number and checks lo < v <= hi (open_lo) or lo <= v <= hi
double Ranged(const ParamReader& r, double lo, double hi, bool open_lo, const char* unit) {
  const double v = r.Double();
  if (open_lo ? !(v > lo && v <= hi) : !(v >= lo && v <= hi))
    r.Fail("got " + FormatNumber(v) + "; expected " + (open_lo ? "(" : "[") + FormatNumber(lo) +
           ", " + FormatNumber(hi) + "]" + (*unit ? std::string(" ") + unit : std::string()));
  return v;
}

int RangedInt(const ParamReader& r, int lo, int hi) {
  const int v = r.Int();
  if (v < lo || v > hi)
    r.Fail("got " + std::to_string(v) + "; expected an integer in [" + std::to_string(lo) + ", " +
           std::to_string(hi) + "]");
  return v;
}

AdversityPreset ReadPreset(const std::string& name, const ParamReader& r, const std::string& file) {
  static const std::regex kName("[A-Za-z0-9_-]+");
  if (auto problem = NameLengthProblem(name)) r.Fail("preset " + *problem);
  if (!std::regex_match(name, kName))
    r.Fail("preset name '" + name + "' is not valid; expected letters, digits, '_' and '-'");
  r.ExpectMap({"description", "sensors", "fog", "dust", "smoke", "rain", "snow", "lights", "npcs"});
  AdversityPreset p;
  p.name = name;
  p.file = file;
  if (const auto found = r.Find("description")) p.description = found->String();
  if (r.Has("sensors")) {
    const ParamReader s = r.Child("sensors");
    s.ExpectMap({"rgb", "depth", "lidar", "imu"});  // AdversitySensorNames
    for (const std::string& sensor : AdversitySensorNames())
      if (const auto found = s.Find(sensor)) p.sensor_effects.emplace_back(sensor, found->String());
  }
  if (r.Has("fog")) {
    const ParamReader f = r.Child("fog");
    f.ExpectMap({"mor_m", "height_falloff_per_m"});
    p.fog_mor_m = Ranged(f.Child("mor_m"), 0, 1e5, true, "m");
    if (f.Has("height_falloff_per_m"))
      p.fog_height_falloff_per_m = Ranged(f.Child("height_falloff_per_m"), 0, 10, false, "1/m");
  }
  if (r.Has("dust")) {
    const ParamReader f = r.Child("dust");
    f.ExpectMap({"mor_m"});
    p.dust_mor_m = Ranged(f.Child("mor_m"), 0, 1e5, true, "m");
  }
  if (r.Has("smoke")) {
    const ParamReader s = r.Child("smoke");
    s.ExpectMap({"sigma_t_per_m", "coverage", "extent_fraction", "height_m"});
    p.smoke_sigma_t_per_m = Ranged(s.Child("sigma_t_per_m"), 0, 100, true, "1/m");
    if (const auto found = s.Find("coverage")) p.smoke_coverage = Ranged(*found, 0, 1, false, "");
    if (s.Has("extent_fraction"))
      p.smoke_extent_fraction = Ranged(s.Child("extent_fraction"), 0, 1, true, "");
    if (const auto found = s.Find("height_m")) p.smoke_height_m = Ranged(*found, 0, 100, true, "m");
  }
  if (r.Has("rain")) {
    const ParamReader s = r.Child("rain");
    s.ExpectMap({"rate_mm_h"});
    p.rain_rate_mm_h = Ranged(s.Child("rate_mm_h"), 0, 500, true, "mm/h");
  }
  if (r.Has("snow")) {
    const ParamReader s = r.Child("snow");
    s.ExpectMap({"rate_mm_h"});
    p.snow_rate_mm_h = Ranged(s.Child("rate_mm_h"), 0, 100, true, "mm/h");
  }
  if (r.Has("lights")) {
    const ParamReader s = r.Child("lights");
    s.ExpectMap({"scale", "flicker_depth", "flicker_hz"});
    if (const auto found = s.Find("scale")) p.light_scale = Ranged(*found, 0, 1, false, "");
    if (const auto found = s.Find("flicker_depth"))
      p.flicker_depth = Ranged(*found, 0, 1, false, "");
    if (const auto found = s.Find("flicker_hz")) p.flicker_hz = Ranged(*found, 0, 100, true, "Hz");
  }
  if (r.Has("npcs")) {
    const ParamReader s = r.Child("npcs");
    s.ExpectMap({"people", "vehicles", "speed_m_s", "pause_sec", "behaviour", "clearance_m",
                 "block_goal", "contact"});
    if (const auto found = s.Find("people")) p.npc_people = RangedInt(*found, 0, 100);
    if (const auto found = s.Find("vehicles")) p.npc_vehicles = RangedInt(*found, 0, 20);
    if (const auto found = s.Find("speed_m_s")) p.npc_speed_m_s = Ranged(*found, 0, 5, true, "m/s");
    if (const auto found = s.Find("pause_sec")) p.npc_pause_sec = Ranged(*found, 0, 60, false, "s");
    if (s.Has("behaviour")) {
      const std::string b = s.Child("behaviour").Enum({"avoid", "ignore", "block"});
      p.npc_behaviour = b == "avoid"    ? AgentBehaviour::kAvoid
                        : b == "ignore" ? AgentBehaviour::kIgnore
                                        : AgentBehaviour::kBlock;
    }
    if (const auto found = s.Find("contact")) p.npc_contact = found->Bool();
    if (const auto found = s.Find("clearance_m"))
      p.npc_clearance_m = Ranged(*found, 0, 10, false, "m");
    if (const auto found = s.Find("block_goal")) {
      if (p.npc_behaviour != AgentBehaviour::kBlock)
        found->Fail(
            "a goal only for behaviour: block; expected behaviour: block or no "
            "block_goal");
      const std::vector<double> g = found->Doubles(2);
      if (std::abs(g[0]) > 1e5 || std::abs(g[1]) > 1e5)
        found->Fail("expected a world point [x, y] with |x|, |y| <= 1e5 m");
      p.npc_block_goal = Eigen::Vector2d(g[0], g[1]);
    }
  }
  return p;
}

// a number of a generated preset document (shortest text that reads back the same double)
ConfigValue PresetNumber(double v) { return ConfigValue::Scalar(FormatNumber(v)); }

// a mapping of `entries`, in order
ConfigValue PresetBlock(std::initializer_list<std::pair<const char*, ConfigValue>> entries) {
  ConfigValue m = ConfigValue::Map();
  for (const auto& [key, value] : entries) m = WithEntry(m, key, value);
  return m;
}

// the preset as the mapping of its blocks (what a preset file's entry holds)
ConfigValue PresetNode(const AdversityPreset& p) {
  ConfigValue n = ConfigValue::Map();
  if (p.fog_mor_m) {
    n = WithEntry(
        n, "fog",
        PresetBlock({{"mor_m", PresetNumber(*p.fog_mor_m)},
                     {"height_falloff_per_m", PresetNumber(p.fog_height_falloff_per_m)}}));
  }
  if (p.dust_mor_m) n = WithEntry(n, "dust", PresetBlock({{"mor_m", PresetNumber(*p.dust_mor_m)}}));
  if (p.smoke_sigma_t_per_m) {
    n = WithEntry(n, "smoke",
                  PresetBlock({{"sigma_t_per_m", PresetNumber(*p.smoke_sigma_t_per_m)},
                               {"coverage", PresetNumber(p.smoke_coverage)},
                               {"extent_fraction", PresetNumber(p.smoke_extent_fraction)},
                               {"height_m", PresetNumber(p.smoke_height_m)}}));
  }
  if (p.rain_rate_mm_h)
    n = WithEntry(n, "rain", PresetBlock({{"rate_mm_h", PresetNumber(*p.rain_rate_mm_h)}}));
  if (p.snow_rate_mm_h)
    n = WithEntry(n, "snow", PresetBlock({{"rate_mm_h", PresetNumber(*p.snow_rate_mm_h)}}));
  n = WithEntry(n, "lights",
                PresetBlock({{"scale", PresetNumber(p.light_scale)},
                             {"flicker_depth", PresetNumber(p.flicker_depth)},
                             {"flicker_hz", PresetNumber(p.flicker_hz)}}));
  n = WithEntry(
      n, "npcs",
      PresetBlock({{"people", PresetNumber(p.npc_people)},
                   {"vehicles", PresetNumber(p.npc_vehicles)},
                   {"speed_m_s", PresetNumber(p.npc_speed_m_s)},
                   {"pause_sec", PresetNumber(p.npc_pause_sec)},
                   {"behaviour", ConfigValue::Scalar(AgentBehaviourName(p.npc_behaviour))},
                   {"clearance_m", PresetNumber(p.npc_clearance_m)},
                   {"contact", ConfigValue::Scalar(p.npc_contact ? "true" : "false")}}));
  if (p.npc_block_goal) {
    const std::string goal = "[" + FormatNumber(p.npc_block_goal->x()) + ", " +
                             FormatNumber(p.npc_block_goal->y()) + "]";
    n = WithEntry(n, "npcs", WithEntry(n["npcs"], "block_goal", ParseYaml(goal, "")));
  }
  return n;
}

std::string Names(const std::vector<AdversityPreset>& presets) {
  std::string s;
  for (const AdversityPreset& p : presets) s += (s.empty() ? "" : ", ") + p.name;
  return s;
}

}  // namespace

bool AdversityPreset::empty() const {
  return !fog_mor_m && !dust_mor_m && !smoke_sigma_t_per_m && !rain_rate_mm_h && !snow_rate_mm_h &&
         light_scale == 1.0 && flicker_depth == 0.0 && npc_people == 0 && npc_vehicles == 0;
}

std::string BundledAdversityPresetsPath() {
  const fs::path source = fs::path(PENUMBRA_SOURCE_DIR) / "worlds" / "adversity" / "presets.yaml";
  std::error_code ec;
  if (fs::is_regular_file(source, ec)) return source.string();
  return "worlds/adversity/presets.yaml";  // a build moved away from its source tree
}

std::vector<AdversityPreset> LoadAdversityPresetFile(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec))
    throw ConfigError(path, 0, "",
                      "adversity preset file not found; expected an existing YAML file");
  return ParseAdversityPresets(ReadInputFile(path, "adversity preset file"), path);
}

std::vector<AdversityPreset> ParseAdversityPresets(const std::string& text,
                                                   const std::string& path) {
  std::vector<AdversityPreset> out;
  {
    const ParamReader r(ParseYaml(text, path), path, nullptr);
    r.ExpectMap({"presets"});
    const ParamReader presets = r.Child("presets");
    for (const auto& [name, p] : presets.Entries()) out.push_back(ReadPreset(name, p, path));
    if (out.empty()) presets.Fail("no presets; expected a mapping of preset names to presets");
  }
  return out;
}

std::string AdversityPresetFileText(const AdversityPreset& preset) {
  ConfigValue node = PresetNode(preset);
  if (!preset.description.empty())
    node = WithEntry(node, "description", ConfigValue::Scalar(preset.description));
  if (!preset.sensor_effects.empty()) {
    ConfigValue sensors = ConfigValue::Map();
    for (const auto& [sensor, text] : preset.sensor_effects)
      sensors = WithEntry(sensors, sensor, ConfigValue::Scalar(text));
    node = WithEntry(node, "sensors", sensors);
  }
  return "presets:\n  " + preset.name + ": " + EmitYamlFlow(node) + "\n";
}

const std::vector<std::string>& AdversitySensorNames() {
  static const std::vector<std::string> kSensors = {"rgb", "depth", "lidar", "imu"};
  return kSensors;
}

std::vector<std::string> BundledAdversityPresetNames() {
  std::vector<std::string> names;
  for (const AdversityPreset& p : LoadAdversityPresetFile(BundledAdversityPresetsPath()))
    names.push_back(p.name);
  return names;
}

std::string ResolveAdversitySpec(const std::string& spec, const std::string& base_dir,
                                 const std::string& file, int line) {
  std::string resolved = spec;
  if (IsFileSpec(spec)) {
    const size_t hash = spec.find('#');
    fs::path p(spec.substr(0, hash));
    if (p.is_relative()) p = (base_dir.empty() ? fs::current_path() : fs::path(base_dir)) / p;
    resolved = p.lexically_normal().string() + (hash == std::string::npos ? "" : spec.substr(hash));
  }
  LoadAdversityPreset(resolved, file, line);  // checks it
  return resolved;
}

const std::vector<std::string>& AdversityPresetBlocks() {
  static const std::vector<std::string> kBlocks = {"fog",  "dust",   "smoke", "rain",
                                                   "snow", "lights", "npcs"};
  return kBlocks;
}

AdversityPreset EditAdversityPreset(const AdversityPreset& base, const std::string& block,
                                    const std::string& block_yaml) {
  const std::vector<std::string>& blocks = AdversityPresetBlocks();
  if (std::find(blocks.begin(), blocks.end(), block) == blocks.end()) {
    std::string valid;
    for (const std::string& b : blocks) valid += (valid.empty() ? "" : ", ") + b;
    throw ConfigError("", 0, block, "unknown adversity block; expected one of: " + valid);
  }
  try {
    ConfigValue node = PresetNode(base);
    ConfigValue patch;
    try {
      YamlParseOptions first_only;
      first_only.single_document = false;
      patch = ParseYaml(block_yaml, "", first_only);
    } catch (const ConfigError& e) {
      if (e.problem().rfind("YAML tag", 0) == 0) throw ConfigError("", 0, block, e.problem());
      throw ConfigError("", 0, block,
                        "not a mapping (" + e.problem() + "); expected a mapping or null");
    }
    if (patch.IsNull()) {
      node = WithoutEntry(node, block);
    } else if (!patch.IsMap()) {
      throw ConfigError("", 0, block, "expected a mapping of the block's keys, or null");
    } else {
      ConfigValue target = node[block];
      if (!target.IsMap()) target = ConfigValue::Map();
      for (const ConfigEntry& e : patch.entries()) {
        if (!e.key_is_scalar)
          throw ConfigError("", 0, block,
                            "invalid value: a list or mapping as a key; expected "
                            "the block's key names");
        target = WithEntry(target, e.key, ConfigValue(e.value));
      }
      node = WithEntry(node, block, target);
    }
    AdversityPreset p = ReadPreset(base.name, ParamReader(node, "", nullptr), base.file);
    p.description = base.description;
    return p;
  } catch (const ConfigError& e) {
    throw ConfigError("", 0, e.key(), e.problem());  // lines of a generated document mean nothing
  }
}

AdversityPreset LoadAdversityPreset(const std::string& spec, const std::string& file, int line) {
  if (IsFileSpec(spec)) {
    const size_t hash = spec.find('#');
    const std::string path = spec.substr(0, hash);
    std::error_code ec;
    if (!fs::is_regular_file(path, ec))
      throw ConfigError(file, line, "adversity",
                        "preset file not found: " + path +
                            " (relative paths resolve against the world file's folder); expected "
                            "an existing preset file (.yaml)");
    const std::vector<AdversityPreset> presets = LoadAdversityPresetFile(path);
    if (hash == std::string::npos) {
      if (presets.size() != 1)
        throw ConfigError(
            file, line, "adversity",
            path + " holds " + std::to_string(presets.size()) +
                " presets; expected FILE.yaml#NAME with NAME one of: " + Names(presets));
      return presets.front();
    }
    const std::string name = spec.substr(hash + 1);
    for (const AdversityPreset& p : presets)
      if (p.name == name) return p;
    throw ConfigError(
        file, line, "adversity",
        "unknown preset '" + name + "' in " + path + "; expected one of: " + Names(presets));
  }
  const std::vector<AdversityPreset> bundled =
      LoadAdversityPresetFile(BundledAdversityPresetsPath());
  for (const AdversityPreset& p : bundled)
    if (p.name == spec) return p;
  throw ConfigError(file, line, "adversity",
                    "unknown preset '" + spec + "'; expected one of: " + Names(bundled) +
                        ", or a preset file (FILE.yaml or FILE.yaml#NAME)");
}

ClientAdversityPreset LoadClientAdversityPreset(const std::string& spec,
                                                const std::filesystem::path& folder,
                                                std::string* detail) {
  ClientAdversityPreset out;
  if (!IsFileSpec(spec)) {
    out.preset = LoadAdversityPreset(spec);  // a bundled name; errors quote only the spec
    out.spec = spec;
    return out;
  }
  const size_t hash = spec.find('#');
  const std::string relative = spec.substr(0, hash);
  const std::string shown = SanitizeForMessage(relative, 300);
  if (folder.empty())
    throw ConfigError(
        "", 0, "preset",
        "preset file '" + shown +
            "': this run has no world file, so no folder to read preset files "
            "from; expected a bundled preset (" +
            [] {
              std::string names;
              for (const std::string& n : BundledAdversityPresetNames())
                names += (names.empty() ? "" : ", ") + n;
              return names;
            }() +
            ")");
  ExistingInputFile file;
  try {
    file = ReadExistingFileInside(folder, relative, ".yaml", kMaxClientPresetFileBytes,
                                  "the world file's folder");
  } catch (const InputPathError& e) {
    throw ConfigError("", 0, "preset", e.what());
  }
  // the file's own errors quote its values and keys: the client, which may not be able to
  // read the file itself, gets the file's name, the line and the rule; `detail` the rest
  std::vector<AdversityPreset> presets;
  try {
    presets = ParseAdversityPresets(file.text, file.path.string());
  } catch (const ConfigError& e) {
    if (detail) *detail = e.what();
    throw ConfigError(
        "", 0, "preset",
        "preset file '" + shown + "'" + (e.line() > 0 ? ", line " + std::to_string(e.line()) : "") +
            ": not a valid adversity preset file (the server's log names the key and the "
            "value); expected 'presets:' mapping names ([A-Za-z0-9_-]+) to blocks fog, dust, "
            "smoke, rain, snow, lights, npcs (world/adversity_preset.h)");
  }
  out.spec = file.path.lexically_normal().string();
  if (hash == std::string::npos) {
    if (presets.size() != 1)
      throw ConfigError(
          "", 0, "preset",
          "preset file '" + shown + "' holds " + std::to_string(presets.size()) +
              " presets; expected FILE.yaml#NAME with NAME one of: " + Names(presets));
    out.preset = presets.front();
    return out;
  }
  const std::string name = spec.substr(hash + 1);
  for (const AdversityPreset& p : presets)
    if (p.name == name) {
      out.preset = p;
      out.spec += "#" + name;
      return out;
    }
  throw ConfigError("", 0, "preset",
                    "unknown preset '" + SanitizeForMessage(name, 100) + "' in '" + shown +
                        "'; expected one of: " + Names(presets));
}

}  // namespace penumbra

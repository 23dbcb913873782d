#include "penumbra/replay/world_override.h"

#include <algorithm>
#include <filesystem>

#include "penumbra/core/input_file.h"
#include "penumbra/world/sensors_reader.h"
#include "penumbra/world/yaml_reader.h"

namespace penumbra {
namespace {

// why a top-level key cannot be replaced, or "" when it can
std::string Refusal(const std::string& key) {
  if (key == "robots" || key == "models")
    return "changes the recorded models, which the log's state belongs to; expected only keys "
           "that change what is seen";
  if (key == "physics")
    return "changes the recorded physics; a replay follows the log and simulates nothing "
           "(penumbra replay --resimulate re-runs the recorded physics)";
  if (key == "duration_sec")
    return "a replay spans the log; expected --from SEC / --to SEC on the command line";
  const auto& ok = ReplaceableWorldKeys();
  if (std::find(ok.begin(), ok.end(), key) != ok.end()) return "";
  std::string list;
  for (std::string_view k : ok) list += (list.empty() ? "" : ", ") + std::string(k);
  return "cannot be replaced in a replay; expected some of: " + list;
}

// the top-level sensors (listed first; robots' own sensors follow in robot order)
bool IsTopLevel(const SensorConfig& s) { return s.robot.empty(); }

}  // namespace

const std::vector<std::string_view>& ReplaceableWorldKeys() {
  static const std::vector<std::string_view> kKeys = {
      "cameras",          "mjcf_cameras", "lights",    "sky",    "materials", "render",  "effects",
      "semantic_classes", "output",       "adversity", "agents", "seed",      "sensors", "metrics"};
  return kKeys;
}

WorldConfig ApplyWorldOverride(const WorldConfig& recorded, const std::string& path,
                               WorldOverride* applied) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw ConfigError(path, 0, "", "world override file not found; expected an existing YAML file");
  const std::string text = ReadInputFile(path, "world override file");

  // the keys it names, checked before anything else (the first document, as before)
  YamlParseOptions first_only;
  first_only.single_document = false;
  const ConfigValue root = ParseYaml(text, path, first_only);
  if (!root.IsMap() || root.IsFlow())
    throw ConfigError(path, root.IsDefined() && !root.IsNull() ? root.line() : 0, "",
                      "expected a world-file fragment: a block mapping (one `key: value` per "
                      "line) of some of the keys " +
                          std::string("cameras, lights, sky, materials, render, effects, ..."));
  WorldOverride result;
  result.file = path;
  for (const ConfigEntry& e : root.entries()) {
    const std::string why = Refusal(e.key);
    if (!why.empty()) throw ConfigError(path, e.key_line, e.key, why);
    result.keys.push_back(e.key);
  }

  // the fragment read as a world file of the recorded models (names only: enough for the
  // checks of attach bodies and material names), so that its values are checked, its
  // relative paths resolve against its folder and its errors name its lines
  std::string models;
  for (const bool robots : {true, false}) {
    const bool any = std::any_of(recorded.models.begin(), recorded.models.end(),
                                 [&](const ModelConfig& m) { return m.is_robot == robots; });
    if (!any) continue;
    models += robots ? "robots:\n" : "models:\n";
    for (const ModelConfig& m : recorded.models) {
      if (m.is_robot != robots) continue;
      ConfigValue entry = WithEntry(ConfigValue::Map(), "name", ConfigValue::Scalar(m.name));
      // a generated building not generated yet (no file): its environment entry
      if (m.environment && m.file.empty()) {
        ConfigValue env = ConfigValue::Map();
        env = WithEntry(env, "type", ConfigValue::Scalar(m.environment->type));
        env = WithEntry(env, "seed", ConfigValue::Scalar(std::to_string(m.environment->seed)));
        env = WithEntry(env, "texture_resolution",
                        ConfigValue::Scalar(std::to_string(m.environment->texture_resolution)));
        entry = WithEntry(entry, "environment", env);
      } else {
        entry = WithEntry(entry, "file", ConfigValue::Scalar(m.file));
      }
      models += "  - " + EmitYamlFlow(entry) + "\n";
    }
  }
  std::string combined = text;
  if (!combined.empty() && combined.back() != '\n') combined += '\n';
  const auto fragment_lines = std::count(combined.begin(), combined.end(), '\n');
  combined += models;
  WorldConfig o;
  try {
    o = ParseWorld(combined, path);
  } catch (const ConfigError& e) {
    // the recorded models follow the fragment's last line: an error there (a model file that
    // was moved) is the recorded world's, not a line of the fragment (it cited line 129 of a
    // 127-line file)
    if (e.file() != path || e.line() <= fragment_lines) throw;
    throw ConfigError(recorded.file, recorded.lines ? recorded.lines->Find(e.key()) : 0, e.key(),
                      e.problem());
  }

  WorldConfig w = recorded;
  for (const std::string& key : result.keys) {
    if (key == "cameras") w.cameras = o.cameras;
    if (key == "mjcf_cameras") w.mjcf_cameras = o.mjcf_cameras;
    if (key == "lights") w.lights = o.lights;
    if (key == "sky") w.sky = o.sky;
    if (key == "materials") w.materials = o.materials;
    if (key == "render") w.render = o.render;
    if (key == "effects") w.effects = o.effects;
    if (key == "semantic_classes") w.semantic_classes = o.semantic_classes;
    if (key == "output") w.output_dir = o.output_dir;
    if (key == "agents") w.agents = o.agents;
    if (key == "adversity") {
      w.adversity = o.adversity;
      w.adversity_line = 0;  // a line of the override, not of the recorded world
    }
    if (key == "seed") w.seed = o.seed;
    if (key == "metrics") w.metrics = o.metrics;
    if (key == "sensors") {
      std::vector<SensorConfig> sensors;
      for (const SensorConfig& s : o.sensors)
        if (IsTopLevel(s)) sensors.push_back(s);
      for (const SensorConfig& s : recorded.sensors)
        if (!IsTopLevel(s)) sensors.push_back(s);
      ValidateSensorNames(sensors);
      w.sensors = std::move(sensors);
    }
  }
  w.render.seed = w.seed;
  result.lines = o.lines;
  if (applied) *applied = std::move(result);
  return w;
}

ConfigError LocateReplayError(const WorldConfig& world, const WorldOverride& applied,
                              const ConfigError& e) {
  const bool unplaced = e.file().empty() || (e.file() == world.file && e.line() == 0);
  if (unplaced && !e.key().empty() && e.key().front() != '-') {
    const std::string top = e.key().substr(0, e.key().find_first_of(".["));
    if (std::find(applied.keys.begin(), applied.keys.end(), top) != applied.keys.end())
      return ConfigError(applied.file, applied.lines ? applied.lines->Find(e.key()) : 0, e.key(),
                         e.problem());
  }
  return LocateInWorld(world, e);
}

}  // namespace penumbra

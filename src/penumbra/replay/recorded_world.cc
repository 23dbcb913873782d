#include "penumbra/replay/recorded_world.h"

#include <fmt/format.h>

#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/live/live_effects.h"

namespace penumbra {

RecordedRunFlags ParseRecordedRunFlags(const std::string& command_line) {
  std::vector<std::string> args;
  std::istringstream in(command_line);
  for (std::string a; in >> a;) args.push_back(a);
  RecordedRunFlags f;
  for (size_t i = 0; i < args.size(); ++i) {
    if (i <= 1 && args[i] == "view") f.live = true;
    for (const char* bridge : {"--zmq", "--ros", "--viewer"})
      if (args[i] == bridge || args[i].rfind(std::string(bridge) + "=", 0) == 0) f.live = true;
    std::string flag = args[i], value;
    const size_t eq = flag.find('=');
    if (flag.rfind("--", 0) != 0) continue;
    if (eq != std::string::npos) {
      value = flag.substr(eq + 1);
      flag = flag.substr(0, eq);
    } else if (flag == "--adversity" || flag == "--tier" || flag == "--spp" ||
               flag == "--outputs") {
      if (i + 1 >= args.size()) break;
      value = args[++i];
    }
    if (flag == "--adversity") {
      f.adversity = value;
    } else if (flag == "--tier") {
      f.tier = value;
    } else if (flag == "--spp") {
      try {
        f.samples_per_pixel = std::stoi(value);
      } catch (const std::exception&) {
        // not a number: the recorded run refused it, so it never took effect
      }
    } else if (flag == "--outputs") {
      f.outputs = value;
    }
  }
  return f;
}

WorldConfig RecordedWorld(const RunLogHeader& header) {
  WorldConfig world = header.world_file.empty() ? WorldForBareModel(header.model_file)
                                                : ParseWorld(header.world_text, header.world_file);
  world.seed = header.seed;
  world.render.seed = header.seed;
  world.record = RecordConfig{};  // a replay writes no run log
  const RecordedRunFlags flags = ParseRecordedRunFlags(header.command_line);
  if (flags.tier == "pathtraced") world.render.tier = RenderSettings::Tier::kPathtraced;
  if (flags.tier == "realtime") world.render.tier = RenderSettings::Tier::kRealtime;
  if (flags.samples_per_pixel && *flags.samples_per_pixel > 0)
    world.render.samples_per_pixel = *flags.samples_per_pixel;
  if (flags.outputs) {
    CameraOutputs o = CameraOutputs::None();
    std::istringstream list(*flags.outputs);
    for (std::string name; std::getline(list, name, ',');)
      if (bool* flag = o.Flag(name)) *flag = true;
    for (CameraConfig& c : world.cameras) c.outputs = o;
    world.mjcf_cameras.outputs = o;
    for (CameraConfig& c : world.mjcf_cameras.overrides) c.outputs = o;
  }
  return world;
}

std::vector<std::string> ChangedAssets(const RunLogHeader& header) {
  std::vector<std::string> out;
  for (const RunLogAsset& a : header.assets) {
    if (a.role == "world" || a.sha256.empty()) continue;
    std::string now;
    try {
      now = Sha256OfFile(a.path);
    } catch (const Error& e) {
      out.push_back(a.role + " " + a.path + " cannot be read any more (" + e.what() + ")");
      continue;
    }
    if (now != a.sha256)
      out.push_back(a.role + " " + a.path + " changed since the run was recorded (sha256 " +
                    a.sha256.substr(0, 12) + "... in the log, " + now.substr(0, 12) + "... now)");
  }
  return out;
}

void ScheduleRecordedLiveChange(const EventRecord& e, const std::string& log_path,
                                LiveEffects* live) {
  const nlohmann::json change = nlohmann::json::parse(e.payload, nullptr, false);
  if (change.is_discarded())
    throw ConfigError(log_path, 0, "live",
                      fmt::format("the live change at step {} is not JSON; expected the "
                                  "payload docs/run-log.md describes",
                                  e.step));
  live->ScheduleRecorded(e.step, change);
}

}  // namespace penumbra

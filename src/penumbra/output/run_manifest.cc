#include "penumbra/output/run_manifest.h"

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>
#include <system_error>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"

namespace penumbra {

std::string RunManifestJson(const RunManifest& m) {
  // ordered_json keeps insertion order, so the key order is the struct's
  nlohmann::ordered_json j;
  j["world_file"] = m.world_file;
  j["seed"] = m.seed;
  j["penumbra_version"] = m.penumbra_version;
  j["mujoco_version"] = m.mujoco_version;
  j["embree_version"] = m.embree_version;
  j["command_line"] = m.command_line;
  j["sim_duration_sec"] = m.sim_duration_sec;
  j["interrupted"] = m.interrupted;
  nlohmann::ordered_json frames = nlohmann::ordered_json::object();
  for (const auto& [name, n] : m.frames_per_camera) frames[name] = n;
  j["frames_per_camera"] = frames;
  nlohmann::ordered_json timings = nlohmann::ordered_json::object();
  for (const auto& [name, s] : m.timings_sec) timings[name] = s;
  j["timings_sec"] = timings;
  j["peak_resident_memory_mib"] = m.peak_resident_memory_mib;
  if (!m.error.empty()) j["error"] = m.error;
  if (!m.adversity.empty() || !m.effects.empty() || !m.agents.empty()) {
    j["adversity"] = m.adversity;
    j["effects"] = m.effects;
    j["agents"] = m.agents;
  }
  if (!m.record_file.empty()) {
    nlohmann::ordered_json r;
    r["file"] = m.record_file;
    r["bytes"] = m.record_bytes;
    r["steps"] = m.record_steps;
    r["first_step"] = m.record_first_step;
    r["last_step"] = m.record_last_step;
    r["events"] = m.record_events;
    r["sensor_records"] = m.record_sensor_records;
    j["record"] = r;
  }
  if (!m.falls_json.empty()) j["falls"] = nlohmann::ordered_json::parse(m.falls_json);
  if (m.replay) {
    const ReplayManifest& r = *m.replay;
    nlohmann::ordered_json rj;
    rj["log"] = r.log;
    rj["mode"] = r.mode;
    rj["first_step"] = r.first_step;
    rj["last_step"] = r.last_step;
    rj["world_override"] = r.world_override;
    rj["override_keys"] = r.override_keys;
    rj["adversity"] = r.adversity;
    rj["tier"] = r.tier;
    rj["cameras"] = r.cameras;
    rj["outputs"] = r.outputs;
    rj["warnings"] = r.warnings;
    if (!r.verdict.empty()) rj["verdict"] = r.verdict;
    j["replay"] = rj;
  }
  if (!m.metrics_json.empty()) j["metrics"] = nlohmann::ordered_json::parse(m.metrics_json);
  return j.dump(2) + "\n";
}

void WriteRunManifest(const std::string& output_dir, const RunManifest& manifest) {
  const std::filesystem::path dir(output_dir);
  CreateOutputFolder(dir);
  WriteFileAtomic(dir / "run.json", RunManifestJson(manifest));
}

double PeakResidentMemoryMiB() {
  std::ifstream f("/proc/self/status");
  std::string line;
  while (std::getline(f, line)) {
    // "VmHWM:     12345 kB"
    if (line.rfind("VmHWM:", 0) == 0) {
      std::istringstream in(line.substr(6));
      double kib = 0;
      std::string unit;
      if (in >> kib >> unit && unit == "kB") return kib / 1024.0;
      return 0;
    }
  }
  return 0;
}

}  // namespace penumbra

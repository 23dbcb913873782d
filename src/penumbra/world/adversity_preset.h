#pragma once
// adversity presets: named sets of physical parameters (visibility, smoke, precipitation,
// lighting, NPC traffic) that turn any world into an adverse-condition variant of itself.
// bundled presets `none`, `minor`, `major` live in worlds/adversity/presets.yaml; users
// write their own files in the same format. a preset is applied relative to the world at
// run time (session/effects_stage.h): regions come from the scene's bounds around the robots,
// NPC paths are drawn from the world seed inside the free floor area.
//
// file format (YAML):
//   presets:
//     <name>:                          # [A-Za-z0-9_-]+
//       description: <text>
//       sensors: {rgb: <text>, depth: <text>, lidar: <text>, imu: <text>}  # what it does to each
//       fog:    {mor_m: M, height_falloff_per_m: H}     # homogeneous fog everywhere
//       dust:   {mor_m: M}                              # brown absorbing haze everywhere
//       smoke:  {sigma_t_per_m: S, coverage: C, extent_fraction: F, height_m: Z}
//       rain:   {rate_mm_h: R}
//       snow:   {rate_mm_h: R}
//       lights: {scale: K, flicker_depth: D, flicker_hz: F}
//       npcs:   {people: N, vehicles: V, speed_m_s: S, pause_sec: P,
//                behaviour: avoid | ignore | block, clearance_m: C,
//                block_goal: [X, Y],                # block only: the robots' goal
//                contact: true | false}             # default false: NPCs never push a robot
// every block is optional; MOR is the meteorological optical range (WMO No. 8, 2018;
// sigma_t = 2.996 / MOR, Koschmieder), rain and snow rates are water-equivalent mm/h.
//
// spec strings (world-file key `adversity`, command line --adversity):
//   NAME            a preset of the bundled file
//   FILE.yaml       the only preset of a user file (relative to the world file's folder)
//   FILE.yaml#NAME  preset NAME of a user file
//
// a spec from a client of a running world (set_adversity over ZeroMQ, the viewer, ROS) goes
// through LoadClientAdversityPreset: a preset file must be inside the world file's folder,
// named relative to it (core/output_path_policy.h ReadExistingFileInside: no "..", no
// symbolic link, ends in .yaml, at most kMaxClientPresetFileBytes), and its errors name the
// file, the line and the rule but never quote the file's content.

#include <cstddef>
#include <filesystem>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/effects/agent_path.h"

namespace penumbra {

/// one adversity preset (units SI; see the file header for the meaning of each block).
struct AdversityPreset {
  std::string name;
  std::string description;
  std::string file;  ///< the file it came from
  /// what the preset does to each kind of sensor, as its file states it (`sensors:`): pairs of
  /// sensor (AdversitySensorNames order: rgb, depth, lidar, imu) and text; documentation only,
  /// nothing reads it to simulate.
  std::vector<std::pair<std::string, std::string>> sensor_effects;

  std::optional<double> fog_mor_m;            ///< fog MOR, (0, 1e5] m
  double fog_height_falloff_per_m = 0;        ///< [0, 10] 1/m; 0 = uniform
  std::optional<double> dust_mor_m;           ///< dust MOR, (0, 1e5] m
  std::optional<double> smoke_sigma_t_per_m;  ///< smoke extinction at density 1, (0, 100] 1/m
  double smoke_coverage = 0.5;                ///< fraction of the smoke box with smoke, [0, 1]
  /// horizontal size of the smoke box as a fraction of the robots' area box, (0, 1]
  double smoke_extent_fraction = 1.0;
  double smoke_height_m = 2.5;           ///< smoke box height above the floor, (0, 100] m
  std::optional<double> rain_rate_mm_h;  ///< (0, 500]
  std::optional<double> snow_rate_mm_h;  ///< (0, 100]
  double light_scale = 1.0;              ///< multiplier on every scene light and the sky, [0, 1]
  double flicker_depth = 0.0;            ///< light flicker depth, [0, 1]; 0 = steady
  double flicker_hz = 4.0;               ///< (0, 100]
  int npc_people = 0;                    ///< walking people, [0, 100]
  int npc_vehicles = 0;                  ///< forklifts, [0, 20]
  double npc_speed_m_s = 1.2;            ///< people's speed, (0, 5]; vehicles drive at 1.5x
  double npc_pause_sec = 1.0;            ///< pause at each waypoint, [0, 60]
  /// what the NPCs do about the robots (effects/agent_path.h AgentBehaviour)
  AgentBehaviour npc_behaviour = AgentBehaviour::kAvoid;
  double npc_clearance_m = 0.5;  ///< avoid: kept from a robot's disc, [0, 10] m
  /// NPCs may push the robots (`npcs.contact: true`; AgentConfig::robot_contact). false (the
  /// default): they never move into a robot and yield when one comes into them.
  bool npc_contact = false;
  /// block: where the robots are going (world x, y in m, |x|, |y| <= 1e5; `npcs.block_goal`,
  /// only with behaviour block). block people then start near each robot's route to it
  /// instead of ahead of its start heading (session/effects_stage.h "npcs").
  std::optional<Eigen::Vector2d> npc_block_goal;

  /// true when the preset changes nothing (e.g. `none`).
  bool empty() const;
};

/// worlds/adversity/presets.yaml of the source tree (or, when the binary runs away from
/// its source tree, relative to the current folder).
std::string BundledAdversityPresetsPath();

/// every preset of a preset file, in file order.
/// @throws ConfigError(file, line, "presets.<name>.<key>", ...) for a missing/unreadable
///         file, unknown keys, wrong types and out-of-range values.
std::vector<AdversityPreset> LoadAdversityPresetFile(const std::string& path);

/// every preset of the preset file text `text` (`path` names it in errors), in file order.
/// @throws ConfigError as LoadAdversityPresetFile.
std::vector<AdversityPreset> ParseAdversityPresets(const std::string& text,
                                                   const std::string& path);

/// the text of a preset file holding `preset` alone (under its name, with its description):
/// LoadAdversityPreset of it (FILE or FILE#NAME) gives back an equal preset. what a caller
/// writes to run a preset with a changed field (e.g. `penumbra benchmark` adds the episode's
/// goal as npcs.block_goal, campaign/nav_job.h).
std::string AdversityPresetFileText(const AdversityPreset& preset);

/// the sensors a preset's `sensors:` block may describe: "rgb", "depth", "lidar", "imu".
const std::vector<std::string>& AdversitySensorNames();

/// the names of the bundled presets ("none", "minor", "major").
std::vector<std::string> BundledAdversityPresetNames();

/// checks a spec (see the file header) and returns it with a relative file path made
/// absolute against `base_dir` ("" = the current folder); bundled names stay as they are.
/// @param file, line where the spec was written (for errors; "" = command line)
/// @throws ConfigError(file, line, "adversity", "unknown preset 'x'; expected one of: none,
///         minor, major, or a preset file (.yaml)") and the errors of LoadAdversityPresetFile.
std::string ResolveAdversitySpec(const std::string& spec, const std::string& base_dir,
                                 const std::string& file = "", int line = 0);

/// the preset named by a resolved spec.
/// @throws ConfigError as ResolveAdversitySpec.
AdversityPreset LoadAdversityPreset(const std::string& spec, const std::string& file = "",
                                    int line = 0);

/// the largest preset file a client may name, in bytes (the bundled one is about 2 KB).
inline constexpr size_t kMaxClientPresetFileBytes = 1 << 20;

/// a preset a client asked for, and the spec that names it on the server.
struct ClientAdversityPreset {
  AdversityPreset preset;
  /// the bundled name, or the file's path (world folder / client path, lexically normal)
  /// with "#NAME" when given: what a run log records (LoadAdversityPreset reads it again).
  std::string spec;
};

/// the preset named by `spec` as a client sent it (see the file header): a bundled name, or
/// FILE.yaml / FILE.yaml#NAME read from inside `folder` (the world file's folder; "" = the
/// run has none: only bundled names) under ReadExistingFileInside's rules.
/// @param detail  receives the full error of a preset file that did not parse (with the
///                keys and values it quotes) for the server's own log; may be null
/// @throws ConfigError("", 0, "adversity", ...) for an unknown bundled name;
///         ConfigError("", 0, "preset", ...) for a path the rules refuse (the path and the
///         rule), a file that is not a valid preset file (its name, the line and the rule, no
///         content), or an unknown NAME (the file's preset names).
ClientAdversityPreset LoadClientAdversityPreset(const std::string& spec,
                                                const std::filesystem::path& folder,
                                                std::string* detail = nullptr);

}  // namespace penumbra

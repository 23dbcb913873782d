#pragma once
// generated environments (docs/environments.md): a building written as one MJCF model of static
// primitive geoms, with procedural materials (assets/procedural_material.h), ceiling lamps and
// walkways. each type has a fixed floor plan (walls, doors, windows, walkways); the seed picks the
// furniture, its sizes and places along the walls, the clutter on it and the materials' seeds
// and colours, all from counter-based random numbers (core/rng.h) keyed by the seed, so the
// same config always gives the same bytes. nothing is placed within a walkway's half width, so
// a robot route along a walkway is free of furniture for every seed.
//
// frames: the model frame has z up, the floor's top at z = 0, x east, y north (REP-103).

#include <Eigen/Core>
#include <string>
#include <vector>

#include "penumbra/world/environment_config.h"
#include "penumbra/world/procedural_material_config.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// a polyline kept free of furniture: every collision geom placed by the generator stays at
/// least `half_width_m` (plan view) from it. bundled world files route their robots along
/// these (tests/environment checks that they do).
struct Walkway {
  std::string name;
  std::vector<Eigen::Vector2d> points;  ///< (x, y) in the model frame, m
  double half_width_m = 0.8;
};

/// an axis-aligned plan rectangle of the model frame, m.
struct PlanRect {
  double x0 = 0, y0 = 0, x1 = 0, y1 = 0;
};

/// a file the model refers to (a height field): written next to the model under a name made
/// from its content; `placeholder` in GeneratedEnvironment::mjcf stands for its absolute path.
struct GeneratedFile {
  std::string placeholder;  ///< e.g. "@terrain.hfield@"
  std::string stem, ext;    ///< name parts of the written file ("terrain", ".hfield")
  std::string bytes;
};

/// everything one generated environment consists of.
struct GeneratedEnvironment {
  std::string mjcf;                  ///< the model (MJCF text, static geoms of the world body)
  std::vector<GeneratedFile> files;  ///< files `mjcf` refers to by placeholder
  /// `procedural:` materials of the model's MJCF materials; `material` is the model-local name
  /// (the session prefixes "<model>/"), `line` 0.
  std::vector<ProceduralMaterialEntry> materials;
  /// ceiling lamps in the model frame; names model-local (the session prefixes "<model>/").
  std::vector<LightConfig> lights;
  std::vector<Walkway> walkways;
  /// the rooms (house) or zones (warehouse) by name, for docs and tests.
  std::vector<std::pair<std::string, PlanRect>> rooms;
  /// the rooms and walkways (by name) where vehicles may drive: an adversity preset's
  /// forklifts go only there (session/effects_stage.h "npcs"; CrowdSites::Area::drivable).
  /// the warehouse: its zones and its aisle walkway; the house and the outdoor terrain: none.
  std::vector<std::string> drivable;
  int geoms = 0, colliding_geoms = 0;
  int furniture = 0;  ///< furniture items, racks, pallets placed
};

/// generates `config` (validated: EnvironmentConfig::ValidateOrThrow).
/// @throws Error for an unknown type.
GeneratedEnvironment GenerateEnvironment(const EnvironmentConfig& config);

}  // namespace penumbra

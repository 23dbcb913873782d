#pragma once
// a world-file `models:` entry with `environment:` (world/environment_config.h) becomes a
// generated MJCF model, plus the procedural materials and ceiling lamps that go with it
// (docs/environments.md). called before composing, as mesh files are imported
// (environment/model_sources.h).

#include <string>
#include <vector>

#include "penumbra/environment/environment_generator.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// one generated model: its name and what the generator made.
struct GeneratedModel {
  std::string model;  ///< ModelConfig::name
  GeneratedEnvironment environment;
  std::string file;         ///< the MJCF file written
  double generate_sec = 0;  ///< wall time of the generator (docs: load time)
};

/// what the generated models add to the world besides their MJCF.
struct GeneratedModels {
  std::vector<GeneratedModel> models;
  /// the models' procedural materials, named "<model>/<material>" (line 0).
  std::vector<ProceduralMaterialEntry> materials;
  /// the models' lamps in the world frame (the model pose applied), named "<model>/<lamp>".
  std::vector<LightConfig> lights;
};

/// generates every model of `models` that has `environment`, writes its MJCF to `dir`
/// (created if missing; "" = the folder "penumbra-environments" in the system's temporary
/// folder) under a name made from its content ("<type>-<hash>.xml", written once), and points
/// its `file` at it. other models are left alone.
/// @throws Error when the folder or a file cannot be written.
GeneratedModels GenerateEnvironmentModels(std::vector<ModelConfig>* models, const std::string& dir);

}  // namespace penumbra

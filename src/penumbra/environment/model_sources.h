#pragma once
// the world's models that are not MJCF files, made into MJCF for the session's compose step, and
// their materials for its scene step (session/session.h), in this order:
//   1. before composing: generated environments (`models:` entries with `environment:`,
//      environment_model.h) become MJCF models and their lamps world lights; then mesh files
//      (.obj, .gltf, ...) become generated MJCF models (assets/mesh_model.h);
//   2. while composing: MJCF <mesh> files MuJoCo cannot read become .msh files
//      (assets/mjcf_mesh_conversion.h, through ComposeOptions::convert_mesh);
//   3. on the scene extracted from the compiled model: the imported models' materials, then the
//      procedural materials of the generated models and of the world file
//      (assets/procedural_material.h).
// each step logs one line per model or file it made.

#include <string>
#include <vector>

#include "penumbra/assets/mesh_model.h"
#include "penumbra/effects/crowd_sim.h"
#include "penumbra/environment/environment_model.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// the generated and imported models of one world (steps 1 to 3 of the file comment).
class ModelSources {
 public:
  /// step 1: generates the environments of world->models into `environments_dir`
  /// (GenerateEnvironmentModels; "" = the temporary folder's "penumbra-environments"), points
  /// those world->models at their MJCF files and appends their lamps to world->lights; then
  /// imports the mesh-file models into `mesh_dir` (ImportMeshModels; "" = the temporary
  /// folder). world->models keep their mesh files; models() has the generated MJCF of both.
  /// @throws Error / ConfigError from GenerateEnvironmentModels and ImportMeshModels.
  ModelSources(WorldConfig* world, const std::string& environments_dir,
               const std::string& mesh_dir);

  /// the models to compose: the world's models with every generated and imported file.
  const std::vector<ModelConfig>& models() const { return models_; }

  /// the generated environments' rooms and walkways in the world frame, each placed by the
  /// pose of its model in `world_models` (where crowds go, session/effects_stage.h).
  CrowdSites crowd_sites(const std::vector<ModelConfig>& world_models) const;

  /// step 2: for a model's <mesh> file MuJoCo cannot read, the .msh file it is converted to in
  /// the mesh folder (ConvertForeignMjcfMesh; logged); "" for a file MuJoCo reads.
  /// @throws ConfigError as ConvertForeignMjcfMesh.
  std::string ConvertMjcfMesh(const std::string& mesh_file) const;

  /// step 3: the imported models' materials (ApplyImportedMaterials), then the procedural
  /// materials of the generated models and of `world_file`'s `materials:`
  /// (ApplyProceduralMaterials), on `scene`.
  /// @throws Error / ConfigError from those two.
  void ApplyMaterials(const std::string& world_file, SceneDescription* scene) const;

 private:
  std::string mesh_dir_;
  std::vector<ModelConfig> models_;
  GeneratedModels generated_;
  std::vector<ImportedModel> imported_;
};

}  // namespace penumbra

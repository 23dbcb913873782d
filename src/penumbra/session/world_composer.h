#pragma once
// the composition step of a session: the world's model files become one MJCF document through
// MuJoCo's model-editing API (physics/model_spec_composer.h): each model attached with its name
// as prefix ("M/") at its world-file pose, its world-file sites added, a URDF's floating base a
// free joint, its keyframes full-length keys "M/K" (the other models at their reference
// configuration); the document is MuJoCo's own text of that spec (mj_saveXMLString) with
// Penumbra's ground plane (compose/scene_composer.h).

#include <vector>

#include "penumbra/compose/scene_composer.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// composes `models` (in order) into one MJCF document.
/// URDF files (a .urdf file, or any file whose root element is <robot>) go through
/// options.prepare_urdf (default: physics/urdf_converter.h PrepareUrdfForMujoco) and are
/// then parsed by MuJoCo's own URDF reader.
/// @throws ConfigError naming the model file and line where MuJoCo reports one (XML syntax,
///         schema, unknown references, compile errors of the model), the world-file key of a
///         bad model name, site or floating_base, or a timestep out of range.
ComposedScene ComposeWorld(const std::vector<ModelConfig>& models, const ComposeOptions& options);

}  // namespace penumbra

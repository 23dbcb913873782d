#pragma once
// scene-assembly helpers for cameras and semantic classes (called from app/scene_assembly.cc).

#include <vector>

#include "penumbra/scene/scene_description.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// appends world-file camera `c`, assembled as `cam` (name, intrinsics, pose, outputs), to
/// `cameras` with its distortion and exposure time applied. a stereo camera
/// (c.sensor.stereo_baseline_m) becomes two cameras "<name>/left" (at `cam`'s pose) and
/// "<name>/right" (the left optical frame translated by baseline_m along its x axis), with the
/// same intrinsics.
void AppendWorldCamera(const CameraConfig& c, CameraSpec cam, std::vector<CameraSpec>* cameras);

/// the sensor settings of every camera of `scene` (world-file cameras by name, stereo halves from
/// their pair; MJCF cameras get the defaults), in SceneDescription::cameras order.
std::vector<CameraSensorConfig> SensorConfigsFor(const SceneDescription& scene,
                                                 const WorldConfig& world);

/// glob match: '*' matches any run of characters (also none), '?' one character.
bool GlobMatch(std::string_view pattern, std::string_view text);

/// sets Geom::semantic_class of every geom from the first class (in file order) with a pattern
/// matching the geom's name, its body's name or its material's name; others keep 0.
void ApplySemanticClasses(const std::vector<SemanticClassConfig>& classes, SceneDescription* scene);

}  // namespace penumbra

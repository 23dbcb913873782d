#pragma once
// scene-assembly helpers for cameras and semantic classes (called from session/scene_assembly.cc).

#include <string>
#include <vector>

#include "penumbra/scene/scene_description.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// sets `cam`'s distortion and exposure time from `c` and checks the distortion against the
/// final intrinsics. @throws ConfigError (file `file`, key `key`.distortion, naming the camera)
/// if it folds the image (render/camera/camera_distortion.h).
void ApplyCameraConfig(const CameraConfig& c, CameraSpec* cam, const std::string& file,
                       const std::string& key);

/// appends world-file camera `c`, assembled as `cam` (name, intrinsics, pose, outputs), to
/// `cameras` with ApplyCameraConfig applied. a stereo camera (c.sensor.stereo_baseline_m)
/// becomes two cameras "<name>/left" (at `cam`'s pose) and "<name>/right" (the left optical frame
/// translated by baseline_m along its x axis), with the same intrinsics.
/// @throws ConfigError as ApplyCameraConfig.
void AppendWorldCamera(const CameraConfig& c, CameraSpec cam, std::vector<CameraSpec>* cameras,
                       const std::string& file = "", const std::string& key = "cameras");

/// the sensor settings of every camera of `scene` (world-file cameras by name, stereo halves from
/// their pair, MJCF cameras from their `mjcf_cameras.overrides` entry or the defaults), in
/// SceneDescription::cameras order.
std::vector<CameraSensorConfig> SensorConfigsFor(const SceneDescription& scene,
                                                 const WorldConfig& world);

/// sets Geom::semantic_class of every geom from the first class (in file order) with a pattern
/// matching the geom's name, its body's name or its material's name; others keep 0.
void ApplySemanticClasses(const std::vector<SemanticClassConfig>& classes, SceneDescription* scene);

}  // namespace penumbra

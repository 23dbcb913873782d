#pragma once
// joins what the compiled model says (SceneDescription extracted by physics/) with
// what the world file says: lights, sky, cameras, material overrides.

#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// luminous efficacy used to turn a lamp's power in watts into candela:
/// I = kLumensPerWatt * P / (4 pi) (the definition of the candela at 555 nm, SI brochure 9th ed.).
inline constexpr double kLumensPerWatt = 683.0;

/// returns `extracted` with the world file's material overrides, lights, sky and
/// cameras applied. MJCF cameras get the `mjcf_cameras` defaults and overrides
/// (or are removed when disabled); world-file cameras are attached to their body.
/// @throws ConfigError naming the world file and key for unknown bodies, materials,
///         MJCF cameras and duplicate camera names.
/// `initial` is the world at the start (used to frame auto-framed cameras on the
/// moving bodies).
SceneDescription AssembleScene(SceneDescription extracted, const WorldConfig& world,
                               const WorldSnapshot& initial);

/// pose of a camera's optical frame in the world at `snapshot` (X_WO).
Pose CameraPoseInWorld(const CameraSpec& camera, const WorldSnapshot& snapshot);

}  // namespace penumbra

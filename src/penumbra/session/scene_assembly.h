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

/// share of the image width or height (whichever is reached first) that the model's bounding
/// box spans in an auto-framed camera (CameraConfig::auto_frame, the `default` camera of a
/// bare model); the box is centred in the image.
inline constexpr double kAutoFrameFill = 0.7;

/// direction (world frame, not unit) along which an auto-framed camera looks: from the model's
/// front-left (+x, +y), 21 deg above the horizon; azimuth of the camera seen from the model
/// atan2(0.6, 1) = 31 deg. a bare model's sun stands at azimuth 31 - 60 = -29 deg
/// (world/world_config.cc, WorldForBareModel): 60 deg to the camera's left, so the model is
/// lit from the front-left and its shadow falls to its right in the image, not behind it.
inline const Eigen::Vector3d kAutoFrameView{-1.0, -0.6, -0.45};

/// returns `extracted` with the world file's material overrides, lights, sky and
/// cameras applied. MJCF cameras get the `mjcf_cameras` defaults and overrides
/// (or are removed when disabled); world-file cameras are attached to their body.
/// @throws ConfigError naming the world file and key for unknown bodies, materials,
///         MJCF cameras and duplicate camera names.
/// `initial` is the world at the start (used to frame auto-framed cameras on the
/// moving bodies).
SceneDescription AssembleScene(SceneDescription extracted, const WorldConfig& world,
                               const WorldSnapshot& initial);

}  // namespace penumbra

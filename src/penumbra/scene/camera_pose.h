#pragma once
// where a camera of the scene is at a step: its optical frame (x right, y down, z forward) in
// the world, from the body it is fixed to or the MuJoCo camera that poses it.

#include "penumbra/core/pose.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

/// pose of a camera's optical frame in the world at `snapshot` (X_WO): for an MJCF camera
/// (camera.mjcf_camera >= 0) its WorldSnapshot::X_W_mjcam turned from MuJoCo's camera
/// convention to the optical one (RotationMujocoCameraFromOptical), else X_WB of its body times
/// camera.X_BO.
/// @throws std::out_of_range if the snapshot has no pose for the camera's body or MJCF camera.
Pose CameraPoseInWorld(const CameraSpec& camera, const WorldSnapshot& snapshot);

}  // namespace penumbra

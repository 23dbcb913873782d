#include "penumbra/scene/camera_pose.h"

namespace penumbra {

Pose CameraPoseInWorld(const CameraSpec& camera, const WorldSnapshot& snapshot) {
  if (camera.mjcf_camera >= 0) {
    Pose X_OpticalInCam = Pose::Identity();
    X_OpticalInCam.linear() = RotationMujocoCameraFromOptical();
    return snapshot.X_W_mjcam.at(camera.mjcf_camera) * X_OpticalInCam;
  }
  return snapshot.X_WB.at(camera.body) * camera.X_BO;
}

}  // namespace penumbra

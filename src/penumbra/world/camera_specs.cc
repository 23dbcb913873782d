#include "penumbra/world/camera_specs.h"

#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/render/camera/camera_distortion.h"
#include "penumbra/sensors/camera_profile.h"

namespace penumbra {

void ApplyCameraConfig(const CameraConfig& c, CameraSpec* cam, const std::string& file,
                       const std::string& key) {
  cam->intrinsics.k1 = c.k1;
  cam->intrinsics.k2 = c.k2;
  cam->intrinsics.p1 = c.p1;
  cam->intrinsics.p2 = c.p2;
  cam->intrinsics.k3 = c.k3;
  cam->exposure_time_sec = c.sensor.exposure_time_sec;
  cam->near_m = c.near_m;
  if (auto problem = FindDistortionProblem(cam->intrinsics))
    throw ConfigError(file, 0, key + ".distortion",
                      "camera '" + c.name + "': " + *problem +
                          "; expected k1 k2 p1 p2 k3 that map the image one-to-one");
}

void AppendWorldCamera(const CameraConfig& c, CameraSpec cam, std::vector<CameraSpec>* cameras,
                       const std::string& file, const std::string& key) {
  ApplyCameraConfig(c, &cam, file, key);
  if (!c.sensor.stereo_baseline_m) {
    cameras->push_back(cam);
    return;
  }
  CameraSpec left = cam, right = cam;
  left.name = c.name + "/left";
  right.name = c.name + "/right";
  Pose X_LR = Pose::Identity();
  X_LR.translation() = Eigen::Vector3d(*c.sensor.stereo_baseline_m, 0, 0);
  right.X_BO = cam.X_BO * X_LR;
  cameras->push_back(left);
  cameras->push_back(right);
}

std::vector<CameraSensorConfig> SensorConfigsFor(const SceneDescription& scene,
                                                 const WorldConfig& world) {
  std::vector<CameraSensorConfig> out;
  for (const CameraSpec& spec : scene.cameras) {
    // an MJCF camera without an override: the mjcf_cameras profile
    CameraSensorConfig cfg = spec.mjcf_camera >= 0 ? CameraProfileConfig(world.mjcf_cameras.profile)
                                                   : CameraSensorConfig();
    cfg.exposure_time_sec = spec.exposure_time_sec;
    for (const CameraConfig& c : world.mjcf_cameras.overrides) {
      if (spec.mjcf_camera >= 0 && spec.name == c.name) cfg = c.sensor;
    }
    for (const CameraConfig& c : world.cameras) {
      if (spec.mjcf_camera >= 0) break;
      const bool stereo = c.sensor.stereo_baseline_m.has_value();
      if ((!stereo && spec.name == c.name) ||
          (stereo && (spec.name == c.name + "/left" || spec.name == c.name + "/right"))) {
        cfg = c.sensor;
        break;
      }
    }
    out.push_back(cfg);
  }
  return out;
}

void ApplySemanticClasses(const std::vector<SemanticClassConfig>& classes,
                          SceneDescription* scene) {
  if (classes.empty()) return;
  auto any = [](const std::vector<std::string>& patterns, const std::string& name) {
    if (name.empty()) return false;
    for (const std::string& p : patterns)
      if (GlobMatch(p, name)) return true;
    return false;
  };
  for (Geom& g : scene->geoms) {
    const std::string& body = g.body >= 0 && g.body < static_cast<int>(scene->bodies.size())
                                  ? scene->bodies[g.body].name
                                  : "";
    const std::string& material =
        g.material >= 0 && g.material < static_cast<int>(scene->materials.size())
            ? scene->materials[g.material].name
            : "";
    for (const SemanticClassConfig& c : classes) {
      if (any(c.geoms, g.name) || any(c.bodies, body) || any(c.materials, material)) {
        g.semantic_class = c.id;
        break;
      }
    }
  }
}

}  // namespace penumbra

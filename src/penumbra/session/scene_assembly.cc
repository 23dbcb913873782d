#include "penumbra/session/scene_assembly.h"

#include <fmt/format.h>

#include <cmath>
#include <set>

#include "penumbra/core/error.h"
#include "penumbra/render/sky/sky_math.h"
#include "penumbra/render/sky/sky_model.h"
#include "penumbra/scene/scene_limits.h"
#include "penumbra/scene/world_snapshot.h"
#include "penumbra/session/geom_extents.h"
#include "penumbra/world/camera_specs.h"

namespace penumbra {
namespace {

int BodyOrThrow(const SceneDescription& scene, const std::string& attach, const std::string& file,
                const std::string& key) {
  if (attach.empty() || attach == "world") return 0;
  const int b = scene.FindBody(attach);
  if (b < 0) {
    std::string known;
    for (size_t i = 1; i < scene.bodies.size() && i < 40; ++i) {
      if (scene.bodies[i].name.empty()) continue;
      known += (known.empty() ? "" : ", ") + scene.bodies[i].name;
    }
    throw ConfigError(file, 0, key,
                      "no body named '" + attach + "'; expected \"world\" or one of: " + known);
  }
  return b;
}

std::string FormatXyz(double v) { return fmt::format("{:g}", v); }
std::string FormatXyz(const Eigen::Vector3d& v) {
  return fmt::format("{:g}, {:g}, {:g}", v.x(), v.y(), v.z());
}

Eigen::Vector3d DirectionFromElevationAzimuth(double elevation_deg, double azimuth_deg) {
  const double el = elevation_deg * M_PI / 180.0, az = azimuth_deg * M_PI / 180.0;
  return {std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el)};
}

void ApplyMaterialOverrides(SceneDescription& scene, const WorldConfig& world) {
  for (size_t i = 0; i < world.materials.size(); ++i) {
    const MaterialOverride& o = world.materials[i];
    const int m = scene.FindMaterial(o.name);
    if (m < 0)
      throw ConfigError(world.file, 0, "materials." + o.name,
                        "no MJCF material with that name; expected a prefixed material name such "
                        "as '<model>/<material>'");
    Material& mat = scene.materials[m];
    if (o.base_color) mat.base_color = *o.base_color;
    if (o.roughness) mat.roughness = *o.roughness;
    if (o.metallic) mat.metallic = *o.metallic;
    if (o.specular) mat.specular = *o.specular;
    if (o.emission) mat.emission = *o.emission;
  }
}

Light ToLight(const LightConfig& c, const SceneDescription& scene, const std::string& file,
              size_t index) {
  const std::string key = "lights[" + std::to_string(index) + "]";
  Light l;
  l.name = c.name;
  l.body = BodyOrThrow(scene, c.attach, file, key + ".attach");
  l.position_B = c.position;
  l.direction_B = c.direction.normalized();
  l.color = c.color;
  l.cast_shadow = c.cast_shadow;
  l.radius_m = static_cast<float>(c.radius_m);
  switch (c.type) {
    case Light::Type::kDirectional:
      l.type = Light::Type::kDirectional;
      l.intensity = static_cast<float>(c.illuminance_lux.value_or(10000.0));
      l.angular_radius_deg = static_cast<float>(0.5 * c.angular_diameter_deg);
      break;
    case Light::Type::kPoint:
    case Light::Type::kSpot:
      l.type = c.type;
      l.intensity = static_cast<float>(c.intensity_cd ? *c.intensity_cd
                                                      : kLumensPerWatt * c.power_w.value_or(0.0) /
                                                            (4.0 * M_PI));
      l.spot_inner_deg = static_cast<float>(c.inner_angle_deg);
      l.spot_outer_deg = static_cast<float>(c.outer_angle_deg);
      break;
  }
  return l;
}

// half extents of a box in the geom frame, centred on the geom's origin, that holds the geom
// (planes: none; meshes: see GeomCornersInWorld).
bool GeomHalfExtents(const SceneDescription& scene, const Geom& g, Eigen::Vector3d* h) {
  if (const std::optional<Eigen::Vector3d> p = PrimitiveHalfExtents(g)) {
    *h = *p;
    return true;
  }
  if (g.shape != GeomShape::kHeightField) return false;  // planes; meshes by their vertices
  const HeightField& f = scene.hfields.at(g.hfield);
  *h = Eigen::Vector3d::Constant(
      std::sqrt(f.size_x * f.size_x + f.size_y * f.size_y + f.size_z * f.size_z));
  return true;
}

// bounding box of the geoms of moving bodies at `initial` (all finite geoms if none move):
// meshes by their vertices, other shapes by the corners of their local bounding boxes, posed.
bool BoundsOfModel(const SceneDescription& scene, const WorldSnapshot& initial, Eigen::Vector3d* lo,
                   Eigen::Vector3d* hi) {
  for (bool moving_only : {true, false}) {
    *lo = Eigen::Vector3d::Constant(1e300);
    *hi = Eigen::Vector3d::Constant(-1e300);
    bool any = false;
    auto add = [&](const Eigen::Vector3d& p_W) {
      *lo = lo->cwiseMin(p_W);
      *hi = hi->cwiseMax(p_W);
      any = true;
    };
    for (const Geom& g : scene.geoms) {
      if (g.group > 2 || (moving_only && scene.bodies.at(g.body).is_static)) continue;
      if (static_cast<size_t>(g.body) >= initial.X_WB.size()) continue;
      const Pose X_WG = initial.X_WB[g.body] * g.X_BG;
      Eigen::Vector3d h;
      if (g.shape == GeomShape::kMesh) {
        for (const Eigen::Vector3f& v : scene.meshes.at(g.mesh).vertices)
          add(X_WG * v.cast<double>());
      } else if (GeomHalfExtents(scene, g, &h)) {
        for (int c = 0; c < 8; ++c)
          add(X_WG * Eigen::Vector3d(c & 1 ? h.x() : -h.x(), c & 2 ? h.y() : -h.y(),
                                     c & 4 ? h.z() : -h.z()));
      }
    }
    if (any) return true;
  }
  return false;
}

// the auto-framed camera (docs/cameras.md, "Bare models"): it looks along kAutoFrameView (from
// the front-left, above) and stands where the model's bounding box, centred in the image,
// spans kAutoFrameFill of the image width or height, whichever it reaches first. the position
// is found by fixed-point steps: shift sideways by the box's off-centre offset, move along the
// view by depth x (1 - fill / kAutoFrameFill); every step keeps the box in front of the camera.
Pose AutoFramePose(const SceneDescription& scene, const WorldSnapshot& initial,
                   const CameraIntrinsics& k) {
  Eigen::Vector3d lo, hi;
  if (!BoundsOfModel(scene, initial, &lo, &hi)) {
    lo = scene.center_W - Eigen::Vector3d::Constant(scene.extent_m);
    hi = scene.center_W + Eigen::Vector3d::Constant(scene.extent_m);
  }
  const Eigen::Vector3d center = 0.5 * (lo + hi);
  const double radius = std::max(1e-3, 0.5 * (hi - lo).norm());
  // optical frame: z forward, x right, y down
  const Eigen::Vector3d z = kAutoFrameView.normalized();
  const Eigen::Vector3d x = z.cross(Eigen::Vector3d::UnitZ()).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Eigen::Matrix3d R;
  R.col(0) = x;
  R.col(1) = y;
  R.col(2) = z;
  // tangents of the half angles of view (the principal point taken as the image centre).
  const double tan_x = 0.5 * k.width / k.fx, tan_y = 0.5 * k.height / k.fy;
  const double half = std::atan(std::min(tan_x, tan_y));
  // start: the box's bounding sphere inside the view, so every corner is in front.
  Eigen::Vector3d eye = center - z * std::max(0.1, radius / std::sin(half));
  for (int step = 0; step < 100; ++step) {
    double u_lo = 1e300, u_hi = -1e300, v_lo = 1e300, v_hi = -1e300;
    bool in_front = true;
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d p(c & 1 ? hi.x() : lo.x(), c & 2 ? hi.y() : lo.y(),
                              c & 4 ? hi.z() : lo.z());
      const Eigen::Vector3d q = R.transpose() * (p - eye);
      if (!(q.z() > 1e-3 * radius)) {
        in_front = false;
        break;
      }
      u_lo = std::min(u_lo, q.x() / q.z()), u_hi = std::max(u_hi, q.x() / q.z());
      v_lo = std::min(v_lo, q.y() / q.z()), v_hi = std::max(v_hi, q.y() / q.z());
    }
    const double depth = z.dot(center - eye);
    if (!in_front) {
      eye -= z * radius;  // not reached from the start above; a guard
      continue;
    }
    const double fill = std::max((u_hi - u_lo) / (2 * tan_x), (v_hi - v_lo) / (2 * tan_y));
    const double du = 0.5 * (u_lo + u_hi), dv = 0.5 * (v_lo + v_hi);
    if (std::abs(fill - kAutoFrameFill) < 1e-5 && std::abs(du) < 1e-6 && std::abs(dv) < 1e-6) break;
    // never closer than a tenth of the depth per step (thin boxes seen edge-on).
    const double forward = depth * std::min(0.9, 1.0 - fill / kAutoFrameFill);
    eye += R * Eigen::Vector3d(du * depth, dv * depth, forward);
  }
  Pose X = Pose::Identity();
  X.linear() = R;
  X.translation() = eye;
  return X;
}

CameraIntrinsics IntrinsicsFor(const CameraConfig& c, double fallback_fovy_deg) {
  if (c.intrinsics) {
    CameraIntrinsics k = *c.intrinsics;
    k.width = c.width;
    k.height = c.height;
    return k;
  }
  return CameraIntrinsics::FromFovy(c.width, c.height, c.fovy_deg.value_or(fallback_fovy_deg));
}

void AssembleCameras(SceneDescription& scene, const WorldConfig& world,
                     const WorldSnapshot& initial) {
  std::vector<CameraSpec> cameras;
  // mjcf cameras: defaults, then per-camera overrides
  if (world.mjcf_cameras.enabled) {
    for (CameraSpec cam : scene.cameras) {
      const double fovy = cam.intrinsics.fovy_deg();
      cam.intrinsics =
          CameraIntrinsics::FromFovy(world.mjcf_cameras.width, world.mjcf_cameras.height, fovy);
      cam.rate_hz = world.mjcf_cameras.rate_hz;
      cam.outputs = world.mjcf_cameras.outputs;
      cameras.push_back(cam);
    }
  }
  for (size_t i = 0; i < world.mjcf_cameras.overrides.size(); ++i) {
    const CameraConfig& o = world.mjcf_cameras.overrides[i];
    auto it = std::find_if(cameras.begin(), cameras.end(),
                           [&](const CameraSpec& c) { return c.name == o.name; });
    if (it == cameras.end()) {
      std::string known;
      for (const CameraSpec& c : scene.cameras) known += (known.empty() ? "" : ", ") + c.name;
      throw ConfigError(world.file, 0, "mjcf_cameras.overrides." + o.name,
                        world.mjcf_cameras.enabled
                            ? "no MJCF camera with that name; expected one of: " +
                                  (known.empty() ? std::string("(none)") : known)
                            : "mjcf_cameras.enabled is false; expected no overrides");
    }
    it->intrinsics = IntrinsicsFor(o, o.fovy_deg.value_or(it->intrinsics.fovy_deg()));
    it->rate_hz = o.rate_hz;
    it->outputs = o.outputs;
    ApplyCameraConfig(o, &*it, world.file, "mjcf_cameras.overrides." + o.name);
  }
  const size_t mjcf_count = cameras.size();
  // world-file cameras
  for (size_t i = 0; i < world.cameras.size(); ++i) {
    const CameraConfig& c = world.cameras[i];
    CameraSpec cam;
    cam.name = c.name;
    cam.intrinsics = IntrinsicsFor(c, 60.0);
    cam.rate_hz = c.rate_hz;
    cam.outputs = c.outputs;
    if (c.auto_frame) {
      cam.body = 0;
      cam.X_BO = AutoFramePose(scene, initial, cam.intrinsics);
    } else {
      cam.body =
          BodyOrThrow(scene, c.attach, world.file, "cameras[" + std::to_string(i) + "].attach");
      Pose X_BodyOptical = Pose::Identity();
      X_BodyOptical.linear() = RotationBodyFromOptical();
      cam.X_BO = c.pose.ToPose() * X_BodyOptical;
      // the pose is in range (world validation); the body it hangs on may not be
      if (static_cast<size_t>(cam.body) < initial.X_WB.size()) {
        const Eigen::Vector3d p_W = (initial.X_WB[cam.body] * cam.X_BO).translation();
        if (!(p_W.cwiseAbs().maxCoeff() <= kMaxPositionM))
          throw ConfigError(world.file, 0, "cameras[" + std::to_string(i) + "].attach",
                            "camera '" + c.name + "' starts at (" + FormatXyz(p_W) +
                                ") m in the world (attached to '" + c.attach +
                                "'); expected each coordinate in [-" + FormatXyz(kMaxPositionM) +
                                ", " + FormatXyz(kMaxPositionM) + "] m");
      }
    }
    AppendWorldCamera(c, cam, &cameras, world.file, "cameras[" + std::to_string(i) + "]");
  }
  // the world file's own list was counted when it was read; the MJCF cameras only now
  if (cameras.size() > static_cast<size_t>(kMaxCameras))
    throw ConfigError(world.file, 0, world.mjcf_cameras.enabled ? "mjcf_cameras" : "cameras",
                      std::to_string(cameras.size()) + " cameras (" +
                          std::to_string(cameras.size() - mjcf_count) +
                          " from the world file, stereo pairs counting twice, " +
                          std::to_string(mjcf_count) + " MJCF cameras); expected at most " +
                          std::to_string(kMaxCameras) +
                          " (mjcf_cameras: {enabled: false} leaves the MJCF cameras out)");
  std::set<std::string> names;
  for (const CameraSpec& c : cameras)
    if (!names.insert(c.name).second)
      throw ConfigError(world.file, 0, "cameras",
                        "two cameras are named '" + c.name +
                            "'; expected unique names (MJCF cameras are named '<model>/<camera>')");
  scene.cameras = std::move(cameras);
}

// the file of the world model whose MJCF names start with "<model>/" ("" if none does).
std::string ModelFileOf(const WorldConfig& world, const std::string& name) {
  for (const ModelConfig& m : world.models)
    if (name.size() > m.name.size() && name.compare(0, m.name.size() + 1, m.name + "/") == 0)
      return m.file;
  return world.models.size() == 1 ? world.models.front().file : "";
}

// the compiled models' geoms, MJCF cameras and lights against scene/scene_limits.h, before
// anything is sized or traced.
void CheckSceneLimits(const SceneDescription& scene, const WorldConfig& world,
                      const WorldSnapshot& initial) {
  const std::optional<SceneLimitProblem> p =
      FindSceneLimitProblem(scene, initial, world.mjcf_cameras.enabled);
  if (!p) return;
  const size_t quote = p->object.find('\'');
  const std::string name = quote == std::string::npos
                               ? p->body
                               : p->object.substr(quote + 1, p->object.size() - quote - 2);
  std::string file = ModelFileOf(world, name);
  if (file.empty()) file = ModelFileOf(world, p->body);
  throw ConfigError(file.empty() ? world.file : file, 0, p->object,
                    (p->body.empty() ? "" : "in body '" + p->body + "': ") + p->problem);
}

}  // namespace

SceneDescription AssembleScene(SceneDescription scene, const WorldConfig& world,
                               const WorldSnapshot& initial) {
  CheckSceneLimits(scene, world, initial);
  ApplyMaterialOverrides(scene, world);

  for (size_t i = 0; i < world.lights.size(); ++i)
    scene.lights.push_back(ToLight(world.lights[i], scene, world.file, i));

  const SkyConfig& s = world.sky;
  scene.sky.type = s.type;
  scene.sky.radiance = s.color * static_cast<float>(s.luminance_cd_m2);
  scene.sky.turbidity = static_cast<float>(s.turbidity);
  scene.sky.zenith_luminance = static_cast<float>(s.zenith_luminance_cd_m2);
  scene.sky.sun_direction_W = DirectionFromElevationAzimuth(s.sun_elevation_deg, s.sun_azimuth_deg);

  if (world.default_lights) {
    // the bare-model daylight, by the numbers (render/sky/sky_math.h): the sun carries its
    // direct-normal illuminance at the sky's elevation and turbidity, and the sky's zenith
    // luminance is the one that gives the clear sky's diffuse horizontal illuminance there.
    const float elevation = static_cast<float>(s.sun_elevation_deg);
    const float turbidity = static_cast<float>(s.turbidity);
    if (scene.sky.type == Sky::Type::kDaylight)
      scene.sky.zenith_luminance = SkyModel::PhysicalZenithLuminance(scene.sky);
    Light sun;
    sun.name = "default_sun";
    sun.type = Light::Type::kDirectional;
    sun.direction_B = -scene.sky.sun_direction_W;
    sun.color = {1.0f, 0.96f, 0.9f};
    sun.intensity = SunDirectNormalIlluminance(elevation, turbidity);
    sun.angular_radius_deg = 0.2665f;
    scene.lights.push_back(sun);
  }

  AssembleCameras(scene, world, initial);
  ApplySemanticClasses(world.semantic_classes, &scene);
  return scene;
}

}  // namespace penumbra

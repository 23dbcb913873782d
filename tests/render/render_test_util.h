#pragma once
// hand-built scenes and snapshots for the renderer tests (no MuJoCo needed).

#include <Eigen/Geometry>
#include <cmath>
#include <string>

#include "penumbra/core/pose.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra::testing {

/// a scene with the world body only, a black sky and no lights.
inline SceneDescription EmptyScene() {
  SceneDescription s;
  s.bodies.push_back({"world", -1, true});
  s.sky.type = Sky::Type::kUniform;
  s.sky.radiance = Eigen::Vector3f::Zero();
  return s;
}

/// adds a body (parent world) and returns its index.
inline int AddBody(SceneDescription* s, const std::string& name, bool is_static = false) {
  s->bodies.push_back({name, 0, is_static});
  return static_cast<int>(s->bodies.size()) - 1;
}

/// adds a material and returns its index.
inline int AddMaterial(SceneDescription* s, const Eigen::Vector3f& color, float roughness = 1.0f,
                       float metallic = 0.0f, float specular = 0.0f) {
  Material m;
  m.name = "m" + std::to_string(s->materials.size());
  m.base_color = color;
  m.roughness = roughness;
  m.metallic = metallic;
  m.specular = specular;
  s->materials.push_back(m);
  return static_cast<int>(s->materials.size()) - 1;
}

/// adds a point lamp fixed to the world at p_W (intensity in candela, emitter radius in m for
/// soft shadows; 0 = hard) and returns its index.
inline int AddPointLamp(SceneDescription* s, const Eigen::Vector3d& p_W, float intensity,
                        float radius_m) {
  Light lamp;
  lamp.type = Light::Type::kPoint;
  lamp.position_B = p_W;
  lamp.intensity = intensity;
  lamp.radius_m = radius_m;
  s->lights.push_back(lamp);
  return static_cast<int>(s->lights.size()) - 1;
}

/// adds a geom and returns its index; its MuJoCo id is 100 + index (so ids differ from indices).
inline int AddGeom(SceneDescription* s, GeomShape shape, const Eigen::Vector3d& size,
                   const Pose& X_BG, int body = 0, int material = -1) {
  Geom g;
  g.name = "g" + std::to_string(s->geoms.size());
  g.id = 100 + static_cast<int>(s->geoms.size());
  g.body = body;
  g.shape = shape;
  g.size = size;
  g.X_BG = X_BG;
  g.material = material;
  s->geoms.push_back(g);
  return static_cast<int>(s->geoms.size()) - 1;
}

inline Pose Translation(double x, double y, double z) {
  Pose X = Pose::Identity();
  X.translation() = Eigen::Vector3d(x, y, z);
  return X;
}

/// snapshot with every body at the identity (or the given poses).
inline WorldSnapshot IdentitySnapshot(const SceneDescription& s) {
  WorldSnapshot snap;
  snap.X_WB.assign(s.bodies.size(), Pose::Identity());
  return snap;
}

/// a scene of every shape kind, static and moving, for comparing two ray tracers: a floor
/// plane at z = -1, a static box, sphere and cylinder in front of +x, and a body "mover" (its
/// index in *mover) with a tilted capsule, a cylinder, an ellipsoid and a box.
inline SceneDescription EveryShapeScene(int* mover) {
  SceneDescription scene = EmptyScene();
  AddGeom(&scene, GeomShape::kPlane, {0, 0, 1}, Translation(0, 0, -1));
  AddGeom(&scene, GeomShape::kBox, {0.3, 0.4, 0.5}, Translation(4, 0.8, 0.2));
  AddGeom(&scene, GeomShape::kSphere, {0.35, 0, 0}, Translation(3, -0.7, 0.1));
  AddGeom(&scene, GeomShape::kCylinder, {0.2, 0.6, 0}, Translation(5, -1.5, 0.1));
  const int body = AddBody(&scene, "mover");
  Pose X_BG = Translation(0, 0.3, 0);
  X_BG.linear() = Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  AddGeom(&scene, GeomShape::kCapsule, {0.15, 0.3, 0}, X_BG, body);
  AddGeom(&scene, GeomShape::kCylinder, {0.2, 0.25, 0}, Translation(0, -0.4, 0.2), body);
  AddGeom(&scene, GeomShape::kEllipsoid, {0.2, 0.3, 0.15}, Translation(0, 0.1, -0.45), body);
  AddGeom(&scene, GeomShape::kBox, {0.1, 0.1, 0.1}, Translation(0.1, -0.1, 0.5), body);
  *mover = body;
  return scene;
}

/// EveryShapeScene's mover at (2.5, 0.1, -0.1), turned by yaw_rad about world z.
inline void PoseEveryShapeMover(WorldSnapshot* snapshot, int mover, double yaw_rad) {
  snapshot->X_WB[mover] = Translation(2.5, 0.1, -0.1);
  snapshot->X_WB[mover].linear() =
      Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix();
}

/// optical frame at `p` looking along world +x (image x = world -y, image y = world -z).
inline Pose CameraLookingAlongX(const Eigen::Vector3d& p = Eigen::Vector3d::Zero()) {
  Pose X = Pose::Identity();
  X.linear() = RotationBodyFromOptical();
  X.translation() = p;
  return X;
}

/// optical frame at `p` looking straight down (world -z); image x = world +x, image y = world -y.
inline Pose CameraLookingDown(const Eigen::Vector3d& p) {
  Pose X = Pose::Identity();
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d(1, 0, 0);
  R.col(1) = Eigen::Vector3d(0, -1, 0);
  R.col(2) = Eigen::Vector3d(0, 0, -1);
  X.linear() = R;
  X.translation() = p;
  return X;
}

/// a view with the given pose and a (w x h) camera of vertical field of view fovy_deg.
inline CameraView MakeView(const Pose& X_WO, int w, int h, double fovy_deg, bool rgb = true,
                           bool depth = true, bool seg = true) {
  CameraView v;
  v.X_WO = X_WO;
  v.intrinsics = CameraIntrinsics::FromFovy(w, h, fovy_deg);
  v.outputs[ImageKind::kRgb] = rgb;
  v.outputs[ImageKind::kDepth] = depth;
  v.outputs[ImageKind::kSegmentation] = seg;
  return v;
}

/// settings for exact radiometry: realtime tier, manual exposure, linear tone map.
inline RenderSettings TestSettings(int threads = 1) {
  RenderSettings r;
  r.tier = RenderSettings::Tier::kRealtime;
  r.threads = threads;
  r.auto_exposure = false;
  r.ev100 = 10;
  r.tone_map = RenderSettings::ToneMap::kLinear;
  return r;
}

/// centroid (u, v) and pixel count of the pixels with geom id `id`.
inline Eigen::Vector2d MaskCentroid(const ImageI32& seg, int id, int* count) {
  Eigen::Vector2d c(0, 0);
  int n = 0;
  for (int v = 0; v < seg.height; ++v)
    for (int u = 0; u < seg.width; ++u)
      if (*seg.at(u, v) == id) {
        c += Eigen::Vector2d(u, v);
        ++n;
      }
  *count = n;
  return n > 0 ? Eigen::Vector2d(c / n) : c;
}

}  // namespace penumbra::testing

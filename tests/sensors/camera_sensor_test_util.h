#pragma once
// small hand-built scenes for the camera sensor tests (no MuJoCo).

#include <Eigen/Geometry>

#include "penumbra/core/pose.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra::testing {

inline SceneDescription BlackScene() {
  SceneDescription s;
  s.bodies.push_back({"world", -1, true});
  s.sky.radiance = Eigen::Vector3f::Zero();
  return s;
}

inline int AddMaterial(SceneDescription* s, const Eigen::Vector3f& color,
                       const Eigen::Vector3f& emission = Eigen::Vector3f::Zero()) {
  Material m;
  m.name = "m" + std::to_string(s->materials.size());
  m.base_color = color;
  m.emission = emission;
  s->materials.push_back(m);
  return static_cast<int>(s->materials.size()) - 1;
}

/// adds a geom with MuJoCo id 100 + index; returns its index.
inline int AddGeom(SceneDescription* s, GeomShape shape, const Eigen::Vector3d& size,
                   const Eigen::Vector3d& pos, int material, int body = 0) {
  Geom g;
  g.name = "g" + std::to_string(s->geoms.size());
  g.id = 100 + static_cast<int>(s->geoms.size());
  g.body = body;
  g.shape = shape;
  g.size = size;
  g.X_BG.translation() = pos;
  g.material = material;
  s->geoms.push_back(g);
  return static_cast<int>(s->geoms.size()) - 1;
}

inline WorldSnapshot Snapshot(const SceneDescription& s, double t) {
  WorldSnapshot snap;
  snap.time_sec = t;
  snap.X_WB.assign(s.bodies.size(), Pose::Identity());
  return snap;
}

/// optical frame at `p` looking along world +x: image x = world -y, image y = world -z.
inline Pose LookingAlongX(const Eigen::Vector3d& p) {
  Pose X = Pose::Identity();
  X.linear() = RotationBodyFromOptical();
  X.translation() = p;
  return X;
}

}  // namespace penumbra::testing

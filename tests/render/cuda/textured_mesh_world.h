#pragma once
// a small world written by the tests (no asset files): an MJCF with a coarse sphere mesh that
// carries vertex normals (smooth shading: the outward unit normal at each vertex, far from the
// flat facets' normals at 6 x 10 segments) and texture coordinates (u = 2 (x + y) + 0.5, v =
// 3 z: neither a planar projection along one axis nor the untextured colour), a 2d checker
// texture on it (MuJoCo's builtin, 64 x 64 texels) with a checker normal map (texture
// "checker/normal", the material's PBR map by name: flat and tilted squares, bent in the
// texcoords' tangent frame), a box wrapped in a cube texture, a floor, a lamp, a gradient skybox
// (the background of escaping rays) and a camera that sees all of them
// (docs/journal/2026-11-26-gpu-effects.md,
// "Textured meshes, smooth normals, cube textures and skyboxes on the GPU").

#include <cmath>
#include <sstream>
#include <string>

#include "penumbra/physics/simulation.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/camera_pose.h"

namespace penumbra::textured_mesh {

/// the MJCF text of the world (see the file comment); the sphere has radius 0.5 m.
inline std::string Mjcf() {
  constexpr int kLat = 6, kLon = 10;
  constexpr double kPi = 3.14159265358979323846, r = 0.5;
  std::ostringstream vert, normal, uv, face;
  // vertex 0: the top pole, then rings 1 .. kLat - 1 of kLon vertices, then the bottom pole
  auto add = [&](double x, double y, double z) {
    vert << x << ' ' << y << ' ' << z << "  ";
    normal << x / r << ' ' << y / r << ' ' << z / r << "  ";
    uv << 2 * (x + y) + 0.5 << ' ' << 3 * z << "  ";
  };
  add(0, 0, r);
  for (int i = 1; i < kLat; ++i) {
    const double th = kPi * i / kLat;
    for (int j = 0; j < kLon; ++j) {
      const double ph = 2 * kPi * j / kLon;
      add(r * std::sin(th) * std::cos(ph), r * std::sin(th) * std::sin(ph), r * std::cos(th));
    }
  }
  add(0, 0, -r);
  const int bottom = 1 + (kLat - 1) * kLon;
  auto ring = [&](int i, int j) { return 1 + (i - 1) * kLon + (j % kLon); };
  // counter-clockwise seen from outside
  for (int j = 0; j < kLon; ++j) face << 0 << ' ' << ring(1, j) << ' ' << ring(1, j + 1) << "  ";
  for (int i = 1; i + 1 < kLat; ++i)
    for (int j = 0; j < kLon; ++j) {
      face << ring(i, j) << ' ' << ring(i + 1, j) << ' ' << ring(i, j + 1) << "  ";
      face << ring(i, j + 1) << ' ' << ring(i + 1, j) << ' ' << ring(i + 1, j + 1) << "  ";
    }
  for (int j = 0; j < kLon; ++j)
    face << bottom << ' ' << ring(kLat - 1, j + 1) << ' ' << ring(kLat - 1, j) << "  ";
  std::ostringstream x;
  x << R"(<mujoco model="textured_mesh">
  <asset>
    <texture name="sky" type="skybox" builtin="gradient" rgb1="0.4 0.6 0.8" rgb2="0.05 0.05 0.1"
             width="64" height="64"/>
    <texture name="checker" type="2d" builtin="checker" rgb1="0.9 0.75 0.1"
             rgb2="0.1 0.2 0.8" width="64" height="64"/>
    <texture name="crate" type="cube" builtin="checker" rgb1="0.8 0.3 0.2" rgb2="0.95 0.95 0.9"
             width="32" height="32"/>
    <texture name="checker/normal" type="2d" builtin="checker" rgb1="0.5 0.5 1"
             rgb2="0.75 0.6 0.9" width="64" height="64"/>
    <material name="checker" texture="checker" specular="0.3"/>
    <material name="crate" texture="crate"/>
    <mesh name="ball" vertex=")"
    << vert.str() << R"(" normal=")" << normal.str() << R"(" texcoord=")" << uv.str()
    << R"(" face=")" << face.str() << R"("/>
  </asset>
  <worldbody>
    <light pos="0.8 -1.2 2.5" dir="-0.3 0.4 -1" diffuse="1 1 1"/>
    <geom name="floor" type="plane" size="3 3 0.1" rgba="0.6 0.6 0.6 1"/>
    <geom name="ball" type="mesh" mesh="ball" material="checker" pos="0 0 0.6"
          contype="0" conaffinity="0"/>
    <geom name="crate" type="box" size="0.2 0.2 0.2" pos="0.75 0.6 0.2" euler="0 0 30"
          material="crate"/>
    <camera name="cam" pos="0 -1.9 0.9" xyaxes="1 0 0 0 0.1 1"/>
  </worldbody>
</mujoco>
)";
  return x.str();
}

/// the world loaded (no simulation steps needed: everything is static).
inline Simulation Load() { return Simulation::LoadFromString(Mjcf()); }

/// the world's camera at w x h, rgb and depth.
inline CameraView View(const SceneDescription& scene, const WorldSnapshot& snap, int w, int h) {
  const CameraSpec& cam = scene.cameras.front();
  CameraView view;
  view.X_WO = CameraPoseInWorld(cam, snap);
  view.intrinsics = CameraIntrinsics::FromFovy(w, h, cam.intrinsics.fovy_deg());
  view.near_m = cam.near_m;
  view.outputs[ImageKind::kRgb] = true;
  view.outputs[ImageKind::kDepth] = true;
  view.outputs[ImageKind::kSegmentation] = false;
  return view;
}

/// `scene` with the mesh's vertex normals, texture coordinates, the ball's and the box's
/// textures and the normal map dropped (flat, untextured), for tests that check their
/// threshold tells the two apart.
inline SceneDescription FlatUntextured(const SceneDescription& scene) {
  SceneDescription s = scene;
  for (TriangleMesh& m : s.meshes) m.normals.clear(), m.texcoords.clear();
  for (Texture& t : s.textures)
    if (t.name == "checker/normal") t.name = "unused";
  for (Material& m : s.materials)
    if (m.name == "checker" || m.name == "crate") m.texture = -1;
  return s;
}

}  // namespace penumbra::textured_mesh

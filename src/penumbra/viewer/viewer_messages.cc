#include "penumbra/viewer/viewer_messages.h"

#include <cmath>
#include <cstring>

#include "penumbra/core/error.h"
#include "penumbra/core/srgb.h"

namespace penumbra {

using nlohmann::json;

namespace {

double Round(double v, double scale) { return std::round(v * scale) / scale; }

const char* ShapeName(GeomShape s) {
  switch (s) {
    case GeomShape::kPlane:
      return "plane";
    case GeomShape::kSphere:
      return "sphere";
    case GeomShape::kCapsule:
      return "capsule";
    case GeomShape::kEllipsoid:
      return "ellipsoid";
    case GeomShape::kCylinder:
      return "cylinder";
    case GeomShape::kBox:
      return "box";
    case GeomShape::kMesh:
      return "mesh";
    case GeomShape::kHeightField:
      return "hfield";
  }
  return "box";
}

}  // namespace

json PoseJson(const Pose& X) {
  const Eigen::Quaterniond q(X.rotation());
  const Eigen::Vector3d t = X.translation();
  return json::array({Round(t.x(), 1e5), Round(t.y(), 1e5), Round(t.z(), 1e5), Round(q.w(), 1e6),
                      Round(q.x(), 1e6), Round(q.y(), 1e6), Round(q.z(), 1e6)});
}

json SceneJson(const SceneDescription& scene) {
  json bodies = json::array();
  for (size_t i = 0; i < scene.bodies.size(); ++i) {
    const Body& b = scene.bodies[i];
    // a robot's root: a moving body hanging from the world
    const bool trail = i > 0 && b.parent == 0 && !b.is_static;
    bodies.push_back(
        {{"name", b.name}, {"parent", b.parent}, {"static", b.is_static}, {"trail", trail}});
  }
  json geoms = json::array();
  std::vector<int> mesh_index(scene.meshes.size(), -1), hfield_index(scene.hfields.size(), -1);
  json meshes = json::array(), hfields = json::array();
  for (const Geom& g : scene.geoms) {
    if (g.group > 2) continue;
    Eigen::Vector3f rgb{0.8f, 0.8f, 0.8f};
    float alpha = 1;
    if (g.material >= 0 && g.material < static_cast<int>(scene.materials.size())) {
      rgb = scene.materials[g.material].base_color;
      alpha = scene.materials[g.material].alpha;
    }
    if (alpha < 0.5f) continue;
    json jg = {
        {"body", g.body},
        {"shape", ShapeName(g.shape)},
        {"size", {g.size.x(), g.size.y(), g.size.z()}},
        {"color",
         {Round(LinearToSrgb<double>(rgb.x()), 1e3), Round(LinearToSrgb<double>(rgb.y()), 1e3),
          Round(LinearToSrgb<double>(rgb.z()), 1e3), Round(alpha, 1e3)}},
        {"mesh", -1},
        {"hfield", -1}};
    const json pose = PoseJson(g.X_BG);
    jg["pos"] = {pose[0], pose[1], pose[2]};
    jg["quat"] = {pose[3], pose[4], pose[5], pose[6]};
    if (g.shape == GeomShape::kMesh && g.mesh >= 0 &&
        g.mesh < static_cast<int>(scene.meshes.size())) {
      if (mesh_index[g.mesh] < 0) {
        const TriangleMesh& m = scene.meshes[g.mesh];
        json v = json::array(), f = json::array();
        for (const Eigen::Vector3f& p : m.vertices)
          for (int k = 0; k < 3; ++k) v.push_back(Round(p[k], 1e4));
        for (const Eigen::Vector3i& t : m.faces)
          for (int k = 0; k < 3; ++k) f.push_back(t[k]);
        mesh_index[g.mesh] = static_cast<int>(meshes.size());
        meshes.push_back({{"v", std::move(v)}, {"f", std::move(f)}});
      }
      jg["mesh"] = mesh_index[g.mesh];
    } else if (g.shape == GeomShape::kMesh) {
      continue;
    }
    if (g.shape == GeomShape::kHeightField) {
      if (g.hfield < 0 || g.hfield >= static_cast<int>(scene.hfields.size())) continue;
      if (hfield_index[g.hfield] < 0) {
        const HeightField& h = scene.hfields[g.hfield];
        json e = json::array();
        for (float x : h.elevation) e.push_back(Round(x, 1e4));
        hfield_index[g.hfield] = static_cast<int>(hfields.size());
        hfields.push_back({{"rows", h.rows},
                           {"cols", h.cols},
                           {"e", std::move(e)},
                           {"size", {h.size_x, h.size_y, h.size_z, h.size_base}}});
      }
      jg["hfield"] = hfield_index[g.hfield];
    }
    geoms.push_back(std::move(jg));
  }
  return {{"type", "scene"},
          {"bodies", std::move(bodies)},
          {"geoms", std::move(geoms)},
          {"meshes", std::move(meshes)},
          {"hfields", std::move(hfields)},
          {"center", {scene.center_W.x(), scene.center_W.y(), scene.center_W.z()}},
          {"extent", scene.extent_m}};
}

json CameraPosesJson(const SceneDescription& scene, const WorldSnapshot& snapshot) {
  json out = json::object();
  for (const CameraSpec& c : scene.cameras) {
    Pose X_WO;
    if (c.mjcf_camera >= 0) {
      if (c.mjcf_camera >= static_cast<int>(snapshot.X_W_mjcam.size())) continue;
      X_WO = snapshot.X_W_mjcam[c.mjcf_camera];
      X_WO.linear() = X_WO.linear() * RotationMujocoCameraFromOptical();
    } else {
      if (c.body < 0 || c.body >= static_cast<int>(snapshot.X_WB.size())) continue;
      X_WO = snapshot.X_WB[c.body] * c.X_BO;
    }
    out[c.name] = PoseJson(X_WO);
  }
  return out;
}

json BodyPosesJson(const WorldSnapshot& snapshot) {
  json out = json::array();
  for (const Pose& X : snapshot.X_WB)
    for (auto& v : PoseJson(X)) out.push_back(v);
  return out;
}

std::string PackFrameMessage(const json& header, const std::string& payload) {
  const std::string h = header.dump();
  const uint32_t n = static_cast<uint32_t>(h.size());
  std::string out(4 + h.size() + payload.size(), '\0');
  const unsigned char le[4] = {static_cast<unsigned char>(n), static_cast<unsigned char>(n >> 8),
                               static_cast<unsigned char>(n >> 16),
                               static_cast<unsigned char>(n >> 24)};
  std::memcpy(out.data(), le, 4);
  std::memcpy(out.data() + 4, h.data(), h.size());
  if (!payload.empty()) std::memcpy(out.data() + 4 + h.size(), payload.data(), payload.size());
  return out;
}

std::pair<json, std::string> UnpackFrameMessage(const std::string& m) {
  if (m.size() < 4) throw Error("frame message: shorter than its 4-byte header length");
  const auto* b = reinterpret_cast<const unsigned char*>(m.data());
  const uint32_t n = b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<uint32_t>(b[3]) << 24);
  if (m.size() < 4 + static_cast<size_t>(n))
    throw Error("frame message: header length " + std::to_string(n) + " exceeds the message");
  // the documented error for a header that is not JSON, not the parser's own exception
  json header;
  try {
    header = json::parse(m.substr(4, n));
  } catch (const json::exception& e) {
    throw Error(std::string("frame message: the header is not JSON: ") + e.what());
  }
  return {std::move(header), m.substr(4 + n)};
}

}  // namespace penumbra

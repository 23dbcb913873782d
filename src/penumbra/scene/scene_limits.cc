#include "penumbra/scene/scene_limits.h"

#include <algorithm>
#include <cmath>

#include "penumbra/core/number_text.h"

namespace penumbra {
namespace {

std::string SizeRange() {
  return "[" + FormatG(kMinGeomSizeM) + ", " + FormatG(kMaxGeomSizeM) + "] m";
}

std::string PositionRange() {
  return "each coordinate in [" + FormatG(-kMaxPositionM) + ", " + FormatG(kMaxPositionM) + "] m";
}

// first coordinate of p outside +-kMaxPositionM (or NaN), as a message.
std::optional<std::string> PositionProblem(const std::string& what, const Eigen::Vector3d& p) {
  for (int i = 0; i < 3; ++i) {
    if (!(std::abs(p[i]) <= kMaxPositionM)) {
      return what + " " + "xyz"[i] + " is " + FormatG(p[i]) + " m at the initial pose; expected " +
             PositionRange();
    }
  }
  return std::nullopt;
}

std::string Quoted(const std::string& kind, const std::string& name, int index) {
  return kind + (name.empty() ? " #" + std::to_string(index) : " '" + name + "'");
}

// the size parameters that a primitive shape uses (MuJoCo's geom size semantics).
int UsedSizes(GeomShape shape) {
  switch (shape) {
    case GeomShape::kSphere:
      return 1;
    case GeomShape::kCapsule:
    case GeomShape::kCylinder:
    case GeomShape::kPlane:
      return 2;
    case GeomShape::kEllipsoid:
    case GeomShape::kBox:
      return 3;
    default:
      return 0;  // mesh and height field: checked through their data
  }
}

std::optional<std::string> GeomSizeProblem(const SceneDescription& scene, const Geom& g) {
  for (int i = 0; i < UsedSizes(g.shape); ++i) {
    const double s = g.size[i];
    if (g.shape == GeomShape::kPlane && s == 0) continue;  // 0 = infinite plane
    if (!(s >= kMinGeomSizeM && s <= kMaxGeomSizeM)) {
      return "size[" + std::to_string(i) + "] is " + FormatG(s) + " m; expected " + SizeRange() +
             (g.shape == GeomShape::kPlane ? " or 0 (infinite plane)" : "");
    }
  }
  if (g.shape == GeomShape::kMesh && g.mesh >= 0 &&
      g.mesh < static_cast<int>(scene.meshes.size())) {
    const TriangleMesh& mesh = scene.meshes[g.mesh];
    for (const Eigen::Vector3f& v : mesh.vertices) {
      const float a = v.cwiseAbs().maxCoeff();
      if (!(a <= kMaxGeomSizeM)) {
        return "mesh '" + mesh.name + "' has a vertex coordinate of " + FormatG(a) +
               " m (after the MJCF scale); expected |coordinates| <= " + FormatG(kMaxGeomSizeM) +
               " m";
      }
    }
  }
  if (g.shape == GeomShape::kHeightField && g.hfield >= 0 &&
      g.hfield < static_cast<int>(scene.hfields.size())) {
    const HeightField& h = scene.hfields[g.hfield];
    const double sizes[4] = {h.size_x, h.size_y, h.size_z, h.size_base};
    for (int i = 0; i < 4; ++i) {
      if (!(std::abs(sizes[i]) <= kMaxGeomSizeM)) {
        return "height field '" + h.name + "' size[" + std::to_string(i) + "] is " +
               FormatG(sizes[i]) + " m; expected |size| <= " + FormatG(kMaxGeomSizeM) + " m";
      }
    }
  }
  return std::nullopt;
}

}  // namespace

std::optional<std::string> FindIntrinsicsProblem(const CameraIntrinsics& k) {
  if (!(std::isfinite(k.fx) && k.fx > 0)) return "fx is " + FormatG(k.fx) + "; expected > 0 (px)";
  if (!(std::isfinite(k.fy) && k.fy > 0)) return "fy is " + FormatG(k.fy) + "; expected > 0 (px)";
  if (!std::isfinite(k.cx)) return "cx is " + FormatG(k.cx) + "; expected a finite number (px)";
  if (!std::isfinite(k.cy)) return "cy is " + FormatG(k.cy) + "; expected a finite number (px)";
  const double tan_max = std::tan(0.5 * kMaxFovyDeg * M_PI / 180.0);
  const double reach_x = std::max(std::abs(k.cx), std::abs(k.width - 1 - k.cx));
  const double reach_y = std::max(std::abs(k.cy), std::abs(k.height - 1 - k.cy));
  const auto wide = [&](const char* f, double fv, const char* c, double reach, int size) {
    return std::string("the ") + (f[1] == 'x' ? "horizontal" : "vertical") +
           " field of view reaches " + FormatG(2 * std::atan(reach / fv) * 180.0 / M_PI) +
           " deg (" + f + " " + FormatG(fv) + ", " + c + " " + FormatG(f[1] == 'x' ? k.cx : k.cy) +
           " for " + std::to_string(size) + " px); expected every pixel within " +
           FormatG(0.5 * kMaxFovyDeg) + " deg of the optical axis, i.e. " + f + " >= max(|" + c +
           "|, |" + std::to_string(size - 1) + " - " + c + "|) / " + FormatG(tan_max);
  };
  if (reach_x > tan_max * k.fx) return wide("fx", k.fx, "cx", reach_x, k.width);
  if (reach_y > tan_max * k.fy) return wide("fy", k.fy, "cy", reach_y, k.height);
  const auto centre = [&](const char* c, double v, int size) -> std::optional<std::string> {
    const double margin = kMaxPrincipalPointOffset * size;
    if (v >= -margin && v <= size + margin) return std::nullopt;
    return std::string(c) + " is " + FormatG(v) + " for " + std::to_string(size) +
           " px; expected [" + FormatG(-margin) + ", " + FormatG(size + margin) +
           "] (px: the principal point within " + FormatG(kMaxPrincipalPointOffset) +
           " image sizes of the image)";
  };
  if (auto p = centre("cx", k.cx, k.width)) return p;
  if (auto p = centre("cy", k.cy, k.height)) return p;
  const double tan_min = std::tan(0.5 * kMinFovyDeg * M_PI / 180.0);
  const auto narrow = [&](const char* f, double fv, int size) {
    return std::string("the ") + (f[1] == 'x' ? "horizontal" : "vertical") + " field of view is " +
           FormatG(2 * std::atan(0.5 * size / fv) * 180.0 / M_PI) + " deg (" + f + " " +
           FormatG(fv) + " for " + std::to_string(size) + " px); expected at least " +
           FormatG(kMinFovyDeg) + " deg, i.e. " + f + " <= " + FormatG(0.5 * size / tan_min);
  };
  if (k.fx > 0.5 * k.width / tan_min) return narrow("fx", k.fx, k.width);
  if (k.fy > 0.5 * k.height / tan_min) return narrow("fy", k.fy, k.height);
  return std::nullopt;
}

std::optional<SceneLimitProblem> FindSceneLimitProblem(const SceneDescription& scene,
                                                       const WorldSnapshot& initial,
                                                       bool mjcf_cameras) {
  const auto body_name = [&](int b) {
    return b > 0 && b < static_cast<int>(scene.bodies.size()) ? scene.bodies[b].name
                                                              : std::string();
  };
  for (size_t i = 0; i < scene.geoms.size(); ++i) {
    const Geom& g = scene.geoms[i];
    const std::string what = Quoted("geom", g.name, static_cast<int>(i));
    if (auto p = GeomSizeProblem(scene, g)) return SceneLimitProblem{what, body_name(g.body), *p};
    if (g.body < 0 || g.body >= static_cast<int>(initial.X_WB.size())) continue;
    const Eigen::Vector3d c_W = initial.X_WB[g.body] * g.X_BG.translation();
    if (auto p = PositionProblem("centre", c_W))
      return SceneLimitProblem{what, body_name(g.body), *p};
  }
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    const CameraSpec& c = scene.cameras[i];
    if (c.mjcf_camera < 0 || !mjcf_cameras) continue;
    const std::string what = "MJCF camera '" + c.name + "'";
    const std::string body = body_name(c.body);
    // MJCF cameras carry MuJoCo's fovy as intrinsics of the extraction size
    const double fovy = c.intrinsics.fovy_deg();
    if (!(std::isfinite(c.intrinsics.fy) && c.intrinsics.fy > 0 && fovy >= kMinFovyDeg &&
          fovy < kMaxFovyDeg)) {
      return SceneLimitProblem{what, body,
                               "fovy is " + FormatG(fovy) + " deg; expected [" +
                                   FormatG(kMinFovyDeg) + ", " + FormatG(kMaxFovyDeg) +
                                   ") deg, as for world-file cameras"};
    }
    if (c.mjcf_camera < static_cast<int>(initial.X_W_mjcam.size())) {
      if (auto p = PositionProblem("position", initial.X_W_mjcam[c.mjcf_camera].translation()))
        return SceneLimitProblem{what, body, *p};
    }
  }
  for (size_t i = 0; i < scene.lights.size(); ++i) {
    const Light& l = scene.lights[i];
    if (l.mjcf_light < 0 || l.type == Light::Type::kDirectional) continue;
    if (l.mjcf_light >= static_cast<int>(initial.light_position_W.size())) continue;
    if (auto p = PositionProblem("position", initial.light_position_W[l.mjcf_light]))
      return SceneLimitProblem{"MJCF light '" + l.name + "'", body_name(l.body), *p};
  }
  return std::nullopt;
}

}  // namespace penumbra

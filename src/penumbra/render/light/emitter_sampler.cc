#include "penumbra/render/light/emitter_sampler.h"

#include <algorithm>
#include <cmath>
#include <iterator>
#include <numbers>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/light/emitter_math.h"

namespace penumbra {
namespace {

double EmitterLuminance(const Eigen::Vector3f& c) {
  return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z();
}

// normalised cdf from non-negative weights; returns the total.
double BuildCdf(const std::vector<double>& w, std::vector<double>* cdf) {
  cdf->assign(w.size() + 1, 0.0);
  for (size_t i = 0; i < w.size(); ++i) (*cdf)[i + 1] = (*cdf)[i] + w[i];
  const double total = cdf->back();
  if (total > 0)
    for (double& c : *cdf) c /= total;
  return total;
}

// the emitter shape of each GeomShape, in GeomShape's order (kOther: not sampled)
constexpr EmitterShape kEmitterShapeOf[] = {
    EmitterShape::kPlane,     // kPlane
    EmitterShape::kSphere,    // kSphere
    EmitterShape::kCapsule,   // kCapsule
    EmitterShape::kOther,     // kEllipsoid
    EmitterShape::kCylinder,  // kCylinder
    EmitterShape::kBox,       // kBox
    EmitterShape::kMesh,      // kMesh
    EmitterShape::kOther,     // kHeightField
};
static_assert(std::size(kEmitterShapeOf) == static_cast<size_t>(GeomShape::kHeightField) + 1);

EmitterShape ShapeOf(GeomShape s) { return kEmitterShapeOf[static_cast<int>(s)]; }

// the rotation (row-major) and translation of a pose, as the shared functions take them.
void PoseArrays(const Pose& X, double R[9], double t[3]) {
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) R[3 * r + c] = X.linear()(r, c);
    t[r] = X.translation()[r];
  }
}

bool IsSampledShape(const Geom& g) {
  if (g.shape == GeomShape::kPlane) return g.size.x() > 0 && g.size.y() > 0;  // finite planes only
  return ShapeOf(g.shape) != EmitterShape::kOther;
}

}  // namespace

EmitterSampler::EmitterSampler(const SceneDescription& scene)
    : scene_(scene), emitter_of_geom_(scene.geoms.size(), -1) {
  std::vector<double> power;
  for (size_t gi = 0; gi < scene.geoms.size(); ++gi) {
    const Geom& g = scene.geoms[gi];
    if (g.material < 0 || g.material >= static_cast<int>(scene.materials.size())) continue;
    const Material& m = scene.materials[g.material];
    if (g.group > 2 || m.alpha < 0.5f) continue;
    if (!(m.emission.maxCoeff() > 0) || !IsSampledShape(g)) continue;
    Emitter e;
    e.geom = static_cast<int>(gi);
    e.shape = g.shape;
    e.Le = m.emission.cwiseMax(0.0f);
    const Eigen::Vector3d s = g.size;
    std::vector<double> parts;
    switch (g.shape) {
      case GeomShape::kSphere:
        e.area = 4 * std::numbers::pi * s.x() * s.x();
        break;
      case GeomShape::kBox:  // faces +x, -x, +y, -y, +z, -z
        parts = {4 * s.y() * s.z(), 4 * s.y() * s.z(), 4 * s.x() * s.z(),
                 4 * s.x() * s.z(), 4 * s.x() * s.y(), 4 * s.x() * s.y()};
        break;
      case GeomShape::kCylinder:  // side, top cap, bottom cap
        parts = {4 * std::numbers::pi * s.x() * s.y(), std::numbers::pi * s.x() * s.x(),
                 std::numbers::pi * s.x() * s.x()};
        break;
      case GeomShape::kCapsule:  // side, top hemisphere, bottom hemisphere
        parts = {4 * std::numbers::pi * s.x() * s.y(), 2 * std::numbers::pi * s.x() * s.x(),
                 2 * std::numbers::pi * s.x() * s.x()};
        break;
      case GeomShape::kPlane:
        e.area = 4 * s.x() * s.y();
        break;
      case GeomShape::kMesh: {
        if (g.mesh < 0 || g.mesh >= static_cast<int>(scene.meshes.size()))
          throw Error("EmitterSampler: emissive geom '" + g.name + "' refers to missing mesh " +
                      std::to_string(g.mesh));
        const TriangleMesh& mesh = scene.meshes[g.mesh];
        parts.reserve(mesh.faces.size());
        for (const Eigen::Vector3i& f : mesh.faces) {
          const Eigen::Vector3d a = mesh.vertices.at(f[0]).cast<double>();
          const Eigen::Vector3d b = mesh.vertices.at(f[1]).cast<double>();
          const Eigen::Vector3d c = mesh.vertices.at(f[2]).cast<double>();
          parts.push_back(0.5 * (b - a).cross(c - a).norm());
        }
        break;
      }
      default:
        break;
    }
    if (!parts.empty()) e.area = BuildCdf(parts, &e.part_cdf);
    if (!(e.area > 0) || !std::isfinite(e.area)) continue;
    emitter_of_geom_[gi] = static_cast<int>(emitters_.size());
    power.push_back(EmitterLuminance(e.Le) * e.area);
    emitters_.push_back(std::move(e));
    // the plain data of the shared functions (render/light/emitter_math.h), pointing into the
    // emitter's part cdf and the scene's mesh
    Emitter& added = emitters_.back();
    EmitterPod& pod = added.pod;
    pod.shape = ShapeOf(g.shape);
    for (int k = 0; k < 3; ++k) pod.size[k] = g.size[k];
    pod.area = added.area;
    pod.part_cdf = added.part_cdf.empty() ? nullptr : added.part_cdf.data();
    pod.num_parts = added.part_cdf.empty() ? 0 : static_cast<int32_t>(added.part_cdf.size()) - 1;
    if (g.shape == GeomShape::kMesh) {
      const TriangleMesh& mesh = scene.meshes[g.mesh];
      pod.vertices = mesh.vertices.empty() ? nullptr : mesh.vertices.front().data();
      pod.faces = mesh.faces.empty() ? nullptr : mesh.faces.front().data();
    }
  }
  BuildCdf(power, &pick_cdf_);
}

Pose EmitterSampler::GeomPose(const std::vector<Pose>& X_WB, const Emitter& e) const {
  const Geom& g = scene_.geoms[e.geom];
  const Pose& X_WBody =
      g.body >= 0 && g.body < static_cast<int>(X_WB.size()) ? X_WB[g.body] : Pose::Identity();
  return X_WBody * g.X_BG;
}

bool EmitterSampler::Sample(const std::vector<Pose>& X_WB, const Eigen::Vector3f& p_W, float u_pick,
                            float u1, float u2, EmitterSample* s) const {
  if (emitters_.empty()) return false;
  double u_rest = 0;
  const int k =
      EmitterPickFromCdf(pick_cdf_.data(), static_cast<int>(pick_cdf_.size()) - 1, u_pick, &u_rest);
  const double p_pick = pick_cdf_[k + 1] - pick_cdf_[k];
  if (!(p_pick > 0)) return false;
  const Emitter& e = emitters_[k];
  double R[9], t[3];
  PoseArrays(GeomPose(X_WB, e), R, t);
  const double p[3] = {p_W.x(), p_W.y(), p_W.z()};
  s->geom = e.geom;
  s->Le = e.Le;
  EmitterPoint ep;
  const bool ok = EmitterSamplePoint(e.pod, p_pick, R, t, p, u_rest, u1, u2, &ep);
  s->p_W = Eigen::Vector3d(ep.q[0], ep.q[1], ep.q[2]).cast<float>();
  s->n_W = Eigen::Vector3d(ep.n[0], ep.n[1], ep.n[2]).cast<float>();
  s->wi = Eigen::Vector3d(ep.wi[0], ep.wi[1], ep.wi[2]).cast<float>();
  s->distance = static_cast<float>(ep.distance);
  s->pdf = ep.pdf;
  return ok;
}

float EmitterSampler::Pdf(const std::vector<Pose>& X_WB, int geom, const Eigen::Vector3f& p_W,
                          const Eigen::Vector3f& p_hit_W, const Eigen::Vector3f& n_hit_W) const {
  if (geom < 0 || geom >= static_cast<int>(emitter_of_geom_.size())) return 0.0f;
  const int k = emitter_of_geom_[geom];
  if (k < 0) return 0.0f;
  const Emitter& e = emitters_[k];
  const double p_pick = pick_cdf_[k + 1] - pick_cdf_[k];
  if (!(p_pick > 0)) return 0.0f;
  const Eigen::Vector3d c = e.pod.shape == EmitterShape::kSphere
                                ? Eigen::Vector3d(GeomPose(X_WB, e).translation())
                                : Eigen::Vector3d::Zero();
  const double p[3] = {p_W.x(), p_W.y(), p_W.z()};
  const double hit[3] = {p_hit_W.x(), p_hit_W.y(), p_hit_W.z()};
  const double n[3] = {n_hit_W.x(), n_hit_W.y(), n_hit_W.z()};
  return EmitterPointPdf(e.pod, p_pick, c.data(), p, hit, n);
}

}  // namespace penumbra

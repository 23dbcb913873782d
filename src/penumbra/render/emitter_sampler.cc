#include "penumbra/render/emitter_sampler.h"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <string>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

double EmitterLuminance(const Eigen::Vector3f& c) {
  return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z();
}

// index of the cdf interval holding u, and u rescaled to [0, 1) within it.
int PickFromCdf(const std::vector<double>& cdf, double u, double* u_rest) {
  const int n = static_cast<int>(cdf.size()) - 1;
  int i = static_cast<int>(std::upper_bound(cdf.begin(), cdf.end(), u) - cdf.begin()) - 1;
  i = std::clamp(i, 0, n - 1);
  while (i < n - 1 && cdf[i + 1] <= cdf[i]) ++i;
  const double width = cdf[i + 1] - cdf[i];
  *u_rest = width > 0 ? std::clamp((u - cdf[i]) / width, 0.0, 1.0 - 1e-12) : 0.5;
  return i;
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

// an orthonormal basis around unit n (Duff et al., "Building an orthonormal basis,
// revisited", JCGT 2017).
void Basis(const Eigen::Vector3d& n, Eigen::Vector3d* t, Eigen::Vector3d* b) {
  const double sign = std::copysign(1.0, n.z());
  const double a = -1.0 / (sign + n.z());
  const double bb = n.x() * n.y() * a;
  *t = Eigen::Vector3d(1 + sign * n.x() * n.x() * a, sign * bb, -sign * n.x());
  *b = Eigen::Vector3d(bb, sign + n.y() * n.y() * a, -n.y());
}

Eigen::Vector3d UniformSphere(double u1, double u2) {
  const double z = 1 - 2 * u1;
  const double r = std::sqrt(std::max(0.0, 1 - z * z));
  const double phi = 2 * std::numbers::pi * u2;
  return {r * std::cos(phi), r * std::sin(phi), z};
}

bool IsSampledShape(const Geom& g) {
  switch (g.shape) {
    case GeomShape::kSphere:
    case GeomShape::kBox:
    case GeomShape::kMesh:
    case GeomShape::kCylinder:
    case GeomShape::kCapsule:
      return true;
    case GeomShape::kPlane:
      return g.size.x() > 0 && g.size.y() > 0;  // finite planes only
    default:
      return false;
  }
}

// 1 - cos(theta_max) of the cone a sphere of radius r subtends at distance dc > r, stable for
// small cones.
double OneMinusCosCone(double r, double dc) {
  const double sin2 = std::min(1.0, r * r / (dc * dc));
  return sin2 / (1 + std::sqrt(std::max(0.0, 1 - sin2)));
}

// a point counts as outside a sphere (cone sampling) beyond this factor of r^2.
constexpr double kOutsideFactor = 1.0001;

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
  }
  BuildCdf(power, &pick_cdf_);
}

Pose EmitterSampler::GeomPose(const std::vector<Pose>& X_WB, const Emitter& e) const {
  const Geom& g = scene_.geoms[e.geom];
  const Pose& X_WBody =
      g.body >= 0 && g.body < static_cast<int>(X_WB.size()) ? X_WB[g.body] : Pose::Identity();
  return X_WBody * g.X_BG;
}

void EmitterSampler::SampleArea(const Emitter& e, float u_part, float u1, float u2,
                                Eigen::Vector3d* p, Eigen::Vector3d* n) const {
  const Geom& g = scene_.geoms[e.geom];
  const Eigen::Vector3d s = g.size;
  double ur = u_part;
  int part = 0;
  if (!e.part_cdf.empty()) part = PickFromCdf(e.part_cdf, u_part, &ur);
  switch (e.shape) {
    case GeomShape::kSphere:
      *n = UniformSphere(u1, u2);
      *p = s.x() * *n;
      break;
    case GeomShape::kPlane:
      *p = Eigen::Vector3d((2 * u1 - 1) * s.x(), (2 * u2 - 1) * s.y(), 0);
      *n = Eigen::Vector3d(0, 0, 1);
      break;
    case GeomShape::kBox: {
      const int axis = part / 2;
      const double sign = (part % 2 == 0) ? 1.0 : -1.0;
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      Eigen::Vector3d q;
      q[axis] = sign * s[axis];
      q[a1] = (2 * u1 - 1) * s[a1];
      q[a2] = (2 * u2 - 1) * s[a2];
      *p = q;
      *n = Eigen::Vector3d::Zero();
      (*n)[axis] = sign;
      break;
    }
    case GeomShape::kCylinder:
    case GeomShape::kCapsule: {
      const double r = s.x(), h = s.y();
      if (part == 0) {  // side
        const double phi = 2 * std::numbers::pi * u1;
        *n = Eigen::Vector3d(std::cos(phi), std::sin(phi), 0);
        *p = Eigen::Vector3d(r * n->x(), r * n->y(), (2 * u2 - 1) * h);
      } else {
        const double sign = part == 1 ? 1.0 : -1.0;
        if (e.shape == GeomShape::kCylinder) {  // cap disc
          const double rr = r * std::sqrt(static_cast<double>(u1)), phi = 2 * std::numbers::pi * u2;
          *p = Eigen::Vector3d(rr * std::cos(phi), rr * std::sin(phi), sign * h);
          *n = Eigen::Vector3d(0, 0, sign);
        } else {  // hemisphere: uniform on the half sphere z * sign >= 0
          const double z = static_cast<double>(u1);
          const double rr = std::sqrt(std::max(0.0, 1 - z * z)), phi = 2 * std::numbers::pi * u2;
          *n = Eigen::Vector3d(rr * std::cos(phi), rr * std::sin(phi), sign * z);
          *p = r * *n + Eigen::Vector3d(0, 0, sign * h);
        }
      }
      break;
    }
    case GeomShape::kMesh: {
      const TriangleMesh& mesh = scene_.meshes[g.mesh];
      const Eigen::Vector3i& f = mesh.faces[part];
      const Eigen::Vector3d a = mesh.vertices[f[0]].cast<double>();
      const Eigen::Vector3d b = mesh.vertices[f[1]].cast<double>();
      const Eigen::Vector3d c = mesh.vertices[f[2]].cast<double>();
      const double su = std::sqrt(static_cast<double>(u1));
      const double b0 = 1 - su, b1 = static_cast<double>(u2) * su;
      *p = b0 * a + b1 * b + (1 - b0 - b1) * c;
      *n = (b - a).cross(c - a).normalized();
      break;
    }
    default:
      *p = Eigen::Vector3d::Zero();
      *n = Eigen::Vector3d::UnitZ();
      break;
  }
}

bool EmitterSampler::Sample(const std::vector<Pose>& X_WB, const Eigen::Vector3f& p_W, float u_pick,
                            float u1, float u2, EmitterSample* s) const {
  if (emitters_.empty()) return false;
  double u_rest = 0;
  const int k = PickFromCdf(pick_cdf_, u_pick, &u_rest);
  const double p_pick = pick_cdf_[k + 1] - pick_cdf_[k];
  if (!(p_pick > 0)) return false;
  const Emitter& e = emitters_[k];
  const Pose X_WG = GeomPose(X_WB, e);
  const Eigen::Vector3d p = p_W.cast<double>();
  s->geom = e.geom;
  s->Le = e.Le;

  if (e.shape == GeomShape::kSphere) {
    const double r = scene_.geoms[e.geom].size.x();
    const Eigen::Vector3d c = X_WG.translation();
    const Eigen::Vector3d to_c = c - p;
    const double dc2 = to_c.squaredNorm();
    if (dc2 > kOutsideFactor * r * r) {
      // uniform direction in the subtended cone, then the nearer intersection with the sphere.
      const double dc = std::sqrt(dc2);
      const double one_minus_cos_max = OneMinusCosCone(r, dc);
      const double cos_t = 1 - u1 * one_minus_cos_max;
      const double sin_t = std::sqrt(std::max(0.0, 1 - cos_t * cos_t));
      const double phi = 2 * std::numbers::pi * u2;
      const Eigen::Vector3d w = to_c / dc;
      Eigen::Vector3d t, b;
      Basis(w, &t, &b);
      const Eigen::Vector3d wi = sin_t * std::cos(phi) * t + sin_t * std::sin(phi) * b + cos_t * w;
      // distance along wi to the sphere: dc cos_t - sqrt(r^2 - dc^2 sin_t^2) (clamped at tangency).
      const double disc = std::max(0.0, r * r - dc2 * sin_t * sin_t);
      const double dist = dc * cos_t - std::sqrt(disc);
      const Eigen::Vector3d hit = p + dist * wi;
      s->p_W = hit.cast<float>();
      s->n_W = (hit - c).normalized().cast<float>();
      s->wi = wi.cast<float>();
      s->distance = static_cast<float>(dist);
      s->pdf = static_cast<float>(p_pick / (2 * std::numbers::pi * one_minus_cos_max));
      return s->pdf > 0 && dist > 0;
    }
  }
  Eigen::Vector3d q_G, n_G;
  SampleArea(e, static_cast<float>(u_rest), u1, u2, &q_G, &n_G);
  const Eigen::Vector3d q = X_WG * q_G;
  const Eigen::Vector3d n = X_WG.linear() * n_G;
  const Eigen::Vector3d d = q - p;
  const double dist2 = d.squaredNorm();
  if (!(dist2 > 0)) return false;
  const double dist = std::sqrt(dist2);
  const Eigen::Vector3d wi = d / dist;
  const double cos_l = std::abs(n.dot(wi));
  if (!(cos_l > 1e-7)) return false;
  s->p_W = q.cast<float>();
  s->n_W = n.cast<float>();
  s->wi = wi.cast<float>();
  s->distance = static_cast<float>(dist);
  s->pdf = static_cast<float>(p_pick * dist2 / (e.area * cos_l));
  return std::isfinite(s->pdf) && s->pdf > 0;
}

float EmitterSampler::Pdf(const std::vector<Pose>& X_WB, int geom, const Eigen::Vector3f& p_W,
                          const Eigen::Vector3f& p_hit_W, const Eigen::Vector3f& n_hit_W) const {
  if (geom < 0 || geom >= static_cast<int>(emitter_of_geom_.size())) return 0.0f;
  const int k = emitter_of_geom_[geom];
  if (k < 0) return 0.0f;
  const Emitter& e = emitters_[k];
  const double p_pick = pick_cdf_[k + 1] - pick_cdf_[k];
  if (!(p_pick > 0)) return 0.0f;
  const Eigen::Vector3d p = p_W.cast<double>();
  if (e.shape == GeomShape::kSphere) {
    const double r = scene_.geoms[e.geom].size.x();
    const double dc2 = (GeomPose(X_WB, e).translation() - p).squaredNorm();
    if (dc2 > kOutsideFactor * r * r)
      return static_cast<float>(p_pick /
                                (2 * std::numbers::pi * OneMinusCosCone(r, std::sqrt(dc2))));
  }
  const Eigen::Vector3d d = p_hit_W.cast<double>() - p;
  const double dist2 = d.squaredNorm();
  if (!(dist2 > 0)) return 0.0f;
  const double cos_l = std::abs(n_hit_W.cast<double>().normalized().dot(d / std::sqrt(dist2)));
  if (!(cos_l > 1e-7)) return 0.0f;
  return static_cast<float>(p_pick * dist2 / (e.area * cos_l));
}

}  // namespace penumbra

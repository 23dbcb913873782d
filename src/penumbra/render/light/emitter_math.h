#pragma once
// the emissive geoms' sampling (render/light/emitter_sampler.h: one emitter picked by power, then a
// point on it: uniform in the cone a sphere subtends, else uniform by area, converted to solid
// angle) as PB_HOST_DEVICE functions in double over plain data, called by the CPU's
// EmitterSampler. the model and its references are in emitter_sampler.h.
//
// bit-for-bit rule: the expressions keep the rounding of the Eigen code they replaced. Eigen
// 3.4 sums a Vector3d's dot product and squared norm (x + y) + z (two lanes of a packet, then the
// third; unlike a Vector3f's x + (y + z)), and an Isometry3d times a point as a chain of fused
// multiply-adds, fma(R(r, 2), z, fma(R(r, 1), y, R(r, 0) x)) + t, since its packet multiply-add is
// an FMA instruction under -march=native (-ffp-contract=off does not reach intrinsics); its
// rotation times a vector takes that chain for rows 0 and 1 and x + (y + z) for row 2: PoseApply
// and RotateApply write these with fma(). each was checked bit for bit against Eigen on a million
// random cases (this build: GCC 12, Eigen 3.4.0, -O3 -march=native -ffp-contract=off).

#include <cmath>
#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

/// a geom's shape as EmitterPod takes it (GeomShape's values are mapped by the caller).
enum class EmitterShape : int32_t { kSphere = 0, kPlane, kBox, kCylinder, kCapsule, kMesh, kOther };

/// one emissive geom as plain data (EmitterSampler's): its shape and size (the geom's size),
/// emission Le (cd/m^2), total area (m^2), the cdf of its parts by area (box faces, cylinder or
/// capsule side and caps, mesh triangles; num_parts + 1 values, or none) and, for a mesh, its
/// vertices (x, y, z floats) and faces (3 vertex indices each).
struct EmitterPod {
  EmitterShape shape = EmitterShape::kOther;
  double size[3] = {0, 0, 0};
  double area = 0;
  const double* part_cdf = nullptr;
  int32_t num_parts = 0;
  const float* vertices = nullptr;
  const int32_t* faces = nullptr;
};

namespace emitter_detail {

constexpr double kPi = 3.14159265358979323846;
/// a point counts as outside a sphere (cone sampling) beyond this factor of r^2.
constexpr double kOutsideFactor = 1.0001;

}  // namespace emitter_detail

/// a . b of double 3-vectors summed as Eigen sums a Vector3d's: (x + y) + z.
PB_HOST_DEVICE inline double EmitterDot(const double a[3], const double b[3]) {
  return (a[0] * b[0] + a[1] * b[1]) + a[2] * b[2];
}

/// v / |v| component by component where |v|^2 > 0 (Eigen's normalized() of a Vector3d).
PB_HOST_DEVICE inline void EmitterNormalize(const double v[3], double out[3]) {
  const double z = EmitterDot(v, v);
  if (!(z > 0)) {
    for (int k = 0; k < 3; ++k) out[k] = v[k];
    return;
  }
  const double n = sqrt(z);
  for (int k = 0; k < 3; ++k) out[k] = v[k] / n;
}

/// R q + t for a row-major rotation R (9 values) and translation t, rounded as Eigen's
/// Isometry3d * Vector3d (file comment).
PB_HOST_DEVICE inline void PoseApply(const double R[9], const double t[3], const double q[3],
                                     double out[3]) {
  for (int r = 0; r < 3; ++r)
    out[r] = fma(R[3 * r + 2], q[2], fma(R[3 * r + 1], q[1], R[3 * r] * q[0])) + t[r];
}

/// R v, rounded as Eigen's Isometry3d::linear() * Vector3d: rows 0 and 1 as one packet of two
/// (the chain of fused multiply-adds), row 2 alone, x + (y + z) (measured bit for bit on a
/// million random rotations and vectors).
PB_HOST_DEVICE inline void RotateApply(const double R[9], const double v[3], double out[3]) {
  for (int r = 0; r < 2; ++r)
    out[r] = fma(R[3 * r + 2], v[2], fma(R[3 * r + 1], v[1], R[3 * r] * v[0]));
  out[2] = R[6] * v[0] + (R[7] * v[1] + R[8] * v[2]);
}

/// the index of the interval of cdf (n intervals, n + 1 values) that holds u (the last value
/// <= u, as std::upper_bound), moved past empty intervals, and u rescaled to [0, 1) within it.
PB_HOST_DEVICE inline int EmitterPickFromCdf(const double* cdf, int n, double u, double* u_rest) {
  int lo = 0, hi = n + 1;  // the first index with cdf[index] > u, in [0, n + 1]
  while (lo < hi) {
    const int mid = lo + (hi - lo) / 2;
    if (u < cdf[mid]) {
      hi = mid;
    } else {
      lo = mid + 1;
    }
  }
  int i = lo - 1;
  i = i < 0 ? 0 : (n - 1 < i ? n - 1 : i);
  while (i < n - 1 && cdf[i + 1] <= cdf[i]) ++i;
  const double width = cdf[i + 1] - cdf[i];
  *u_rest = width > 0 ? pbm::Clamp((u - cdf[i]) / width, 0.0, 1.0 - 1e-12) : 0.5;
  return i;
}

/// 1 - cos(theta_max) of the cone a sphere of radius r subtends at distance dc > r (stable for
/// small cones).
PB_HOST_DEVICE inline double EmitterOneMinusCosCone(double r, double dc) {
  const double sin2 = pbm::Min(1.0, r * r / (dc * dc));
  return sin2 / (1 + sqrt(pbm::Max(0.0, 1 - sin2)));
}

/// a uniform point on emitter e's surface in the geom frame and its outward unit normal, from
/// u_part (the part, by area) and u1, u2.
PB_HOST_DEVICE inline void EmitterSampleArea(const EmitterPod& e, float u_part, float u1, float u2,
                                             double p[3], double n[3]) {
  using emitter_detail::kPi;
  const double* s = e.size;
  double ur = u_part;
  int part = 0;
  if (e.num_parts > 0) part = EmitterPickFromCdf(e.part_cdf, e.num_parts, u_part, &ur);
  switch (e.shape) {
    case EmitterShape::kSphere: {
      // uniform on the sphere (Archimedes): z uniform in [-1, 1]
      const double z = 1 - 2 * static_cast<double>(u1);
      const double r = sqrt(pbm::Max(0.0, 1 - z * z));
      const double phi = 2 * kPi * static_cast<double>(u2);
      n[0] = r * cos(phi), n[1] = r * sin(phi), n[2] = z;
      for (int k = 0; k < 3; ++k) p[k] = s[0] * n[k];
      break;
    }
    case EmitterShape::kPlane:
      p[0] = (2 * u1 - 1) * s[0], p[1] = (2 * u2 - 1) * s[1], p[2] = 0;
      n[0] = 0, n[1] = 0, n[2] = 1;
      break;
    case EmitterShape::kBox: {
      const int axis = part / 2;
      const double sign = (part % 2 == 0) ? 1.0 : -1.0;
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      p[axis] = sign * s[axis];
      p[a1] = (2 * u1 - 1) * s[a1];
      p[a2] = (2 * u2 - 1) * s[a2];
      n[0] = n[1] = n[2] = 0;
      n[axis] = sign;
      break;
    }
    case EmitterShape::kCylinder:
    case EmitterShape::kCapsule: {
      const double r = s[0], h = s[1];
      if (part == 0) {  // side
        const double phi = 2 * kPi * u1;
        n[0] = cos(phi), n[1] = sin(phi), n[2] = 0;
        p[0] = r * n[0], p[1] = r * n[1], p[2] = (2 * u2 - 1) * h;
      } else {
        const double sign = part == 1 ? 1.0 : -1.0;
        if (e.shape == EmitterShape::kCylinder) {  // cap disc
          const double rr = r * sqrt(static_cast<double>(u1)), phi = 2 * kPi * u2;
          p[0] = rr * cos(phi), p[1] = rr * sin(phi), p[2] = sign * h;
          n[0] = 0, n[1] = 0, n[2] = sign;
        } else {  // hemisphere: uniform on the half sphere z * sign >= 0
          const double z = static_cast<double>(u1);
          const double rr = sqrt(pbm::Max(0.0, 1 - z * z)), phi = 2 * kPi * u2;
          n[0] = rr * cos(phi), n[1] = rr * sin(phi), n[2] = sign * z;
          p[0] = r * n[0] + 0.0, p[1] = r * n[1] + 0.0, p[2] = r * n[2] + sign * h;
        }
      }
      break;
    }
    case EmitterShape::kMesh: {
      const int32_t* f = e.faces + 3 * part;
      double a[3], b[3], c[3];
      for (int k = 0; k < 3; ++k) {
        a[k] = e.vertices[3 * f[0] + k];
        b[k] = e.vertices[3 * f[1] + k];
        c[k] = e.vertices[3 * f[2] + k];
      }
      const double su = sqrt(static_cast<double>(u1));
      const double b0 = 1 - su, b1 = static_cast<double>(u2) * su;
      for (int k = 0; k < 3; ++k) p[k] = b0 * a[k] + b1 * b[k] + (1 - b0 - b1) * c[k];
      const double ba[3] = {b[0] - a[0], b[1] - a[1], b[2] - a[2]};
      const double ca[3] = {c[0] - a[0], c[1] - a[1], c[2] - a[2]};
      const double x[3] = {ba[1] * ca[2] - ba[2] * ca[1], ba[2] * ca[0] - ba[0] * ca[2],
                           ba[0] * ca[1] - ba[1] * ca[0]};
      EmitterNormalize(x, n);
      break;
    }
    default:
      p[0] = p[1] = p[2] = 0;
      n[0] = 0, n[1] = 0, n[2] = 1;
      break;
  }
}

/// a sample of emitter e (picked with probability p_pick, posed by rotation R_WG, row-major,
/// and translation t_WG) seen from point p: the sampled point q and its outward normal n (world),
/// the unit direction wi from p, the distance and the solid-angle density (emitter choice
/// included), from u_rest (the part, EmitterPickFromCdf's rescaled number), u1 and u2.
/// returns false when the density is zero or not finite (p on the emitter's plane).
struct EmitterPoint {
  double q[3], n[3], wi[3];
  double distance = 0;
  float pdf = 0;
};

PB_HOST_DEVICE inline bool EmitterSamplePoint(const EmitterPod& e, double p_pick,
                                              const double R_WG[9], const double t_WG[3],
                                              const double p[3], double u_rest, float u1, float u2,
                                              EmitterPoint* s) {
  using emitter_detail::kPi;
  if (e.shape == EmitterShape::kSphere) {
    const double r = e.size[0];
    const double* c = t_WG;
    const double to_c[3] = {c[0] - p[0], c[1] - p[1], c[2] - p[2]};
    const double dc2 = EmitterDot(to_c, to_c);
    if (dc2 > emitter_detail::kOutsideFactor * r * r) {
      // uniform direction in the subtended cone, then the nearer intersection with the sphere.
      const double dc = sqrt(dc2);
      const double one_minus_cos_max = EmitterOneMinusCosCone(r, dc);
      const double cos_t = 1 - u1 * one_minus_cos_max;
      const double sin_t = sqrt(pbm::Max(0.0, 1 - cos_t * cos_t));
      const double phi = 2 * kPi * u2;
      const double w[3] = {to_c[0] / dc, to_c[1] / dc, to_c[2] / dc};
      // the basis of Duff et al. ("Building an orthonormal basis, revisited", JCGT 2017)
      const double sign = copysign(1.0, w[2]);
      const double a = -1.0 / (sign + w[2]);
      const double bb = w[0] * w[1] * a;
      const double t[3] = {1 + sign * w[0] * w[0] * a, sign * bb, -sign * w[0]};
      const double b[3] = {bb, sign + w[1] * w[1] * a, -w[1]};
      const double sc = sin_t * cos(phi), ss = sin_t * sin(phi);
      for (int k = 0; k < 3; ++k) s->wi[k] = sc * t[k] + ss * b[k] + cos_t * w[k];
      // distance along wi to the sphere: dc cos_t - sqrt(r^2 - dc^2 sin_t^2) (clamped at
      // tangency).
      const double disc = pbm::Max(0.0, r * r - dc2 * sin_t * sin_t);
      const double dist = dc * cos_t - sqrt(disc);
      for (int k = 0; k < 3; ++k) s->q[k] = p[k] + dist * s->wi[k];
      const double hc[3] = {s->q[0] - c[0], s->q[1] - c[1], s->q[2] - c[2]};
      EmitterNormalize(hc, s->n);
      s->distance = dist;
      s->pdf = static_cast<float>(p_pick / (2 * kPi * one_minus_cos_max));
      return s->pdf > 0 && dist > 0;
    }
  }
  double q_G[3], n_G[3];
  EmitterSampleArea(e, static_cast<float>(u_rest), u1, u2, q_G, n_G);
  PoseApply(R_WG, t_WG, q_G, s->q);
  RotateApply(R_WG, n_G, s->n);
  const double d[3] = {s->q[0] - p[0], s->q[1] - p[1], s->q[2] - p[2]};
  const double dist2 = EmitterDot(d, d);
  if (!(dist2 > 0)) return false;
  const double dist = sqrt(dist2);
  for (int k = 0; k < 3; ++k) s->wi[k] = d[k] / dist;
  const double cos_l = fabs(EmitterDot(s->n, s->wi));
  if (!(cos_l > 1e-7)) return false;
  s->distance = dist;
  s->pdf = static_cast<float>(p_pick * dist2 / (e.area * cos_l));
#if defined(__CUDA_ARCH__)
  return isfinite(s->pdf) && s->pdf > 0;
#else
  return std::isfinite(s->pdf) && s->pdf > 0;
#endif
}

/// the solid-angle density with which EmitterSamplePoint, at p, returns the direction to point
/// p_hit with unit normal n_hit (any sign) on emitter e (picked with probability p_pick, its
/// centre t_WG).
PB_HOST_DEVICE inline float EmitterPointPdf(const EmitterPod& e, double p_pick,
                                            const double t_WG[3], const double p[3],
                                            const double p_hit[3], const double n_hit[3]) {
  using emitter_detail::kPi;
  if (e.shape == EmitterShape::kSphere) {
    const double r = e.size[0];
    const double to_c[3] = {t_WG[0] - p[0], t_WG[1] - p[1], t_WG[2] - p[2]};
    const double dc2 = EmitterDot(to_c, to_c);
    if (dc2 > emitter_detail::kOutsideFactor * r * r)
      return static_cast<float>(p_pick / (2 * kPi * EmitterOneMinusCosCone(r, sqrt(dc2))));
  }
  const double d[3] = {p_hit[0] - p[0], p_hit[1] - p[1], p_hit[2] - p[2]};
  const double dist2 = EmitterDot(d, d);
  if (!(dist2 > 0)) return 0.0f;
  double n[3];
  EmitterNormalize(n_hit, n);
  const double sd = sqrt(dist2);
  const double du[3] = {d[0] / sd, d[1] / sd, d[2] / sd};
  const double cos_l = fabs(EmitterDot(n, du));
  if (!(cos_l > 1e-7)) return 0.0f;
  return static_cast<float>(p_pick * dist2 / (e.area * cos_l));
}

}  // namespace penumbra

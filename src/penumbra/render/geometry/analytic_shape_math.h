#pragma once
// the analytic shapes' intersection and normal formulas on plain arrays, written once for both
// processors (PB_HOST_DEVICE, core/host_device.h): IntersectAnalytic / AnalyticNormal
// (analytic_shapes.h, the CPU's Eigen forms) and the CUDA backend (render/cuda/) call these.
// no Eigen here, so that device code can include it. exact ray intersection with the quadric
// MuJoCo primitives in the geom frame in double precision: plane (rectangle), sphere, ellipsoid,
// cylinder (with caps) and capsule (cylinder with hemispherical ends).
//
// quadratic roots use the numerically stable form of Pharr, Jakob, Humphreys, "Physically
// Based Rendering", 4th ed., sec. 6.8.1 (discriminant from the ray's closest approach).

#include <cmath>

#include "penumbra/core/host_device.h"

namespace penumbra {

/// the analytic shapes. sizes follow MuJoCo's geom_size (see Geom::size).
enum class AnalyticKind { kPlane, kSphere, kCapsule, kEllipsoid, kCylinder };

/// which part of a shape a ray hit (selects the normal formula).
enum class ShapePart { kMain = 0, kTop = 1, kBottom = 2 };

/// IntersectAnalytic on plain arrays, for both processors (PB_HOST_DEVICE: the CPU's
/// IntersectAnalytic and the CUDA backend, render/cuda/, run this one definition). `size` as
/// AnalyticShape::size, o and d in the shape's frame; writes the root and its part
/// (ShapePart as int) and returns true, or returns false.
PB_HOST_DEVICE inline bool IntersectAnalyticArrays(AnalyticKind kind, const double size[3],
                                                   const double o[3], const double d[3],
                                                   double tmin, double tmax, double* t, int* part);

/// AnalyticNormal on plain arrays (for both processors): unit outward normal n of the shape at
/// surface point p (geom frame) on part `part` (ShapePart as int).
PB_HOST_DEVICE inline void AnalyticNormalArrays(AnalyticKind kind, const double size[3],
                                                const double p[3], int part, double n[3]);

namespace analytic_detail {

// running closest root in (tmin, tmax).
struct Closest {
  double tmin, tmax;
  bool found = false;
  double t = 0;
  int part = 0;
  PB_HOST_DEVICE void Offer(double tc, int p) {
    if (tc > tmin && tc < tmax && (!found || tc < t)) {
      found = true;
      t = tc;
      part = p;
    }
  }
};

// roots of |o + t d|^2 = r^2 over the first `dim` coordinates (2: infinite cylinder about z,
// 3: sphere), stable form (pbrt-v4 sec. 6.8.1): the discriminant comes from the squared
// distance of the line to the centre instead of b^2 - 4ac. sums run left to right (as Eigen's
// dot and squaredNorm of 2 or 3 doubles, which analytic_lanes.cc reproduces). returns false
// if the line misses.
template <int dim>
PB_HOST_DEVICE inline bool QuadricRoots(const double o[3], const double d[3], double r, double* t0,
                                        double* t1) {
  double a = d[0] * d[0] + d[1] * d[1];
  double od = o[0] * d[0] + o[1] * d[1];
  double oo = o[0] * o[0] + o[1] * o[1];
  if constexpr (dim == 3) {
    a = a + d[2] * d[2];
    od = od + o[2] * d[2];
    oo = oo + o[2] * o[2];
  }
  if (!(a > 0)) return false;
  const double b = 2 * od;
  const double c = oo - r * r;
  const double k = b / (2 * a);
  const double vx = o[0] - k * d[0], vy = o[1] - k * d[1];
  double vv = vx * vx + vy * vy;
  if constexpr (dim == 3) {
    const double vz = o[2] - k * d[2];
    vv = vv + vz * vz;
  }
  const double disc = 4 * a * (r * r - vv);
  if (disc < 0) return false;
  const double root = sqrt(disc);
  const double q = b < 0 ? -0.5 * (b - root) : -0.5 * (b + root);
  if (q == 0) {
    // b == 0 and a tangent ray: a double root at t = 0 (c == 0) or none.
    if (c != 0) return false;
    *t0 = *t1 = 0;
    return true;
  }
  *t0 = q / a;
  *t1 = c / q;
  if (*t0 > *t1) {
    const double s = *t0;
    *t0 = *t1;
    *t1 = s;
  }
  return true;
}

}  // namespace analytic_detail

PB_HOST_DEVICE inline bool IntersectAnalyticArrays(AnalyticKind kind, const double size[3],
                                                   const double o[3], const double d[3],
                                                   double tmin, double tmax, double* t, int* part) {
  using analytic_detail::QuadricRoots;
  constexpr int kMainPart = static_cast<int>(ShapePart::kMain);
  constexpr int kTopPart = static_cast<int>(ShapePart::kTop);
  constexpr int kBottomPart = static_cast<int>(ShapePart::kBottom);
  analytic_detail::Closest best{tmin, tmax};
  double t0, t1;
  switch (kind) {
    case AnalyticKind::kPlane: {
      if (d[2] == 0) return false;
      const double tc = -o[2] / d[2];
      const double x = o[0] + tc * d[0], y = o[1] + tc * d[1];
      if (fabs(x) <= size[0] && fabs(y) <= size[1]) best.Offer(tc, kMainPart);
      break;
    }
    case AnalyticKind::kSphere:
      if (QuadricRoots<3>(o, d, size[0], &t0, &t1)) {
        best.Offer(t0, kMainPart);
        best.Offer(t1, kMainPart);
      }
      break;
    case AnalyticKind::kEllipsoid: {
      // a unit sphere after scaling each axis by 1 / radius (t is unchanged by the scaling).
      const double inv[3] = {1.0 / size[0], 1.0 / size[1], 1.0 / size[2]};
      const double os[3] = {o[0] * inv[0], o[1] * inv[1], o[2] * inv[2]};
      const double ds[3] = {d[0] * inv[0], d[1] * inv[1], d[2] * inv[2]};
      if (QuadricRoots<3>(os, ds, 1.0, &t0, &t1)) {
        best.Offer(t0, kMainPart);
        best.Offer(t1, kMainPart);
      }
      break;
    }
    case AnalyticKind::kCylinder:
    case AnalyticKind::kCapsule: {
      const double r = size[0], h = size[1];
      // side: infinite cylinder about z, kept where |z| <= h.
      if (QuadricRoots<2>(o, d, r, &t0, &t1)) {
        if (fabs(o[2] + t0 * d[2]) <= h) best.Offer(t0, kMainPart);
        if (fabs(o[2] + t1 * d[2]) <= h) best.Offer(t1, kMainPart);
      }
      if (kind == AnalyticKind::kCylinder) {
        // flat caps at z = +-h.
        if (d[2] != 0) {
          for (int s = 1; s >= -1; s -= 2) {
            const double tc = (s * h - o[2]) / d[2];
            const double x = o[0] + tc * d[0], y = o[1] + tc * d[1];
            if (x * x + y * y <= r * r) best.Offer(tc, s > 0 ? kTopPart : kBottomPart);
          }
        }
      } else {
        // hemispheres centred at z = +-h, kept on their outer halves.
        for (int s = 1; s >= -1; s -= 2) {
          const double oc[3] = {o[0], o[1], o[2] - s * h};
          if (!QuadricRoots<3>(oc, d, r, &t0, &t1)) continue;
          if (s * (oc[2] + t0 * d[2]) >= 0) best.Offer(t0, s > 0 ? kTopPart : kBottomPart);
          if (s * (oc[2] + t1 * d[2]) >= 0) best.Offer(t1, s > 0 ? kTopPart : kBottomPart);
        }
      }
      break;
    }
  }
  if (!best.found) return false;
  *t = best.t;
  *part = best.part;
  return true;
}

PB_HOST_DEVICE inline void AnalyticNormalArrays(AnalyticKind kind, const double size[3],
                                                const double p[3], int part, double n[3]) {
  n[0] = p[0], n[1] = p[1], n[2] = p[2];  // sphere
  switch (kind) {
    case AnalyticKind::kPlane:
      n[0] = 0, n[1] = 0, n[2] = 1;
      return;
    case AnalyticKind::kSphere:
      break;
    case AnalyticKind::kEllipsoid:
      // gradient of sum (x_i / r_i)^2.
      for (int i = 0; i < 3; ++i) n[i] = p[i] / (size[i] * size[i]);
      break;
    case AnalyticKind::kCylinder:
      if (part == static_cast<int>(ShapePart::kTop) ||
          part == static_cast<int>(ShapePart::kBottom)) {
        n[0] = 0, n[1] = 0, n[2] = part == static_cast<int>(ShapePart::kTop) ? 1 : -1;
        return;
      }
      n[2] = 0;
      break;
    case AnalyticKind::kCapsule:
      if (part == static_cast<int>(ShapePart::kTop)) {
        n[2] = p[2] - size[1];
      } else if (part == static_cast<int>(ShapePart::kBottom)) {
        n[2] = p[2] + size[1];
      } else {
        n[2] = 0;
      }
      break;
  }
  // norm as Eigen's: sqrt of the left-to-right sum of squares
  const double len = sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]);
  if (len > 0) {
    n[0] = n[0] / len, n[1] = n[1] / len, n[2] = n[2] / len;
  } else {
    n[0] = 0, n[1] = 0, n[2] = 1;
  }
}

}  // namespace penumbra

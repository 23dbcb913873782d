#include "penumbra/render/embree/analytic_lanes.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace penumbra {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kNaN = std::numeric_limits<double>::quiet_NaN();
constexpr int kW = kAnalyticLanes;

// the helpers below run over a fixed number W of lanes (4, 8 or 16: AnalyticLaneWidth), so
// that the compiler unrolls and vectorises them without remainder loops.

// the running closest hit of every lane (analytic_shapes.cc's Closest::Offer, branch-free):
// t = +inf means none yet, and a candidate is only ever taken when it is < tmax <= +inf.
template <int W>
struct BestLanes {
  alignas(64) double t[W];
  alignas(64) double part[W];
  BestLanes() {
    std::fill(t, t + W, kInf);
    std::fill(part, part + W, 0.0);
  }
};

inline void Offer(double tc, bool ok, double part, double tmin, double tmax, double* t, double* p) {
  const bool take = ok & (tc > tmin) & (tc < tmax) & (tc < *t);
  *t = take ? tc : *t;
  *p = take ? part : *p;
}

// QuadricRoots<dim> of analytic_shapes.cc on lanes [0, W): the roots of |o + t d|^2 = r^2
// over the first `dim` coordinates, sorted (lo <= hi), NaN in both where the scalar version
// returns false. the same operations in the same order (Eigen's dot and squaredNorm of 2 or 3
// doubles sum left to right).
template <int dim, int W>
void RootsLanes(const double* ox, const double* oy, const double* oz, const double* dx,
                const double* dy, const double* dz, double r, double* lo, double* hi) {
  alignas(64) double a[W], b[W], c[W], disc[W], root[W];
  const double r2 = r * r;
  for (int i = 0; i < W; ++i) {
    double aa = dx[i] * dx[i] + dy[i] * dy[i];
    double od = ox[i] * dx[i] + oy[i] * dy[i];
    double oo = ox[i] * ox[i] + oy[i] * oy[i];
    if constexpr (dim == 3) {
      aa = aa + dz[i] * dz[i];
      od = od + oz[i] * dz[i];
      oo = oo + oz[i] * oz[i];
    }
    const double bb = 2 * od;
    const double k = bb / (2 * aa);
    const double vx = ox[i] - k * dx[i], vy = oy[i] - k * dy[i];
    double vv = vx * vx + vy * vy;
    if constexpr (dim == 3) {
      const double vz = oz[i] - k * dz[i];
      vv = vv + vz * vz;
    }
    a[i] = aa;
    b[i] = bb;
    c[i] = oo - r2;
    disc[i] = 4 * aa * (r2 - vv);
  }
  // Eigen's packet sqrt (std::sqrt in the loop would not vectorise: it may set errno).
  using Array = Eigen::Array<double, W, 1>;
  Eigen::Map<Array> root_lanes(root);
  root_lanes = Eigen::Map<const Array>(disc).sqrt();
  for (int i = 0; i < W; ++i) {
    const double q = b[i] < 0 ? -0.5 * (b[i] - root[i]) : -0.5 * (b[i] + root[i]);
    const double t0 = q / a[i], t1 = c[i] / q;
    const bool swap = t0 > t1;
    // q == 0 (b == 0 and a tangent ray): a double root at t = 0 if c == 0, else none.
    const bool zero_q = q == 0;
    const bool ok = (a[i] > 0) & !(disc[i] < 0) & !(zero_q & (c[i] != 0));
    const double l = zero_q ? 0.0 : (swap ? t1 : t0);
    const double h = zero_q ? 0.0 : (swap ? t0 : t1);
    lo[i] = ok ? l : kNaN;
    hi[i] = ok ? h : kNaN;
  }
}

template <int W>
void PlaneLanes(const AnalyticShape& shape, const AnalyticRayLanes& r, BestLanes<W>* best) {
  const double sx = shape.size.x(), sy = shape.size.y();
  for (int i = 0; i < W; ++i) {
    const double tc = -r.oz[i] / r.dz[i];
    const double x = r.ox[i] + tc * r.dx[i], y = r.oy[i] + tc * r.dy[i];
    const bool ok = (r.dz[i] != 0) & (std::abs(x) <= sx) & (std::abs(y) <= sy);
    Offer(tc, ok, 0.0, r.tmin[i], r.tmax[i], &best->t[i], &best->part[i]);
  }
}

template <int W>
void SphereLanes(const AnalyticRayLanes& r, double radius, BestLanes<W>* best) {
  alignas(64) double lo[W], hi[W];
  RootsLanes<3, W>(r.ox, r.oy, r.oz, r.dx, r.dy, r.dz, radius, lo, hi);
  for (int i = 0; i < W; ++i) {
    Offer(lo[i], true, 0.0, r.tmin[i], r.tmax[i], &best->t[i], &best->part[i]);
    Offer(hi[i], true, 0.0, r.tmin[i], r.tmax[i], &best->t[i], &best->part[i]);
  }
}

template <int W>
void EllipsoidLanes(const AnalyticShape& shape, const AnalyticRayLanes& r, BestLanes<W>* best) {
  // a unit sphere after scaling each axis by 1 / radius (as IntersectAnalytic).
  const Eigen::Vector3d inv = shape.size.cwiseInverse();
  alignas(64) double ox[W], oy[W], oz[W], dx[W], dy[W], dz[W], lo[W], hi[W];
  for (int i = 0; i < W; ++i) {
    ox[i] = r.ox[i] * inv.x();
    oy[i] = r.oy[i] * inv.y();
    oz[i] = r.oz[i] * inv.z();
    dx[i] = r.dx[i] * inv.x();
    dy[i] = r.dy[i] * inv.y();
    dz[i] = r.dz[i] * inv.z();
  }
  RootsLanes<3, W>(ox, oy, oz, dx, dy, dz, 1.0, lo, hi);
  for (int i = 0; i < W; ++i) {
    Offer(lo[i], true, 0.0, r.tmin[i], r.tmax[i], &best->t[i], &best->part[i]);
    Offer(hi[i], true, 0.0, r.tmin[i], r.tmax[i], &best->t[i], &best->part[i]);
  }
}

// cylinder (flat caps) or capsule (hemispherical ends) of radius r and half length h.
template <int W>
void CylinderOrCapsuleLanes(const AnalyticShape& shape, const AnalyticRayLanes& r,
                            BestLanes<W>* best) {
  const double radius = shape.size.x(), h = shape.size.y();
  constexpr double kMain = static_cast<int>(ShapePart::kMain);
  constexpr double kTop = static_cast<int>(ShapePart::kTop);
  constexpr double kBottom = static_cast<int>(ShapePart::kBottom);
  alignas(64) double lo[W], hi[W];
  // side: the infinite cylinder about z, kept where |z| <= h.
  RootsLanes<2, W>(r.ox, r.oy, r.oz, r.dx, r.dy, r.dz, radius, lo, hi);
  for (int i = 0; i < W; ++i) {
    const bool in_lo = std::abs(r.oz[i] + lo[i] * r.dz[i]) <= h;
    const bool in_hi = std::abs(r.oz[i] + hi[i] * r.dz[i]) <= h;
    Offer(lo[i], in_lo, kMain, r.tmin[i], r.tmax[i], &best->t[i], &best->part[i]);
    Offer(hi[i], in_hi, kMain, r.tmin[i], r.tmax[i], &best->t[i], &best->part[i]);
  }
  if (shape.kind == AnalyticKind::kCylinder) {
    // flat caps at z = +-h.
    const double r2 = radius * radius;
    for (int i = 0; i < W; ++i) {
      const bool dz_ok = r.dz[i] != 0;
      const double t_top = (h - r.oz[i]) / r.dz[i];
      const double xt = r.ox[i] + t_top * r.dx[i], yt = r.oy[i] + t_top * r.dy[i];
      Offer(t_top, dz_ok & (xt * xt + yt * yt <= r2), kTop, r.tmin[i], r.tmax[i], &best->t[i],
            &best->part[i]);
      const double t_bottom = (-h - r.oz[i]) / r.dz[i];
      const double xb = r.ox[i] + t_bottom * r.dx[i], yb = r.oy[i] + t_bottom * r.dy[i];
      Offer(t_bottom, dz_ok & (xb * xb + yb * yb <= r2), kBottom, r.tmin[i], r.tmax[i], &best->t[i],
            &best->part[i]);
    }
    return;
  }
  // capsule: spheres centred at z = +-h, kept on their outer halves.
  alignas(64) double oc[W];
  for (const double s : {1.0, -1.0}) {
    for (int i = 0; i < W; ++i) oc[i] = r.oz[i] - s * h;
    RootsLanes<3, W>(r.ox, r.oy, oc, r.dx, r.dy, r.dz, radius, lo, hi);
    const double part = s > 0 ? kTop : kBottom;
    for (int i = 0; i < W; ++i) {
      const bool out_lo = s * (oc[i] + lo[i] * r.dz[i]) >= 0;
      const bool out_hi = s * (oc[i] + hi[i] * r.dz[i]) >= 0;
      Offer(lo[i], out_lo, part, r.tmin[i], r.tmax[i], &best->t[i], &best->part[i]);
      Offer(hi[i], out_hi, part, r.tmin[i], r.tmax[i], &best->t[i], &best->part[i]);
    }
  }
}

template <int W>
void IntersectLanesW(const AnalyticShape& shape, const AnalyticRayLanes& rays,
                     AnalyticHitLanes* hits) {
  BestLanes<W> best;
  switch (shape.kind) {
    case AnalyticKind::kPlane:
      PlaneLanes<W>(shape, rays, &best);
      break;
    case AnalyticKind::kSphere:
      SphereLanes<W>(rays, shape.size.x(), &best);
      break;
    case AnalyticKind::kEllipsoid:
      EllipsoidLanes<W>(shape, rays, &best);
      break;
    case AnalyticKind::kCylinder:
    case AnalyticKind::kCapsule:
      CylinderOrCapsuleLanes<W>(shape, rays, &best);
      break;
  }
  std::copy(best.t, best.t + W, hits->t);
  std::copy(best.part, best.part + W, hits->part);
}

template <int W>
void TransformLanesW(const Eigen::Matrix3d& R, const Eigen::Vector3d& p, const float* ox,
                     const float* oy, const float* oz, const float* dx, const float* dy,
                     const float* dz, AnalyticRayLanes* rays) {
  // rows 0 and 1 as Eigen's packet path ((R_r0 x + R_r1 y) + R_r2 z), row 2 as its scalar
  // path (R_20 x + (R_21 y + R_22 z)); then + p.
  const double r00 = R(0, 0), r01 = R(0, 1), r02 = R(0, 2);
  const double r10 = R(1, 0), r11 = R(1, 1), r12 = R(1, 2);
  const double r20 = R(2, 0), r21 = R(2, 1), r22 = R(2, 2);
  const double px = p.x(), py = p.y(), pz = p.z();
  alignas(64) double gx[W], gy[W], gz[W], hx[W], hy[W], hz[W];
  for (int i = 0; i < W; ++i) {
    const double x = ox[i], y = oy[i], z = oz[i];
    gx[i] = ((r00 * x + r01 * y) + r02 * z) + px;
    gy[i] = ((r10 * x + r11 * y) + r12 * z) + py;
    gz[i] = (r20 * x + (r21 * y + r22 * z)) + pz;
    const double u = dx[i], v = dy[i], w = dz[i];
    hx[i] = (r00 * u + r01 * v) + r02 * w;
    hy[i] = (r10 * u + r11 * v) + r12 * w;
    hz[i] = r20 * u + (r21 * v + r22 * w);
  }
  std::copy(gx, gx + W, rays->ox);
  std::copy(gy, gy + W, rays->oy);
  std::copy(gz, gz + W, rays->oz);
  std::copy(hx, hx + W, rays->dx);
  std::copy(hy, hy + W, rays->dy);
  std::copy(hz, hz + W, rays->dz);
}

}  // namespace

int AnalyticLaneWidth(int n) { return n <= 4 ? 4 : n <= 8 ? 8 : kAnalyticLanes; }

void IntersectAnalyticLanes(const AnalyticShape& shape, const AnalyticRayLanes& rays, int n,
                            AnalyticHitLanes* hits) {
  switch (AnalyticLaneWidth(n)) {
    case 4:
      IntersectLanesW<4>(shape, rays, hits);
      break;
    case 8:
      IntersectLanesW<8>(shape, rays, hits);
      break;
    default:
      IntersectLanesW<kAnalyticLanes>(shape, rays, hits);
      break;
  }
}

void TransformRayLanes(const Eigen::Matrix3d& R_GI, const Eigen::Vector3d& p_GI, const float* ox,
                       const float* oy, const float* oz, const float* dx, const float* dy,
                       const float* dz, int n, AnalyticRayLanes* rays) {
  switch (AnalyticLaneWidth(n)) {
    case 4:
      TransformLanesW<4>(R_GI, p_GI, ox, oy, oz, dx, dy, dz, rays);
      break;
    case 8:
      TransformLanesW<8>(R_GI, p_GI, ox, oy, oz, dx, dy, dz, rays);
      break;
    default:
      TransformLanesW<kAnalyticLanes>(R_GI, p_GI, ox, oy, oz, dx, dy, dz, rays);
      break;
  }
}

}  // namespace penumbra

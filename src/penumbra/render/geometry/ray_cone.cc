#include "penumbra/render/geometry/ray_cone.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace penumbra {
namespace {

// relative growth of the bounds for float rounding (the rounding itself is ~1e-7).
constexpr float kGrow = 1e-5f;

// a side plane that never separates anything (a degenerate edge of the cone).
RayCone::Plane NoPlane(const Eigen::Vector3f& axis) {
  return {axis, -std::numeric_limits<float>::infinity()};
}

}  // namespace

RayCone RayCone::FromRays(const Ray* rays, int n) {
  RayCone cone;
  if (n <= 0) return cone;
  const Eigen::Vector3f o = rays[0].o;
  // any axis that every direction makes an acute angle with will do; the first, middle and
  // last directions span a tile's directions.
  const Eigen::Vector3f s =
      rays[0].d.normalized() + rays[n / 2].d.normalized() + rays[n - 1].d.normalized();
  const float s_len = s.norm();
  if (!(s_len > 0)) return cone;
  const Eigen::Vector3f a = s / s_len;
  const Eigen::Vector3f b1 = a.unitOrthogonal();
  const Eigen::Vector3f b2 = a.cross(b1);
  float delta2 = 0;
  float x0 = std::numeric_limits<float>::infinity(), x1 = -x0, y0 = x0, y1 = -x0;
  float near = x0;
  for (int i = 0; i < n; ++i) {
    const Ray& r = rays[i];
    const float da = r.d.dot(a);
    // every direction within ~84 deg of the axis: cos^2 > 0.01.
    if (!(da > 0 && da * da > 0.01f * r.d.squaredNorm() && r.tmin >= 0)) return cone;
    delta2 = std::max(delta2, (r.o - o).squaredNorm());
    const float inv = 1.0f / da;
    const float x = r.d.dot(b1) * inv, y = r.d.dot(b2) * inv;
    x0 = std::min(x0, x), x1 = std::max(x1, x);
    y0 = std::min(y0, y), y1 = std::max(y1, y);
    near = std::min(near, r.tmin * da);
  }
  if (!std::isfinite(delta2) || !std::isfinite(near)) return cone;
  x0 -= kGrow * (1 + std::abs(x0)), x1 += kGrow * (1 + std::abs(x1));
  y0 -= kGrow * (1 + std::abs(y0)), y1 += kGrow * (1 + std::abs(y1));
  cone.valid = true;
  cone.apex = o;
  cone.delta = delta2 > 0 ? std::sqrt(delta2) * (1 + kGrow) + 1e-6f : 0.0f;
  cone.axis = a;
  // (x, y) bounds the tangent of a direction's angle from the axis.
  const float tan_theta = std::sqrt(std::max(x0 * x0, x1 * x1) + std::max(y0 * y0, y1 * y1));
  cone.sin_theta = std::min(1.0f, tan_theta / std::sqrt(1 + tan_theta * tan_theta) + kGrow);
  cone.planes = {Plane{(b1 - x0 * a).normalized(), 0}, Plane{(x1 * a - b1).normalized(), 0},
                 Plane{(b2 - y0 * a).normalized(), 0}, Plane{(y1 * a - b2).normalized(), 0},
                 Plane{a, std::max(0.0f, near * (1 - kGrow))}};
  return cone;
}

RayCone RayCone::FromCorners(const Eigen::Vector3f& apex,
                             const std::array<Eigen::Vector3f, 4>& corners, float tmin) {
  RayCone cone;
  Eigen::Vector3f s = Eigen::Vector3f::Zero();
  for (const Eigen::Vector3f& c : corners) s += c.normalized();
  const float s_len = s.norm();
  if (!(s_len > 0) || !(tmin >= 0)) return cone;
  const Eigen::Vector3f a = s / s_len;
  float near = std::numeric_limits<float>::infinity();
  float sin_theta = 0;
  for (const Eigen::Vector3f& c : corners) {
    const float c_len = c.norm();
    const float da = c.dot(a);
    if (!(da > 0.1f * c_len)) return cone;  // wider than ~84 deg from the axis
    near = std::min(near, tmin * da);
    sin_theta = std::max(sin_theta, c.cross(a).norm() / c_len);
  }
  cone.valid = true;
  cone.apex = apex;
  cone.axis = a;
  cone.sin_theta = std::min(1.0f, sin_theta + kGrow);
  for (int k = 0; k < 4; ++k) {
    // the plane through the apex and corners k, k + 1, facing the other two.
    Eigen::Vector3f n = corners[k].cross(corners[(k + 1) % 4]);
    const float len = n.norm();
    if (!(len > 1e-12f * corners[k].squaredNorm())) {
      cone.planes[k] = NoPlane(a);  // a tile one pixel wide or high
      continue;
    }
    n /= len;
    if (n.dot(corners[(k + 2) % 4] + corners[(k + 3) % 4]) < 0) n = -n;
    cone.planes[k] = {n, 0};
  }
  cone.planes[4] = {a, std::max(0.0f, near * (1 - kGrow))};
  return cone;
}

}  // namespace penumbra

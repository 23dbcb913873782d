#pragma once
// a convex cone (a frustum without a far plane) that holds a set of rays, for culling: every
// point o_i + t d_i, t >= tmin_i, of the rays lies inside the planes n . (p - apex) >= offset
// grown by `delta`, and every direction within angle theta of `axis`. built either from the
// rays themselves (any rays that leave one region in less than a half space of directions) or,
// for a pinhole camera, from the four corner rays of a pixel tile (the directions of a pinhole
// are an affine function of the pixel coordinates, so a tile's rays lie in the convex cone of
// its corner rays).

#include <Eigen/Core>
#include <array>

#include "penumbra/render/ray.h"

namespace penumbra {

/// a cone of rays (file comment). `valid` false: no bound (the rays spread too wide).
struct RayCone {
  /// a plane through the apex, n unit: the rays lie where n . (p - apex) >= offset - delta.
  struct Plane {
    Eigen::Vector3f n{0, 0, 1};
    float offset = 0;
  };
  bool valid = false;
  Eigen::Vector3f apex{0, 0, 0};  ///< world frame, m
  float delta = 0;                ///< every ray origin lies within delta (m) of the apex
  Eigen::Vector3f axis{0, 0, 1};  ///< unit
  float sin_theta = 1;            ///< sine of the largest angle of a ray direction from the axis
  /// 4 side planes and the near plane (axis . (p - apex) >= smallest tmin d . axis).
  std::array<Plane, 5> planes;

  /// the cone of `n` rays with tmin >= 0 whose directions lie within ~84 deg of the mean of
  /// the first, middle and last directions (else invalid): apex rays[0].o, side planes from
  /// the extremes of d.b1 / d.a and d.b2 / d.a in an orthonormal basis (a, b1, b2), grown for
  /// float rounding. O(n).
  static RayCone FromRays(const Ray* rays, int n);

  /// the cone of rays from `apex` whose directions are convex combinations of `corners` (the
  /// four corner rays of a pinhole camera's pixel tile, in order around the tile; the same
  /// float ray directions the camera generates), with t >= tmin along each.
  static RayCone FromCorners(const Eigen::Vector3f& apex,
                             const std::array<Eigen::Vector3f, 4>& corners, float tmin);
};

}  // namespace penumbra

#pragma once
// exact ray intersection with the quadric MuJoCo primitives, in the geom frame and in
// double precision: plane (rectangle), sphere, ellipsoid, cylinder (with caps) and
// capsule (cylinder with hemispherical ends). used as Embree user geometry by RayScene.
//
// the formulas are analytic_shape_math.h's (plain arrays, PB_HOST_DEVICE: the CUDA backend
// runs the same code); these are their Eigen forms.
//
// quadratic roots use the numerically stable form of Pharr, Jakob, Humphreys, "Physically
// Based Rendering", 4th ed., sec. 6.8.1 (discriminant from the ray's closest approach).

#include <Eigen/Core>

#include "penumbra/render/geometry/analytic_shape_math.h"

namespace penumbra {

/// an analytic shape centred at the origin of its frame, axis along z.
struct AnalyticShape {
  AnalyticKind kind = AnalyticKind::kSphere;
  /// plane: half x, half y; sphere: r; capsule / cylinder: r, half length; ellipsoid: radii.
  Eigen::Vector3d size{1, 1, 1};
};

/// smallest t in (tmin, tmax) at which o + t d meets the surface of `shape`; also reports
/// the part hit. d need not be unit. returns false if there is none.
bool IntersectAnalytic(const AnalyticShape& shape, const Eigen::Vector3d& o,
                       const Eigen::Vector3d& d, double tmin, double tmax, double* t,
                       ShapePart* part);

/// unit outward normal of `shape` at surface point p (geom frame) on `part`.
Eigen::Vector3d AnalyticNormal(const AnalyticShape& shape, const Eigen::Vector3d& p,
                               ShapePart part);

/// half extents of the shape's axis-aligned bounding box in its own frame.
Eigen::Vector3d AnalyticHalfExtents(const AnalyticShape& shape);

}  // namespace penumbra

#pragma once
// IntersectAnalytic (analytic_shapes.h) for a batch of rays at once: the rays of an Embree
// packet that reach one analytic geom, in structure-of-arrays form, intersected with
// branch-free loops over the lanes that the compiler vectorises (SSE2: 2, AVX-512: 8 doubles
// per instruction). the arithmetic is IntersectAnalytic's, operation for operation and in
// double (pbrt-v4's stable quadric roots, Pharr, Jakob, Humphreys, "Physically Based
// Rendering", 4th ed., sec. 6.8.1): each lane gets the same hit or miss, t and ShapePart as
// IntersectAnalytic on that ray, bit for bit where the compiler does not fuse multiply-adds
// differently in the two (the project builds with -ffp-contract=off).

#include <Eigen/Core>

#include "penumbra/render/geometry/analytic_shapes.h"

namespace penumbra {

/// the most rays one IntersectAnalyticLanes call takes (Embree's widest packet).
constexpr int kAnalyticLanes = 16;

/// up to kAnalyticLanes rays o + t d, t in (tmin, tmax), in a shape's frame (structure of
/// arrays, double). d need not be unit.
struct AnalyticRayLanes {
  alignas(64) double ox[kAnalyticLanes];
  alignas(64) double oy[kAnalyticLanes];
  alignas(64) double oz[kAnalyticLanes];
  alignas(64) double dx[kAnalyticLanes];
  alignas(64) double dy[kAnalyticLanes];
  alignas(64) double dz[kAnalyticLanes];
  alignas(64) double tmin[kAnalyticLanes];
  alignas(64) double tmax[kAnalyticLanes];
};

/// closest hits of a batch of rays.
struct AnalyticHitLanes {
  /// t of lane i's closest hit in (tmin, tmax); +infinity where lane i misses (a hit always
  /// has t < tmax <= +infinity).
  alignas(64) double t[kAnalyticLanes];
  /// the ShapePart hit (its integer value as a double), where lane i hits.
  alignas(64) double part[kAnalyticLanes];
};

/// how many lanes the lane functions below process for n rays: n rounded up to 4, 8 or
/// kAnalyticLanes (fixed counts let the compiler unroll and vectorise without remainders).
int AnalyticLaneWidth(int n);

/// IntersectAnalytic(shape, o_i, d_i, tmin_i, tmax_i) for the lanes i in [0, n), n <=
/// kAnalyticLanes. lanes [n, AnalyticLaneWidth(n)) are computed too: they must hold some
/// ray (e.g. copies of lane 0) and their results are to be ignored.
void IntersectAnalyticLanes(const AnalyticShape& shape, const AnalyticRayLanes& rays, int n,
                            AnalyticHitLanes* hits);

/// the rays of lanes [0, n) taken from frame I to a shape's frame G in double:
/// o_G = R_GI o_I + p_GI, d_G = R_GI d_I (o_I, d_I: float lanes; tmin, tmax are not touched).
/// like IntersectAnalyticLanes, it reads and writes lanes [0, AnalyticLaneWidth(n)).
/// the sums run in the order of Eigen's 3 x 3 product in an SSE2 build, so that the result is
/// that of `R_GI * o_I.cast<double>() + p_GI` there, bit for bit.
void TransformRayLanes(const Eigen::Matrix3d& R_GI, const Eigen::Vector3d& p_GI, const float* ox,
                       const float* oy, const float* oz, const float* dx, const float* dy,
                       const float* dz, int n, AnalyticRayLanes* rays);

}  // namespace penumbra

#pragma once
// Brown-Conrady ("plumb_bob") lens distortion in OpenCV's convention (OpenCV docs, "Camera
// Calibration and 3D Reconstruction"; Brown, "Decentering distortion of lenses", 1966), and its
// exact inverse by Newton iteration. header-only so that the world-file loader can reject
// folding distortion at load without linking the renderer.
//
// normalised coordinates (x, y) = (X/Z, Y/Z) in the optical frame (x right, y down, z forward);
// distorted normalised coordinates (x_d, y_d) map to pixels as (fx x_d + cx, fy y_d + cy).

#include <algorithm>
#include <cmath>
#include <optional>
#include <string>

#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// the distortion map D: undistorted normalised (x, y) -> distorted (x_d, y_d), with its 2x2
/// Jacobian (row-major: dxd/dx, dxd/dy, dyd/dx, dyd/dy) when `jac` is not null.
inline void DistortNormalized(const CameraIntrinsics& k, double x, double y, double* xd, double* yd,
                              double jac[4] = nullptr) {
  const double r2 = x * x + y * y;
  const double radial = 1.0 + r2 * (k.k1 + r2 * (k.k2 + r2 * k.k3));
  *xd = x * radial + 2.0 * k.p1 * x * y + k.p2 * (r2 + 2.0 * x * x);
  *yd = y * radial + k.p1 * (r2 + 2.0 * y * y) + 2.0 * k.p2 * x * y;
  if (jac) {
    const double dr = k.k1 + r2 * (2.0 * k.k2 + 3.0 * k.k3 * r2);  // d radial / d r2
    jac[0] = radial + 2.0 * x * x * dr + 2.0 * k.p1 * y + 6.0 * k.p2 * x;
    jac[1] = 2.0 * x * y * dr + 2.0 * k.p1 * x + 2.0 * k.p2 * y;
    jac[2] = 2.0 * x * y * dr + 2.0 * k.p1 * x + 2.0 * k.p2 * y;
    jac[3] = radial + 2.0 * y * y * dr + 6.0 * k.p1 * y + 2.0 * k.p2 * x;
  }
}

/// determinant of the Jacobian of D at undistorted (x, y); > 0 where D preserves orientation.
inline double DistortionJacobianDet(const CameraIntrinsics& k, double x, double y) {
  double xd, yd, j[4];
  DistortNormalized(k, x, y, &xd, &yd, j);
  return j[0] * j[3] - j[1] * j[2];
}

/// residual tolerance of UndistortNormalized in normalised units (1e-12 ~ 1e-9 px at f = 1000).
inline constexpr double kUndistortTolerance = 1e-12;

/// inverts D by Newton iteration from (x_d, y_d): finds (x, y) with |D(x, y) - (x_d, y_d)|_inf
/// <= kUndistortTolerance. returns false if it does not converge in 50 iterations or the
/// Jacobian is singular (outputs then hold the last iterate).
inline bool UndistortNormalized(const CameraIntrinsics& k, double xd, double yd, double* x,
                                double* y) {
  double ux = xd, uy = yd;
  for (int it = 0; it < 50; ++it) {
    double fx, fy, j[4];
    DistortNormalized(k, ux, uy, &fx, &fy, j);
    const double ex = fx - xd, ey = fy - yd;
    if (std::abs(ex) <= kUndistortTolerance && std::abs(ey) <= kUndistortTolerance) {
      *x = ux;
      *y = uy;
      return true;
    }
    const double det = j[0] * j[3] - j[1] * j[2];
    if (!(std::abs(det) > 1e-300)) break;
    ux -= (j[3] * ex - j[1] * ey) / det;
    uy -= (-j[2] * ex + j[0] * ey) / det;
    if (!std::isfinite(ux) || !std::isfinite(uy)) break;
  }
  *x = ux;
  *y = uy;
  return false;
}

/// checks that D is invertible over the image: every pixel of a dense grid (the whole border
/// every 2 px and a 64 x 64 interior grid) has a Newton preimage, and the Jacobian determinant
/// is > 0 along 64 steps of the straight segment from the principal point's preimage to each
/// border pixel's preimage (the image's field of view is star-shaped around the optical axis),
/// so D neither folds nor flips inside the field of view. returns a description of the first
/// problem found, or nullopt when the distortion is valid (always for zero distortion).
inline std::optional<std::string> FindDistortionProblem(const CameraIntrinsics& k) {
  if (!k.has_distortion()) return std::nullopt;
  for (double c : {k.k1, k.k2, k.p1, k.p2, k.k3})
    if (!std::isfinite(c)) return std::string("distortion coefficients must be finite");
  double x0, y0;
  if (!UndistortNormalized(k, 0.0, 0.0, &x0, &y0))
    return std::string("the principal point has no undistorted preimage");
  auto check_pixel = [&](double u, double v, bool border) -> std::optional<std::string> {
    const double xd = (u - k.cx) / k.fx, yd = (v - k.cy) / k.fy;
    double x, y;
    auto at = [&] { return "pixel (" + std::to_string(u) + ", " + std::to_string(v) + ")"; };
    if (!UndistortNormalized(k, xd, yd, &x, &y))
      return "the distortion cannot be inverted at " + at() + " (it folds the image)";
    if (!(DistortionJacobianDet(k, x, y) > 0))
      return "the distortion folds the image at " + at() + " (Jacobian determinant <= 0)";
    if (border) {
      for (int s = 1; s <= 64; ++s) {
        const double a = s / 64.0;
        const double px = x0 + a * (x - x0), py = y0 + a * (y - y0);
        if (!(DistortionJacobianDet(k, px, py) > 0))
          return "the distortion folds the image between the principal point and " + at() +
                 " (Jacobian determinant <= 0)";
      }
    }
    return std::nullopt;
  };
  const double W = k.width - 1, H = k.height - 1;
  for (double u = 0; u <= W + 1.5; u += 2) {
    const double uu = std::min(u, W);
    for (double v : {0.0, H})
      if (auto p = check_pixel(uu, v, true)) return p;
  }
  for (double v = 0; v <= H + 1.5; v += 2) {
    const double vv = std::min(v, H);
    for (double u : {0.0, W})
      if (auto p = check_pixel(u, vv, true)) return p;
  }
  for (int i = 0; i <= 64; ++i)
    for (int j = 0; j <= 64; ++j)
      if (auto p = check_pixel(W * i / 64.0, H * j / 64.0, false)) return p;
  return std::nullopt;
}

}  // namespace penumbra

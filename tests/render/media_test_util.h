#pragma once
// scenes for the media / particle / effects renderer tests: an emissive wall in front of a
// camera that looks along world +x, media built directly as EffectsFrame values.

#include <cmath>
#include <memory>

#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/scene/effects_frame.h"
#include "render/render_test_util.h"

namespace penumbra::testing {

/// a scene with an emissive (albedo 0) wall facing the origin at x = distance_m, black sky, no
/// lights. the wall is large enough to fill a narrow view.
inline SceneDescription EmissiveWallScene(double distance_m, float emission) {
  SceneDescription s = EmptyScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Zero());
  s.materials[m].emission = Eigen::Vector3f::Constant(emission);
  AddGeom(&s, GeomShape::kBox, {0.05, 20, 20}, Translation(distance_m + 0.05, 0, 0), 0, m);
  return s;
}

/// settings of a tier for exact radiometry (manual exposure, linear tone map, no denoiser).
inline RenderSettings TierSettings(RenderSettings::Tier tier, int spp = 64, int threads = 1) {
  RenderSettings r = TestSettings(threads);
  r.tier = tier;
  r.samples_per_pixel = spp;
  r.max_bounces = 4;
  r.denoise = false;
  return r;
}

/// an unbounded homogeneous medium.
inline HomogeneousMedium Fog(float sigma_t, float albedo, float g = 0.0f) {
  HomogeneousMedium m;
  m.sigma_t_per_m = Eigen::Vector3f::Constant(sigma_t);
  m.albedo = Eigen::Vector3f::Constant(albedo);
  m.g = g;
  return m;
}

/// mean of channel c of the radiance over the pixels [u0, u1) x [v0, v1).
inline double MeanRadiance(const ImageF& img, int u0, int u1, int v0, int v1, int c = 1) {
  double sum = 0;
  for (int v = v0; v < v1; ++v)
    for (int u = u0; u < u1; ++u) sum += img.at(u, v)[c];
  return sum / ((u1 - u0) * (v1 - v0));
}

/// length (m) from the optical centre to the point at z-depth z seen by pixel (u, v).
inline double RangeOfPixel(const CameraIntrinsics& k, int u, int v, double z) {
  const double x = (u - k.cx) / k.fx, y = (v - k.cy) / k.fy;
  return z * std::sqrt(1 + x * x + y * y);
}

/// a linear density ramp along grid x on a (nx x 2 x 2) grid: density = a + b x_c at voxel
/// centre x_c, constant along y and z.
inline GridMedium RampGrid(const Eigen::Vector3d& centre, const Eigen::Vector3d& half, int nx,
                           float a, float b, float sigma_t, float albedo) {
  GridMedium g;
  g.X_WG = Translation(centre.x(), centre.y(), centre.z());
  g.half_extents_m = half;
  g.nx = nx, g.ny = 2, g.nz = 2;
  auto d = std::make_shared<std::vector<float>>(static_cast<size_t>(nx) * 4);
  for (int k = 0; k < 2; ++k)
    for (int j = 0; j < 2; ++j)
      for (int i = 0; i < nx; ++i) {
        const double xc = -half.x() + (i + 0.5) * 2 * half.x() / nx;
        (*d)[(static_cast<size_t>(k) * 2 + j) * nx + i] = static_cast<float>(a + b * xc);
      }
  g.density = d;
  g.sigma_t_per_m = Eigen::Vector3f::Constant(sigma_t);
  g.albedo = Eigen::Vector3f::Constant(albedo);
  g.max_density = static_cast<float>(std::max(a + b * half.x(), a - b * half.x()));
  return g;
}

/// integral of RampGrid's trilinear density along grid x across the whole box (the values are
/// held constant between the box faces and the outermost voxel centres).
inline double RampIntegral(double half_x, int nx, double a, double b) {
  const double x0 = -half_x + half_x / nx, x1 = half_x - half_x / nx;
  const double d0 = a + b * x0, d1 = a + b * x1;
  return (x0 + half_x) * d0 + (x1 - x0) * 0.5 * (d0 + d1) + (half_x - x1) * d1;
}

}  // namespace penumbra::testing

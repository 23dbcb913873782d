#pragma once
// radiance of the sky seen by rays that leave the scene, for both render tiers.
// uniform sky: constant radiance. daylight sky: the Preetham, Shirley and Smits
// analytic model ("A practical analytic model for daylight", SIGGRAPH 1999),
// Perez distribution of luminance Y and chromaticity x, y for a turbidity, with the
// luminance scaled so that the zenith has Sky::zenith_luminance (cd/m^2).

#include <Eigen/Core>
#include <memory>

#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// evaluates and samples a Sky. immutable after construction, thread-safe.
class SkyModel {
 public:
  /// @throws ConfigError for turbidity outside [1.7, 10] or a zero sun direction.
  explicit SkyModel(const Sky& sky);

  /// linear rgb radiance (cd/m^2 per channel) arriving from unit world direction
  /// `dir_W` (pointing away from the scene). below the horizon a daylight sky returns
  /// the horizon value darkened as ground bounce (documented in the .cc).
  Eigen::Vector3f Radiance(const Eigen::Vector3f& dir_W) const;

  /// irradiance (lux per channel) on a surface with unit normal n_W from the whole sky,
  /// ignoring occlusion: integral of Radiance(w) max(0, n.w) dw. precomputed on an octahedral
  /// grid of normals, bilinear between nodes (no trigonometry; within 1% of the integral).
  Eigen::Vector3f Irradiance(const Eigen::Vector3f& n_W) const;

  /// samples a direction with density roughly proportional to radiance from two
  /// uniform numbers in [0, 1); returns the direction and writes its solid-angle pdf.
  Eigen::Vector3f Sample(float u1, float u2, float* pdf) const;

  /// solid-angle pdf of Sample() producing `dir_W`.
  float Pdf(const Eigen::Vector3f& dir_W) const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace penumbra

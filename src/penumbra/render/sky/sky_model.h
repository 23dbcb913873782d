#pragma once
// radiance of the sky seen by rays that leave the scene, for both render tiers.
// uniform sky: constant radiance. daylight sky: the Preetham, Shirley and Smits
// analytic model ("A practical analytic model for daylight", SIGGRAPH 1999),
// Perez distribution of luminance Y and chromaticity x, y for a turbidity, with the
// luminance scaled so that the zenith has Sky::zenith_luminance (cd/m^2). the physical scale of
// daylight (the sun's direct-normal and the sky's diffuse illuminance for an elevation and a
// turbidity) is in render/sky/sky_math.h; an MJCF skybox is what the camera and mirrors see.

#include <Eigen/Core>
#include <memory>

#include "penumbra/render/sky/sky_eval_math.h"
#include "penumbra/render/sky/sky_sampling_math.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// an MJCF skybox (MuJoCo `<texture type="skybox">`) seen as the environment: rays that leave
/// the scene from the camera or off a mirror show it, as MuJoCo 2.2.2 draws it; light still
/// comes from the sky.
struct SkyboxBackground {
  /// six square faces in MuJoCo's order (+x, -x, +y, -y, +z, -z); null: no skybox.
  std::shared_ptr<const TextureImage> image;
  /// illuminance (lux) of the world-fixed directional lights (the sun) on an upward-facing
  /// surface: a white texel shows the radiance of a white Lambertian surface facing up under
  /// the sky and these lights, (E_sky(up) + sun_horizontal_lux) / pi, so the skybox reads as its
  /// texture colour next to lit surfaces, as in MuJoCo.
  float sun_horizontal_lux = 0.0f;
};

/// the first skybox texture of `scene` (MuJoCo draws one) with the horizontal illuminance of its
/// active directional lights fixed to the world; an empty image if the scene has none.
SkyboxBackground MjcfSkyboxOf(const SceneDescription& scene);

/// evaluates and samples a Sky. immutable after construction, thread-safe.
class SkyModel {
 public:
  /// @throws ConfigError for turbidity outside [1.7, 10], a zero sun direction, or a skybox
  ///         that is not six square faces or has a negative or non-finite sun_horizontal_lux.
  explicit SkyModel(const Sky& sky, SkyboxBackground skybox = {});

  /// linear rgb radiance (cd/m^2 per channel) arriving from unit world direction
  /// `dir_W` (pointing away from the scene). below the horizon a daylight sky returns
  /// the horizon value darkened as ground bounce (documented in the .cc).
  Eigen::Vector3f Radiance(const Eigen::Vector3f& dir_W) const;

  /// linear rgb radiance (cd/m^2 per channel) seen along `dir_W` by a ray that leaves the scene
  /// straight from the camera or off a mirror: the MJCF skybox where there is one (texel colour
  /// decoded from sRGB, bilinear within its face, looked up as MuJoCo 2.2.2 draws its skybox,
  /// render/sky/sky_math.h, times skybox_white_luminance()), else Radiance(dir_W). light
  /// (irradiance, sampling) always comes from Radiance.
  Eigen::Vector3f Background(const Eigen::Vector3f& dir_W) const;

  /// the skybox this sky was built with (an empty image: none).
  const SkyboxBackground& skybox() const;

  /// radiance (cd/m^2) of a white skybox texel (0 without a skybox).
  float skybox_white_luminance() const;

  /// illuminance (lux) of the upper hemisphere of a daylight sky on an upward-facing surface per
  /// cd/m^2 of zenith luminance: the luminance Y of the Preetham model integrated with cos(theta)
  /// (midpoint rule, 256 x 512 cells). the zenith luminance that gives a diffuse horizontal
  /// illuminance D is D / this.
  /// @throws ConfigError as the constructor for a bad turbidity or sun direction.
  static double HorizontalIlluminancePerZenithLuminance(const Sky& sky);

  /// the zenith luminance (cd/m^2) of daylight by the numbers for `sky`'s sun elevation and
  /// turbidity: the one whose upper hemisphere gives the clear sky's diffuse horizontal
  /// illuminance SkyDiffuseHorizontalIlluminance (render/sky/sky_math.h) on a horizontal surface;
  /// 0 with the sun at or below the horizon.
  /// @throws ConfigError as the constructor for a bad turbidity or sun direction.
  static float PhysicalZenithLuminance(const Sky& sky);

  /// irradiance (lux per channel) on a surface with unit normal n_W from the whole sky,
  /// ignoring occlusion: integral of Radiance(w) max(0, n.w) dw. precomputed on an octahedral
  /// grid of normals, bilinear between nodes (no trigonometry; within 1% of the integral).
  Eigen::Vector3f Irradiance(const Eigen::Vector3f& n_W) const;

  /// samples a direction with density roughly proportional to radiance from two
  /// uniform numbers in [0, 1); returns the direction and writes its solid-angle pdf
  /// (the shared SkySampleDirection, render/sky/sky_sampling_math.h).
  Eigen::Vector3f Sample(float u1, float u2, float* pdf) const;

  /// solid-angle pdf of Sample() producing `dir_W` (the shared SkyDirectionPdf).
  float Pdf(const Eigen::Vector3f& dir_W) const;

  /// the sampling tables as plain data for the shared functions of render/sky/sky_sampling_math.h
  /// (pointers into this SkyModel's state, as pod()).
  const SkySamplingPod& sampling_pod() const;

  /// this sky as plain data for the shared host/device functions (render/sky/sky_eval_math.h:
  /// SkyRadiance, SkyIrradiance, SkyBackground give Radiance, Irradiance and Background bit for
  /// bit); its pointers (irradiance table, skybox texels) live as long as this SkyModel's state
  /// (copies of a SkyModel share it).
  const SkyModelPod& pod() const;

 private:
  struct Impl;
  std::shared_ptr<const Impl> impl_;
};

}  // namespace penumbra

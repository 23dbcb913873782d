#pragma once
// camera white balance: per-channel gains applied to the linear radiance before exposure and
// the tone map (Film::Develop), so that a neutral surface under the estimated illuminant comes
// out neutral. plain functions on plain data, shared by every render backend.
//
//   gains     von Kries scaling in the linear sRGB (Rec. 709) camera space: for an illuminant
//             white w (rgb), g_c = Y(w) / w_c, Y the Rec. 709 luminance, so a neutral surface
//             lit by w becomes grey and keeps its luminance (the exposure is unchanged).
//   auto      gray world (G. Buchsbaum, "A spatial processor model for object colour
//             perception", J. Franklin Institute 310(1), 1980): the illuminant is the mean of
//             the image's radiance.
//   daylight  the scene's own daylight as the illuminant estimate: the irradiance of the
//             daylight sky model (render/sky/sky_model.h; a uniform sky does not count) plus every
//             directional light on an upward horizontal surface. a scene without either (lamps
//             only) and a neutral white get unit gains.
//   Kelvin    a Planckian illuminant of that colour temperature: chromaticity x, y from the
//             cubic fits of Kang, Moon, Hong, Lee, Cho and Kim ("Design of advanced color
//             temperature control system for HDTV applications", J. Korean Physical Society
//             41(6), 2002; 1667 K to 25000 K), converted to linear sRGB with the matrix of IEC
//             61966-2-1.
// gains are clamped to [1/16, 16]; an illuminant with a channel <= 0 or not finite gives unit
// gains.

#include <Eigen/Core>

#include "penumbra/core/image.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// how a camera balances its colours.
struct WhiteBalance {
  enum class Mode {
    kNone,      ///< unit gains (the renderer's linear rgb as it is)
    kAuto,      ///< gray world over each frame
    kDaylight,  ///< the scene's sky and sun on a horizontal surface
    kKelvin,    ///< a Planckian illuminant of `kelvin`
  };
  Mode mode = Mode::kDaylight;
  double kelvin = 6500;  ///< colour temperature, K, in [1667, 25000] (mode kKelvin)

  static constexpr double kMinKelvin = 1667, kMaxKelvin = 25000;
};

/// the gains g (rgb) that make the illuminant white `w` (linear rgb) neutral: Y(w) / w_c,
/// clamped to [1/16, 16]; exactly unit gains if the channels of w are equal, a channel is <= 0
/// or not finite.
Eigen::Vector3f WhiteBalanceGains(const Eigen::Vector3f& w);

/// linear sRGB of a Planckian illuminant of colour temperature kelvin (clamped to
/// [1667, 25000] K), scaled to luminance 1.
Eigen::Vector3f PlanckianWhiteRgb(double kelvin);

/// the gray-world illuminant of a (H x W x 3) radiance image: the mean of each channel over
/// the finite pixels (fixed summation order); zero if there are none.
Eigen::Vector3f GrayWorldWhite(const ImageF& radiance);

/// the illuminance (lux per channel) of the scene's daylight on an upward horizontal surface:
/// a daylight sky's irradiance (SkyModel::Irradiance((0, 0, 1)); 0 for a uniform sky) plus
/// color * intensity *
/// max(0, -direction_z) of every active directional light (world-fixed: body 0).
Eigen::Vector3f DaylightWhite(const SceneDescription& scene);

/// the gains of `wb` for one frame: `daylight_white` (DaylightWhite, computed once) for
/// kDaylight, GrayWorldWhite(radiance) for kAuto.
Eigen::Vector3f GainsForFrame(const WhiteBalance& wb, const Eigen::Vector3f& daylight_white,
                              const ImageF& radiance);

}  // namespace penumbra

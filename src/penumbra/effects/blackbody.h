#pragma once
// colour and luminance of a blackbody (fire, sparks, glow lights).
//
// Planck's law: B(lambda, T) = 2 h c^2 / lambda^5 / (exp(h c / (lambda k T)) - 1),
// W sr^-1 m^-3, integrated against the CIE 1931 2-degree colour matching functions in the
// analytic multi-lobe Gaussian fit of Wyman, Sloan, Shirley, "Simple Analytic
// Approximations to the CIE XYZ Color Matching Functions", JCGT 2(2), 2013 (the "1931
// multi-lobe" fit), over 360-830 nm at 1 nm (Simpson's rule); XYZ to linear sRGB with the
// IEC 61966-2-1 matrix; luminance Y = 683 lm/W x the y-bar integral.

#include <Eigen/Core>

namespace penumbra {

/// CIE 1931 x-bar, y-bar, z-bar at wavelength lambda_nm (Wyman et al. 2013 multi-lobe fit).
Eigen::Vector3d CieXyzBar(double lambda_nm);

/// Planck's spectral radiance, W sr^-1 m^-2 per nm of wavelength, at lambda_nm and T_k.
double PlanckRadiance(double lambda_nm, double T_k);

/// tristimulus integral of Planck's law against the CIE fit: X, Y, Z in W sr^-1 m^-2
/// (CMF-weighted radiance), T_k > 0.
Eigen::Vector3d BlackbodyXyz(double T_k);

/// linear sRGB (Rec.709 primaries, D65 white) from CIE XYZ (IEC 61966-2-1 matrix).
Eigen::Vector3d XyzToLinearSrgb(const Eigen::Vector3d& xyz);

/// chromaticity of a blackbody at T_k as linear sRGB, normalised to max component 1;
/// out-of-gamut (negative) components are clipped to 0 before normalising (below
/// ~1900 K the blackbody lies outside the sRGB gamut, blue is slightly negative).
Eigen::Vector3d BlackbodyLinearSrgb(double T_k);

/// luminance of a blackbody at T_k, cd/m^2: 683 lm/W x integral B(lambda, T) y-bar dlambda.
double BlackbodyLuminance(double T_k);

/// relative luminance of a linear sRGB colour (Rec.709: 0.2126 r + 0.7152 g + 0.0722 b).
double LinearSrgbLuminance(const Eigen::Vector3d& rgb);

/// fast table of BlackbodyLinearSrgb and BlackbodyLuminance for 300-4000 K (10 K steps,
/// linear interpolation; relative error of the luminance < 0.5% above 600 K); T outside
/// the range is clamped. thread-safe (built once).
struct BlackbodyTable {
  /// colour (max component 1) at T_k.
  static Eigen::Vector3f Color(double T_k);
  /// luminance at T_k, cd/m^2 (log-linear interpolation).
  static double Luminance(double T_k);
};

}  // namespace penumbra

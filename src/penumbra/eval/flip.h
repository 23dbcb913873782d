#pragma once
// LDR-FLIP, the perceptual difference of a test image from a reference image as a viewer sees
// it when the two alternate on a screen: P. Andersson, J. Nilsson, T. Akenine-Moller,
// M. Oskarsson, K. Astrom and M. D. Fairchild, "FLIP: A Difference Evaluator for Alternating
// Images", Proc. ACM Comput. Graph. Interact. Tech. 3(2), 2020 (HPG 2020).
//
// per pixel, for 8-bit sRGB images of the same size:
//   colour: sRGB -> linear RGB -> CIE XYZ (D65) -> YCxCz (linearized CIELAB); each opponent
//     channel is filtered with its contrast sensitivity function, a 2D kernel
//     sum_k a_k sqrt(pi / b_k) exp(-pi^2 r^2 / b_k) (r in degrees of visual angle, normalized to
//     sum 1; achromatic a = 1, b = 0.0047; red-green a = 1, b = 0.0053; blue-yellow a = 34.1,
//     b = 0.04 plus a = 13.5, b = 0.025; radius ceil(3 sqrt(0.04 / (2 pi^2)) ppd) pixels, edge
//     pixels repeated), back to linear RGB clamped to [0, 1], to CIELAB, Hunt-adjusted
//     (a, b scaled by 0.01 L), compared by the HyAB distance |dL| + sqrt(da^2 + db^2), raised to
//     qc = 0.7 and remapped to [0, 1]: [0, pc cmax) -> [0, pt), [pc cmax, cmax] -> [pt, 1] with
//     pc = 0.4, pt = 0.95 and cmax the distance (^0.7) between Hunt-adjusted pure green and blue;
//   features: on the unfiltered luminance Y / Yn, the gradient magnitude (edges) and the second
//     derivative magnitude (points) of a Gaussian of sd 0.5 * 0.082 ppd pixels (radius
//     ceil(3 sd)), each derivative kernel's positive weights summing to 1 and negative ones to
//     -1; feature difference = (max(|d edge|, |d point|) / sqrt(2))^0.5;
//   FLIP = colour^(1 - feature), in [0, 1].
// the filters are applied as separable 1D passes (each 2D kernel above is a product, or for
// blue-yellow a sum of two products, of 1D Gaussians). the result agrees with NVIDIA's
// flip-evaluator (tests/eval/flip_reference_test.py states the tolerance).

#include <array>

#include "penumbra/core/image.h"

namespace penumbra {

/// FLIP's default viewing condition: a 0.7 m wide, 3840-pixel monitor seen from 0.7 m,
/// 0.7 * (3840 / 0.7) * pi / 180 = 67.0206 pixels per degree of visual angle.
inline constexpr double kFlipDefaultPixelsPerDegree = 3840.0 * 3.14159265358979323846 / 180.0;
/// the largest pixels per degree FlipErrorMap accepts (its colour kernel is then 271 pixels
/// wide).
inline constexpr double kFlipMaxPixelsPerDegree = 1000.0;

/// pixels per degree of visual angle of a screen `width_px` pixels and `width_m` metres wide
/// seen from `distance_m` metres (FLIP's small-angle form distance * width_px / width_m *
/// pi / 180).
double FlipPixelsPerDegree(double distance_m, double width_px, double width_m);

/// the per-pixel LDR-FLIP error of `test` against `reference`, both (H x W x 3) uint8 sRGB of
/// the same size: an (H x W x 1) float image in [0, 1] (0 where the two agree), for a viewer
/// at `pixels_per_degree` (see the file comment for the model). memory: about 60 bytes a pixel
/// while it runs.
/// @throws Error when either image is empty, has channels != 3 or data of another size than
///         width x height x 3, the sizes differ, or pixels_per_degree is not in
///         (0, kFlipMaxPixelsPerDegree].
ImageF FlipErrorMap(const ImageU8& reference, const ImageU8& test,
                    double pixels_per_degree = kFlipDefaultPixelsPerDegree);

/// the pooled values of a FLIP error map, as NVIDIA's FLIP tool prints them.
struct FlipStats {
  double mean = 0;             ///< mean over all pixels: "the FLIP" of an image pair
  double weighted_median = 0;  ///< weighted percentiles: the error values sorted ascending, the
  double weighted_q1 = 0;      ///< first whose running sum exceeds p (0.5, 0.25, 0.75) times
  double weighted_q3 = 0;      ///< the sum of all; 0 for a map that is all 0
  double min = 0;
  double max = 0;
};

/// the FlipStats of an (H x W x 1) error map (FlipErrorMap).
/// @throws Error for an empty map or one with channels != 1.
FlipStats PoolFlipErrors(const ImageF& error_map);

/// the error map coloured with the magma colour map FLIP uses (256 entries; the value v picks
/// entry floor(255 v + 0.5) after clamping v to [0, 1]; each entry rounded to 8 bits): an
/// (H x W x 3) uint8 image, black-purple for 0 through orange to pale yellow for 1.
/// @throws Error as PoolFlipErrors.
ImageU8 FlipMagmaHeatmap(const ImageF& error_map);

/// entry i (0..255) of the magma colour map, RGB in [0, 1] (display values, sRGB-encoded).
/// @throws Error for i outside [0, 255].
std::array<float, 3> FlipMagmaColour(int i);

}  // namespace penumbra

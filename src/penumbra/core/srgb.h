#pragma once
// the sRGB transfer functions (IEC 61966-2-1:1999, "Multimedia systems and equipment - Colour
// measurement and management - Part 2-1: Default RGB colour space - sRGB"), written once for
// every module and both processors (PB_HOST_DEVICE):
//
//   encode (OETF), linear l in [0, 1] -> code value v in [0, 1]:
//     v = 12.92 l                       for l <= 0.0031308
//     v = 1.055 l^(1 / 2.4) - 0.055     otherwise
//   decode (EOTF), code value v in [0, 1] -> linear l in [0, 1]:
//     l = v / 12.92                     for v <= 0.04045
//     l = ((v + 0.055) / 1.055)^2.4     otherwise
//
// both are templates over the number type (float or double) and evaluate every step in it, so
// a caller picks its precision by the argument type: the 8-bit tables (scene/texture_image.cc,
// render/film/film.cc) are built in double, MJCF colours are decoded in float
// (physics/scene_extractor.cc). float arguments meant for the double formula need an explicit
// LinearToSrgb<double>(x).

#include <cmath>
#include <type_traits>

#include "penumbra/core/host_device.h"

namespace penumbra {

namespace srgb_internal {
// x^y in the argument's precision (powf for float, pow for double), on the host and the device
PB_HOST_DEVICE inline float Pow(float x, float y) { return powf(x, y); }
PB_HOST_DEVICE inline double Pow(double x, double y) { return pow(x, y); }
// std::clamp(x, 0, 1): NaN stays NaN
template <typename T>
PB_HOST_DEVICE inline T Clamp01(T x) {
  return x < T(0) ? T(0) : (T(1) < x ? T(1) : x);
}
}  // namespace srgb_internal

/// sRGB encoding (OETF) of a linear value: `linear` is clamped to [0, 1] first (NaN stays NaN);
/// the result is the code value in [0, 1] (255 times it, rounded, is the 8-bit code). T is
/// float or double; every step is evaluated in T.
template <typename T>
PB_HOST_DEVICE inline T LinearToSrgb(T linear) {
  static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>, "float or double");
  const T v = srgb_internal::Clamp01(linear);
  return v <= T(0.0031308) ? T(12.92) * v
                           : T(1.055) * srgb_internal::Pow(v, T(1) / T(2.4)) - T(0.055);
}

/// sRGB decoding (EOTF) of a code value: `srgb` (code / 255 for 8-bit data) is clamped to
/// [0, 1] first (NaN stays NaN); the result is the linear value in [0, 1]. T is float or
/// double; every step is evaluated in T.
template <typename T>
PB_HOST_DEVICE inline T SrgbToLinear(T srgb) {
  static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>, "float or double");
  const T c = srgb_internal::Clamp01(srgb);
  return c <= T(0.04045) ? c / T(12.92) : srgb_internal::Pow((c + T(0.055)) / T(1.055), T(2.4));
}

}  // namespace penumbra

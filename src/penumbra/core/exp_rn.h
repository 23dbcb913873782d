#pragma once
// ExpRn: e^x for a float x, computed by the same IEEE double operations on both processors
// (MulRnD, AddRnD, rint, ldexp and one rounding to float, all exactly rounded and never
// contracted), so the CPU and the CUDA backend get the same bits where a decision hangs on an
// exponential (the rain streaks' culling in media, render/particles/streak_cull_math.h). glibc's
// expf and CUDA's expf are each within an ulp or two of e^x but not always equal to each other.
//
// method: Cody and Waite's reduction x = k ln 2 + r with k = rint(x / ln 2), |r| <= ln 2 / 2
// (W. J. Cody and W. Waite, "Software Manual for the Elementary Functions", 1980, ch. 6), e^r by
// its Taylor series to r^13 / 13! in Horner's form (truncation below 3e-17 relative for
// |r| <= 0.35), then 2^k e^r by ldexp. in double every step's error stays below 1e-15
// relative, far below float's half ulp (3e-8): the float result is e^x correctly rounded but
// for arguments within about 1e-15 relative of a rounding midpoint (in a sweep of 2^21
// arguments over [-104, 88.7], tests/core/exp_rn_test.cc, none differs by more than an ulp from
// the correctly rounded e^x and almost all are equal to it).

#include <cmath>

#include "penumbra/core/host_device.h"

namespace penumbra {

/// e^x rounded to float, the same bits on the CPU and the GPU. x NaN: NaN; x > 88.8: +inf
/// (e^88.73 is past FLT_MAX); x < -104: 0 (e^-104 is below half of the least subnormal).
PB_HOST_DEVICE inline float ExpRn(float x) {
  if (!(x == x)) return x;
  if (x > 88.8f) return INFINITY;
  if (x < -104.0f) return 0.0f;
  const double xd = x;
  // k = rint(x / ln 2), r = x - k ln 2 (|k| <= 151: k ln 2's rounding is below 2e-14 absolute)
  const double k = rint(MulRnD(xd, 1.4426950408889634074));
  const double r = AddRnD(xd, MulRnD(-k, 0.69314718055994530942));
  // 1 / n! for n = 13 .. 1, then 1
  constexpr double kInvFactorial[13] = {1.6059043836821614599e-10,
                                        2.0876756987868098979e-09,
                                        2.5052108385441718775e-08,
                                        2.7557319223985890653e-07,
                                        2.7557319223985890653e-06,
                                        2.4801587301587301587e-05,
                                        1.9841269841269841270e-04,
                                        1.3888888888888888889e-03,
                                        8.3333333333333333333e-03,
                                        4.1666666666666666667e-02,
                                        1.6666666666666666667e-01,
                                        5.0000000000000000000e-01,
                                        1.0};
  double p = kInvFactorial[0];
  for (int i = 1; i < 13; ++i) p = AddRnD(MulRnD(p, r), kInvFactorial[i]);
  p = AddRnD(MulRnD(p, r), 1.0);
  return static_cast<float>(ldexp(p, static_cast<int>(k)));
}

}  // namespace penumbra

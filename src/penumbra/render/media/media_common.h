#pragma once
// small shared pieces of participating-media rendering: the meteorological optical range
// (MOR) to extinction conversion and the Henyey-Greenstein phase function.

#include <Eigen/Core>
#include <algorithm>
#include <cmath>

#include "penumbra/render/media/media_realtime_math.h"
#include "penumbra/render/media/media_scene_math.h"
#include "penumbra/render/shading_lanes.h"

namespace penumbra {

/// extinction coefficient sigma_t (1/m) of a homogeneous medium whose meteorological optical
/// range is mor_m (m): MOR is the distance at which the transmittance of a collimated beam
/// falls to 5 % (WMO, "Guide to Instruments and Methods of Observation", WMO-No. 8, vol. I,
/// ch. 9, 2018; Koschmieder's law with a 5 % contrast threshold), so
/// sigma_t = -ln(0.05) / MOR = ln(20) / MOR (about 2.996 / MOR).
/// returns 0 for mor_m = +inf; mor_m must be > 0.
inline double SigmaTFromMorM(double mor_m) { return std::log(20.0) / mor_m; }

/// the MOR (m) of extinction sigma_t (1/m), the inverse of SigmaTFromMorM (+inf for 0).
inline double MorMFromSigmaT(double sigma_t_per_m) { return std::log(20.0) / sigma_t_per_m; }

/// Henyey-Greenstein phase function: MediaPhaseHG (render/media/media_realtime_math.h, shared with
/// the CUDA backend), with kInv4Pi.
inline float HenyeyGreenstein(float cos_theta, float g) { return MediaPhaseHG(cos_theta, g); }

/// samples wi from the Henyey-Greenstein distribution around wo (unit, pointing back along the
/// incoming ray) with two uniform numbers in [0, 1); the pdf of wi is HenyeyGreenstein(dot(wo,
/// wi), g) (PBR 4th ed., eq. 11.17 and SampleHenyeyGreenstein; SampleHenyeyGreensteinDir of
/// render/media/media_scene_math.h).
inline Eigen::Vector3f SampleHenyeyGreenstein(const Eigen::Vector3f& wo, float g, float u1,
                                              float u2, float* pdf) {
  const Float3 wi = SampleHenyeyGreensteinDir(Float3{wo.x(), wo.y(), wo.z()}, g, u1, u2, pdf);
  return {wi.x, wi.y, wi.z};
}

/// mean of the three channels.
inline float Mean3(const Eigen::Vector3f& v) { return (v.x() + v.y() + v.z()) * (1.0f / 3.0f); }

}  // namespace penumbra

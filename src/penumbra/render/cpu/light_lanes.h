#pragma once
// lane forms of the scalar tests of lights with an extent (render/light/lamp_math.h) for the
// realtime tier's light loop (render/cpu/realtime_integrator.cc), which runs kLanes pixels at once.

#include "penumbra/render/shading_lanes.h"

namespace penumbra {

/// LightStraddlesHorizon (render/light/lamp_math.h) for every lane: lane k is
/// LightStraddlesHorizon(cos_t[k], sin2_sigma[k], sin_sigma[k]), by the same comparisons of the
/// same values (cos_t * cos_t rounded as there; a lane holding NaN straddles, as there).
inline LaneMask LightStraddlesHorizonLanes(const Lanes& cos_t, const Lanes& sin2_sigma,
                                           const Lanes& sin_sigma) {
  const LaneMask wholly =
      (GreaterEqual(cos_t * cos_t, sin2_sigma) || !GreaterThan(sin2_sigma, 0.0f)) &&
      !(GreaterThan(cos_t, 0.0f) && GreaterThan(sin_sigma, cos_t));
  return !wholly;
}

}  // namespace penumbra

#pragma once
// the realtime tier's compositing of a particle streak (render/particle_streaks.h) over what
// lies behind it, written once for the CPU backend (RealtimeIntegrator's view effects) and the
// CUDA backend's kernels.

#include "penumbra/core/host_device.h"

namespace penumbra {

/// one channel of a streak of coverage `alpha` in (0, 1] and radiance `Lp` (cd/m^2) drawn over
/// the radiance `L` behind it: alpha Lp + (1 - alpha) L (Porter and Duff's "over", "Compositing
/// digital images", SIGGRAPH 1984).
PB_HOST_DEVICE inline float StreakOver(float alpha, float Lp, float L) {
  return alpha * Lp + (1.0f - alpha) * L;
}

}  // namespace penumbra

#pragma once
// the mirror layer's importance sampling as formulas both backends can call
// (render/cpu/mirror_layer.h; PB_HOST_DEVICE, core/host_device.h; the shared shading contract:
// Eigen-free, no std:: containers): which grid a mirror weight is traced on, the bilinear
// weights of a pixel between traced grid pixels, and the layer's blend.

#include "penumbra/core/host_device.h"

namespace penumbra {

/// mirror weights at or above this are traced at every pixel.
constexpr float kMirrorDenseReflectance = 0.25f;
/// mirror weights in [this, kMirrorDenseReflectance) are traced at every 2nd pixel in u and v,
/// weaker ones at every 4th.
constexpr float kMirrorHalfStepReflectance = 0.1f;

/// the grid step (pixels, in u and in v) on which a mirror layer of weight r in (0, 1] traces
/// its reflected radiance: 1, 2 or 4 (see the constants above).
PB_HOST_DEVICE inline int MirrorGridStep(float r) {
  return r >= kMirrorDenseReflectance ? 1 : r >= kMirrorHalfStepReflectance ? 2 : 4;
}

/// the bilinear weight, along one image axis, of the traced grid pixel `side` (0: the one at or
/// before the pixel, 1: the next one, `step` pixels on) for a pixel `offset` pixels past the
/// first (0 <= offset < step): 1 - offset / step, or offset / step.
PB_HOST_DEVICE inline float MirrorGridWeight(int offset, int step, int side) {
  const float f = static_cast<float>(offset) / static_cast<float>(step);
  return side == 0 ? 1.0f - f : f;
}

/// one channel of a pixel with a mirror layer of weight r: (1 - r) L + r L_m, L the surface's
/// own radiance and L_m the reflected radiance (MuJoCo's material `reflectance`).
PB_HOST_DEVICE inline float MirrorBlend(float L, float L_m, float r) {
  return (1.0f - r) * L + r * L_m;
}

}  // namespace penumbra

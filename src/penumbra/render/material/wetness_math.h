#pragma once
// surface wetness of the rain effects (EffectsFrame::surface_wetness) as one PB_HOST_DEVICE
// formula for both backends (docs/gpu.md, "One shading code"): the CPU's ApplySurfaceWetness
// (material_eval.h) and the CUDA realtime path's EvaluateSurface (render/transport/surface.h)
// call it. Lagarde, "Water drop 2a - Dynamic rain and its effects" and "Water drop 2b", 2013:
// wet porous surfaces absorb more light (diffuse albedo x lerp(1, 0.3, w')) and a water film
// makes them glossier (gloss = 1 - roughness, times lerp(1, 2.5, w'), capped at 1). w' = w s,
// with s the facing weight clamp((n_z - 0.3) / 0.4, 0, 1) of the unit shading normal (world z
// up): vertical and downward-facing surfaces stay dry; metals keep their albedo.

#include "penumbra/core/host_device.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

/// what wetness `wetness` (clamped to [0, 1]) does to a surface whose unit world shading
/// normal has z component `n_z`, of metallic `metallic` and perceptual roughness `roughness`:
/// false if nothing (dry: w' <= 0 or NaN); else true with *albedo_scale, the factor on the
/// base colour's every channel, and *roughness_out, the wet roughness. the operation order is
/// the CPU's (bit-for-bit rule of shading_math.h).
PB_HOST_DEVICE inline bool SurfaceWetnessTerms(float wetness, float n_z, float metallic,
                                               float roughness, float* albedo_scale,
                                               float* roughness_out) {
  const float facing = pbm::Clamp((n_z - 0.3f) / 0.4f, 0.0f, 1.0f);
  const float w = pbm::Clamp(wetness, 0.0f, 1.0f) * facing;
  if (!(w > 0)) return false;
  const float darken = 1.0f + (0.3f - 1.0f) * w;
  const float m = pbm::Clamp(metallic, 0.0f, 1.0f);
  *albedo_scale = (1.0f - m) * darken + m;
  const float gloss = pbm::Min(1.0f, (1.0f - roughness) * (1.0f + 1.5f * w));
  *roughness_out = 1.0f - gloss;
  return true;
}

}  // namespace penumbra

#pragma once
// hands a RenderAblation (render/render_ablation.h) to the CPU renderer behind a Renderer, for
// `penumbra bench render --ablate` and the tests of the parts it switches off.

#include "penumbra/render/render_ablation.h"
#include "penumbra/render/renderer.h"

namespace penumbra {

/// sets the ablation of `renderer` when it is the CPU (Embree) renderer and returns true;
/// returns false (and changes nothing) for other backends or null.
bool SetRenderAblation(Renderer* renderer, const RenderAblation& ablation);

}  // namespace penumbra

#include "penumbra/render/backends/render_ablation_switch.h"

#include "penumbra/render/cpu/embree_renderer.h"

namespace penumbra {

bool SetRenderAblation(Renderer* renderer, const RenderAblation& ablation) {
  auto* cpu = dynamic_cast<EmbreeRenderer*>(renderer);
  if (cpu == nullptr) return false;
  cpu->set_ablation(ablation);
  return true;
}

}  // namespace penumbra

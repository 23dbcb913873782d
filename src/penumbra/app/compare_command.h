#pragma once
// `penumbra compare A.png B.png [--heatmap OUT.png] [--ppd N]`: the LDR-FLIP difference of
// image B from reference image A (eval/flip.h, docs/evaluation.md "Image fidelity"): prints the
// mean FLIP and the weighted median and quartiles, min and max as NVIDIA's FLIP tool does;
// --heatmap writes the per-pixel error coloured with FLIP's magma map.

#include <memory>

#include "penumbra/app/command.h"

namespace penumbra {

/// the `compare` verb (app/command.h).
std::unique_ptr<Command> MakeCompareCommand();

}  // namespace penumbra

#include "penumbra/physics/physics_options.h"

#include <mujoco/mujoco.h>

#include <string>

#include "penumbra/core/error.h"

namespace penumbra {

void ApplyContactOptions(const ContactOptions& options, mjOption* opt) {
  if (options.noslip_iterations &&
      (*options.noslip_iterations < 0 || *options.noslip_iterations > kMaxNoslipIterations))
    throw ConfigError("", 0, "physics.noslip_iterations",
                      "got " + std::to_string(*options.noslip_iterations) + "; expected [0, " +
                          std::to_string(kMaxNoslipIterations) + "] (0 = off)");
  if (options.noslip_iterations) opt->noslip_iterations = *options.noslip_iterations;
  if (options.speculative) {
    if (*options.speculative) {
      opt->enableflags |= mjENBL_SPECULATIVE;
    } else {
      opt->enableflags &= ~mjENBL_SPECULATIVE;
    }
  }
}

}  // namespace penumbra

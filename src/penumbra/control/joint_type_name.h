#pragma once
// MJCF's names of joint types, for run descriptions and run-log headers.

#include "penumbra/control/model_info.h"

namespace penumbra {

/// the MJCF name of a joint type: "free", "ball", "slide" or "hinge" (MJCF XML reference,
/// joint/type).
const char* JointTypeName(JointInfo::Type type);

}  // namespace penumbra

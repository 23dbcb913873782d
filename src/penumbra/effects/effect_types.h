#pragma once
// the effects registry: every effect type, in one list. adding an effect type = its own
// effects/types/<name>.{h,cc} (the contract is in effect_type.h) + its #include and its
// entry at the END of EffectParams below. nothing else switches on the type: the world
// reader, validation, the engine, run labels and the work estimate go through the list.
//
// the position in the list is part of each effect's random-stream key (EffectBindContext::key),
// so existing entries keep their place and new ones are appended.

#include <variant>

#include "penumbra/effects/types/dust.h"
#include "penumbra/effects/types/fire.h"
#include "penumbra/effects/types/flashlight.h"
#include "penumbra/effects/types/fog.h"
#include "penumbra/effects/types/light_event.h"
#include "penumbra/effects/types/rain.h"
#include "penumbra/effects/types/smoke.h"
#include "penumbra/effects/types/snow.h"
#include "penumbra/effects/types/sparks.h"
#include "penumbra/effects/types/sun.h"
#include "penumbra/effects/types/vdb_smoke.h"
#include "penumbra/effects/types/wetness.h"

namespace penumbra {

/// the parameters of one effect; the alternative held is the effect's type.
using EffectParams = std::variant<FogParams, DustParams, SmokeParams, VdbSmokeParams, FireParams,
                                  RainParams, SnowParams, SparksParams, LightEventParams,
                                  FlashlightParams, SunParams, WetnessParams>;

}  // namespace penumbra

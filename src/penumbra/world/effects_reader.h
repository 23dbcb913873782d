#pragma once
// the world file's `effects:` list: adverse conditions (effects/effect_config.h). each
// entry has name (required, unique), type (required: a name of the effects registry,
// effects/effect_types.h: fog | dust | smoke | vdb_smoke | fire | rain | snow | sparks |
// light_event | flashlight | sun | wetness), start_sec, stop_sec, fade_in_sec, fade_out_sec,
// region {min: [x, y, z], max: [x, y, z]} and the parameters of its type next to them (read
// by the type's own reader); every key, unit, default and range is in docs/effects.md.
//
// example:
//   effects:
//     - {name: haze, type: fog, mor_m: 80, height_falloff_per_m: 0.3}
//     - {name: storm, type: rain, rate_mm_h: 20, wind_m_s: [3, 0, 0], start_sec: 2}

#include <string>
#include <vector>

#include "penumbra/config/param_reader.h"
#include "penumbra/effects/effect_config.h"

namespace penumbra {

/// reads and validates the `effects` list (`list` is the value of the `effects` key).
/// relative `file:` paths (vdb_smoke) resolve against the world file's folder.
/// @param file the world file, named in errors and used to resolve paths
/// @throws ConfigError naming the file, line, key path ("effects[2].mor_m") and what was
///         expected: unknown keys or types, wrong value types, out-of-range values
///         (EffectConfig::Validate), duplicate names, dangling rain / fire references.
std::vector<EffectConfig> ReadEffects(const ParamReader& list, const std::string& file);

}  // namespace penumbra

#pragma once
// a live change of one block of an adversity preset (world/adversity_preset.h), as
// live/live_effects.h applies it while a run goes on. implemented in adversity_preset.cc,
// with the preset file's reader, so that a block is checked exactly as a preset file's is.

#include <string>
#include <vector>

#include "penumbra/world/adversity_preset.h"

namespace penumbra {

/// the blocks of a preset (the keys of a preset file's entry besides `description`), in file
/// order: fog, dust, smoke, rain, snow, lights, npcs.
const std::vector<std::string>& AdversityPresetBlocks();

/// `base` with one block changed: the keys of `block_yaml` (a YAML or JSON mapping, e.g.
/// `{"mor_m": 20}`) replace those of the block and the block's other keys keep their values
/// (a block the preset lacks starts from its defaults; fog, dust, smoke, rain and snow then
/// need their required key); `block_yaml` "null" removes the block. the result is checked as
/// a preset file's block is; name, description and file are kept.
/// @throws ConfigError("", 0, "<block>.<key>", ...) for an unknown block (naming the valid
///         ones), unknown keys, wrong types and out-of-range values, before anything changes.
AdversityPreset EditAdversityPreset(const AdversityPreset& base, const std::string& block,
                                    const std::string& block_yaml);

}  // namespace penumbra

#pragma once
// the world file's `sites:` (world/world_config.h SiteConfig) added to a composed document:
// foot points, tool centre points and other frames a third-party model lacks, so that
// controllers that want MJCF sites (trot_gait feet, diff_ik's TCP) work on it unchanged.
// internal to src/penumbra/compose (ComposeWorld calls it).

#include <vector>

#include "penumbra/world/world_config.h"

namespace tinyxml2 {
class XMLElement;
}

namespace penumbra::compose {

/// adds <site name="M/S" pos quat group="4"/> for every site S of every model M to the body
/// it names (at its pose) or to the body of the geom it names (at the geom's centre: its
/// pos, or the midpoint of its fromto, plus the pose's offset). `root` is the composed
/// <mujoco> element.
/// @throws ConfigError("", 0, "<model key>.sites[i].<key>", ...) (the world file and line are
///         filled in by LocateInWorld) for an unknown body or geom, or a site name that the
///         model already has.
void AddWorldSites(const std::vector<ModelConfig>& models, tinyxml2::XMLElement* root);

}  // namespace penumbra::compose

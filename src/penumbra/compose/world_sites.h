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
/// it names (at its pose) or to the body of the geom it names (at the geom's centre: the
/// midpoint of its fromto, else its pos, plus the pose's offset). fromto and pos are those
/// MuJoCo compiles: written on the geom or inherited from its default class (its class=, else
/// the childclass of the nearest enclosing body, then that class's parents), as Menagerie's
/// models position their foot geoms (`<default class="foot"><geom pos=...>`). for a mesh geom
/// the centre is its frame origin, not the mesh's centroid. resolved in the composed document
/// (whose classes carry the model prefix) because the site must be written into it before
/// MuJoCo compiles it. `root` is the composed <mujoco> element.
/// @throws ConfigError("", 0, "<model key>.sites[i].<key>", ...) (the world file and line are
///         filled in by LocateInWorld) for an unknown body or geom, or a site name that the
///         model already has.
void AddWorldSites(const std::vector<ModelConfig>& models, tinyxml2::XMLElement* root);

}  // namespace penumbra::compose

#include "penumbra/render/renderer.h"

#include <cmath>
#include <string>

#include "penumbra/core/error.h"

namespace penumbra {

void CheckRenderInputs(size_t num_scene_bodies, const WorldSnapshot& snapshot,
                       const CameraView& view) {
  if (snapshot.X_WB.size() != num_scene_bodies)
    throw Error("Render: snapshot has " + std::to_string(snapshot.X_WB.size()) +
                " body poses, scene has " + std::to_string(num_scene_bodies) + " bodies");
  if (!(view.near_m >= 0 && std::isfinite(view.near_m)))
    throw Error("Render: camera near_m " + std::to_string(view.near_m) +
                " is not a finite distance >= 0");
}

}  // namespace penumbra

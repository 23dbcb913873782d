#pragma once
// the half extents of MuJoCo's primitive geom shapes, shared by the floor map (agent placement)
// and the auto-framed camera's bounding box.

#include <Eigen/Core>
#include <optional>

#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// half extents, m, of the geom's local axis-aligned bounding box, centred on the geom frame,
/// for sphere (r, r, r), capsule (r, r, r + half length), cylinder (r, r, half length),
/// ellipsoid and box (their size); std::nullopt for planes, meshes and height fields, whose
/// boxes need the scene's mesh or height-field data (MJCF geom size conventions: MuJoCo XML
/// reference, geom/size).
std::optional<Eigen::Vector3d> PrimitiveHalfExtents(const Geom& g);

}  // namespace penumbra

#pragma once
// closed, outward-oriented solids generated in code for the decomposition tests and
// `penumbra bench decompose` (m): an L and a U (extruded polygons), a torus and a bowl
// (a hemispherical shell with a flat annular rim).

#include <string>
#include <vector>

#include "penumbra/decompose/solid_mesh.h"

namespace penumbra {

/// an L: 1 x 1 outline with 0.4-wide arms, extruded 0.4 along z.
SolidMesh MakeLShape();
/// a U: 1 x 1 outline, 0.3-wide posts on a 0.3-high base, extruded 0.4 along z.
SolidMesh MakeUShape();
/// a torus around z: ring radius `major` (m), tube radius `minor` (m), `ring_segments` x
/// `tube_segments` quads (>= 3 each).
SolidMesh MakeTorus(double major = 0.35, double minor = 0.12, int ring_segments = 32,
                    int tube_segments = 16);
/// a bowl opening up (+z): outer radius `outer`, inner radius `inner` (< outer) (m), rim at
/// z = 0, bottom at z = -outer; `segments` around z (>= 3), `rings` from rim to pole (>= 2).
SolidMesh MakeBowl(double outer = 0.5, double inner = 0.45, int segments = 32, int rings = 10);
/// a prism: the simple polygon `outline` (counter-clockwise, x-y, m) extruded from z = 0 to
/// `height`; the caps are ear-clipped.
SolidMesh ExtrudePolygon(const std::vector<Eigen::Vector2d>& outline, double height);

/// the named test shape: "l", "u", "torus" or "bowl". @throws Error for another name.
SolidMesh MakeTestShape(const std::string& name);
/// the names MakeTestShape knows, in order.
std::vector<std::string> TestShapeNames();

}  // namespace penumbra

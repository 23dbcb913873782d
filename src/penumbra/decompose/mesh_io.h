#pragma once
// reading a closed mesh for decomposition and writing convex parts.

#include <string>
#include <vector>

#include "penumbra/decompose/decomposition.h"
#include "penumbra/decompose/solid_mesh.h"

namespace penumbra {

/// reads OFF, OBJ, STL (ASCII or binary) or PLY with assimp in the file's own axes (coincident
/// vertices merged, polygons triangulated), times `scale` (m per file unit).
/// @throws Error "<path>: ..." when the file cannot be read or holds no triangles.
SolidMesh ReadMeshFile(const std::string& path, double scale = 1.0);

/// writes the parts as one Wavefront OBJ with an object `part_<i>` per part (m).
/// @throws Error naming the path when it cannot be written.
void WritePartsObj(const Decomposition& decomposition, const std::string& path);

/// the MJCF of the parts: one `<mesh name="<prefix>_<i>" vertex="..."/>` per part for
/// `<asset>` and one `<geom name="<prefix>_<i>" type="mesh" mesh="<prefix>_<i>"/>` per part for a
/// `<body>`, with
/// `geom_attributes` (e.g. `rgba="..."`) added to each geom. vertices in m, printed with 17
/// significant digits (exact round trip).
struct PartsMjcf {
  std::string assets;
  std::string geoms;
};
PartsMjcf PartsToMjcf(const Decomposition& decomposition, const std::string& prefix,
                      const std::string& geom_attributes = "");

}  // namespace penumbra

#pragma once
// MJCF <mesh file> elements naming a format MuJoCo 2.2.2 cannot read (glTF, FBX, COLLADA, PLY;
// it reads STL, OBJ and its own MSH) are converted to MSH files through ImportMeshFile
// (assets/mesh_import.h) with the format's default units and up axis (docs/assets.md): all
// of the file's meshes become one mesh (positions, normals, texcoords); its materials are not
// used (the MJCF's <material> applies). the <mesh>'s own scale / refpos / refquat still apply
// (MuJoCo applies them to the converted file).

#include <string>
#include <vector>

#include "penumbra/compose/scene_composer.h"

namespace penumbra {

/// rewrites every <asset>/<mesh file> of `composed` whose file MuJoCo 2.2.2 cannot read to a
/// converted "<stem>-<hash>.msh" in `dir` (created if missing; "" = "penumbra-mesh-models" in
/// the temporary folder). returns the converted source files, in document order.
/// @throws ConfigError naming the MJCF file and line of the <mesh> (composed->sources) and
///         the mesh file when it cannot be imported.
std::vector<std::string> ConvertForeignMjcfMeshes(ComposedScene* composed, const std::string& dir);

}  // namespace penumbra

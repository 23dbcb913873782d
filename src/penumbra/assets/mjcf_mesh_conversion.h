#pragma once
// an MJCF <mesh file> naming a format MuJoCo cannot read (glTF, FBX, COLLADA, PLY; it reads
// STL, OBJ and its own MSH) is converted to an MSH file through ImportMeshFile
// (assets/mesh_import.h) with the format's default units and up axis (docs/assets.md): all
// of the file's meshes become one mesh (positions, normals, texcoords); its materials are not
// used (the MJCF's <material> applies). the <mesh>'s own scale / refpos / refquat still apply
// (MuJoCo applies them to the converted file). the composition step calls it for every mesh
// file of a model (session/world_composer.h, ComposeOptions::convert_mesh).

#include <string>

namespace penumbra {

/// for a mesh file `file` (absolute path) that MuJoCo cannot read: the converted
/// "<stem>-<hash>.msh" in `dir` (created if missing; "" = "penumbra-mesh-models" in the
/// temporary folder); "" for a file MuJoCo reads itself (or that is no mesh model file).
/// @throws ConfigError naming the mesh file when it cannot be imported.
std::string ConvertForeignMjcfMesh(const std::string& file, const std::string& dir);

}  // namespace penumbra

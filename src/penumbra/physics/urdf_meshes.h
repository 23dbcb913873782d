#pragma once
// URDF meshes that MuJoCo cannot read (COLLADA .dae and the other formats assimp reads)
// converted into binary STL, which it can. ROS description packages mostly ship DAE visuals;
// MuJoCo reads STL, OBJ and MSH.

#include <string>
#include <utility>
#include <vector>

namespace penumbra {

/// true when MuJoCo reads the mesh file itself: its extension is .stl, .obj or .msh
/// (any case). `filename` may carry a path or a package:// prefix.
bool MujocoReadsMeshFile(const std::string& filename);

/// the triangles of the mesh file at `path` as binary STL bytes, through assimp 5.2:
///  - aiProcess_Triangulate and aiProcess_PreTransformVertices: polygons become triangles
///    and every node's transform (the scene graph, COLLADA's <unit meter> scale and its
///    up-axis rotation) is applied to the vertices; points and lines are dropped.
///  - COLLADA files (.dae, .zae): assimp turns X_UP/Z_UP documents into Y-up; the result
///    is rotated back by +90 deg about x (x, y, z) -> (x, -z, y), so a Z_UP document
///    (the ROS convention) keeps its own coordinates and a Y_UP one gets +y as +z, the way
///    a URDF link frame (z up) expects.
///  - other formats keep their coordinates; units are metres as stored (URDF's convention).
/// the URDF's <mesh scale> is not applied here (MuJoCo applies it to the STL).
/// deterministic: the same file gives the same bytes (fixed 80-byte header naming the
/// source file's name, facet normals from the vertices, attribute bytes 0).
/// @throws Error naming `path` and assimp's message if assimp cannot read it or it has no
///         triangles.
std::string MeshFileToStl(const std::string& path);

/// a URDF whose unreadable meshes were converted: `urdf` is the text with each such
/// <mesh filename> replaced by the name of its STL (and each readable one that was found by
/// the path found), and `files` holds those STL files as
/// (name, bytes). names are "<source stem>-<16 hex digits of the source's FNV-1a 64 hash>.stl",
/// so the same mesh gets the same name and different meshes with one stem differ.
struct UrdfMeshConversion {
  std::string urdf;
  std::vector<std::pair<std::string, std::string>> files;
};

/// finds every <link>/<visual|collision>/<geometry>/<mesh> of the URDF text `urdf_text`
/// (read from `urdf_path`) whose file MuJoCo cannot read and converts it with
/// MeshFileToStl; a file MuJoCo reads is named by the path where it was found. a filename resolves
/// like this, first existing wins: "file://" is dropped; "package://PKG/REST" looks for REST in the
/// URDF's folder and in its parent (the usual PKG/urdf/robot.urdf + PKG/meshes layout); a relative
/// path against the URDF's folder; an absolute path as is; finally the file's bare name in the
/// URDF's folder (where MuJoCo's own URDF importer looks). text without such meshes is returned
/// unchanged.
/// @throws ConfigError(urdf_path, line of the <mesh>, "", ...) naming the link and the mesh
///         filename when the file is not found (listing the paths tried) or assimp fails.
UrdfMeshConversion ConvertUrdfMeshes(const std::string& urdf_path, const std::string& urdf_text);

}  // namespace penumbra

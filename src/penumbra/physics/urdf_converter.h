#pragma once
// URDF -> MJCF through MuJoCo's own URDF importer (mj_loadXML + mj_saveLastXML),
// a thin adapter for the scene composer.

#include <string>

namespace penumbra {

/// the MJCF text MuJoCo produces for the URDF file at `urdf_path`.
/// unless the URDF has its own <mujoco> extension element, the import keeps visual
/// geoms (compiler discardvisual="false": they become contype=0 conaffinity=0
/// group=1 geoms, collision geoms stay in group 0) and keeps every link as a body
/// (fusestatic="false"), so links named in world files still exist. mesh file names
/// in the result are as MuJoCo stores them (path stripped) and resolve against the
/// URDF's folder. a root link without a joint is welded to the world, as in MuJoCo.
/// meshes MuJoCo cannot read (DAE and the other formats assimp reads) are converted
/// to binary STL first (physics/urdf_meshes.h): each is written to `mesh_dir` (created if
/// missing; empty: the folder "penumbra-urdf-meshes" in the system's temporary folder) and
/// the result's <mesh file> names it by its absolute path. the files' names come from their
/// content, so the same URDF gives the same text and bytes every time.
/// @throws ConfigError(urdf_path, line, "", MuJoCo's message) if MuJoCo cannot load it;
///         ConfigError(urdf_path, mesh line, "", ...) naming link and mesh if a mesh cannot
///         be found or converted; Error if the converted text or meshes cannot be written.
std::string ConvertUrdfToMjcfInto(const std::string& urdf_path, const std::string& mesh_dir);

/// ConvertUrdfToMjcfInto(urdf_path, ""): converted meshes go to the temporary folder.
std::string ConvertUrdfToMjcf(const std::string& urdf_path);

/// the URDF text at `urdf_path` ready for MuJoCo's own URDF parser (mj_parseXMLString; the
/// composition step, physics/model_spec_composer.h): the import options above added unless
/// the URDF has its own <mujoco> element, mesh files named by the paths where they were found
/// (physics/urdf_meshes.h), and meshes MuJoCo cannot read converted to STL files in
/// `mesh_dir` (as ConvertUrdfToMjcfInto) and named by their absolute paths.
/// @throws ConfigError(urdf_path, mesh line, "", ...) as ConvertUrdfToMjcfInto; Error if a
///         converted mesh cannot be written.
std::string PrepareUrdfForMujoco(const std::string& urdf_path, const std::string& mesh_dir);

}  // namespace penumbra

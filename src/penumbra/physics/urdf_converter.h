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
/// @throws ConfigError(urdf_path, line, "", MuJoCo's message) if MuJoCo cannot load it;
///         Error if the converted text cannot be written.
std::string ConvertUrdfToMjcf(const std::string& urdf_path);

}  // namespace penumbra

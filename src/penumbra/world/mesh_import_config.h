#pragma once
// the world-file keys of a `models:` entry whose file is a mesh (OBJ, glTF, FBX, COLLADA, STL,
// PLY): how the file's coordinates become metres in the z-up world frame (docs/assets.md).

#include <string>
#include <string_view>
#include <vector>

namespace penumbra {

class ParamReader;

/// how a mesh file's coordinates and materials are converted (docs/assets.md, "Units and axes").
/// a point p of the file becomes R_up (M p) scale in the model frame: M mirrors the file's x axis
/// when left_handed, R_up turns the file's up axis into +z.
struct MeshImportConfig {
  /// metres per file unit (`scale:`, or `units:` m / cm / mm / in / ft); 0 = the format's
  /// default (glTF: 1, the spec's metres; FBX: the file's UnitScaleFactor; others: 1).
  double scale = 0;
  /// the file's up axis: "x", "y", "z", "-x", "-y", "-z"; "" = the format's default (glTF,
  /// OBJ, COLLADA, FBX: "y"; STL, PLY: "z"). "y" maps (x, y, z) to (x, -z, y).
  std::string up_axis;
  /// `handedness: left`: the file is left-handed; its x axis is negated (and triangle winding
  /// reversed) before the up-axis rotation.
  bool left_handed = false;
  /// luminance, cd/m^2, of an emissive factor of 1 (glTF emissiveFactor / MTL Ke)
  /// (`emissive_cd_m2:`).
  double emissive_cd_m2 = 100;
  /// `collision:` how the mesh collides: "hull" (MuJoCo's convex hull of each mesh of the
  /// file), "heightfield" (a height field of the mesh sampled from above every
  /// heightfield_cell_m: render/geometry/height_field_sampling.h; the mesh itself visual only),
  /// "coacd" (the file's meshes welded into one closed solid and split into convex parts by CoACD,
  /// decompose/coacd.h, cached on disk; the mesh itself visual only), "none" (visual only).
  std::string collision = "hull";
  /// `heightfield_cell_m:` sample spacing of `collision: heightfield`, m, in [0.005, 10].
  double heightfield_cell_m = 0.1;
  /// `concavity_threshold:` of `collision: coacd`: the largest concavity a part may have, as a
  /// fraction of the largest extent of the mesh's bounding box, in [0.001, 1]
  /// (DecompositionOptions::concavity_threshold).
  double concavity_threshold = 0.025;
  /// `max_parts:` of `collision: coacd`: most convex parts, in [1, 1024]
  /// (DecompositionOptions::max_parts).
  int max_parts = 32;
  /// 1-based world-file line of the entry (0 = unknown), for errors found at import.
  int line = 0;

  /// @throws ConfigError(file, line, key, ...) for a scale outside (0, 1e6] or an unknown axis.
  void ValidateOrThrow(const std::string& file, const std::string& key) const;
};

/// true when `path`'s extension (any case) is a mesh format a `models:` entry may name:
/// .obj .gltf .glb .fbx .dae .stl .ply.
bool IsMeshModelFile(const std::string& path);

/// the mesh keys a `models:` entry may have besides name/file/pose/...: units, scale, up_axis,
/// handedness, emissive_cd_m2, collision, heightfield_cell_m, concavity_threshold, max_parts.
const std::vector<std::string_view>& MeshImportKeys();

/// the mesh keys of the model entry at key path `key` ("models[0]", "robots[1]": ModelConfig::key)
/// of the world file `world_file`, read from the file again (the world file's reader checks
/// them at load; ModelConfig does not carry them). defaults when `world_file` or `key` is empty
/// (bare models, worlds built in code), the file cannot be read (a replay of a world whose file
/// is gone) or the entry has none of the keys.
/// @throws ConfigError as ReadMeshImportKeys.
MeshImportConfig MeshImportConfigOf(const std::string& world_file, const std::string& key);

/// reads the mesh keys of model entry `r` (any of MeshImportKeys()) into `out`.
/// @throws ConfigError naming the line and key: both `units` and `scale`, an unknown unit,
///         axis or handedness, a non-positive scale, or mesh keys on a model whose file is not
///         a mesh (`is_mesh` false).
void ReadMeshImportKeys(const ParamReader& r, bool is_mesh, MeshImportConfig* out);

}  // namespace penumbra

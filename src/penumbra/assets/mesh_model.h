#pragma once
// a mesh file placed by a world-file `models:` entry becomes an MJCF model that MuJoCo
// compiles, plus the imported materials that the renderer's scene gets after extraction
// (docs/assets.md).
//
// the generated MJCF (written next to the meshes, "<stem>-<hash>.xml"): one mesh geom of the
// world body per imported mesh ("<i>_<mesh name>", MuJoCo binary .msh files with positions,
// normals and texcoords in metres, z up), each with the material "<material name>" (rgba =
// the base colour factor, sRGB): static geometry whose meshes say inertia="shell", so that
// MuJoCo's compile-time inertia of every mesh accepts open and flat ones (it refuses "mesh
// volume is too small" otherwise). the geoms
// collide with MuJoCo's default (the convex hull of each mesh) and are in group 0. as every
// model, the composer prefixes the names with "<model>/" and places the geoms at the model pose.
// ApplyImportedMaterials then gives the scene's "<model>/<material name>" materials the
// imported factors and texture images.

#include <optional>
#include <string>
#include <vector>

#include "penumbra/assets/mesh_import.h"
#include "penumbra/decompose/mesh_io.h"
#include "penumbra/decompose/solid_mesh.h"
#include "penumbra/render/geometry/height_field_sampling.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// one mesh model after import: the model's name and what was read.
struct ImportedModel {
  std::string model;  ///< ModelConfig::name
  ImportedAsset asset;
  double import_sec = 0;  ///< wall time of ImportMeshFile (docs: import time per asset)
  /// `collision: coacd` only: convex parts, whether they came from the decomposition cache,
  /// the wall time of the decomposition (or of the cache read), its largest concavity as a
  /// fraction of the mesh's extent, and the sum of the parts' hull volumes over the mesh volume.
  int collision_parts = 0;
  bool decomposition_cache_hit = false;
  double decompose_sec = 0;
  double relative_max_concavity = 0;
  double hull_volume_ratio = 0;
};

/// MuJoCo's legacy binary .msh bytes of `mesh` (4 int32 counts nvertex, nnormal, ntexcoord,
/// nface, then float32 positions, normals, texcoords and int32 faces, little-endian). meshes
/// with fewer than 4 vertices get copies of their first vertex (MuJoCo's minimum); a flat mesh
/// (all vertices within 1e-6 of its extent from one plane) gets one vertex no face uses,
/// 1e-4 of its extent behind the plane, so that qhull can build MuJoCo's convex hull.
std::string MshBytes(const TriangleMesh& mesh);

/// how a generated mesh model collides (MeshImportConfig::collision).
struct MeshModelCollision {
  /// false: the mesh geoms get contype = conaffinity = 0 (visual only).
  bool mesh_geoms_collide = true;
  /// with `hfield`: its MuJoCo binary file (absolute path).
  std::string hfield_file;
  /// a height field that collides instead (model frame): the asset "collision_heightfield"
  /// and its geom "collision_heightfield" in group 3 (not drawn; render/ray_query.h traces
  /// groups <= 2).
  std::optional<SampledHeightField> hfield;
  /// convex parts that collide instead (model frame, m; `collision: coacd`): PartsToMjcf with
  /// prefix "collision_part" (part k: the asset "collision_part_<k>" with its hull's vertices,
  /// MuJoCo takes their convex hull, and its geom "collision_part_<k>") in group 3 (not drawn).
  PartsMjcf convex_parts;
};

/// the meshes of `asset` welded into one solid for convex decomposition: vertices at bit-equal
/// positions merged (ordered by first use), degenerate triangles dropped.
SolidMesh WeldedSolid(const ImportedAsset& asset);

/// the MJCF text of `asset` (file comment) whose <mesh file>s are `msh_files` (absolute paths,
/// one per asset.meshes entry), colliding as `collision` says.
std::string MeshModelMjcf(const ImportedAsset& asset, const std::vector<std::string>& msh_files,
                          const MeshModelCollision& collision = {});

/// the height field of `asset`'s triangles (model frame) sampled from above every `cell_m`
/// over their plan bounds with an Embree RayQuery (render/geometry/height_field_sampling.h).
/// @throws Error if the asset has no triangles or the grid is too large.
SampledHeightField SampleMeshHeightField(const ImportedAsset& asset, double cell_m);

/// imports every model of `models` whose file is a mesh (IsMeshModelFile), with the mesh keys
/// of its world-file entry (MeshImportConfigOf(world_file, key)), and points its `file` at the
/// generated MJCF in `dir` (created if missing; "" = the folder "penumbra-mesh-models" in the
/// system's temporary folder). files are named by a hash of their content, so a second
/// import writes nothing new. `collision: coacd` decomposes through the on-disk cache at
/// DefaultDecompositionCacheDir() (decompose/decomposition_cache.h), so a second load reads
/// the parts instead of computing them. other models are left alone.
/// @throws ConfigError naming the world file `world_file`, the entry's line and key when the
///         mesh cannot be imported (the message names the mesh file) or, with `collision:
///         coacd`, is not a closed, consistently oriented solid once welded (the message names
///         the first bad edge), or Error when a file cannot be written.
std::vector<ImportedModel> ImportMeshModels(std::vector<ModelConfig>* models,
                                            const std::string& dir, const std::string& world_file);

/// gives every material "<model>/<name>" of `scene` that an imported model defines its
/// factors and images: base_color, roughness, metallic, emission, the base colour texture
/// (Material::texture), and the normal, metallic-roughness, occlusion and emissive maps as 2d
/// textures named "<model>/<name>/normal", ... (render/material/material_eval.h, "PBR maps").
/// @throws Error when such a material is missing from the scene (a composer bug).
void ApplyImportedMaterials(const std::vector<ImportedModel>& models, SceneDescription* scene);

}  // namespace penumbra

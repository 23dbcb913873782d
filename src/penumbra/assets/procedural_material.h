#pragma once
// procedural physically based materials: wood planks, ceramic tiles, concrete, plaster, painted
// metal, cardboard and fabric, generated from a seed as tileable albedo (sRGB), roughness /
// metallic (linear, glTF layout: G roughness, B metallic) and tangent-space normal maps (linear),
// with their features at physical scale (docs/assets.md, "Procedural materials").
//
// method: every map is a function of the texture coordinates (u, v) in [0, 1)^2 built from
// periodic value noise (lattice values from a 64-bit hash of (seed, cell), smoothstep
// interpolation, fractal sums of octaves whose cell counts divide the period, so every map
// tiles) and the type's layout (plank rows, tile grid, weave, flutes). a height field in metres
// gives the normal map by central differences over one texel (n = normalize(-dh/dx, -dh/dy, 1),
// x along +u, y towards the image's top). no random state: the same config gives bit-identical
// maps on any thread count (rows are generated independently).
//
// physical scale (per type, default image side size_m): wood planks 0.15 m wide, 1.2 m long,
// staggered, 1 mm joints (1.2 m image); tiles 0.30 m with 4 mm recessed grout (0.6 m);
// concrete pores of 1-4 mm and blotches of 0.1-0.5 m (1 m); plaster trowel undulation of
// ~0.1 m (1 mm) and 4 mm sand grains (1 m); painted metal orange peel of 4 mm and scratches
// 2-20 cm long (1 m); cardboard flutes of 8 mm under the liner, fibres (0.5 m); fabric
// threads of 1 mm in a plain weave (0.2 m). docs/assets.md has the table.

#include <memory>
#include <string>

#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/texture_image.h"
#include "penumbra/world/procedural_material_config.h"

namespace penumbra {

/// the maps of one procedural material and the image side they tile with. the data maps hold
/// sRGB-encoded values (render/material/material_eval.h, "PBR maps").
struct ProceduralMaps {
  std::shared_ptr<const TextureImage> albedo;           ///< sRGB colour
  std::shared_ptr<const TextureImage> metal_roughness;  ///< G roughness, B metallic
  std::shared_ptr<const TextureImage> normal;           ///< tangent-space normals, (n + 1) / 2
  double size_m = 1;                                    ///< metres per image side
};

/// the default image side of `type`, m (file comment).
double ProceduralDefaultSize(const std::string& type);

/// generates the maps of `config` (ProceduralMaterialConfig::ValidateOrThrow'd).
/// @throws Error for an unknown type.
ProceduralMaps GenerateProceduralMaterial(const ProceduralMaterialConfig& config);

/// bumped whenever GenerateProceduralMaterial's maps for the same config may change (the
/// disk cache's entries of other versions are then never read).
inline constexpr int kProceduralMaterialVersion = 1;

/// the canonical text of `config` (type, seed, size, resolution, colour and
/// kProceduralMaterialVersion) that names its maps in the cache.
/// @throws Error for an unknown type.
std::string ProceduralMaterialKey(const ProceduralMaterialConfig& config);

/// GenerateProceduralMaterial through an on-disk cache in the folder `cache_dir` (created on
/// the first store): the file "<16 hex digits of Fnv1a64(key)>.pmaps" holds the key and the
/// three maps' level-0 bytes (3 x resolution^2 x 3 bytes; 2.4 MB at 512^2). a file whose key,
/// size or header differs, or that cannot be read, counts as a miss; a miss generates the maps
/// and stores them (written whole and renamed into place; a failed store only logs a warning).
/// the mip levels are built at every load. `*cache_hit` (optional) tells which happened.
/// @throws Error for an unknown type.
ProceduralMaps CachedProceduralMaterial(const ProceduralMaterialConfig& config,
                                        const std::string& cache_dir, bool* cache_hit = nullptr);

/// for every `materials:` entry with `procedural:` (ProceduralMaterialsOf), generates its maps
/// (CachedProceduralMaterial in DefaultCacheDir("materials"), core/cache_dir.h) and
/// makes them the scene material's: texture (albedo, "<material>/albedo"), and the maps
/// "<material>/metallic_roughness" and "<material>/normal" (render/material/material_eval.h, "PBR
/// maps"), added to scene->textures; base_color 1, roughness and metallic
/// factors 1 (the maps hold them), texuniform on with texrepeat 2 / size_m (one image per
/// size_m metres on planes and boxes: MuJoCo repeats a texuniform texture texrepeat / 2 times
/// per metre). the entry's own base_color / roughness / ... (applied
/// after this by the scene assembly) then scale the maps.
/// @throws ConfigError(world_file, entry line, "materials.<name>", ...) when the scene has no
///         material of that name.
void ApplyProceduralMaterials(const std::vector<ProceduralMaterialEntry>& entries,
                              const std::string& world_file, SceneDescription* scene);

}  // namespace penumbra

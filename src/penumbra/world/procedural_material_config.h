#pragma once
// the world-file `procedural:` key of a `materials:` entry: a physically based material whose
// albedo, roughness and normal maps Penumbra generates from a seed (assets/procedural_material.h,
// docs/assets.md "Procedural materials").

#include <Eigen/Core>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace penumbra {

class ParamReader;

/// what to generate. the maps tile every `size_m` metres (one image); on primitives (planes,
/// boxes, ...) they are laid out per metre (texuniform), on meshes with texcoords one image
/// per texcoord unit.
struct ProceduralMaterialConfig {
  /// wood, tiles, concrete, plaster, painted_metal, cardboard, fabric (ProceduralTypes()).
  std::string type;
  uint64_t seed = 0;     ///< same seed, same maps (bit-identical)
  double size_m = 0;     ///< side of one image, m, in (0, 100]; 0 = the type's default
  int resolution = 512;  ///< texels per side, 16 ... 4096
  /// linear base colour of the type's palette (tiles, painted_metal, fabric: the colour; the
  /// others: a tint multiplying their natural colours); unset = the type's default.
  std::optional<Eigen::Vector3f> color;

  /// @throws ConfigError(file, line, key + ...) for an unknown type or out-of-range value.
  void ValidateOrThrow(const std::string& file, int line, const std::string& key) const;
};

/// the procedural types, in documentation order.
const std::vector<std::string_view>& ProceduralTypes();

/// a `materials:` entry with `procedural:`.
struct ProceduralMaterialEntry {
  std::string material;  ///< the prefixed material name (the entry's key)
  int line = 0;          ///< 1-based line of the entry in the world file
  ProceduralMaterialConfig config;
};

/// the `materials:` entries with `procedural:` of the world file `world_file`, in file order,
/// read from the file again (the world file's reader checks them at load; MaterialOverride
/// does not carry them). empty when `world_file` is "" or cannot be read (a replay of a world
/// whose file is gone).
/// @throws ConfigError as ReadProceduralMaterial.
std::vector<ProceduralMaterialEntry> ProceduralMaterialsOf(const std::string& world_file);

/// reads a `procedural:` mapping (type, seed, size_m, resolution, color).
/// @throws ConfigError naming the line and key for unknown keys, types and bad values.
ProceduralMaterialConfig ReadProceduralMaterial(const ParamReader& r);

}  // namespace penumbra

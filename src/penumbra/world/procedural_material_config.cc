#include "penumbra/world/procedural_material_config.h"

#include "penumbra/config/param_reader.h"
#include "penumbra/core/error.h"
#include "penumbra/world/world_file_document.h"

namespace penumbra {

const std::vector<std::string_view>& ProceduralTypes() {
  static const std::vector<std::string_view> types = {
      "wood", "tiles", "concrete", "plaster", "painted_metal", "cardboard", "fabric"};
  return types;
}

void ProceduralMaterialConfig::ValidateOrThrow(const std::string& file, int line,
                                               const std::string& key) const {
  bool known = false;
  for (std::string_view t : ProceduralTypes()) known |= t == type;
  if (!known)
    throw ConfigError(file, line, key + ".type",
                      "'" + type + "'; expected one of: " + JoinNames(ProceduralTypes()));
  if (!(size_m >= 0 && size_m <= 100))
    throw ConfigError(file, line, key + ".size_m", "expected a size in (0, 100] m");
  if (resolution < 16 || resolution > 4096)
    throw ConfigError(file, line, key + ".resolution", "expected 16 ... 4096 texels");
  if (color && !(color->minCoeff() >= 0 && color->maxCoeff() <= 1))
    throw ConfigError(file, line, key + ".color", "expected 3 numbers in [0, 1]");
}

ProceduralMaterialConfig ReadProceduralMaterial(const ParamReader& r) {
  r.ExpectMap({"type", "seed", "size_m", "resolution", "color"});
  ProceduralMaterialConfig c;
  c.type = r.Child("type").Enum(ProceduralTypes());
  if (const auto found = r.Find("seed")) c.seed = found->Uint64();
  if (r.Has("size_m")) {
    c.size_m = r.Child("size_m").Double();
    if (!(c.size_m > 0 && c.size_m <= 100)) r.Child("size_m").Fail("expected a size in (0, 100] m");
  }
  if (r.Has("resolution")) {
    c.resolution = r.Child("resolution").Int();
    if (c.resolution < 16 || c.resolution > 4096)
      r.Child("resolution").Fail("expected 16 ... 4096 texels per side");
  }
  if (r.Has("color")) {
    const Eigen::Vector3d v = r.Child("color").Vector3();
    if (!(v.minCoeff() >= 0 && v.maxCoeff() <= 1))
      r.Child("color").Fail("expected 3 numbers in [0, 1] (linear rgb)");
    c.color = v.cast<float>();
  }
  return c;
}

std::vector<ProceduralMaterialEntry> ProceduralMaterialsOf(const std::string& world_file) {
  std::vector<ProceduralMaterialEntry> out;
  if (world_file.empty()) return out;
  // a world whose file is gone (a replay's recorded world): none
  const std::optional<ConfigValue> root = ReadWorldFileDocument(world_file);
  if (!root) return out;
  const ParamReader doc(*root, world_file, nullptr);
  doc.ExpectMapAnyKeys();
  if (!doc.Has("materials")) return out;
  for (auto& [name, entry] : doc.Child("materials").Entries()) {
    entry.ExpectMapAnyKeys();
    if (!entry.Has("procedural")) continue;
    ProceduralMaterialEntry e;
    e.material = name;
    e.line = entry.line();
    e.config = ReadProceduralMaterial(entry.Child("procedural"));
    out.push_back(std::move(e));
  }
  return out;
}

}  // namespace penumbra

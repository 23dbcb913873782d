#include "penumbra/world/mesh_import_config.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <optional>

#include "penumbra/config/param_reader.h"
#include "penumbra/core/error.h"
#include "penumbra/world/world_file_document.h"

namespace penumbra {
namespace {

constexpr double kMaxScale = 1e6;

bool ValidAxis(const std::string& a) {
  return a.empty() || a == "x" || a == "y" || a == "z" || a == "-x" || a == "-y" || a == "-z";
}

}  // namespace

void MeshImportConfig::ValidateOrThrow(const std::string& file, const std::string& key) const {
  if (!(scale >= 0 && scale <= kMaxScale))
    throw ConfigError(file, line, key + ".scale",
                      "expected metres per file unit in (0, 1e6] (0 = the format's default)");
  if (!ValidAxis(up_axis))
    throw ConfigError(file, line, key + ".up_axis",
                      "'" + up_axis + "'; expected one of x, y, z, -x, -y, -z");
  if (!(emissive_cd_m2 >= 0 && emissive_cd_m2 <= 1e9))
    throw ConfigError(file, line, key + ".emissive_cd_m2", "expected a luminance in [0, 1e9]");
}

bool IsMeshModelFile(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext == ".obj" || ext == ".gltf" || ext == ".glb" || ext == ".fbx" || ext == ".dae" ||
         ext == ".stl" || ext == ".ply";
}

const std::vector<std::string_view>& MeshImportKeys() {
  static const std::vector<std::string_view> keys = {"units",
                                                     "scale",
                                                     "up_axis",
                                                     "handedness",
                                                     "emissive_cd_m2",
                                                     "collision",
                                                     "heightfield_cell_m",
                                                     "concavity_threshold",
                                                     "max_parts"};
  return keys;
}

void ReadMeshImportKeys(const ParamReader& r, bool is_mesh, MeshImportConfig* out) {
  out->line = r.line();
  for (std::string_view k : MeshImportKeys()) {
    if (r.Has(k) && !is_mesh)
      r.Child(k).Fail(
          "applies to mesh files only; expected a model file ending in .obj, .gltf, .glb, .fbx, "
          ".dae, .stl or .ply");
  }
  if (r.Has("units") && r.Has("scale"))
    r.Child("scale").Fail("given together with units; expected one of units and scale");
  if (r.Has("units")) {
    const std::string u = r.Child("units").Enum({"m", "cm", "mm", "in", "ft"});
    out->scale = u == "m"    ? 1.0
                 : u == "cm" ? 0.01
                 : u == "mm" ? 0.001
                 : u == "in" ? 0.0254
                             : 0.3048;
  }
  if (r.Has("scale")) {
    out->scale = r.Child("scale").Double();
    if (!(out->scale > 0 && out->scale <= kMaxScale))
      r.Child("scale").Fail("expected metres per file unit in (0, 1e6]");
  }
  if (const auto found = r.Find("up_axis"))
    out->up_axis = found->Enum({"x", "y", "z", "-x", "-y", "-z"});
  if (r.Has("handedness"))
    out->left_handed = r.Child("handedness").Enum({"right", "left"}) == "left";
  if (r.Has("emissive_cd_m2")) {
    out->emissive_cd_m2 = r.Child("emissive_cd_m2").Double();
    if (!(out->emissive_cd_m2 >= 0 && out->emissive_cd_m2 <= 1e9))
      r.Child("emissive_cd_m2").Fail("expected a luminance in [0, 1e9] cd/m^2");
  }
  if (r.Has("collision"))
    out->collision = r.Child("collision").Enum({"hull", "heightfield", "coacd", "none"});
  if (r.Has("heightfield_cell_m")) {
    if (out->collision != "heightfield")
      r.Child("heightfield_cell_m").Fail("applies to collision: heightfield only");
    out->heightfield_cell_m = r.Child("heightfield_cell_m").Double();
    if (!(out->heightfield_cell_m >= 0.005 && out->heightfield_cell_m <= 10))
      r.Child("heightfield_cell_m").Fail("expected a sample spacing in [0.005, 10] m");
  }
  if (r.Has("concavity_threshold")) {
    if (out->collision != "coacd")
      r.Child("concavity_threshold").Fail("applies to collision: coacd only");
    out->concavity_threshold = r.Child("concavity_threshold").Double();
    if (!(out->concavity_threshold >= 0.001 && out->concavity_threshold <= 1))
      r.Child("concavity_threshold")
          .Fail("expected a fraction of the mesh's largest extent in [0.001, 1]");
  }
  if (r.Has("max_parts")) {
    if (out->collision != "coacd") r.Child("max_parts").Fail("applies to collision: coacd only");
    out->max_parts = r.Child("max_parts").Int();
    if (!(out->max_parts >= 1 && out->max_parts <= 1024))
      r.Child("max_parts").Fail("expected a number of parts in [1, 1024]");
  }
}

MeshImportConfig MeshImportConfigOf(const std::string& world_file, const std::string& key) {
  MeshImportConfig out;
  if (world_file.empty() || key.empty()) return out;
  // key: "<list>[<index>]"
  const size_t open = key.find('['), close = key.find(']');
  if (open == std::string::npos || close == std::string::npos || close < open) return out;
  const std::string list = key.substr(0, open);
  const size_t index = std::stoul(key.substr(open + 1, close - open - 1));
  // a world whose file is gone (a replay's recorded world): the format defaults
  const std::optional<ConfigValue> root = ReadWorldFileDocument(world_file);
  if (!root) return out;
  const ParamReader doc(*root, world_file, nullptr);
  doc.ExpectMapAnyKeys();
  if (!doc.Has(list)) return out;
  const ParamReader entries = doc.Child(list);
  if (index >= entries.size()) return out;
  const ParamReader entry = entries.Element(index);
  entry.ExpectMapAnyKeys();
  const std::string file = entry.Has("file") ? entry.Child("file").String() : "";
  ReadMeshImportKeys(entry, IsMeshModelFile(file), &out);
  return out;
}

}  // namespace penumbra

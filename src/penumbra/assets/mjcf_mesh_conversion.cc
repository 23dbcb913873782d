#include "penumbra/assets/mjcf_mesh_conversion.h"

#include <fmt/format.h>

#include <algorithm>
#include <cctype>
#include <filesystem>

#include "penumbra/assets/mesh_import.h"
#include "penumbra/assets/mesh_model.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

std::string LowerMeshExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

// the meshes of `asset` as one mesh (vertex indices offset per part; normals and texcoords
// kept only when every part has them).
TriangleMesh Merge(const ImportedAsset& asset) {
  TriangleMesh out;
  out.name = fs::path(asset.file).stem().string();
  bool normals = true, texcoords = true;
  for (const ImportedMesh& m : asset.meshes) {
    normals &= !m.mesh.normals.empty();
    texcoords &= !m.mesh.texcoords.empty();
  }
  for (const ImportedMesh& m : asset.meshes) {
    const int base = static_cast<int>(out.vertices.size());
    out.vertices.insert(out.vertices.end(), m.mesh.vertices.begin(), m.mesh.vertices.end());
    if (normals)
      out.normals.insert(out.normals.end(), m.mesh.normals.begin(), m.mesh.normals.end());
    if (texcoords)
      out.texcoords.insert(out.texcoords.end(), m.mesh.texcoords.begin(), m.mesh.texcoords.end());
    for (const Eigen::Vector3i& f : m.mesh.faces)
      out.faces.push_back(f + Eigen::Vector3i::Constant(base));
  }
  return out;
}

}  // namespace

std::string ConvertForeignMjcfMesh(const std::string& file, const std::string& dir) {
  const std::string ext = LowerMeshExtension(file);
  if (ext == ".stl" || ext == ".obj" || ext == ".msh" || !IsMeshModelFile(file)) return "";
  ImportedAsset asset;
  try {
    asset = ImportMeshFile(file, MeshImportConfig{});
  } catch (const ConfigError& err) {
    throw ConfigError(err.file(), err.line(), "mesh.file",
                      "cannot convert mesh file " + err.file() + " for MuJoCo: " + err.problem());
  }
  const fs::path folder =
      dir.empty() ? fs::temp_directory_path() / "penumbra-mesh-models" : fs::path(dir);
  const std::string bytes = MshBytes(Merge(asset));
  std::error_code ec;
  fs::create_directories(folder, ec);
  return WriteContentNamedFile(folder, fs::path(file).stem().string(), ".msh", bytes);
}

}  // namespace penumbra

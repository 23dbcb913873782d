#include "penumbra/decompose/mesh_io.h"

#include <assimp/postprocess.h>
#include <assimp/scene.h>
#include <fmt/format.h>

#include <assimp/Importer.hpp>
#include <filesystem>
#include <fstream>

#include "penumbra/core/error.h"

namespace penumbra {

SolidMesh ReadMeshFile(const std::string& path, double scale) {
  if (!std::filesystem::is_regular_file(path))
    throw Error(path + ": no such file; expected a mesh (.off, .obj, .stl, .ply)");
  // assimp (as the world-file importer, assets/mesh_import.h) with the file's own coordinates:
  // node transforms baked in, polygons triangulated; vertices at bit-equal positions merged
  // across the file's meshes so that the surface is one solid
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(
      path, aiProcess_Triangulate | aiProcess_PreTransformVertices | aiProcess_SortByPType);
  if (!scene || !scene->mRootNode)
    throw Error(path + ": cannot read the mesh (" + importer.GetErrorString() + ")");
  SolidMesh soup;
  for (unsigned m = 0; m < scene->mNumMeshes; ++m) {
    const aiMesh* mesh = scene->mMeshes[m];
    const int base = static_cast<int>(soup.vertices.size());
    for (unsigned i = 0; i < mesh->mNumVertices; ++i) {
      const aiVector3D& v = mesh->mVertices[i];
      soup.vertices.emplace_back(v.x * scale, v.y * scale, v.z * scale);
    }
    for (unsigned f = 0; f < mesh->mNumFaces; ++f) {
      const aiFace& face = mesh->mFaces[f];
      if (face.mNumIndices != 3) continue;  // points and lines
      soup.triangles.push_back({base + static_cast<int>(face.mIndices[0]),
                                base + static_cast<int>(face.mIndices[1]),
                                base + static_cast<int>(face.mIndices[2])});
    }
  }
  const SolidMesh out = WeldVertices(soup);
  if (out.triangles.empty())
    throw Error(path +
                ": holds no triangles; expected a closed, manifold surface in .off, .obj, .stl "
                "or .ply");
  return out;
}

void WritePartsObj(const Decomposition& decomposition, const std::string& path) {
  std::ofstream out(path);
  if (!out) throw Error(path + ": cannot open for writing");
  out << fmt::format("# {} convex parts ({}), m\n", decomposition.parts.size(),
                     DecompositionMethodName(decomposition.method));
  int base = 1;
  for (size_t i = 0; i < decomposition.parts.size(); ++i) {
    const SolidMesh& hull = decomposition.parts[i].hull;
    out << "o part_" << i << "\n";
    for (const Eigen::Vector3d& v : hull.vertices)
      out << fmt::format("v {:.17g} {:.17g} {:.17g}\n", v.x(), v.y(), v.z());
    for (const auto& t : hull.triangles)
      out << fmt::format("f {} {} {}\n", t[0] + base, t[1] + base, t[2] + base);
    base += static_cast<int>(hull.vertices.size());
  }
  if (!out) throw Error(path + ": write failed");
}

PartsMjcf PartsToMjcf(const Decomposition& decomposition, const std::string& prefix,
                      const std::string& geom_attributes) {
  PartsMjcf mjcf;
  for (size_t i = 0; i < decomposition.parts.size(); ++i) {
    const std::string name = fmt::format("{}_{}", prefix, i);
    std::string vertex;
    for (const Eigen::Vector3d& v : decomposition.parts[i].hull.vertices)
      vertex +=
          fmt::format("{}{:.17g} {:.17g} {:.17g}", vertex.empty() ? "" : " ", v.x(), v.y(), v.z());
    mjcf.assets += fmt::format("<mesh name=\"{}\" vertex=\"{}\"/>\n", name, vertex);
    mjcf.geoms += fmt::format("<geom name=\"{0}\" type=\"mesh\" mesh=\"{0}\"{1}{2}/>\n", name,
                              geom_attributes.empty() ? "" : " ", geom_attributes);
  }
  return mjcf;
}

}  // namespace penumbra

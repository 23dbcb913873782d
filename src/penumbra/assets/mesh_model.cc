#include "penumbra/assets/mesh_model.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <memory>

#include "penumbra/assets/height_field_model.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/core/srgb.h"
#include "penumbra/decompose/decomposition_cache.h"
#include "penumbra/decompose/mesh_io.h"
#include "penumbra/render/backends/renderer_factory.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

template <typename T>
void AppendMeshBytes(std::string* out, T v) {
  char b[sizeof(T)];
  std::memcpy(b, &v, sizeof(T));
  out->append(b, sizeof(T));
}

std::string XmlEscape(const std::string& s) {
  std::string out;
  for (const char c : s) {
    switch (c) {
      case '&':
        out += "&amp;";
        break;
      case '<':
        out += "&lt;";
        break;
      case '>':
        out += "&gt;";
        break;
      case '"':
        out += "&quot;";
        break;
      default:
        out += c;
    }
  }
  return out;
}

}  // namespace

std::string MshBytes(const TriangleMesh& mesh) {
  std::vector<Eigen::Vector3f> v = mesh.vertices;
  std::vector<Eigen::Vector3f> n = mesh.normals;
  std::vector<Eigen::Vector2f> t = mesh.texcoords;
  // a flat mesh (a label, a floor tile): one unreferenced vertex off its plane, or qhull
  // cannot build MuJoCo's convex hull
  if (!v.empty() && !mesh.faces.empty()) {
    Eigen::Vector3d c = Eigen::Vector3d::Zero(), area_n = Eigen::Vector3d::Zero();
    Eigen::Vector3d lo = v[0].cast<double>(), hi = lo;
    for (const Eigen::Vector3f& p : v) {
      c += p.cast<double>();
      lo = lo.cwiseMin(p.cast<double>());
      hi = hi.cwiseMax(p.cast<double>());
    }
    c /= static_cast<double>(v.size());
    for (const Eigen::Vector3i& f : mesh.faces) {
      const Eigen::Vector3d a = v[f[0]].cast<double>();
      area_n += (v[f[1]].cast<double>() - a).cross(v[f[2]].cast<double>() - a);
    }
    const double extent = (hi - lo).norm();
    if (area_n.norm() > 0 && extent > 0) {
      const Eigen::Vector3d nn = area_n.normalized();
      double off = 0;
      for (const Eigen::Vector3f& p : v)
        off = std::max(off, std::abs((p.cast<double>() - c).dot(nn)));
      if (off < 1e-6 * extent) {
        v.push_back((c - 1e-4 * extent * nn).cast<float>());
        if (!n.empty()) n.push_back(nn.cast<float>());
        if (!t.empty()) t.push_back(Eigen::Vector2f::Zero());
      }
    }
  }
  while (!v.empty() && v.size() < 4) {
    v.push_back(v.front());
    if (!n.empty()) n.push_back(n.front());
    if (!t.empty()) t.push_back(t.front());
  }
  std::string out;
  AppendMeshBytes<int32_t>(&out, static_cast<int32_t>(v.size()));
  AppendMeshBytes<int32_t>(&out, static_cast<int32_t>(n.size()));
  AppendMeshBytes<int32_t>(&out, static_cast<int32_t>(t.size()));
  AppendMeshBytes<int32_t>(&out, static_cast<int32_t>(mesh.faces.size()));
  for (const Eigen::Vector3f& p : v)
    for (int k = 0; k < 3; ++k) AppendMeshBytes<float>(&out, p[k]);
  for (const Eigen::Vector3f& p : n)
    for (int k = 0; k < 3; ++k) AppendMeshBytes<float>(&out, p[k]);
  for (const Eigen::Vector2f& p : t)
    for (int k = 0; k < 2; ++k) AppendMeshBytes<float>(&out, p[k]);
  for (const Eigen::Vector3i& f : mesh.faces)
    for (int k = 0; k < 3; ++k) AppendMeshBytes<int32_t>(&out, f[k]);
  return out;
}

std::string MeshModelMjcf(const ImportedAsset& asset, const std::vector<std::string>& msh_files,
                          const MeshModelCollision& collision) {
  std::string x = fmt::format("<mujoco model=\"{}\">\n  <asset>\n",
                              XmlEscape(fs::path(asset.file).stem().string()));
  for (size_t i = 0; i < asset.meshes.size(); ++i)
    x += fmt::format("    <mesh name=\"{}\" file=\"{}\" inertia=\"shell\"/>\n",
                     XmlEscape(asset.meshes[i].mesh.name), XmlEscape(msh_files.at(i)));
  for (const ImportedMaterial& m : asset.materials) {
    const Eigen::Vector3f& c = m.factors.base_color;
    x += fmt::format("    <material name=\"{}\" rgba=\"{:.6g} {:.6g} {:.6g} 1\"/>\n",
                     XmlEscape(m.name), LinearToSrgb<double>(c.x()), LinearToSrgb<double>(c.y()),
                     LinearToSrgb<double>(c.z()));
  }
  x += collision.convex_parts.assets;
  if (collision.hfield)
    x += fmt::format("    <hfield name=\"collision_heightfield\" file=\"{}\" size=\"{}\"/>\n",
                     XmlEscape(collision.hfield_file), HfieldSizeAttribute(*collision.hfield, 0.1));
  // geoms of the world body: their inertia is never used, but MuJoCo computes every mesh's at
  // compile time and refuses a volume of zero; inertia="shell" (by area) lets open and flat
  // meshes load
  x += "  </asset>\n  <worldbody>\n";
  for (const ImportedMesh& m : asset.meshes)
    x += fmt::format("    <geom name=\"{0}\" type=\"mesh\" mesh=\"{0}\" material=\"{1}\"{2}/>\n",
                     XmlEscape(m.mesh.name), XmlEscape(asset.materials.at(m.material).name),
                     collision.mesh_geoms_collide ? "" : " contype=\"0\" conaffinity=\"0\"");
  x += collision.convex_parts.geoms;
  if (collision.hfield) {
    const Eigen::Vector3d p = HfieldGeomPosition(*collision.hfield);
    x += fmt::format(
        "    <geom name=\"collision_heightfield\" type=\"hfield\" hfield=\"collision_heightfield\" "
        "pos=\"{:.6f} {:.6f} {:.6f}\" group=\"3\"/>\n",
        p.x(), p.y(), p.z());
  }
  x += "  </worldbody>\n</mujoco>\n";
  return x;
}

SampledHeightField SampleMeshHeightField(const ImportedAsset& asset, double cell_m) {
  // the asset's meshes as the static geoms of a scene of one body, traced with Embree
  SceneDescription scene;
  scene.bodies.push_back(Body{"world", -1, true});
  scene.materials.push_back(Material{});
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d hi = -lo;
  for (size_t i = 0; i < asset.meshes.size(); ++i) {
    scene.meshes.push_back(asset.meshes[i].mesh);
    Geom g;
    g.name = asset.meshes[i].mesh.name;
    g.id = static_cast<int>(i);
    g.body = 0;
    g.shape = GeomShape::kMesh;
    g.mesh = static_cast<int>(i);
    g.material = 0;
    scene.geoms.push_back(g);
    for (const Eigen::Vector3f& v : asset.meshes[i].mesh.vertices) {
      lo = lo.cwiseMin(v.cast<double>());
      hi = hi.cwiseMax(v.cast<double>());
    }
  }
  if (!(lo.x() <= hi.x()))
    throw Error("no triangles to sample a height field from in " + asset.file);
  const std::unique_ptr<RayQuery> query = MakeRayQuery(scene, RenderSettings::Backend::kEmbree);
  WorldSnapshot snapshot;
  snapshot.X_WB = {Pose::Identity()};
  query->Update(snapshot);
  return SampleHeightField(*query, lo.head<2>(), hi.head<2>(), cell_m, hi.z() + 1, lo.z());
}

SolidMesh WeldedSolid(const ImportedAsset& asset) {
  SolidMesh soup;
  for (const ImportedMesh& m : asset.meshes) {
    const int base = static_cast<int>(soup.vertices.size());
    for (const Eigen::Vector3f& v : m.mesh.vertices) soup.vertices.push_back(v.cast<double>());
    for (const Eigen::Vector3i& f : m.mesh.faces)
      soup.triangles.push_back({base + f[0], base + f[1], base + f[2]});
  }
  return WeldVertices(soup);
}

std::vector<ImportedModel> ImportMeshModels(std::vector<ModelConfig>* models,
                                            const std::string& dir, const std::string& world_file) {
  std::vector<ImportedModel> out;
  fs::path folder =
      dir.empty() ? fs::temp_directory_path() / "penumbra-mesh-models" : fs::path(dir);
  // absolute: the generated MJCF names its .msh files by these paths, which MuJoCo resolves
  // against the MJCF's own folder (a relative --out gave "out/meshes/out/meshes/x.msh")
  std::error_code abs_ec;
  if (const fs::path a = fs::absolute(folder, abs_ec); !abs_ec) folder = a;
  bool made = false;
  for (size_t i = 0; i < models->size(); ++i) {
    ModelConfig& m = (*models)[i];
    if (!IsMeshModelFile(m.file)) continue;
    if (!made) {
      std::error_code ec;
      fs::create_directories(folder, ec);
      if (ec)
        throw Error("cannot create the mesh model folder " + folder.string() + ": " + ec.message());
      made = true;
    }
    const std::string key = (m.key.empty() ? "models[" + m.name + "]" : m.key) + ".file";
    ImportedModel im;
    im.model = m.name;
    const MeshImportConfig config = MeshImportConfigOf(world_file, m.key);
    const auto t0 = std::chrono::steady_clock::now();
    try {
      im.asset = ImportMeshFile(m.file, config);
    } catch (const ConfigError& e) {
      // name the world-file entry; the problem names the mesh file
      throw ConfigError(world_file, config.line, key,
                        "cannot import mesh file " + e.file() + ": " + e.problem());
    }
    im.import_sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    const std::string stem = fs::path(m.file).stem().string();
    std::vector<std::string> msh_files;
    for (const ImportedMesh& mesh : im.asset.meshes) {
      const std::string bytes = MshBytes(mesh.mesh);
      msh_files.push_back(WriteContentNamedFile(folder, stem, ".msh", bytes));
    }
    // collision: the meshes' convex hulls, a height field sampled from the meshes, or nothing
    MeshModelCollision collision;
    collision.mesh_geoms_collide = config.collision == "hull";
    if (config.collision == "heightfield") {
      SampledHeightField field = SampleMeshHeightField(im.asset, config.heightfield_cell_m);
      collision.hfield_file =
          WriteContentNamedFile(folder, stem + "-collision", ".hfield", HfieldFileBytes(field));
      collision.hfield = std::move(field);
    }
    if (config.collision == "coacd") {
      DecompositionOptions options;
      options.concavity_threshold = config.concavity_threshold;
      options.max_parts = config.max_parts;
      const SolidMesh solid = WeldedSolid(im.asset);
      const auto t1 = std::chrono::steady_clock::now();
      CachedDecomposition d;
      try {
        d = DecomposeCached(solid, options, DecompositionCache(DefaultDecompositionCacheDir()),
                            m.file);
      } catch (const ConfigError&) {
        throw;
      } catch (const Error& e) {
        throw ConfigError(world_file, config.line,
                          (m.key.empty() ? "models[" + m.name + "]" : m.key) + ".collision",
                          std::string("collision: coacd needs a closed, consistently oriented "
                                      "solid once coincident vertices are merged (else use hull, "
                                      "heightfield or none): ") +
                              e.what());
      }
      im.decompose_sec =
          std::chrono::duration<double>(std::chrono::steady_clock::now() - t1).count();
      im.decomposition_cache_hit = d.cache_hit;
      im.collision_parts = static_cast<int>(d.decomposition.parts.size());
      im.relative_max_concavity = d.decomposition.relative_max_concavity();
      im.hull_volume_ratio = d.decomposition.mesh_volume > 0
                                 ? d.decomposition.HullVolumeSum() / d.decomposition.mesh_volume
                                 : 0;
      if (d.decomposition.hit_part_limit)
        spdlog::warn(
            "{}: max_parts {} forced merges over the concavity threshold {} (largest "
            "concavity {:.4f} of the extent)",
            m.file, config.max_parts, config.concavity_threshold, im.relative_max_concavity);
      collision.convex_parts = PartsToMjcf(d.decomposition, "collision_part", "group=\"3\"");
    }
    const std::string xml = MeshModelMjcf(im.asset, msh_files, collision);
    m.file = WriteContentNamedFile(folder, stem, ".xml", xml);
    out.push_back(std::move(im));
  }
  return out;
}

void ApplyImportedMaterials(const std::vector<ImportedModel>& models, SceneDescription* scene) {
  for (const ImportedModel& im : models) {
    for (const ImportedMaterial& mat : im.asset.materials) {
      const std::string name = im.model + "/" + mat.name;
      const int k = scene->FindMaterial(name);
      if (k < 0) throw Error("imported material '" + name + "' is missing from the scene");
      Material& m = scene->materials[k];
      m.base_color = mat.factors.base_color;
      m.roughness = mat.factors.roughness;
      m.metallic = mat.factors.metallic;
      m.emission = mat.factors.emission;
      m.texrepeat = {1, 1};
      m.texuniform = false;
      auto add = [&](const std::shared_ptr<const TextureImage>& image, const char* map) {
        if (!image) return -1;
        Texture t;
        t.name = name + "/" + map;
        t.kind = Texture::Kind::k2D;
        t.image = image;
        scene->textures.push_back(std::move(t));
        return static_cast<int>(scene->textures.size()) - 1;
      };
      // the maps by name (render/material/material_eval.h, "PBR maps")
      m.texture = add(mat.base_color, "base_color");
      add(mat.normal, "normal");
      add(mat.metallic_roughness, "metallic_roughness");
      add(mat.occlusion, "occlusion");
      add(mat.emissive, "emissive");
    }
  }
}

}  // namespace penumbra

#include "penumbra/environment/model_sources.h"

#include <spdlog/spdlog.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <utility>

#include "penumbra/assets/mjcf_mesh_conversion.h"
#include "penumbra/assets/procedural_material.h"

namespace penumbra {

ModelSources::ModelSources(WorldConfig* world, const std::string& environments_dir,
                           const std::string& mesh_dir)
    : mesh_dir_(mesh_dir), models_(world->models) {
  // generated environments (models: entries with environment:) become MJCF models next to the
  // composed model, their lamps world lights, their materials procedural ones
  generated_ = GenerateEnvironmentModels(&models_, environments_dir);
  for (const GeneratedModel& g : generated_.models)
    spdlog::info(
        "generated {} ({}): {} geoms ({} colliding), {} furniture items, {} materials, "
        "{} lamps in {:.3f} s",
        g.model, g.file, g.environment.geoms, g.environment.colliding_geoms,
        g.environment.furniture, g.environment.materials.size(), g.environment.lights.size(),
        g.generate_sec);
  world->lights.insert(world->lights.end(), generated_.lights.begin(), generated_.lights.end());
  for (size_t i = 0; i < models_.size(); ++i) world->models[i].file = models_[i].file;
  // mesh files (models: entries with .obj, .gltf, ...) become generated MJCF models there too
  imported_ = ImportMeshModels(&models_, mesh_dir_, world->file);
  for (const ImportedModel& im : imported_)
    spdlog::info("imported {} ({}): {} meshes, {} triangles, {} materials in {:.3f} s", im.model,
                 im.asset.file, im.asset.meshes.size(), im.asset.triangles,
                 im.asset.materials.size(), im.import_sec);
  for (const ImportedModel& im : imported_)
    if (im.collision_parts > 0)
      spdlog::info(
          "collision of {}: {} convex parts (CoACD, max concavity {:.4f} of the extent, "
          "hull volumes {:.3f} x the mesh's) {} in {:.3f} s",
          im.model, im.collision_parts, im.relative_max_concavity, im.hull_volume_ratio,
          im.decomposition_cache_hit ? "read from the cache" : "computed", im.decompose_sec);
}

CrowdSites ModelSources::crowd_sites(const std::vector<ModelConfig>& world_models) const {
  CrowdSites sites;
  for (const GeneratedModel& g : generated_.models) {
    Pose X_WM = Pose::Identity();
    for (const ModelConfig& m : world_models)
      if (m.name == g.model) X_WM = m.pose.ToPose();
    for (const auto& [name, r] : g.environment.rooms) {
      CrowdSites::Area a;
      a.name = g.model + "/" + name;
      a.drivable = std::find(g.environment.drivable.begin(), g.environment.drivable.end(), name) !=
                   g.environment.drivable.end();
      a.min_W = Eigen::Vector2d(1e300, 1e300);
      a.max_W = -a.min_W;
      for (const Eigen::Vector2d& c : {Eigen::Vector2d(r.x0, r.y0), Eigen::Vector2d(r.x1, r.y0),
                                       Eigen::Vector2d(r.x0, r.y1), Eigen::Vector2d(r.x1, r.y1)}) {
        const Eigen::Vector2d w = (X_WM * Eigen::Vector3d(c.x(), c.y(), 0)).head<2>();
        a.min_W = a.min_W.cwiseMin(w);
        a.max_W = a.max_W.cwiseMax(w);
      }
      sites.areas.push_back(a);
    }
    for (const Walkway& w : g.environment.walkways) {
      CrowdSites::Lane l;
      l.name = g.model + "/" + w.name;
      l.drivable = std::find(g.environment.drivable.begin(), g.environment.drivable.end(),
                             w.name) != g.environment.drivable.end();
      for (const Eigen::Vector2d& p : w.points)
        l.points_W.push_back((X_WM * Eigen::Vector3d(p.x(), p.y(), 0)).head<2>());
      sites.lanes.push_back(std::move(l));
    }
  }
  return sites;
}

std::string ModelSources::ConvertMjcfMesh(const std::string& mesh_file) const {
  // MJCF <mesh> files MuJoCo cannot read (glTF, FBX, COLLADA, PLY) become .msh files
  std::string converted = ConvertForeignMjcfMesh(mesh_file, mesh_dir_);
  if (!converted.empty()) spdlog::info("converted MJCF mesh {} for MuJoCo", mesh_file);
  return converted;
}

void ModelSources::ApplyMaterials(const std::string& world_file, SceneDescription* scene) const {
  ApplyImportedMaterials(imported_, scene);
  std::vector<ProceduralMaterialEntry> procedural = generated_.materials;
  for (ProceduralMaterialEntry& e : ProceduralMaterialsOf(world_file))
    procedural.push_back(std::move(e));
  ApplyProceduralMaterials(procedural, world_file, scene);
}

}  // namespace penumbra

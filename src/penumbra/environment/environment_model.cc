#include "penumbra/environment/environment_model.h"

#include <chrono>
#include <filesystem>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"

namespace penumbra {

GeneratedModels GenerateEnvironmentModels(std::vector<ModelConfig>* models,
                                          const std::string& dir) {
  namespace fs = std::filesystem;
  GeneratedModels out;
  const fs::path folder =
      dir.empty() ? fs::temp_directory_path() / "penumbra-environments" : fs::path(dir);
  for (ModelConfig& m : *models) {
    if (!m.environment) continue;
    std::error_code ec;
    fs::create_directories(folder, ec);
    if (ec)
      throw Error("cannot create the environment folder " + folder.string() + ": " + ec.message());
    GeneratedModel g;
    g.model = m.name;
    const auto t0 = std::chrono::steady_clock::now();
    g.environment = GenerateEnvironment(*m.environment);
    g.generate_sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    // the files the model refers to, then the model with their paths
    std::string mjcf = g.environment.mjcf;
    for (const GeneratedFile& f : g.environment.files) {
      const std::string path = WriteContentNamedFile(folder, f.stem, f.ext, f.bytes);
      for (size_t at = mjcf.find(f.placeholder); at != std::string::npos;
           at = mjcf.find(f.placeholder, at + path.size()))
        mjcf.replace(at, f.placeholder.size(), path);
    }
    g.file = WriteContentNamedFile(folder, m.environment->type, ".xml", mjcf);
    m.file = g.file;
    for (ProceduralMaterialEntry e : g.environment.materials) {
      e.material = m.name + "/" + e.material;
      out.materials.push_back(std::move(e));
    }
    const Pose X_WM = m.pose.ToPose();
    for (LightConfig l : g.environment.lights) {
      l.name = m.name + "/" + l.name;
      l.position = X_WM * l.position;
      l.direction = X_WM.linear() * l.direction;
      out.lights.push_back(std::move(l));
    }
    out.models.push_back(std::move(g));
  }
  return out;
}

}  // namespace penumbra

#include "penumbra/session/world_composer.h"

#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cctype>
#include <filesystem>

#include "penumbra/physics/model_spec_composer.h"
#include "penumbra/physics/urdf_converter.h"

namespace penumbra {
namespace {

// a .urdf file, or a file whose root element is <robot>
bool IsUrdf(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  if (ext == ".urdf") return true;
  tinyxml2::XMLDocument doc;
  if (doc.LoadFile(path.c_str()) != tinyxml2::XML_SUCCESS || doc.RootElement() == nullptr)
    return false;  // MuJoCo's parser names the problem
  return std::string(doc.RootElement()->Name()) == "robot";
}

void PoseOf(const PoseConfig& pose, std::array<double, 3>* pos, std::array<double, 4>* quat) {
  const Pose X = pose.ToPose();
  const Eigen::Quaterniond q = Eigen::Quaterniond(X.linear()).normalized();
  *pos = {X.translation().x(), X.translation().y(), X.translation().z()};
  *quat = {q.w(), q.x(), q.y(), q.z()};
}

}  // namespace

ComposedScene ComposeWorld(const std::vector<ModelConfig>& models, const ComposeOptions& options) {
  CheckComposeInput(models, options);
  ModelSpecComposer composer("<mujoco/>", options.timestep_sec.has_value());
  for (size_t i = 0; i < models.size(); ++i) {
    const ModelConfig& m = models[i];
    SpecModel spec;
    spec.name = m.name;
    spec.file = m.file;
    spec.key = m.key.empty() ? "models[" + m.name + "]" : m.key;
    PoseOf(m.pose, &spec.pos, &spec.quat);
    spec.floating_base = m.floating_base;
    spec.convert_mesh = options.convert_mesh;
    if (IsUrdf(m.file)) {
      spec.from_urdf = true;
      spec.text =
          options.prepare_urdf ? options.prepare_urdf(m.file) : PrepareUrdfForMujoco(m.file, "");
    }
    for (size_t s = 0; s < m.sites.size(); ++s) {
      SpecSite site;
      site.name = m.sites[s].name;
      site.body = m.sites[s].body;
      site.geom = m.sites[s].geom;
      site.key = spec.key + ".sites[" + std::to_string(s) + "]";
      PoseOf(m.sites[s].pose, &site.pos, &site.quat);
      spec.sites.push_back(std::move(site));
    }
    composer.Attach(spec);
  }
  SpecOptionOverrides overrides;
  overrides.timestep_sec = options.timestep_sec;
  const PhysicsOptions& p = options.physics;
  overrides.integrator = p.integrator;
  if (p.gravity_mps2)
    overrides.gravity_mps2 =
        std::array<double, 3>{p.gravity_mps2->x(), p.gravity_mps2->y(), p.gravity_mps2->z()};
  overrides.solver_iterations = p.solver_iterations;
  overrides.cone = p.cone;
  overrides.contact.noslip_iterations = p.noslip_iterations;
  overrides.contact.speculative = p.speculative;
  const std::string xml = composer.SaveXml(overrides);
  return MakeComposedScene(xml, models, composer.warnings(), options);
}

}  // namespace penumbra

#include "penumbra/compose/scene_composer.h"

#include <tinyxml2.h>

#include <functional>
#include <memory>
#include <string_view>

#include "penumbra/compose/mjcf_text.h"
#include "penumbra/core/error.h"
#include "penumbra/core/magnitude_limits.h"
#include "penumbra/core/output_file.h"

namespace penumbra {
namespace {

using compose::FormatNumbers;
using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;

void ValidateModels(const std::vector<ModelConfig>& models) {
  for (size_t i = 0; i < models.size(); ++i) {
    const ModelConfig& m = models[i];
    const std::string key = "models[" + std::to_string(i) + "].name";
    if (m.name.empty()) {
      throw ConfigError(m.file, 0, key, "empty model name; expected a unique non-empty name");
    }
    if (m.name.find('/') != std::string::npos) {
      throw ConfigError(m.file, 0, key,
                        "model name '" + m.name +
                            "' contains '/'; expected a name without '/' "
                            "(it prefixes MJCF names as '" +
                            m.name + "/...')");
    }
    for (size_t j = 0; j < i; ++j) {
      if (models[j].name == m.name) {
        throw ConfigError(m.file, 0, key,
                          "duplicate model name '" + m.name + "' (also used by " + models[j].file +
                              "); expected unique model names");
      }
    }
    if (m.file.empty()) {
      throw ConfigError("", 0, "models[" + std::to_string(i) + "].file",
                        "empty file for model '" + m.name + "'; expected an MJCF or URDF file");
    }
  }
}

// true if `e` or an element below it is a <geom type="plane">
bool HasPlane(const XMLElement* e) {
  if (e == nullptr) return false;
  if (std::string_view(e->Name()) == "geom" && e->Attribute("type", "plane")) return true;
  for (const XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
    if (HasPlane(c)) return true;
  }
  return false;
}

// ComposeOptions::ground_plane: an infinite plane at z = 0 with a 1 m grey checker (the
// look of worlds/models/ramp.xml's floor), added when no model has a plane
void AddGroundPlane(XMLDocument* doc, XMLElement* root) {
  XMLElement* worldbody = root->FirstChildElement("worldbody");
  if (HasPlane(worldbody)) return;
  if (worldbody == nullptr) worldbody = root->InsertNewChildElement("worldbody");
  XMLElement* asset = root->FirstChildElement("asset");
  if (asset == nullptr) {
    asset = doc->NewElement("asset");
    if (XMLElement* before = worldbody->PreviousSiblingElement()) {
      root->InsertAfterChild(before, asset);
    } else {
      root->InsertFirstChild(asset);
    }
  }
  XMLElement* tex = asset->InsertNewChildElement("texture");
  tex->SetAttribute("name", "ground_grid");
  tex->SetAttribute("type", "2d");
  tex->SetAttribute("builtin", "checker");
  tex->SetAttribute("rgb1", "0.46 0.47 0.48");
  tex->SetAttribute("rgb2", "0.40 0.41 0.42");
  tex->SetAttribute("width", "256");
  tex->SetAttribute("height", "256");
  tex->SetAttribute("mark", "edge");
  tex->SetAttribute("markrgb", "0.3 0.3 0.32");
  XMLElement* mat = asset->InsertNewChildElement("material");
  mat->SetAttribute("name", "ground");
  mat->SetAttribute("texture", "ground_grid");
  mat->SetAttribute("texrepeat", "1 1");
  mat->SetAttribute("texuniform", "true");
  mat->SetAttribute("specular", "0.2");
  mat->SetAttribute("shininess", "0.1");
  XMLElement* geom = doc->NewElement("geom");
  geom->SetAttribute("name", "ground");
  geom->SetAttribute("type", "plane");
  geom->SetAttribute("size", "0 0 0.05");
  geom->SetAttribute("material", "ground");
  worldbody->InsertFirstChild(geom);
}

}  // namespace

void CheckComposeInput(const std::vector<ModelConfig>& models, const ComposeOptions& options) {
  ValidateModels(models);
  if (options.timestep_sec &&
      !(*options.timestep_sec >= kMinTimestepSec && *options.timestep_sec <= kMaxTimestepSec)) {
    throw ConfigError("", 0, "timestep_sec",
                      "timestep " + FormatNumbers({*options.timestep_sec}) +
                          " is not valid; expected seconds in [" +
                          FormatNumbers({kMinTimestepSec}) + ", " +
                          FormatNumbers({kMaxTimestepSec}) + "]");
  }
}

ComposedScene MakeComposedScene(const std::string& xml, const std::vector<ModelConfig>& models,
                                std::vector<std::string> warnings, const ComposeOptions& options) {
  ComposedScene scene;
  XMLDocument& doc = *scene.document;
  if (doc.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS || !doc.RootElement() ||
      std::string_view(doc.RootElement()->Name()) != "mujoco") {
    throw Error("MakeComposedScene: the composed text is not an MJCF document: " +
                std::string(doc.ErrorStr() ? doc.ErrorStr() : ""));
  }
  XMLElement* root = doc.RootElement();
  root->SetAttribute("model", "penumbra_world");
  std::string comment = " composed by penumbra from:";
  for (const ModelConfig& m : models) comment += " " + m.name + " (" + m.file + ")";
  doc.InsertFirstChild(doc.NewComment((comment + " ").c_str()));
  for (const ModelConfig& m : models) scene.model_names.push_back(m.name);
  scene.warnings = std::move(warnings);
  if (options.ground_plane) AddGroundPlane(&doc, root);
  return scene;
}

ComposedScene::ComposedScene() : document(std::make_unique<XMLDocument>()) {}
ComposedScene::ComposedScene(const ComposedScene& other)
    : document(std::make_unique<XMLDocument>()),
      model_names(other.model_names),
      warnings(other.warnings) {
  other.document->DeepCopy(document.get());
}
ComposedScene& ComposedScene::operator=(const ComposedScene& other) {
  if (this != &other) {
    other.document->DeepCopy(document.get());
    model_names = other.model_names;
    warnings = other.warnings;
  }
  return *this;
}
ComposedScene::ComposedScene(ComposedScene&&) noexcept = default;
ComposedScene& ComposedScene::operator=(ComposedScene&&) noexcept = default;
ComposedScene::~ComposedScene() = default;

std::string ComposedScene::Xml() const {
  tinyxml2::XMLPrinter printer;
  document->Print(&printer);
  return printer.CStr();
}

void WriteComposedScene(const ComposedScene& scene, const std::string& path) {
  WriteFileAtomic(path, scene.Xml());
}

}  // namespace penumbra

#include "penumbra/compose/world_sites.h"

#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <map>
#include <set>
#include <string>

#include "penumbra/compose/mjcf_frames.h"
#include "penumbra/compose/mjcf_text.h"
#include "penumbra/core/error.h"

namespace penumbra::compose {
namespace {

using tinyxml2::XMLElement;

struct Names {
  std::map<std::string, XMLElement*> bodies, geoms;
  std::set<std::string> sites;
};

void Collect(XMLElement* parent, Names* names) {
  for (XMLElement* e = parent->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string tag = e->Name();
    const char* name = e->Attribute("name");
    if (name != nullptr) {
      if (tag == "body") names->bodies[name] = e;
      if (tag == "geom") names->geoms[name] = e;
      if (tag == "site") names->sites.insert(name);
    }
    if (tag == "body") Collect(e, names);
  }
}

// the model's names of one kind (prefix removed), for messages: at most 12
std::string Listing(const std::map<std::string, XMLElement*>& all, const std::string& prefix) {
  std::string out;
  int n = 0;
  for (const auto& [name, e] : all) {
    if (name.rfind(prefix, 0) != 0) continue;
    if (++n > 12) return out + ", ...";
    out += (out.empty() ? "" : ", ") + name.substr(prefix.size());
  }
  return out.empty() ? "none" : out;
}

Eigen::Vector3d GeomCentre(const XMLElement* geom) {
  if (const char* fromto = geom->Attribute("fromto")) {
    const auto v = ParseNumbers(fromto);
    if (v && v->size() == 6) {
      return 0.5 * Eigen::Vector3d((*v)[0] + (*v)[3], (*v)[1] + (*v)[4], (*v)[2] + (*v)[5]);
    }
  }
  if (const char* pos = geom->Attribute("pos")) {
    const auto v = ParseNumbers(pos);
    if (v && v->size() == 3) return Eigen::Vector3d((*v)[0], (*v)[1], (*v)[2]);
  }
  return Eigen::Vector3d::Zero();
}

}  // namespace

void AddWorldSites(const std::vector<ModelConfig>& models, XMLElement* root) {
  bool any = false;
  for (const ModelConfig& m : models) any = any || !m.sites.empty();
  if (!any) return;
  XMLElement* world = root->FirstChildElement("worldbody");
  if (world == nullptr) world = root->InsertNewChildElement("worldbody");
  Names names;
  Collect(world, &names);
  for (const ModelConfig& m : models) {
    const std::string prefix = m.name + "/";
    const std::string entry = m.key.empty() ? "models[" + m.name + "]" : m.key;
    for (size_t i = 0; i < m.sites.size(); ++i) {
      const SiteConfig& s = m.sites[i];
      const std::string key = entry + ".sites[" + std::to_string(i) + "]";
      const std::string full = prefix + s.name;
      if (names.sites.count(full)) {
        throw ConfigError("", 0, key + ".name",
                          "model '" + m.name + "' already has a site '" + s.name +
                              "'; expected a new name (or use the model's site directly)");
      }
      XMLElement* parent = nullptr;
      Pose X_PS = s.pose.ToPose();
      if (!s.geom.empty()) {
        const auto it = names.geoms.find(prefix + s.geom);
        if (it == names.geoms.end()) {
          throw ConfigError(
              "", 0, key + ".geom",
              "model '" + m.name + "' has no geom '" + s.geom +
                  "'; expected one of its named geoms: " + Listing(names.geoms, prefix));
        }
        parent = it->second->Parent()->ToElement();
        X_PS.translation() += GeomCentre(it->second);
      } else if (s.body == "world") {
        parent = world;
      } else {
        const auto it = names.bodies.find(prefix + s.body);
        if (it == names.bodies.end()) {
          throw ConfigError("", 0, key + ".body",
                            "model '" + m.name + "' has no body '" + s.body +
                                "'; expected one of its bodies: " + Listing(names.bodies, prefix) +
                                " (or world)");
        }
        parent = it->second;
      }
      XMLElement* site = parent->InsertNewChildElement("site");
      site->SetAttribute("name", full.c_str());
      const Eigen::Vector3d p = X_PS.translation();
      site->SetAttribute("pos", FormatNumbers({p.x(), p.y(), p.z()}).c_str());
      const Eigen::Quaterniond q(X_PS.linear());
      site->SetAttribute("quat", FormatNumbers(QuatToVector(q.normalized())).c_str());
      site->SetAttribute("group", "4");
      names.sites.insert(full);
    }
  }
}

}  // namespace penumbra::compose

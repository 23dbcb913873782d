#include "penumbra/compose/world_sites.h"

#include <tinyxml2.h>

#include <Eigen/Geometry>
#include <functional>
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

// the composed document's default classes by name (class names are unique: each model's are
// prefixed with its name)
std::map<std::string, const XMLElement*> DefaultClasses(const XMLElement* root) {
  std::map<std::string, const XMLElement*> out;
  const std::function<void(const XMLElement*)> walk = [&](const XMLElement* d) {
    if (const char* c = d->Attribute("class")) out.emplace(c, d);
    for (const XMLElement* e = d->FirstChildElement("default"); e;
         e = e->NextSiblingElement("default"))
      walk(e);
  };
  for (const XMLElement* d = root->FirstChildElement("default"); d;
       d = d->NextSiblingElement("default"))
    walk(d);
  return out;
}

// the value of `attr` that `geom` has, written on it or inherited from its default class as
// MuJoCo resolves it: its class=, else the childclass of the nearest enclosing body, then that
// class's ancestors (every element of the composed document has one of the two: the composer
// gives top-level elements their model's root class); nullptr when none sets it
const char* GeomAttribute(const XMLElement* geom, const char* attr,
                          const std::map<std::string, const XMLElement*>& classes) {
  if (const char* v = geom->Attribute(attr)) return v;
  const char* cls = geom->Attribute("class");
  for (const tinyxml2::XMLNode* n = geom->Parent(); cls == nullptr && n; n = n->Parent()) {
    const XMLElement* p = n->ToElement();
    if (p == nullptr || std::string(p->Name()) == "worldbody") break;
    if (std::string(p->Name()) == "body") cls = p->Attribute("childclass");
  }
  if (cls == nullptr) return nullptr;
  const auto it = classes.find(cls);
  for (const XMLElement* d = it == classes.end() ? nullptr : it->second;
       d && std::string(d->Name()) == "default";
       d = d->Parent() ? d->Parent()->ToElement() : nullptr) {
    // several <geom> defaults in one class: the last one written wins
    const char* v = nullptr;
    for (const XMLElement* g = d->FirstChildElement("geom"); g; g = g->NextSiblingElement("geom"))
      if (const char* a = g->Attribute(attr)) v = a;
    if (v) return v;
  }
  return nullptr;
}

// the geom's centre in its body's frame: the midpoint of its fromto (which MuJoCo uses over
// pos), else its pos, each written on it or set by its default class; the origin when neither
Eigen::Vector3d GeomCentre(const XMLElement* geom,
                           const std::map<std::string, const XMLElement*>& classes) {
  if (const char* fromto = GeomAttribute(geom, "fromto", classes)) {
    const auto v = ParseNumbers(fromto);
    if (v && v->size() == 6) {
      return 0.5 * Eigen::Vector3d((*v)[0] + (*v)[3], (*v)[1] + (*v)[4], (*v)[2] + (*v)[5]);
    }
  }
  if (const char* pos = GeomAttribute(geom, "pos", classes)) {
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
  const auto classes = DefaultClasses(root);
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
        X_PS.translation() += GeomCentre(it->second, classes);
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

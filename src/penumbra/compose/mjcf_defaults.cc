#include "penumbra/compose/mjcf_defaults.h"

#include "penumbra/compose/mjcf_schema.h"

namespace penumbra::compose {
namespace {

using tinyxml2::XMLElement;

bool IsTag(const XMLElement* e, const char* name) { return std::string(e->Name()) == name; }

}  // namespace

DefaultTree DefaultTree::Build(const MjcfSource& src) {
  DefaultTree tree;
  tree.classes_.push_back(Class{"main", -1, {}});
  for (XMLElement* s = src.root()->FirstChildElement("default"); s;
       s = s->NextSiblingElement("default")) {
    if (const char* name = s->Attribute("class"); name && *name) tree.classes_[kRoot].name = name;
    tree.classes_[kRoot].sections.push_back(s);
  }
  for (XMLElement* s : std::vector<XMLElement*>(tree.classes_[kRoot].sections)) {
    tree.AddNested(s, kRoot, src);
  }
  return tree;
}

void DefaultTree::AddNested(XMLElement* section, int parent, const MjcfSource& src) {
  for (XMLElement* c = section->FirstChildElement("default"); c;
       c = c->NextSiblingElement("default")) {
    const char* name = c->Attribute("class");
    if (name == nullptr || *name == '\0') {
      src.Fail(c, "default.class", "nested <default> without a class name; expected class=\"...\"");
    }
    if (Find(name)) {
      src.Fail(c, std::string("default[") + name + "]",
               "repeated default class name; expected unique class names");
    }
    classes_.push_back(Class{name, parent, {c}});
    AddNested(c, static_cast<int>(classes_.size()) - 1, src);
  }
}

std::optional<int> DefaultTree::Find(const std::string& name) const {
  for (size_t i = 0; i < classes_.size(); ++i) {
    if (classes_[i].name == name) return static_cast<int>(i);
  }
  return std::nullopt;
}

std::vector<XMLElement*> DefaultTree::AllElementDefaults(const char* tag) const {
  std::vector<XMLElement*> out;
  for (const Class& c : classes_) {
    for (XMLElement* s : c.sections) {
      for (XMLElement* e = s->FirstChildElement(tag); e; e = e->NextSiblingElement(tag)) {
        out.push_back(e);
      }
    }
  }
  return out;
}

const char* DefaultTree::Lookup(int cls, const char* tag, const char* attr) const {
  for (int c = cls; c >= 0; c = classes_[c].parent) {
    const auto& sections = classes_[c].sections;
    for (auto s = sections.rbegin(); s != sections.rend(); ++s) {
      // the last element default of this tag in the section wins
      const char* found = nullptr;
      for (XMLElement* e = (*s)->FirstChildElement(tag); e; e = e->NextSiblingElement(tag)) {
        if (const char* v = e->Attribute(attr)) found = v;
      }
      if (found) return found;
    }
  }
  return nullptr;
}

bool DefaultTree::DefaultActuatorHasDynamics(int cls) const {
  for (int c = cls; c >= 0; c = classes_[c].parent) {
    const auto& sections = classes_[c].sections;
    for (auto s = sections.rbegin(); s != sections.rend(); ++s) {
      // walk this section's actuator defaults backwards: the last one that sets dyntype wins
      std::vector<XMLElement*> acts;
      for (XMLElement* e = (*s)->FirstChildElement(); e; e = e->NextSiblingElement()) {
        if (IsActuatorTag(e->Name())) acts.push_back(e);
      }
      for (auto a = acts.rbegin(); a != acts.rend(); ++a) {
        const std::string tag = (*a)->Name();
        if (tag == "general") {
          if (const char* d = (*a)->Attribute("dyntype")) return std::string(d) != "none";
          continue;
        }
        return tag == "intvelocity" || tag == "cylinder" || tag == "muscle";
      }
    }
  }
  return false;
}

int DefaultTree::ClassOf(const XMLElement* elem, bool in_worldbody, const MjcfSource& src) const {
  const auto resolve = [&](const XMLElement* e, const char* attr) {
    const char* name = e->Attribute(attr);
    const auto id = Find(name);
    if (!id) {
      src.Fail(e, std::string(e->Name()) + "." + attr,
               std::string("unknown default class '") + name +
                   "'; expected a class defined in this model's <default>");
    }
    return *id;
  };
  if (elem->Attribute("class")) return resolve(elem, "class");
  if (in_worldbody) {
    for (const tinyxml2::XMLNode* n = elem->Parent(); n; n = n->Parent()) {
      const XMLElement* p = n->ToElement();
      if (p == nullptr || IsTag(p, "worldbody")) break;
      if (IsTag(p, "body") && p->Attribute("childclass")) return resolve(p, "childclass");
    }
  }
  return kRoot;
}

}  // namespace penumbra::compose

#include "penumbra/compose/mjcf_autolimits.h"

#include <functional>

#include "penumbra/compose/mjcf_defaults.h"
#include "penumbra/compose/mjcf_schema.h"

namespace penumbra::compose {
namespace {

using tinyxml2::XMLElement;

bool Is(const XMLElement* e, const char* name) { return std::string(e->Name()) == name; }

// an element's name for the warning: its name, else "<tag> (line N)"
std::string Label(const MjcfSource& src, const XMLElement* e) {
  if (const char* n = e->Attribute("name"); n && *n) return n;
  return std::string("<") + e->Name() + "> (line " + std::to_string(src.Where(e).line) + ")";
}

std::string Listing(const char* kind, const std::vector<std::string>& names) {
  std::string s = std::to_string(names.size()) + " " + kind + " (";
  for (size_t i = 0; i < names.size() && i < 8; ++i) s += (i ? ", " : "") + names[i];
  if (names.size() > 8) s += ", ...";
  return s + ")";
}

class Resolver {
 public:
  explicit Resolver(const MjcfSource& src) : src_(src), tree_(DefaultTree::Build(src)) {}

  // true when `range` is set on `e` (or its defaults) and `limited` is not ("auto" = unset).
  // `default_tag`: the element default that applies ("joint", "tendon"), nullptr for an
  // actuator (any actuator default)
  bool NeedsLimit(const XMLElement* e, bool in_worldbody, const char* default_tag,
                  const char* range, const char* limited) const {
    const int cls = tree_.ClassOf(e, in_worldbody, src_);
    const char* r = Value(e, cls, default_tag, range);
    if (r == nullptr) return false;
    const char* l = Value(e, cls, default_tag, limited);
    return l == nullptr || std::string(l) == "auto";
  }

 private:
  const char* Value(const XMLElement* e, int cls, const char* default_tag, const char* attr) const {
    if (const char* v = e->Attribute(attr)) return v;
    return default_tag ? tree_.Lookup(cls, default_tag, attr) : ActuatorDefault(cls, attr);
  }
  // the actuator defaults of all actuator tags share one slot per class: the last written wins
  const char* ActuatorDefault(int cls, const char* attr) const {
    for (int c = cls; c >= 0; c = tree_.Parent(c)) {
      const char* found = nullptr;
      for (const XMLElement* s : tree_.Sections(c))
        for (const XMLElement* d = s->FirstChildElement(); d; d = d->NextSiblingElement())
          if (IsActuatorTag(d->Name()))
            if (const char* v = d->Attribute(attr)) found = v;
      if (found) return found;
    }
    return nullptr;
  }

  const MjcfSource& src_;
  DefaultTree tree_;
};

}  // namespace

AutolimitsChange ApplyMujoco3Autolimits(const MjcfSource& src, std::vector<std::string>* warnings) {
  AutolimitsChange change;
  XMLElement* root = src.root();
  if (root == nullptr || src.from_urdf()) return change;
  for (const XMLElement* c = root->FirstChildElement("compiler"); c;
       c = c->NextSiblingElement("compiler"))
    if (c->Attribute("autolimits")) return change;
  const Resolver resolver(src);
  const auto limit = [&](XMLElement* e, bool in_worldbody, const char* default_tag,
                         const char* range, const char* limited, std::vector<std::string>* names) {
    if (!resolver.NeedsLimit(e, in_worldbody, default_tag, range, limited)) return;
    e->SetAttribute(limited, "true");
    names->push_back(Label(src, e));
  };
  const std::function<void(XMLElement*)> walk = [&](XMLElement* parent) {
    for (XMLElement* e = parent->FirstChildElement(); e; e = e->NextSiblingElement()) {
      if (Is(e, "joint")) limit(e, true, "joint", "range", "limited", &change.joints);
      if (Is(e, "body")) walk(e);
    }
  };
  for (XMLElement* wb = root->FirstChildElement("worldbody"); wb;
       wb = wb->NextSiblingElement("worldbody"))
    walk(wb);
  for (XMLElement* sec = root->FirstChildElement("tendon"); sec;
       sec = sec->NextSiblingElement("tendon"))
    for (XMLElement* t = sec->FirstChildElement(); t; t = t->NextSiblingElement())
      if (Is(t, "spatial") || Is(t, "fixed"))
        limit(t, false, "tendon", "range", "limited", &change.tendons);
  for (XMLElement* sec = root->FirstChildElement("actuator"); sec;
       sec = sec->NextSiblingElement("actuator")) {
    for (XMLElement* a = sec->FirstChildElement(); a; a = a->NextSiblingElement()) {
      if (!IsActuatorTag(a->Name())) continue;
      // MuJoCo 2.2.2's schema: <adhesion> and <damper> are always ctrl-limited and have no
      // ctrllimited; only <general> has actlimited (checked with mujoco-compile)
      if (!Is(a, "adhesion") && !Is(a, "damper"))
        limit(a, false, nullptr, "ctrlrange", "ctrllimited", &change.actuator_ctrl);
      limit(a, false, nullptr, "forcerange", "forcelimited", &change.actuator_force);
      if (Is(a, "general"))
        limit(a, false, nullptr, "actrange", "actlimited", &change.actuator_act);
    }
  }
  if (change.total() == 0) return change;
  std::string parts;
  const auto add = [&](const char* kind, const std::vector<std::string>& names) {
    if (!names.empty()) parts += (parts.empty() ? "" : ", ") + Listing(kind, names);
  };
  add("joints: limited", change.joints);
  add("tendons: limited", change.tendons);
  add("actuators: ctrllimited", change.actuator_ctrl);
  add("actuators: forcelimited", change.actuator_force);
  add("actuators: actlimited", change.actuator_act);
  warnings->push_back(src.file() +
                      ": <compiler> does not set autolimits, which MuJoCo 3 turns on by default "
                      "and MuJoCo 2.2.2 off; as MuJoCo 3 would, set \"true\" where a range is "
                      "given without its limited attribute: " +
                      parts);
  return change;
}

}  // namespace penumbra::compose

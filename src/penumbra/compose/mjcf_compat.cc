#include "penumbra/compose/mjcf_compat.h"

#include <regex>

#include "penumbra/core/error.h"

namespace penumbra::compose {
namespace {

using tinyxml2::XMLElement;

enum class Action {
  kReplaceValue,  // value `value` becomes `replacement`
  kDrop,          // the attribute is removed
  kReject,        // ConfigError with `text`
  kLightType,     // <light type="directional|spot"> becomes directional="true|false"
};

// one MuJoCo-3 keyword: attribute `attr` of element `tag` (with value `value` when not
// null). every entry was checked to fail mj_loadXML in MuJoCo 2.2.2.
struct Rule {
  const char* tag;
  const char* attr;
  const char* value;
  Action action;
  const char* replacement;
  const char* text;  // why it is safe (drop/replace) or what to write instead (reject)
};

const std::vector<Rule>& Rules() {
  static const std::vector<Rule> rules = {
      {"option", "integrator", "implicitfast", Action::kReplaceValue, "implicit",
       "'implicit' is the same implicit-in-velocity integrator with the Coriolis terms "
       "kept (a little slower, at least as stable)"},
      {"option", "ls_iterations", nullptr, Action::kDrop, nullptr,
       "MuJoCo 2.2.2's line search has fixed settings"},
      {"option", "ls_tolerance", nullptr, Action::kDrop, nullptr,
       "MuJoCo 2.2.2's line search has fixed settings"},
      {"option", "ccd_iterations", nullptr, Action::kDrop, nullptr,
       "MuJoCo 2.2.2's convex collision uses its mpr_iterations"},
      {"option", "ccd_tolerance", nullptr, Action::kDrop, nullptr,
       "MuJoCo 2.2.2's convex collision uses its mpr_tolerance"},
      {"option", "sdf_iterations", nullptr, Action::kDrop, nullptr,
       "MuJoCo 2.2.2 has no SDF collision"},
      {"option", "sdf_initpoints", nullptr, Action::kDrop, nullptr,
       "MuJoCo 2.2.2 has no SDF collision"},
      {"flag", "eulerdamp", nullptr, Action::kDrop, nullptr,
       "MuJoCo 2.2.2's Euler integrator always integrates joint damping implicitly"},
      {"flag", "nativeccd", nullptr, Action::kDrop, nullptr,
       "MuJoCo 2.2.2 has only its own MPR convex collision"},
      {"flag", "island", nullptr, Action::kDrop, nullptr,
       "constraint islands only speed up the solver"},
      {"flag", "midphase", nullptr, Action::kDrop, nullptr,
       "the BVH midphase only speeds up collision detection"},
      {"flag", "autoreset", nullptr, Action::kDrop, nullptr,
       "MuJoCo 2.2.2 never resets on bad numbers; Penumbra stops with an error instead"},
      {"global", "ellipsoidinertia", nullptr, Action::kDrop, nullptr,
       "it only changes how MuJoCo's viewer draws inertia"},
      {"global", "bvactive", nullptr, Action::kDrop, nullptr, "it only changes MuJoCo's viewer"},
      {"global", "cameraid", nullptr, Action::kDrop, nullptr,
       "it only picks MuJoCo's viewer camera"},
      {"global", "realtime", nullptr, Action::kDrop, nullptr, "it only sets MuJoCo's viewer speed"},
      {"rgba", "bv", nullptr, Action::kDrop, nullptr, "it only colours MuJoCo's viewer"},
      {"rgba", "bvactive", nullptr, Action::kDrop, nullptr, "it only colours MuJoCo's viewer"},
      {"rgba", "frustum", nullptr, Action::kDrop, nullptr, "it only colours MuJoCo's viewer"},
      {"scale", "frustum", nullptr, Action::kDrop, nullptr, "it only scales MuJoCo's viewer"},
      {"compiler", "alignfree", nullptr, Action::kDrop, nullptr,
       "the free bodies keep the frames their author wrote (the physics is the same)"},
      {"compiler", "saveinertial", nullptr, Action::kDrop, nullptr,
       "it only changes MuJoCo's saved XML"},
      {"mesh", "maxhullvert", nullptr, Action::kDrop, nullptr,
       "MuJoCo 2.2.2 uses the full convex hull for collisions"},
      {"mesh", "inertia", "legacy", Action::kDrop, nullptr,
       "'legacy' is MuJoCo 2.2.2's own mesh inertia"},
      {"mesh", "inertia", nullptr, Action::kReject, nullptr,
       "MuJoCo 2.2.2 computes mesh inertia from the volume; remove it (or for 'shell' set "
       "shellinertia=\"true\" on the geoms that use the mesh)"},
      {"light", "type", nullptr, Action::kLightType, nullptr, ""},
      {"position", "kv", nullptr, Action::kReject, nullptr,
       "write <general gaintype=\"fixed\" gainprm=\"KP\" biastype=\"affine\" "
       "biasprm=\"0 -KP -KV\"> with the same joint, ctrlrange and forcerange"},
      {"position", "dampratio", nullptr, Action::kReject, nullptr,
       "give the damping gain instead: <general gaintype=\"fixed\" gainprm=\"KP\" "
       "biastype=\"affine\" biasprm=\"0 -KP -KV\"> with KV = 2 dampratio sqrt(KP I), I the "
       "joint's effective inertia (kg m^2)"},
      {"position", "inheritrange", nullptr, Action::kReject, nullptr,
       "set ctrlrange to the joint's range (times inheritrange, about its centre)"},
      {"intvelocity", "inheritrange", nullptr, Action::kReject, nullptr,
       "set actrange to the joint's range (times inheritrange, about its centre)"},
      {"body", "gravcomp", nullptr, Action::kReject, nullptr,
       "remove it (MuJoCo 2.2.2 has no gravity compensation; a controller with gravity "
       "compensation, e.g. diff_ik, provides it)"},
      {"joint", "actuatorfrcrange", nullptr, Action::kReject, nullptr,
       "limit the joint's actuators instead (their forcerange, forcelimited=\"true\")"},
      {"joint", "actuatorfrclimited", nullptr, Action::kReject, nullptr,
       "limit the joint's actuators instead (their forcerange, forcelimited=\"true\")"},
      {"joint", "actuatorgravcomp", nullptr, Action::kReject, nullptr,
       "remove it (MuJoCo 2.2.2 has no gravity compensation)"},
  };
  return rules;
}

struct ElementHint {
  const char* tag;
  const char* text;
};

const std::vector<ElementHint>& ElementHints() {
  static const std::vector<ElementHint> hints = {
      {"frame", "move its pos/quat into its children (a body, geom or site each)"},
      {"replicate", "write the repeated elements out"},
      {"flexcomp", "MuJoCo 2.2.2 has no flex objects; use <composite>"},
      {"flex", "MuJoCo 2.2.2 has no flex objects; use <composite>"},
      {"deformable", "MuJoCo 2.2.2 has no flex objects; use <composite>"},
      {"plugin", "MuJoCo 2.2.2 has no engine plugins"},
      {"extension", "MuJoCo 2.2.2 has no engine plugins"},
      {"attach", "copy the attached model's bodies into this one"},
      {"layer", "give the <material> a single texture"},
  };
  return hints;
}

std::string Where(const Origin& o) { return o.file + ":" + std::to_string(o.line); }

// a keyword without a faithful 2.2.2 form: reported all together after the walk
struct Rejection {
  const XMLElement* element;
  std::string key, problem;
};

void Visit(const MjcfSource& src, XMLElement* e, std::vector<std::string>* warnings,
           std::vector<Rejection>* rejections) {
  const std::string tag = e->Name();
  for (const Rule& r : Rules()) {
    if (tag != r.tag) continue;
    const char* v = e->Attribute(r.attr);
    if (v == nullptr || (r.value != nullptr && std::string(v) != r.value)) continue;
    const std::string what = std::string("<") + r.tag + " " + r.attr + "=\"" + v + "\">";
    const std::string key = std::string(r.tag) + "." + r.attr;
    switch (r.action) {
      case Action::kReplaceValue:
        warnings->push_back(Where(src.Where(e)) + ": " + what +
                            " is newer than MuJoCo 2.2.2; using \"" + r.replacement +
                            "\": " + r.text);
        e->SetAttribute(r.attr, r.replacement);
        break;
      case Action::kDrop:
        warnings->push_back(Where(src.Where(e)) + ": " + what +
                            " is newer than MuJoCo 2.2.2; ignored: " + r.text);
        e->DeleteAttribute(r.attr);
        break;
      case Action::kReject:
        rejections->push_back({e, key,
                               std::string("'") + r.attr +
                                   "' is newer than MuJoCo 2.2.2 (Penumbra's physics); " + r.text});
        break;
      case Action::kLightType: {
        const std::string type = v;
        if (type != "directional" && type != "spot") {
          rejections->push_back(
              {e, key,
               "light type '" + type +
                   "' is newer than MuJoCo 2.2.2, which has spot and directional lights; "
                   "expected type=\"spot\" or \"directional\" (2.2.2: directional=\"false\" "
                   "or \"true\")"});
          break;
        }
        const char* directional = type == "directional" ? "true" : "false";
        warnings->push_back(Where(src.Where(e)) + ": " + what +
                            " is newer than MuJoCo 2.2.2; using directional=\"" + directional +
                            "\"");
        e->DeleteAttribute("type");
        e->SetAttribute("directional", directional);
        break;
      }
    }
  }
  for (XMLElement* c = e->FirstChildElement(); c; c = c->NextSiblingElement()) {
    Visit(src, c, warnings, rejections);
  }
}

}  // namespace

void DowngradeMjcf3(const MjcfSource& src, std::vector<std::string>* warnings) {
  if (src.root() == nullptr) return;
  std::vector<Rejection> rejections;
  Visit(src, src.root(), warnings, &rejections);
  if (rejections.empty()) return;
  // all of them in one error: the first names the file, line and key; the others follow
  std::string problem = rejections[0].problem;
  if (rejections.size() > 1) {
    problem = "(1 of " + std::to_string(rejections.size()) +
              " keywords newer than MuJoCo 2.2.2 in this model) " + problem;
    for (size_t i = 1; i < rejections.size(); ++i) {
      const Rejection& r = rejections[i];
      // the other ones by place and keyword (the first's advice applies to its repeats)
      problem += "; (" + std::to_string(i + 1) + ") " + Where(src.Where(r.element)) + ": " + r.key +
                 (r.key == rejections[0].key ? "" : ": " + r.problem);
    }
  }
  src.Fail(rejections[0].element, rejections[0].key, problem);
}

std::optional<std::string> NewerElementHint(const std::string& tag) {
  for (const ElementHint& h : ElementHints()) {
    if (tag == h.tag) {
      return "<" + tag + "> is newer than MuJoCo 2.2.2 (Penumbra's physics); " + h.text;
    }
  }
  return std::nullopt;
}

std::optional<std::string> HintForMujocoError(const std::string& message) {
  static const std::regex attr_re("unrecognized attribute: '([^']*)'");
  static const std::regex keyword_re("invalid keyword: '([^']*)'");
  static const std::regex element_re(
      "Schema violation: unrecognized element[^']*Element '([^']*)'");
  std::smatch m;
  if (std::regex_search(message, m, attr_re)) {
    const std::string attr = m[1].str();
    for (const Rule& r : Rules()) {
      if (attr == r.attr && r.action == Action::kReject) {
        return "'" + attr + "' is newer than MuJoCo 2.2.2 (Penumbra's physics); " + r.text;
      }
    }
    return "'" + attr +
           "' is not an attribute of this element in MuJoCo 2.2.2 (Penumbra's physics); it may "
           "come from a newer MuJoCo: remove it or use its MuJoCo 2.2.2 equivalent";
  }
  if (std::regex_search(message, m, keyword_re)) {
    const std::string word = m[1].str();
    for (const Rule& r : Rules()) {
      if (r.value != nullptr && word == r.value && r.action == Action::kReplaceValue) {
        return "'" + word + "' is newer than MuJoCo 2.2.2; use '" + r.replacement + "'";
      }
    }
    return "'" + word +
           "' is not a MuJoCo 2.2.2 keyword here (it may come from a newer MuJoCo); see the "
           "MuJoCo 2.2.2 XML reference for the values this attribute takes";
  }
  if (std::regex_search(message, m, element_re)) {
    if (auto hint = NewerElementHint(m[1].str())) return hint;
  }
  return std::nullopt;
}

}  // namespace penumbra::compose

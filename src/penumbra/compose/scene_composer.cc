#include "penumbra/compose/scene_composer.h"

#include <tinyxml2.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <functional>
#include <memory>
#include <string_view>

#include "penumbra/compose/mjcf_compat.h"
#include "penumbra/compose/mjcf_text.h"
#include "penumbra/compose/model_composer.h"
#include "penumbra/compose/world_sites.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/scene/scene_limits.h"

namespace penumbra {
namespace {

using compose::AttrList;
using compose::FindAttr;
using compose::FormatNumbers;
using compose::ModelComposer;
using compose::ParseNumbers;
using compose::SetAttr;
using tinyxml2::XMLDocument;
using tinyxml2::XMLElement;

using Models = std::vector<std::unique_ptr<ModelComposer>>;
using Sources = std::unordered_map<const XMLElement*, SourceLocation>;

// records where `copy` (and its subtree) came from: `original` of model `m`, same shape
void Record(const ModelComposer& m, const XMLElement* original, const XMLElement* copy,
            Sources* sources) {
  const compose::Origin o = m.source().Where(original);
  if (o.line > 0) (*sources)[copy] = {o.file, o.line};
  const XMLElement* a = original->FirstChildElement();
  const XMLElement* b = copy->FirstChildElement();
  for (; a && b; a = a->NextSiblingElement(), b = b->NextSiblingElement()) {
    Record(m, a, b, sources);
  }
}

// calls f(a, b) for the elements of two documents of the same shape, in document order
void WalkPair(const tinyxml2::XMLNode* a, const tinyxml2::XMLNode* b,
              const std::function<void(const XMLElement*, const XMLElement*)>& f) {
  const XMLElement* x = a->FirstChildElement();
  const XMLElement* y = b->FirstChildElement();
  for (; x && y; x = x->NextSiblingElement(), y = y->NextSiblingElement()) {
    f(x, y);
    WalkPair(x, y, f);
  }
}

// the source map of `from` (elements of `from_doc`) for the deep copy `to_doc`
Sources CopySources(const Sources& from, const XMLDocument& from_doc, const XMLDocument& to_doc) {
  Sources out;
  if (from.empty()) return out;
  WalkPair(&from_doc, &to_doc, [&](const XMLElement* a, const XMLElement* b) {
    const auto it = from.find(a);
    if (it != from.end()) out[b] = it->second;
  });
  return out;
}

// MuJoCo 2.2.2 defaults of the compiler attributes the composer carries over
const AttrList& CompilerDefaults() {
  static const AttrList defaults = {
      {"autolimits", "false"},      {"boundmass", "0"},          {"boundinertia", "0"},
      {"settotalmass", "-1"},       {"balanceinertia", "false"}, {"fitaabb", "false"},
      {"discardvisual", "false"},   {"convexhull", "true"},      {"usethread", "true"},
      {"fusestatic", "false"},      {"inertiafromgeom", "auto"}, {"inertiagrouprange", "0 5"},
      {"exactmeshinertia", "false"}};
  return defaults;
}

// MuJoCo 2.2.2 default sizes (measured: mj_loadXML of a model without <size>)
constexpr int kDefaultNjmax = 500;
constexpr int kDefaultNconmax = 100;

// equal as numbers when both read as numbers, else as text
bool SameValue(const std::string& a, const std::string& b) {
  const auto na = ParseNumbers(a);
  const auto nb = ParseNumbers(b);
  if (na && nb && !na->empty()) return *na == *nb;
  return a == b;
}

AttrList Attributes(const XMLElement* e) {
  AttrList out;
  for (const tinyxml2::XMLAttribute* a = e->FirstAttribute(); a; a = a->Next()) {
    SetAttr(&out, a->Name(), a->Value());
  }
  return out;
}

void ApplyAttrs(XMLElement* e, const AttrList& attrs) {
  for (const auto& [n, v] : attrs) e->SetAttribute(n.c_str(), v.c_str());
}

std::string ModelLabel(const ModelComposer& m) {
  return "model '" + m.config().name + "' (" + m.source().file() + ")";
}

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

// one composed <compiler>: angle radian, every carried attribute agreed or reconciled
struct ComposedCompiler {
  AttrList attrs;
  AttrList lengthrange;
  std::vector<bool> strip_inertials;
};

ComposedCompiler ReconcileCompilers(const Models& models, std::vector<std::string>* warnings) {
  ComposedCompiler out;
  out.strip_inertials.assign(models.size(), false);
  const auto value_of = [&](const ModelComposer& m, const std::string& attr) {
    const std::string* v = FindAttr(m.compiler().other, attr);
    return v ? *v : *FindAttr(CompilerDefaults(), attr);
  };
  const auto explicit_anywhere = [&](const std::string& attr) {
    for (const auto& m : models) {
      if (FindAttr(m->compiler().other, attr)) return true;
    }
    return false;
  };
  const auto fail = [&](const ModelComposer& m, const std::string& attr,
                        const std::string& problem) {
    const compose::Origin o = m.source().Where(m.compiler().first);
    throw ConfigError(o.file, o.line, "compiler." + attr, problem);
  };
  for (const auto& [attr, def] : CompilerDefaults()) {
    if (!explicit_anywhere(attr)) continue;
    const std::string first = value_of(*models[0], attr);
    if (attr == "autolimits") {
      // a model valid without autolimits compiles identically with it
      bool any = false;
      for (const auto& m : models) any = any || value_of(*m, attr) == "true";
      SetAttr(&out.attrs, attr, any ? "true" : "false");
    } else if (attr == "usethread") {
      SetAttr(&out.attrs, attr, first);
    } else if (attr == "settotalmass") {
      for (const auto& m : models) {
        if (models.size() > 1 && !SameValue(value_of(*m, attr), "-1")) {
          fail(*m, attr,
               "settotalmass rescales the whole composed world; expected it unset when "
               "composing several models");
        }
      }
      SetAttr(&out.attrs, attr, first);
    } else if (attr == "inertiafromgeom") {
      bool any_true = false, any_auto = false;
      for (const auto& m : models) {
        const std::string v = value_of(*m, attr);
        any_true = any_true || v == "true";
        any_auto = any_auto || v == "auto";
        if (v == "false" && !SameValue(v, first)) {
          fail(*m, attr,
               "'false' differs from '" + first + "' of " + ModelLabel(*models[0]) +
                   "; expected all models to agree (true and auto can be combined)");
        }
      }
      if (any_true && any_auto) {
        // "true" ignores <inertial>: drop them and compose as "auto"
        for (size_t i = 0; i < models.size(); ++i) {
          out.strip_inertials[i] = value_of(*models[i], attr) == "true";
        }
        SetAttr(&out.attrs, attr, "auto");
      } else {
        for (const auto& m : models) {
          if (!SameValue(value_of(*m, attr), first)) {
            fail(*m, attr,
                 "'" + value_of(*m, attr) + "' differs from '" + first + "' of " +
                     ModelLabel(*models[0]) + "; expected all models to agree");
          }
        }
        SetAttr(&out.attrs, attr, first);
      }
    } else {
      for (const auto& m : models) {
        if (!SameValue(value_of(*m, attr), first)) {
          fail(*m, attr,
               "'" + value_of(*m, attr) + "' differs from '" + first + "' of " +
                   ModelLabel(*models[0]) +
                   "; expected all composed models to agree on this compiler setting");
        }
      }
      SetAttr(&out.attrs, attr, first);
    }
  }
  for (const auto& m : models) {
    if (m->compiler().lengthrange.empty()) continue;
    if (out.lengthrange.empty()) {
      out.lengthrange = m->compiler().lengthrange;
    } else if (m->compiler().lengthrange != out.lengthrange) {
      warnings->push_back(ModelLabel(*m) +
                          ": <compiler><lengthrange> differs from an earlier model's; using the "
                          "earlier one");
    }
  }
  return out;
}

// merged attributes of every `section` element of a model, plus those of one child tag
AttrList MergedAttrs(const ModelComposer& m, const std::string& section) {
  AttrList out;
  for (XMLElement* s : m.Sections(section)) {
    for (const auto& [n, v] : Attributes(s)) SetAttr(&out, n, v);
  }
  return out;
}

// the model's <option timestep> (the last one set, as MuJoCo reads them) against
// kMinTimestepSec..kMaxTimestepSec, with its file and line.
void CheckModelTimestep(const ModelComposer& m) {
  XMLElement* where = nullptr;
  for (XMLElement* s : m.Sections("option"))
    if (s->Attribute("timestep")) where = s;
  if (where == nullptr) return;
  const std::string text = where->Attribute("timestep");
  const auto v = ParseNumbers(text);
  if (v && v->size() == 1 && (*v)[0] >= kMinTimestepSec && (*v)[0] <= kMaxTimestepSec) return;
  m.source().Fail(where, "option.timestep",
                  "'" + text + "' is not a usable physics timestep; expected seconds in [" +
                      FormatNumbers({kMinTimestepSec}) + ", " + FormatNumbers({kMaxTimestepSec}) +
                      "] (or set physics.timestep_sec in a world file, which overrides it)");
}

void ComposeOption(const Models& models, const ComposeOptions& options, XMLElement* root,
                   Sources* sources, std::vector<std::string>* warnings) {
  // the world file's physics options, as <option> attributes
  AttrList overrides;
  if (options.timestep_sec) SetAttr(&overrides, "timestep", FormatNumbers({*options.timestep_sec}));
  const PhysicsOptions& p = options.physics;
  if (p.integrator) SetAttr(&overrides, "integrator", *p.integrator);
  if (p.gravity_mps2) {
    SetAttr(&overrides, "gravity",
            FormatNumbers({p.gravity_mps2->x(), p.gravity_mps2->y(), p.gravity_mps2->z()}));
  }
  if (p.solver_iterations) SetAttr(&overrides, "iterations", std::to_string(*p.solver_iterations));
  if (p.cone) SetAttr(&overrides, "cone", *p.cone);
  // the first model that has an <option> decides; later explicit values that differ warn
  AttrList attrs, flags;
  const ModelComposer* owner = nullptr;
  for (const auto& m : models) {
    AttrList a = MergedAttrs(*m, "option");
    AttrList f;
    for (XMLElement* s : m->Sections("option")) {
      for (XMLElement* c = s->FirstChildElement(); c; c = c->NextSiblingElement()) {
        if (std::string(c->Name()) != "flag") {
          m->source().Fail(c, std::string("option.") + c->Name(),
                           "unsupported element; expected <flag>");
        }
        for (const auto& [n, v] : Attributes(c)) SetAttr(&f, n, v);
      }
    }
    if (a.empty() && f.empty()) continue;
    if (owner == nullptr) {
      owner = m.get();
      attrs = a;
      flags = f;
      continue;
    }
    // the differing attributes the world file does not decide
    std::vector<std::string> names;
    const auto differs = [&](const AttrList& mine, const AttrList& used, const char* prefix) {
      for (const auto& [n, v] : mine) {
        const std::string* u = FindAttr(used, n);
        const bool decided = std::any_of(overrides.begin(), overrides.end(),
                                         [&](const auto& o) { return o.first == n; });
        if (!decided && (u == nullptr || !SameValue(*u, v))) names.push_back(prefix + n);
      }
    };
    differs(a, attrs, "");
    differs(f, flags, "flag ");
    if (!names.empty()) {
      std::string list;
      for (const std::string& n : names) list += (list.empty() ? "" : ", ") + n;
      warnings->push_back(ModelLabel(*m) + ": its <option> differs from " + ModelLabel(*owner) +
                          "'s (" + list +
                          "); the composed world uses the latter. the world file's physics "
                          "section decides timestep_sec, integrator, gravity_mps2, "
                          "solver_iterations and cone (docs/world-file.md)");
    }
  }
  // the world file's physics.timestep_sec wins; else the deciding model's own timestep must be
  // in the range that the world file's is held to (scene/scene_limits.h)
  if (owner != nullptr && !options.timestep_sec) CheckModelTimestep(*owner);
  for (const auto& [n, v] : overrides) SetAttr(&attrs, n, v);
  if (attrs.empty() && flags.empty()) return;
  XMLElement* opt = root->InsertNewChildElement("option");
  ApplyAttrs(opt, attrs);
  if (owner != nullptr) {
    const compose::Origin o = owner->source().Where(owner->Sections("option").front());
    if (o.line > 0) (*sources)[opt] = {o.file, o.line};
  }
  if (!flags.empty()) ApplyAttrs(opt->InsertNewChildElement("flag"), flags);
}

int SizeValue(const ModelComposer& m, const AttrList& size, const std::string& name, int fallback) {
  const std::string* v = FindAttr(size, name);
  if (v == nullptr) return fallback;
  const auto n = ParseNumbers(*v);
  if (!n || n->size() != 1 || std::floor((*n)[0]) != (*n)[0]) {
    XMLElement* s = m.Sections("size").back();
    m.source().Fail(s, "size." + name, "'" + *v + "' is not valid; expected an integer");
  }
  return static_cast<int>((*n)[0]);
}

void ComposeSize(const Models& models, int composed_keys, XMLElement* root) {
  AttrList out;
  long long njmax = 0, nconmax = 0, nstack = 0;
  int nuserdata = 0, nkey = 0;
  bool any_stack = false, any_userdata = false, any_nkey = false;
  std::vector<AttrList> sizes;
  for (const auto& m : models) sizes.push_back(MergedAttrs(*m, "size"));
  for (size_t i = 0; i < models.size(); ++i) {
    const ModelComposer& m = *models[i];
    const AttrList& s = sizes[i];
    const int nj = SizeValue(m, s, "njmax", kDefaultNjmax);
    const int nc = SizeValue(m, s, "nconmax", kDefaultNconmax);
    njmax += nj > 0 ? nj : kDefaultNjmax;
    nconmax += nc > 0 ? nc : kDefaultNconmax;
    // stack: each model's explicit size, or an estimate of MuJoCo 2.2.2's automatic size
    // for it (about 5 njmax^2 + 10 nv njmax, measured on the humanoid sample)
    const int ns = SizeValue(m, s, "nstack", -1);
    const long long nj_eff = nj > 0 ? nj : kDefaultNjmax;
    if (ns > 0) {
      any_stack = true;
      nstack += ns;
    } else {
      nstack += 5 * nj_eff * nj_eff + 10 * static_cast<long long>(m.sizes().nv) * nj_eff + 10000;
    }
    if (FindAttr(s, "nuserdata")) {
      any_userdata = true;
      nuserdata = std::max(nuserdata, SizeValue(m, s, "nuserdata", 0));
    }
    if (FindAttr(s, "nkey")) {
      any_nkey = true;
      nkey += SizeValue(m, s, "nkey", 0);
    }
  }
  const bool several = models.size() > 1;
  const bool any_nj = std::any_of(sizes.begin(), sizes.end(),
                                  [](const AttrList& s) { return FindAttr(s, "njmax"); });
  const bool any_nc = std::any_of(sizes.begin(), sizes.end(),
                                  [](const AttrList& s) { return FindAttr(s, "nconmax"); });
  // constraint and contact buffers: the worlds' needs add up
  if (several || any_nj) SetAttr(&out, "njmax", std::to_string(njmax));
  if (several || any_nc) SetAttr(&out, "nconmax", std::to_string(nconmax));
  // all automatic: MuJoCo sizes the composed stack itself; else the sum of the parts
  if (any_stack) SetAttr(&out, "nstack", std::to_string(nstack));
  if (any_userdata) SetAttr(&out, "nuserdata", std::to_string(nuserdata));
  if (any_nkey) SetAttr(&out, "nkey", std::to_string(std::max(nkey, composed_keys)));
  // user data lengths: each model's explicit size or its longest user= (MuJoCo's -1)
  for (const char* kind : {"body", "jnt", "geom", "site", "cam", "tendon", "actuator", "sensor"}) {
    const std::string attr = std::string("nuser_") + kind;
    int n = 0;
    bool any = false;
    for (size_t i = 0; i < models.size(); ++i) {
      const int v = SizeValue(*models[i], sizes[i], attr, -1);
      any = any || FindAttr(sizes[i], attr);
      n = std::max(n, v >= 0 ? v : models[i]->MaxUserLength(kind));
    }
    if (any || (several && n > 0)) SetAttr(&out, attr, std::to_string(n));
  }
  if (!out.empty()) ApplyAttrs(root->InsertNewChildElement("size"), out);
}

// the first model that has a <visual> decides (sub-elements merged over its sections)
void ComposeVisual(const Models& models, XMLElement* root) {
  for (const auto& m : models) {
    const auto sections = m->Sections("visual");
    if (sections.empty()) continue;
    XMLElement* vis = root->InsertNewChildElement("visual");
    for (XMLElement* s : sections) {
      for (XMLElement* c = s->FirstChildElement(); c; c = c->NextSiblingElement()) {
        XMLElement* target = vis->FirstChildElement(c->Name());
        if (target == nullptr) target = vis->InsertNewChildElement(c->Name());
        ApplyAttrs(target, Attributes(c));
      }
    }
    return;
  }
}

void ComposeStatistic(const Models& models, XMLElement* root, std::vector<std::string>* warnings) {
  const ModelComposer* owner = nullptr;
  AttrList used;
  for (const auto& m : models) {
    AttrList a = MergedAttrs(*m, "statistic");
    if (a.empty()) continue;
    if (owner == nullptr) {
      owner = m.get();
      used = a;
      continue;
    }
    for (const auto& [n, v] : a) {
      const std::string* u = FindAttr(used, n);
      if (u == nullptr || !SameValue(*u, v)) {
        warnings->push_back(ModelLabel(*m) + ": its <statistic> differs from " +
                            ModelLabel(*owner) + "'s; the composed world uses the latter");
        break;
      }
    }
  }
  if (owner) ApplyAttrs(root->InsertNewChildElement("statistic"), used);
}

void ComposeDefaults(const Models& models, XMLDocument* doc, XMLElement* root, Sources* sources) {
  XMLElement* top = nullptr;
  for (const auto& m : models) {
    if (!top) top = root->InsertNewChildElement("default");
    XMLElement* cls = top->InsertNewChildElement("default");
    cls->SetAttribute("class", m->RootClassName().c_str());
    for (XMLElement* s : m->defaults().root_sections()) {
      for (XMLElement* c = s->FirstChildElement(); c; c = c->NextSiblingElement()) {
        if (std::string(c->Name()) == "default") {
          Record(*m, c, cls->InsertEndChild(c->DeepClone(doc))->ToElement(), sources);
          continue;
        }
        // several top-level <default> sections all write into the root class
        XMLElement* same = nullptr;
        for (XMLElement* e = cls->FirstChildElement(c->Name()); e;
             e = e->NextSiblingElement(c->Name())) {
          same = e;
        }
        if (same) {
          ApplyAttrs(same, Attributes(c));
        } else {
          Record(*m, c, cls->InsertEndChild(c->DeepClone(doc))->ToElement(), sources);
        }
      }
    }
  }
}

// appends the children of every model's `section` elements to one composed section.
// actuators: MuJoCo 2.2.2 requires stateless actuators before stateful ones, so all
// models' stateless actuators come first, then all stateful ones (each in model order)
void ComposeSection(const Models& models, const std::string& section, XMLDocument* doc,
                    XMLElement* root, Sources* sources) {
  XMLElement* out = nullptr;
  const bool actuators = section == "actuator";
  for (int pass = 0; pass < (actuators ? 2 : 1); ++pass) {
    for (const auto& m : models) {
      size_t index = 0;
      for (XMLElement* s : m->Sections(section)) {
        for (XMLElement* c = s->FirstChildElement(); c; c = c->NextSiblingElement(), ++index) {
          if (actuators && m->sizes().actuator_stateful.at(index) != (pass == 1)) continue;
          if (!out) out = root->InsertNewChildElement(section.c_str());
          Record(*m, c, out->InsertEndChild(c->DeepClone(doc))->ToElement(), sources);
        }
      }
    }
  }
}

// splits a model's ctrl vector into its stateless and stateful parts
std::pair<std::vector<double>, std::vector<double>> SplitCtrl(const std::vector<bool>& stateful,
                                                              const std::vector<double>& ctrl) {
  std::pair<std::vector<double>, std::vector<double>> out;
  for (size_t i = 0; i < ctrl.size(); ++i) {
    (stateful[i] ? out.second : out.first).push_back(ctrl[i]);
  }
  return out;
}

// keys: each model's key becomes "M/K" with the other models at their reference state
int ComposeKeys(const Models& models, XMLElement* root, Sources* sources,
                std::vector<std::string>* warnings) {
  bool any = false;
  for (const auto& m : models) any = any || !m->keys().empty();
  if (!any) return 0;
  for (const auto& m : models) {
    if (!m->sizes().known) {
      warnings->push_back("all keyframes dropped: the state size of " + ModelLabel(*m) +
                          " cannot be derived from its XML (" + m->sizes().why_unknown + ")");
      return 0;
    }
  }
  XMLElement* section = nullptr;
  int count = 0;
  for (size_t mi = 0; mi < models.size(); ++mi) {
    const ModelComposer& m = *models[mi];
    const auto& sz = m.sizes();
    for (compose::KeyData key : m.keys()) {
      const auto check = [&](const std::optional<std::vector<double>>& v, int n, const char* what) {
        if (v && static_cast<int>(v->size()) != n) {
          warnings->push_back(ModelLabel(m) + ": keyframe '" + key.name.value_or("") +
                              "' dropped: " + what + " has " + std::to_string(v->size()) +
                              " numbers, the model has " + std::to_string(n));
          return false;
        }
        return true;
      };
      if (!check(key.qpos, sz.nq, "qpos") || !check(key.qvel, sz.nv, "qvel") ||
          !check(key.act, sz.na, "act") || !check(key.ctrl, sz.nu, "ctrl") ||
          !check(key.mpos, 3 * sz.nmocap, "mpos") || !check(key.mquat, 4 * sz.nmocap, "mquat")) {
        continue;
      }
      m.PlaceKey(&key);
      std::vector<double> qpos, qvel, act, ctrl, ctrl_stateful, mpos, mquat;
      for (size_t j = 0; j < models.size(); ++j) {
        const auto& s = models[j]->sizes();
        const bool own = j == mi;
        const auto append = [](std::vector<double>* dst, const std::vector<double>& src) {
          dst->insert(dst->end(), src.begin(), src.end());
        };
        append(&qpos, own && key.qpos ? *key.qpos : s.qpos0);
        append(&qvel, own && key.qvel ? *key.qvel : std::vector<double>(s.nv, 0.0));
        append(&act, own && key.act ? *key.act : std::vector<double>(s.na, 0.0));
        const auto [sl, sf] = SplitCtrl(
            s.actuator_stateful, own && key.ctrl ? *key.ctrl : std::vector<double>(s.nu, 0.0));
        append(&ctrl, sl);
        append(&ctrl_stateful, sf);
        append(&mpos, own && key.mpos ? *key.mpos : s.mocap_pos);
        append(&mquat, own && key.mquat ? *key.mquat : s.mocap_quat);
      }
      ctrl.insert(ctrl.end(), ctrl_stateful.begin(), ctrl_stateful.end());
      if (!section) section = root->InsertNewChildElement("keyframe");
      XMLElement* k = section->InsertNewChildElement("key");
      if (key.elem != nullptr) Record(m, key.elem, k, sources);
      if (key.name) k->SetAttribute("name", (m.prefix() + *key.name).c_str());
      if (key.time) k->SetAttribute("time", FormatNumbers({*key.time}).c_str());
      for (const auto& [attr, v] :
           {std::pair<const char*, const std::vector<double>*>{"qpos", &qpos},
            {"qvel", &qvel},
            {"act", &act},
            {"ctrl", &ctrl},
            {"mpos", &mpos},
            {"mquat", &mquat}}) {
        if (!v->empty()) k->SetAttribute(attr, FormatNumbers(*v).c_str());
      }
      ++count;
    }
  }
  return count;
}

}  // namespace

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

ComposedScene ComposeWorld(const std::vector<ModelConfig>& models, const ComposeOptions& options) {
  ValidateModels(models);
  if (options.timestep_sec &&
      !(*options.timestep_sec >= kMinTimestepSec && *options.timestep_sec <= kMaxTimestepSec)) {
    throw ConfigError("", 0, "timestep_sec",
                      "timestep " + FormatNumbers({*options.timestep_sec}) +
                          " is not valid; expected seconds in [" +
                          FormatNumbers({kMinTimestepSec}) + ", " +
                          FormatNumbers({kMaxTimestepSec}) + "]");
  }
  ComposedScene scene;
  Models composers;
  for (const ModelConfig& m : models) {
    composers.push_back(std::make_unique<ModelComposer>(m, options.urdf_to_mjcf));
    scene.model_names.push_back(m.name);
  }
  const ComposedCompiler compiler = ReconcileCompilers(composers, &scene.warnings);
  for (size_t i = 0; i < composers.size(); ++i) {
    composers[i]->Prepare(compiler.strip_inertials[i], &scene.warnings);
  }

  XMLDocument& doc = *scene.document;
  std::string comment = " composed by penumbra from:";
  for (const auto& m : composers) {
    comment += " " + m->config().name + " (" + m->source().file() + ")";
  }
  doc.InsertEndChild(doc.NewComment((comment + " ").c_str()));
  XMLElement* root = doc.NewElement("mujoco");
  doc.InsertEndChild(root);
  root->SetAttribute("model", "penumbra_world");

  XMLElement* comp = root->InsertNewChildElement("compiler");
  comp->SetAttribute("angle", "radian");
  ApplyAttrs(comp, compiler.attrs);
  if (!compiler.lengthrange.empty()) {
    ApplyAttrs(comp->InsertNewChildElement("lengthrange"), compiler.lengthrange);
  }
  ComposeOption(composers, options, root, &scene.sources, &scene.warnings);
  XMLElement* size_anchor = root->LastChildElement();
  ComposeVisual(composers, root);
  ComposeStatistic(composers, root, &scene.warnings);
  ComposeDefaults(composers, &doc, root, &scene.sources);
  for (const char* section :
       {"custom", "asset", "worldbody", "contact", "equality", "tendon", "actuator", "sensor"}) {
    ComposeSection(composers, section, &doc, root, &scene.sources);
  }
  if (options.ground_plane) AddGroundPlane(&doc, root);
  compose::AddWorldSites(models, root);  // the world file's sites: (compose/world_sites.h)
  const int nkeys = ComposeKeys(composers, root, &scene.sources, &scene.warnings);
  // <size> needs the key count; put it after <option> as MuJoCo's writer does
  XMLDocument size_doc;
  XMLElement* size_root = size_doc.NewElement("mujoco");
  size_doc.InsertEndChild(size_root);
  ComposeSize(composers, nkeys, size_root);
  if (XMLElement* size = size_root->FirstChildElement("size")) {
    root->InsertAfterChild(size_anchor, size->DeepClone(&doc));
  }

  return scene;
}

ComposedScene::ComposedScene() : document(std::make_unique<XMLDocument>()) {}
ComposedScene::ComposedScene(const ComposedScene& other)
    : document(std::make_unique<XMLDocument>()),
      model_names(other.model_names),
      warnings(other.warnings) {
  other.document->DeepCopy(document.get());
  sources = CopySources(other.sources, *other.document, *document);
}
ComposedScene& ComposedScene::operator=(const ComposedScene& other) {
  if (this != &other) {
    other.document->DeepCopy(document.get());
    model_names = other.model_names;
    warnings = other.warnings;
    sources = CopySources(other.sources, *other.document, *document);
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

std::optional<SourceLocation> ComposedScene::SourceOfLine(int xml_line) const {
  // the printed text parsed again has the line numbers MuJoCo's tinyxml2 reports
  XMLDocument printed;
  const std::string xml = Xml();
  if (xml_line <= 0 || printed.Parse(xml.c_str(), xml.size()) != tinyxml2::XML_SUCCESS) {
    return std::nullopt;
  }
  const XMLElement* best = nullptr;
  int best_line = 0;
  WalkPair(document.get(), &printed, [&](const XMLElement* mine, const XMLElement* parsed) {
    const int line = parsed->GetLineNum();
    if (line <= xml_line && line > best_line) {
      best = mine;
      best_line = line;
    }
  });
  if (best == nullptr) return std::nullopt;
  const auto it = sources.find(best);
  if (it == sources.end()) return std::nullopt;
  return it->second;
}

ConfigError LocateComposedError(const ComposedScene& scene, const ConfigError& error) {
  const auto hint = compose::HintForMujocoError(error.problem());
  std::string problem = error.problem();
  if (hint) problem += " (" + *hint + ")";
  if (error.line() > 0) {
    if (const auto src = scene.SourceOfLine(error.line())) {
      problem += " [composed.xml line " + std::to_string(error.line()) + "]";
      return ConfigError(src->file, src->line, error.key(), problem);
    }
  }
  return ConfigError(error.file(), error.line(), error.key(), problem);
}

void WriteComposedScene(const ComposedScene& scene, const std::string& path) {
  WriteFileAtomic(path, scene.Xml());
}

}  // namespace penumbra

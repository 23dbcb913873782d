#include "penumbra/compose/model_composer.h"

#include <Eigen/Geometry>
#include <cmath>
#include <functional>
#include <set>

#include "penumbra/compose/mjcf_autolimits.h"
#include "penumbra/compose/mjcf_compat.h"
#include "penumbra/compose/mjcf_text.h"
#include "penumbra/core/error.h"

namespace penumbra::compose {
namespace {

using tinyxml2::XMLElement;

constexpr double kDegToRad = M_PI / 180.0;
const char* const kOrientationAttrs[] = {"quat", "axisangle", "xyaxes", "zaxis", "euler"};
const char* const kAlternativeAttrs[] = {"axisangle", "xyaxes", "zaxis", "euler"};

bool IsElementNamed(const XMLElement* e, const char* name) {
  return std::string(e->Name()) == name;
}

// compiler attributes that the composer carries over (MJCF 2.2.2 <compiler>), besides
// angle, eulerseq, meshdir, texturedir, assetdir, strippath and coordinate
const std::vector<std::string>& CarriedCompilerAttrs() {
  static const std::vector<std::string> attrs = {
      "autolimits",      "boundmass",         "boundinertia",    "settotalmass", "balanceinertia",
      "fitaabb",         "discardvisual",     "convexhull",      "usethread",    "fusestatic",
      "inertiafromgeom", "inertiagrouprange", "exactmeshinertia"};
  return attrs;
}

// calls f(elem, spec) for every element below `section_elem`, parents before children
void VisitSection(const MjcfSource& src, const std::string& section, XMLElement* section_elem,
                  const std::function<void(XMLElement*, const ElementSpec&)>& f) {
  for (XMLElement* e = section_elem->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const ElementSpec* spec = FindElementSpec(section, section_elem->Name(), e->Name());
    if (spec == nullptr) {
      const auto newer = NewerElementHint(e->Name());
      src.Fail(e, section + "." + e->Name(),
               std::string("unsupported element <") + e->Name() + "> inside <" +
                   section_elem->Name() + ">; expected an MJCF 2.2.2 element" +
                   (newer ? " (" + *newer + ")" : ""));
    }
    f(e, *spec);
    VisitSection(src, section, e, f);
  }
}

Eigen::Vector3d Vec3(const std::vector<double>& v, size_t offset = 0) {
  return Eigen::Vector3d(v[offset], v[offset + 1], v[offset + 2]);
}

void SetNumbers(XMLElement* e, const char* attr, const std::vector<double>& v) {
  e->SetAttribute(attr, FormatNumbers(v).c_str());
}

void SetVec3(XMLElement* e, const char* attr, const Eigen::Vector3d& v) {
  SetNumbers(e, attr, {v.x(), v.y(), v.z()});
}

void SetQuat(XMLElement* e, const Eigen::Quaterniond& q) {
  for (const char* a : kAlternativeAttrs) e->DeleteAttribute(a);
  SetNumbers(e, "quat", QuatToVector(q));
}

int CountTokens(const char* text) {
  if (text == nullptr) return 0;
  const auto v = ParseNumbers(text);
  return v ? static_cast<int>(v->size()) : 0;
}

}  // namespace

void SetAttr(AttrList* list, const std::string& name, const std::string& value) {
  for (auto& [n, v] : *list) {
    if (n == name) {
      v = value;
      return;
    }
  }
  list->emplace_back(name, value);
}

const std::string* FindAttr(const AttrList& list, const std::string& name) {
  for (const auto& [n, v] : list) {
    if (n == name) return &v;
  }
  return nullptr;
}

ModelComposer::ModelComposer(const ModelConfig& config,
                             const std::function<std::string(const std::string&)>& urdf_to_mjcf)
    : config_(config), prefix_(config.name + "/") {
  src_ = MjcfSource::Load(config.file, urdf_to_mjcf);
  DowngradeMjcf3(*src_, &compat_warnings_);
  ApplyMujoco3Autolimits(*src_, &compat_warnings_);
  if (config.floating_base) AddFloatingBase();
  X_WM_ = config.pose.ToPose();
  q_WM_ = Eigen::Quaterniond(X_WM_.linear()).normalized();
  CollectSections();
  ReadCompiler();
}

// floating_base: the root link (the URDF link that is no joint's child) gets a free joint.
// with Penumbra's converter it is a top-level body; MuJoCo's importer with link fusing on
// (a URDF's own <mujoco> extension) puts its geoms straight into the world body and drops
// its <inertial>: then they are wrapped into a body named after the root link, with the
// root link's inertial from the URDF (origin xyz / rpy: fixed-axis roll, pitch, yaw as URDF
// defines them; inertia about the link's inertial frame).
void ModelComposer::AddFloatingBase() {
  const std::string key =
      (config_.key.empty() ? "models[" + config_.name + "]" : config_.key) + ".floating_base";
  if (!src_->from_urdf()) {
    throw ConfigError("", 0, key,
                      "model '" + config_.name +
                          "' is MJCF; expected floating_base only for URDF models (give an MJCF "
                          "body a <freejoint/> in its file)");
  }
  tinyxml2::XMLDocument urdf;
  if (urdf.LoadFile(config_.file.c_str()) != tinyxml2::XML_SUCCESS || !urdf.RootElement()) {
    throw ConfigError(config_.file, 0, key, "cannot read the URDF again to find its root link");
  }
  std::set<std::string> children;
  for (const XMLElement* j = urdf.RootElement()->FirstChildElement("joint"); j;
       j = j->NextSiblingElement("joint")) {
    if (const XMLElement* c = j->FirstChildElement("child"); c && c->Attribute("link"))
      children.insert(c->Attribute("link"));
  }
  const XMLElement* root_link = nullptr;
  for (const XMLElement* l = urdf.RootElement()->FirstChildElement("link"); l;
       l = l->NextSiblingElement("link")) {
    if (l->Attribute("name") && !children.count(l->Attribute("name"))) root_link = l;
  }
  if (root_link == nullptr) throw ConfigError(config_.file, 0, key, "the URDF has no root link");
  XMLElement* world = src_->root()->FirstChildElement("worldbody");
  if (world == nullptr) world = src_->root()->InsertNewChildElement("worldbody");
  // physics/urdf_converter.h keeps every link a body (fusestatic off): the root link is a
  // top-level body with its inertial, which only needs the free joint
  for (XMLElement* e = world->FirstChildElement("body"); e; e = e->NextSiblingElement("body")) {
    if (e->Attribute("name", root_link->Attribute("name"))) {
      e->InsertNewChildElement("freejoint")->SetAttribute("name", "floating_base");
      e->InsertFirstChild(e->LastChild());
      return;
    }
  }
  XMLElement* body = src_->doc()->NewElement("body");
  body->SetAttribute("name", root_link->Attribute("name"));
  while (XMLElement* e = world->FirstChildElement()) body->InsertEndChild(e);
  XMLElement* joint = src_->doc()->NewElement("freejoint");
  joint->SetAttribute("name", "floating_base");
  body->InsertFirstChild(joint);
  if (const XMLElement* in = root_link->FirstChildElement("inertial")) {
    const auto numbers = [&](const XMLElement* e, const char* attr, size_t n) {
      std::vector<double> out(n, 0.0);
      if (e != nullptr && e->Attribute(attr)) {
        const auto v = ParseNumbers(e->Attribute(attr));
        if (!v || v->size() != n) {
          throw ConfigError(config_.file, e->GetLineNum(), key,
                            std::string("root link inertial: '") + e->Attribute(attr) +
                                "' is not " + std::to_string(n) + " numbers");
        }
        out = *v;
      }
      return out;
    };
    const XMLElement* origin = in->FirstChildElement("origin");
    const std::vector<double> xyz = numbers(origin, "xyz", 3);
    const std::vector<double> rpy = numbers(origin, "rpy", 3);
    const XMLElement* I = in->FirstChildElement("inertia");
    const XMLElement* mass = in->FirstChildElement("mass");
    XMLElement* inertial = src_->doc()->NewElement("inertial");
    inertial->SetAttribute("pos", FormatNumbers(xyz).c_str());
    const Eigen::Quaterniond q = Eigen::AngleAxisd(rpy[2], Eigen::Vector3d::UnitZ()) *
                                 Eigen::AngleAxisd(rpy[1], Eigen::Vector3d::UnitY()) *
                                 Eigen::AngleAxisd(rpy[0], Eigen::Vector3d::UnitX());
    inertial->SetAttribute("mass", FormatNumbers(numbers(mass, "value", 1)).c_str());
    // MJCF fullinertia excludes an orientation: the tensor goes into the body frame instead,
    // I_B = R I_L R^T
    const auto v = [&](const char* a) { return numbers(I, a, 1)[0]; };
    Eigen::Matrix3d I_L;
    I_L << v("ixx"), v("ixy"), v("ixz"), v("ixy"), v("iyy"), v("iyz"), v("ixz"), v("iyz"), v("izz");
    const Eigen::Matrix3d R = q.toRotationMatrix();
    const Eigen::Matrix3d I_B = R * I_L * R.transpose();
    inertial->SetAttribute(
        "fullinertia",
        FormatNumbers({I_B(0, 0), I_B(1, 1), I_B(2, 2), I_B(0, 1), I_B(0, 2), I_B(1, 2)}).c_str());
    body->InsertAfterChild(joint, inertial);
  }
  world->InsertEndChild(body);
}

std::string ModelComposer::Key(const XMLElement* elem, const char* attr) const {
  std::vector<std::string> parts;
  for (const XMLElement* e = elem; e && e != src_->root();) {
    std::string part = e->Name();
    if (const char* n = e->Attribute(IsElementNamed(e, "default") ? "class" : "name")) {
      part += std::string("[") + n + "]";
    }
    parts.push_back(part);
    const tinyxml2::XMLNode* p = e->Parent();
    e = p ? p->ToElement() : nullptr;
  }
  std::string key;
  for (auto it = parts.rbegin(); it != parts.rend(); ++it) key += (key.empty() ? "" : ".") + *it;
  if (attr) key += std::string(".") + attr;
  return key;
}

std::optional<std::vector<double>> ModelComposer::Numbers(const XMLElement* elem, const char* attr,
                                                          const char* value, size_t count) const {
  if (value == nullptr) return std::nullopt;
  auto v = ParseNumbers(value);
  if (!v || (count > 0 && v->size() != count)) {
    src_->Fail(elem, Key(elem, attr),
               std::string("'") + value + "' is not valid; expected " +
                   (count > 0 ? std::to_string(count) + " numbers" : std::string("numbers")));
  }
  return v;
}

std::vector<XMLElement*> ModelComposer::Sections(const std::string& name) const {
  std::vector<XMLElement*> out;
  for (const auto& [n, e] : sections_) {
    if (n == name) out.push_back(e);
  }
  return out;
}

void ModelComposer::CollectSections() {
  const auto& known = KnownSections();
  for (XMLElement* e = src_->root()->FirstChildElement(); e; e = e->NextSiblingElement()) {
    const std::string name = e->Name();
    bool ok = false;
    for (const auto& k : known) ok = ok || k == name;
    if (!ok) {
      src_->Fail(e, name,
                 "unsupported top-level element <" + name +
                     ">; expected one of the MJCF 2.2.2 "
                     "sections (compiler, option, size, visual, statistic, default, custom, asset, "
                     "worldbody, contact, equality, tendon, actuator, sensor, keyframe)");
    }
    sections_.emplace_back(name, e);
  }
}

void ModelComposer::ReadCompiler() {
  const auto& carried = CarriedCompilerAttrs();
  for (XMLElement* c : Sections("compiler")) {
    if (compiler_.first == nullptr) compiler_.first = c;
    for (const tinyxml2::XMLAttribute* a = c->FirstAttribute(); a; a = a->Next()) {
      const std::string name = a->Name();
      const std::string value = a->Value();
      const std::string key = "compiler." + name;
      if (name == "angle") {
        if (value != "radian" && value != "degree") {
          src_->Fail(c, key, "'" + value + "' is not valid; expected radian or degree");
        }
        compiler_.degree = value == "degree";
      } else if (name == "eulerseq") {
        if (value.size() != 3 || value.find_first_not_of("xyzXYZ") != std::string::npos) {
          src_->Fail(c, key, "'" + value + "' is not valid; expected 3 letters of xyzXYZ");
        }
        compiler_.eulerseq = value;
      } else if (name == "meshdir") {
        compiler_.meshdir = value;
      } else if (name == "texturedir") {
        compiler_.texturedir = value;
      } else if (name == "assetdir") {
        compiler_.assetdir = value;
      } else if (name == "strippath") {
        if (value != "true" && value != "false") {
          src_->Fail(c, key, "'" + value + "' is not valid; expected true or false");
        }
        compiler_.strippath = value == "true";
      } else if (name == "coordinate") {
        if (value != "local") {
          src_->Fail(c, key,
                     "'" + value +
                         "' is not supported; expected local (re-save the model with "
                         "local coordinates)");
        }
      } else {
        bool ok = false;
        for (const auto& k : carried) ok = ok || k == name;
        if (!ok) {
          src_->Fail(c, key, "unknown compiler attribute; expected an MJCF 2.2.2 attribute");
        }
        SetAttr(&compiler_.other, name, value);
      }
    }
    for (XMLElement* sub = c->FirstChildElement(); sub; sub = sub->NextSiblingElement()) {
      if (!IsElementNamed(sub, "lengthrange")) {
        src_->Fail(sub, std::string("compiler.") + sub->Name(),
                   "unsupported element; expected <lengthrange>");
      }
      for (const tinyxml2::XMLAttribute* a = sub->FirstAttribute(); a; a = a->Next()) {
        SetAttr(&compiler_.lengthrange, a->Name(), a->Value());
      }
    }
  }
}

void ModelComposer::Prepare(bool strip_inertials, std::vector<std::string>* warnings) {
  warnings->insert(warnings->end(), compat_warnings_.begin(), compat_warnings_.end());
  defaults_ = DefaultTree::Build(*src_);
  CollectNames();
  for (XMLElement* wb : Sections("worldbody")) {
    if (wb->FirstAttribute()) {
      src_->Fail(wb, "worldbody", "the world body cannot have attributes");
    }
    ProcessWorldbody(wb, true, strip_inertials, Eigen::Vector3d::Zero(),
                     Eigen::Quaterniond::Identity(), warnings);
  }
  StripDefaultOrientations();
  CountActuators();
  ResolveAssetPaths();
  ReadKeys();
  Rename();
  AssignClasses();
}

void ModelComposer::CollectNames() {
  for (const auto& [section, elem] : sections_) {
    if (section == "compiler" || section == "option" || section == "size" || section == "visual" ||
        section == "statistic") {
      continue;
    }
    VisitSection(*src_, section, elem, [&](XMLElement* e, const ElementSpec& spec) {
      if (IsElementNamed(e, "composite")) {
        has_composite_ = true;
        const char* p = e->Attribute("prefix");
        composite_prefixes_.push_back(p ? p : "");
      }
      if (!spec.defines || *spec.defines == NameKind::kClass) return;
      // an unnamed mesh, skin, hfield or texture is named after its file (MuJoCo 2.2.2)
      if (section == "asset" && !e->Attribute("name") && e->Attribute("file") &&
          (IsElementNamed(e, "mesh") || IsElementNamed(e, "skin") || IsElementNamed(e, "hfield") ||
           IsElementNamed(e, "texture"))) {
        std::string stem = StripPath(e->Attribute("file"));
        if (const size_t dot = stem.find_last_of('.'); dot != std::string::npos) {
          stem.resize(dot);
        }
        e->SetAttribute("name", stem.c_str());
      }
      const char* name = e->Attribute(spec.name_attr);
      if (name == nullptr) return;
      auto& table = names_[static_cast<int>(*spec.defines)];
      if (!table.insert(name).second) {
        src_->Fail(e, Key(e, "name"),
                   std::string("repeated ") + KindName(*spec.defines) + " name '" + name +
                       "'; expected unique names");
      }
    });
  }
}

OrientationSpec ModelComposer::Orientation(const XMLElement* elem, int cls,
                                           bool use_defaults) const {
  OrientationSpec spec;
  const std::string tag = elem->Name();
  const size_t counts[] = {4, 4, 6, 3, 3};
  std::optional<std::vector<double>>* fields[] = {&spec.quat, &spec.axisangle, &spec.xyaxes,
                                                  &spec.zaxis, &spec.euler};
  for (int i = 0; i < 5; ++i) {
    const char* attr = kOrientationAttrs[i];
    const char* v = elem->Attribute(attr);
    if (v == nullptr && use_defaults) v = defaults_.Lookup(cls, tag.c_str(), attr);
    *fields[i] = Numbers(elem, attr, v, counts[i]);
  }
  return spec;
}

void ModelComposer::ProcessWorldbody(XMLElement* parent, bool top, bool strip_inertials,
                                     const Eigen::Vector3d& body_pos,
                                     const Eigen::Quaterniond& body_quat,
                                     std::vector<std::string>* warnings) {
  // MuJoCo numbers bodies depth-first (pre-order): this body's joints come before the
  // joints of its child bodies, whatever the XML order
  std::vector<XMLElement*> bodies;
  XMLElement* e = parent->FirstChildElement();
  while (e) {
    XMLElement* next = e->NextSiblingElement();
    const std::string tag = e->Name();
    if (tag == "body") {
      bodies.push_back(e);
    } else if (tag == "joint" || tag == "freejoint") {
      ProcessJoint(e, body_pos, body_quat);
    } else if (tag == "geom" || tag == "site" || tag == "camera" || tag == "light") {
      ProcessElementFrame(e, top);
    } else if (tag == "inertial") {
      if (strip_inertials) {
        parent->DeleteChild(e);
      } else {
        ProcessElementFrame(e, false);
      }
    } else if (tag == "composite") {
      sizes_.known = false;
      sizes_.why_unknown = "it has a <composite> element";
      if (top) {
        const auto off = Numbers(e, "offset", e->Attribute("offset"), 3);
        const Eigen::Vector3d o = off ? Vec3(*off) : Eigen::Vector3d::Zero();
        SetVec3(e, "offset", X_WM_ * o);
        if (!X_WM_.linear().isIdentity(1e-12)) {
          warnings->push_back("model '" + config_.name + "': a top-level <composite> (" +
                              Key(e, nullptr) + ") is only translated by the model pose, " +
                              "not rotated");
        }
      }
    }
    e = next;
  }
  for (XMLElement* b : bodies) {
    const OrientationSpec spec = Orientation(b, DefaultTree::kRoot, false);
    int nspec = 0;
    for (const char* a : kOrientationAttrs) nspec += b->Attribute(a) ? 1 : 0;
    if (nspec > 1) {
      src_->Fail(b, Key(b, nullptr),
                 "multiple orientation specifiers; expected at most one of quat, axisangle, "
                 "xyaxes, zaxis, euler");
    }
    std::string err;
    const auto q = ResolveOrientation(spec, compiler_.degree, compiler_.eulerseq, &err);
    if (!q) src_->Fail(b, Key(b, "orientation"), err + "; expected a valid frame orientation");
    const auto p = Numbers(b, "pos", b->Attribute("pos"), 3);
    Eigen::Vector3d pos = p ? Vec3(*p) : Eigen::Vector3d::Zero();
    Eigen::Quaterniond quat = *q;
    if (top) {
      pos = X_WM_ * pos;
      quat = (q_WM_ * quat).normalized();
      SetVec3(b, "pos", pos);
      SetQuat(b, quat);
    } else if (spec.euler || (compiler_.degree && spec.axisangle)) {
      SetQuat(b, quat);
    }
    if (const char* m = b->Attribute("mocap"); m && std::string(m) == "true") {
      ++sizes_.nmocap;
      for (int i = 0; i < 3; ++i) sizes_.mocap_pos.push_back(pos[i]);
      for (double v : QuatToVector(quat)) sizes_.mocap_quat.push_back(v);
    }
    ProcessWorldbody(b, false, strip_inertials, pos, quat, warnings);
  }
}

void ModelComposer::ProcessElementFrame(XMLElement* e, bool top) {
  const std::string tag = e->Name();
  if (tag == "light") {
    if (!top) return;
    const int cls = defaults_.ClassOf(e, true, *src_);
    const char* p = e->Attribute("pos");
    if (!p) p = defaults_.Lookup(cls, "light", "pos");
    const char* d = e->Attribute("dir");
    if (!d) d = defaults_.Lookup(cls, "light", "dir");
    const auto pv = Numbers(e, "pos", p, 3);
    const auto dv = Numbers(e, "dir", d, 3);
    const Eigen::Vector3d pos = pv ? Vec3(*pv) : Eigen::Vector3d::Zero();
    const Eigen::Vector3d dir = dv ? Vec3(*dv) : Eigen::Vector3d(0, 0, -1);
    SetVec3(e, "pos", X_WM_ * pos);
    SetVec3(e, "dir", X_WM_.linear() * dir);
    return;
  }
  int nspec = 0;
  for (const char* a : kOrientationAttrs) nspec += e->Attribute(a) ? 1 : 0;
  if (tag == "inertial" && e->Attribute("fullinertia")) ++nspec;
  if (nspec > 1) {
    src_->Fail(e, Key(e, nullptr),
               "multiple orientation specifiers; expected at most one of quat, axisangle, "
               "xyaxes, zaxis, euler" +
                   std::string(tag == "inertial" ? ", fullinertia" : ""));
  }
  const bool has_defaults = tag != "inertial";
  const int cls = has_defaults ? defaults_.ClassOf(e, true, *src_) : DefaultTree::kRoot;
  const OrientationSpec spec = Orientation(e, cls, has_defaults);
  bool chain_has = false;
  if (has_defaults) {
    for (const char* a : kOrientationAttrs) {
      chain_has = chain_has || defaults_.Lookup(cls, tag.c_str(), a) != nullptr;
    }
  }
  const auto resolve = [&]() {
    std::string err;
    const auto q = ResolveOrientation(spec, compiler_.degree, compiler_.eulerseq, &err);
    if (!q) src_->Fail(e, Key(e, "orientation"), err + "; expected a valid frame orientation");
    return *q;
  };
  const bool angle_dependent =
      e->Attribute("euler") || (compiler_.degree && e->Attribute("axisangle"));
  if (!top) {
    if (angle_dependent || chain_has) SetQuat(e, resolve());
    return;
  }
  // top-level geom/site/camera: place by the model pose
  if (tag == "geom" || tag == "site") {
    const char* ft = e->Attribute("fromto");
    if (!ft) ft = defaults_.Lookup(cls, tag.c_str(), "fromto");
    if (const auto v = Numbers(e, "fromto", ft, 6)) {
      const Eigen::Vector3d a = X_WM_ * Vec3(*v, 0);
      const Eigen::Vector3d b = X_WM_ * Vec3(*v, 3);
      SetNumbers(e, "fromto", {a.x(), a.y(), a.z(), b.x(), b.y(), b.z()});
      if (angle_dependent || chain_has) SetQuat(e, resolve());
      return;
    }
  }
  const char* p = e->Attribute("pos");
  if (!p) p = defaults_.Lookup(cls, tag.c_str(), "pos");
  const auto pv = Numbers(e, "pos", p, 3);
  const Eigen::Vector3d pos = pv ? Vec3(*pv) : Eigen::Vector3d::Zero();
  SetVec3(e, "pos", X_WM_ * pos);
  SetQuat(e, (q_WM_ * resolve()).normalized());
}

void ModelComposer::ProcessJoint(XMLElement* j, const Eigen::Vector3d& body_pos,
                                 const Eigen::Quaterniond& body_quat) {
  std::string type = "free";
  int cls = DefaultTree::kRoot;
  if (IsElementNamed(j, "joint")) {
    cls = defaults_.ClassOf(j, true, *src_);
    const char* t = j->Attribute("type");
    if (!t) t = defaults_.Lookup(cls, "joint", "type");
    type = t ? t : "hinge";
    if (type != "free" && type != "ball" && type != "slide" && type != "hinge") {
      src_->Fail(j, Key(j, "type"),
                 "'" + type + "' is not valid; expected free, ball, slide or hinge");
    }
  }
  const auto value = [&](const char* attr, size_t n) {
    const char* v = j->Attribute(attr);
    if (!v && IsElementNamed(j, "joint")) v = defaults_.Lookup(cls, "joint", attr);
    return Numbers(j, attr, v, n);
  };
  // hinge and ball angles follow compiler angle; slide joints are in metres
  const bool angular = type == "hinge" || type == "ball";
  double ref = 0;
  if (compiler_.degree && angular) {
    if (auto r = value("range", 2)) {
      for (double& x : *r) x *= kDegToRad;
      SetNumbers(j, "range", *r);
    }
    if (type == "hinge") {
      for (const char* a : {"ref", "springref"}) {
        if (auto r = value(a, 1)) {
          (*r)[0] *= kDegToRad;
          SetNumbers(j, a, *r);
          if (std::string(a) == "ref") ref = (*r)[0];
        }
      }
    }
  } else if (type == "hinge" || type == "slide") {
    if (auto r = value("ref", 1)) ref = (*r)[0];
  }
  if (type == "free") {
    sizes_.free_dofs.emplace_back(sizes_.nq, sizes_.nv);
    for (int i = 0; i < 3; ++i) sizes_.qpos0.push_back(body_pos[i]);
    for (double v : QuatToVector(body_quat.normalized())) sizes_.qpos0.push_back(v);
    sizes_.nq += 7;
    sizes_.nv += 6;
  } else if (type == "ball") {
    for (double v : {1.0, 0.0, 0.0, 0.0}) sizes_.qpos0.push_back(v);
    sizes_.nq += 4;
    sizes_.nv += 3;
  } else {
    sizes_.qpos0.push_back(ref);
    sizes_.nq += 1;
    sizes_.nv += 1;
  }
}

void ModelComposer::StripDefaultOrientations() {
  // every element that inherited an orientation now has it explicitly (quat)
  for (const char* tag : {"geom", "site", "camera"}) {
    for (XMLElement* d : defaults_.AllElementDefaults(tag)) {
      for (const char* a : kOrientationAttrs) d->DeleteAttribute(a);
    }
  }
}

void ModelComposer::CountActuators() {
  for (XMLElement* sec : Sections("actuator")) {
    for (XMLElement* a = sec->FirstChildElement(); a; a = a->NextSiblingElement()) {
      if (!IsActuatorTag(a->Name())) continue;  // reported by Rename
      ++sizes_.nu;
      const std::string tag = a->Name();
      bool dyn = false;
      if (tag == "general") {
        if (const char* d = a->Attribute("dyntype")) {
          dyn = std::string(d) != "none";
        } else {
          dyn = defaults_.DefaultActuatorHasDynamics(defaults_.ClassOf(a, false, *src_));
        }
      } else {
        dyn = tag == "intvelocity" || tag == "cylinder" || tag == "muscle";
      }
      if (dyn) ++sizes_.na;
      sizes_.actuator_stateful.push_back(dyn);
    }
  }
}

void ModelComposer::ResolveAssetPaths() {
  const std::string meshdir = !compiler_.meshdir.empty() ? compiler_.meshdir : compiler_.assetdir;
  const std::string texdir =
      !compiler_.texturedir.empty() ? compiler_.texturedir : compiler_.assetdir;
  const auto resolve = [&](XMLElement* e, const char* attr, const std::string& dir) {
    const char* v = e->Attribute(attr);
    if (v == nullptr || *v == '\0') return;
    std::string f = compiler_.strippath ? StripPath(v) : std::string(v);
    if (!IsAbsolutePath(f)) {
      const std::string base = IsAbsolutePath(dir) ? dir : JoinPath(src_->model_dir(), dir);
      f = JoinPath(base.empty() ? src_->model_dir() : base, f);
    }
    f = NormalizePath(f);
    if (!FileExists(f)) {
      src_->Fail(e, Key(e, attr),
                 std::string("asset file '") + v + "' not found (looked for " + f +
                     "); expected an existing file relative to the model file" +
                     (dir.empty() ? std::string() : " and compiler dir '" + dir + "'"));
    }
    e->SetAttribute(attr, f.c_str());
  };
  for (XMLElement* sec : Sections("asset")) {
    for (XMLElement* a = sec->FirstChildElement(); a; a = a->NextSiblingElement()) {
      const std::string tag = a->Name();
      if (tag == "mesh" || tag == "skin" || tag == "hfield") {
        resolve(a, "file", meshdir);
      } else if (tag == "texture") {
        for (const char* attr :
             {"file", "fileright", "fileleft", "fileup", "filedown", "filefront", "fileback"}) {
          resolve(a, attr, texdir);
        }
      }
    }
  }
}

void ModelComposer::ReadKeys() {
  for (XMLElement* sec : Sections("keyframe")) {
    for (XMLElement* k = sec->FirstChildElement(); k; k = k->NextSiblingElement()) {
      if (!IsElementNamed(k, "key")) continue;  // reported by Rename
      KeyData key;
      key.elem = k;
      if (const char* n = k->Attribute("name")) key.name = n;
      if (auto t = Numbers(k, "time", k->Attribute("time"), 1)) key.time = (*t)[0];
      key.qpos = Numbers(k, "qpos", k->Attribute("qpos"), 0);
      key.qvel = Numbers(k, "qvel", k->Attribute("qvel"), 0);
      key.act = Numbers(k, "act", k->Attribute("act"), 0);
      key.ctrl = Numbers(k, "ctrl", k->Attribute("ctrl"), 0);
      key.mpos = Numbers(k, "mpos", k->Attribute("mpos"), 0);
      key.mquat = Numbers(k, "mquat", k->Attribute("mquat"), 0);
      keys_.push_back(std::move(key));
    }
  }
}

void ModelComposer::PlaceKey(KeyData* key) const {
  for (const auto& [qadr, vadr] : sizes_.free_dofs) {
    if (key->qpos && static_cast<int>(key->qpos->size()) >= qadr + 7) {
      auto& q = *key->qpos;
      const Eigen::Vector3d p = X_WM_ * Vec3(q, qadr);
      const Eigen::Quaterniond r =
          q_WM_ * Eigen::Quaterniond(q[qadr + 3], q[qadr + 4], q[qadr + 5], q[qadr + 6]);
      const double vals[7] = {p.x(), p.y(), p.z(), r.w(), r.x(), r.y(), r.z()};
      for (int i = 0; i < 7; ++i) q[qadr + i] = vals[i];
    }
    // free joint qvel: linear velocity in the world frame, angular in the body frame
    if (key->qvel && static_cast<int>(key->qvel->size()) >= vadr + 6) {
      auto& v = *key->qvel;
      const Eigen::Vector3d lin = X_WM_.linear() * Vec3(v, vadr);
      for (int i = 0; i < 3; ++i) v[vadr + i] = lin[i];
    }
  }
  if (key->mpos) {
    for (size_t i = 0; i + 3 <= key->mpos->size(); i += 3) {
      const Eigen::Vector3d p = X_WM_ * Vec3(*key->mpos, i);
      for (int k = 0; k < 3; ++k) (*key->mpos)[i + k] = p[k];
    }
  }
  if (key->mquat) {
    for (size_t i = 0; i + 4 <= key->mquat->size(); i += 4) {
      auto& m = *key->mquat;
      const Eigen::Quaterniond r = q_WM_ * Eigen::Quaterniond(m[i], m[i + 1], m[i + 2], m[i + 3]);
      const auto v = QuatToVector(r);
      for (int k = 0; k < 4; ++k) m[i + k] = v[k];
    }
  }
}

std::string ModelComposer::ResolveRef(const XMLElement* elem, const std::string& key, NameKind kind,
                                      const std::string& value) const {
  if (kind == NameKind::kClass) {
    if (!defaults_.Find(value)) {
      src_->Fail(elem, key,
                 "unknown default class '" + value +
                     "'; expected a class defined in this model's <default>");
    }
    return prefix_ + value;
  }
  const auto& table = names_[static_cast<int>(kind)];
  if (table.count(value)) return prefix_ + value;
  // the world body keeps its name
  if (kind == NameKind::kBody && value == "world") return value;
  // names generated by <composite> cannot be listed from the XML
  for (const auto& p : composite_prefixes_) {
    if (p.empty() || value.rfind(p, 0) == 0) return prefix_ + value;
  }
  src_->Fail(elem, key,
             std::string("unknown ") + KindName(kind) + " '" + value +
                 "'; expected the name of a " + KindName(kind) + " defined in this model");
}

void ModelComposer::Rename() {
  for (const auto& [section, sec] : sections_) {
    if (section == "compiler" || section == "option" || section == "size" || section == "visual" ||
        section == "statistic") {
      continue;
    }
    // references first, so that error messages show the names as written
    VisitSection(*src_, section, sec, [&](XMLElement* e, const ElementSpec& spec) {
      for (const auto& [attr, kind] : spec.refs) {
        if (const char* v = e->Attribute(attr)) {
          e->SetAttribute(attr, ResolveRef(e, Key(e, attr), kind, v).c_str());
        }
      }
      if (spec.objref) {
        for (const auto& [type_attr, name_attr] :
             {std::pair{"objtype", "objname"}, std::pair{"reftype", "refname"}}) {
          const char* type = e->Attribute(type_attr);
          const char* name = e->Attribute(name_attr);
          if (!type || !name) continue;
          const auto kind = KindFromObjType(type);
          if (!kind) {
            src_->Fail(e, Key(e, type_attr),
                       std::string("'") + type +
                           "' is not supported; expected an object type "
                           "with names (body, xbody, geom, site, camera, joint, ...)");
          }
          e->SetAttribute(name_attr, ResolveRef(e, Key(e, name_attr), *kind, name).c_str());
        }
      }
      if (IsElementNamed(e, "composite")) {
        const char* p = e->Attribute("prefix");
        e->SetAttribute("prefix", (prefix_ + (p ? p : "")).c_str());
      }
    });
    VisitSection(*src_, section, sec, [&](XMLElement* e, const ElementSpec& spec) {
      if (!spec.defines) return;
      if (const char* n = e->Attribute(spec.name_attr)) {
        e->SetAttribute(spec.name_attr, (prefix_ + n).c_str());
      }
    });
  }
}

void ModelComposer::AssignClasses() {
  const std::string root = RootClassName();
  const auto set_if_missing = [&](XMLElement* e, const char* attr) {
    if (!e->Attribute(attr)) e->SetAttribute(attr, root.c_str());
  };
  for (XMLElement* wb : Sections("worldbody")) {
    for (XMLElement* e = wb->FirstChildElement(); e; e = e->NextSiblingElement()) {
      const std::string tag = e->Name();
      if (tag == "body") {
        set_if_missing(e, "childclass");
      } else if (tag == "geom" || tag == "site" || tag == "camera" || tag == "light") {
        set_if_missing(e, "class");
      }
    }
  }
  for (const char* section : {"asset", "contact", "equality", "tendon", "actuator"}) {
    for (XMLElement* sec : Sections(section)) {
      for (XMLElement* e = sec->FirstChildElement(); e; e = e->NextSiblingElement()) {
        const std::string tag = e->Name();
        if (std::string(section) == "asset" && tag != "mesh" && tag != "material") continue;
        if (std::string(section) == "contact" && tag != "pair") continue;
        set_if_missing(e, "class");
      }
    }
  }
}

int ModelComposer::MaxUserLength(const std::string& kind) const {
  int n = 0;
  const auto consider = [&](const XMLElement* e) {
    n = std::max(n, CountTokens(e->Attribute("user")));
  };
  const std::string tag = kind == "jnt" ? "joint" : kind == "cam" ? "camera" : kind;
  const std::function<void(const XMLElement*)> walk = [&](const XMLElement* p) {
    for (const XMLElement* e = p->FirstChildElement(); e; e = e->NextSiblingElement()) {
      const std::string t = e->Name();
      if (t == tag) consider(e);
      walk(e);
    }
  };
  for (XMLElement* wb : Sections("worldbody")) {
    if (kind == "body" || kind == "jnt" || kind == "geom" || kind == "site" || kind == "cam") {
      walk(wb);
    }
  }
  for (XMLElement* d : defaults_.AllElementDefaults(tag.c_str())) consider(d);
  if (kind == "tendon") {
    for (XMLElement* sec : Sections("tendon")) {
      for (XMLElement* e = sec->FirstChildElement(); e; e = e->NextSiblingElement()) consider(e);
    }
  }
  if (kind == "actuator") {
    for (XMLElement* sec : Sections("actuator")) {
      for (XMLElement* e = sec->FirstChildElement(); e; e = e->NextSiblingElement()) consider(e);
    }
    for (const char* t : {"general", "motor", "position", "velocity", "intvelocity", "damper",
                          "cylinder", "muscle", "adhesion"}) {
      for (XMLElement* d : defaults_.AllElementDefaults(t)) consider(d);
    }
  }
  if (kind == "sensor") {
    for (XMLElement* sec : Sections("sensor")) {
      for (XMLElement* e = sec->FirstChildElement(); e; e = e->NextSiblingElement()) consider(e);
    }
  }
  return n;
}

}  // namespace penumbra::compose

#include "penumbra/compose/mjcf_schema.h"

#include <array>

namespace penumbra::compose {
namespace {

using K = NameKind;

const std::vector<ElementSpec>& Table() {
  static const std::vector<ElementSpec> table = [] {
    std::vector<ElementSpec> t;
    const auto add = [&t](const char* section, const char* parent, const char* tag,
                          std::optional<NameKind> defines,
                          std::vector<std::pair<const char*, NameKind>> refs = {},
                          bool objref = false) {
      t.push_back(ElementSpec{section, parent, tag, defines,
                              std::string(tag) == "default" ? "class" : "name", std::move(refs),
                              objref});
    };
    // worldbody: children of <composite> first (they only refer to materials)
    for (const char* tag : {"geom", "site", "skin", "tendon"}) {
      add("worldbody", "composite", tag, std::nullopt, {{"material", K::kMaterial}});
    }
    add("worldbody", "composite", "joint", std::nullopt);
    add("worldbody", "composite", "pin", std::nullopt);
    add("worldbody", "*", "body", K::kBody, {{"childclass", K::kClass}});
    add("worldbody", "*", "inertial", std::nullopt);
    add("worldbody", "*", "joint", K::kJoint, {{"class", K::kClass}});
    add("worldbody", "*", "freejoint", K::kJoint);
    add("worldbody", "*", "geom", K::kGeom,
        {{"class", K::kClass},
         {"mesh", K::kMesh},
         {"hfield", K::kHField},
         {"material", K::kMaterial}});
    add("worldbody", "*", "site", K::kSite, {{"class", K::kClass}, {"material", K::kMaterial}});
    add("worldbody", "*", "camera", K::kCamera, {{"class", K::kClass}, {"target", K::kBody}});
    add("worldbody", "*", "light", K::kLight, {{"class", K::kClass}, {"target", K::kBody}});
    add("worldbody", "*", "composite", std::nullopt);  // prefix handled by the composer

    // asset
    add("asset", "*", "texture", K::kTexture);
    add("asset", "*", "hfield", K::kHField);
    add("asset", "*", "mesh", K::kMesh, {{"class", K::kClass}});
    add("asset", "*", "skin", K::kSkin, {{"material", K::kMaterial}});
    add("asset", "skin", "bone", std::nullopt, {{"body", K::kBody}});
    add("asset", "*", "material", K::kMaterial, {{"class", K::kClass}, {"texture", K::kTexture}});

    // default: classes and the element defaults that hold references
    add("default", "*", "default", K::kClass);
    add("default", "*", "geom", std::nullopt,
        {{"material", K::kMaterial}, {"mesh", K::kMesh}, {"hfield", K::kHField}});
    add("default", "*", "site", std::nullopt, {{"material", K::kMaterial}});
    add("default", "*", "material", std::nullopt, {{"texture", K::kTexture}});
    add("default", "*", "tendon", std::nullopt, {{"material", K::kMaterial}});
    for (const char* tag :
         {"mesh", "joint", "camera", "light", "pair", "equality", "general", "motor", "position",
          "velocity", "intvelocity", "damper", "cylinder", "muscle", "adhesion"}) {
      add("default", "*", tag, std::nullopt);
    }

    // contact
    add("contact", "*", "pair", K::kPair,
        {{"class", K::kClass}, {"geom1", K::kGeom}, {"geom2", K::kGeom}});
    add("contact", "*", "exclude", K::kExclude, {{"body1", K::kBody}, {"body2", K::kBody}});

    // equality
    add("equality", "*", "connect", K::kEquality,
        {{"class", K::kClass}, {"body1", K::kBody}, {"body2", K::kBody}});
    add("equality", "*", "weld", K::kEquality,
        {{"class", K::kClass}, {"body1", K::kBody}, {"body2", K::kBody}});
    add("equality", "*", "joint", K::kEquality,
        {{"class", K::kClass}, {"joint1", K::kJoint}, {"joint2", K::kJoint}});
    add("equality", "*", "tendon", K::kEquality,
        {{"class", K::kClass}, {"tendon1", K::kTendon}, {"tendon2", K::kTendon}});
    add("equality", "*", "distance", K::kEquality,
        {{"class", K::kClass}, {"geom1", K::kGeom}, {"geom2", K::kGeom}});

    // tendon
    add("tendon", "spatial", "site", std::nullopt, {{"site", K::kSite}});
    add("tendon", "spatial", "geom", std::nullopt, {{"geom", K::kGeom}, {"sidesite", K::kSite}});
    add("tendon", "spatial", "pulley", std::nullopt);
    add("tendon", "fixed", "joint", std::nullopt, {{"joint", K::kJoint}});
    add("tendon", "*", "spatial", K::kTendon, {{"class", K::kClass}, {"material", K::kMaterial}});
    add("tendon", "*", "fixed", K::kTendon, {{"class", K::kClass}});

    // actuator: one transmission attribute each
    for (const char* tag : {"general", "motor", "position", "velocity", "intvelocity", "damper",
                            "cylinder", "muscle", "adhesion"}) {
      add("actuator", "*", tag, K::kActuator,
          {{"class", K::kClass},
           {"joint", K::kJoint},
           {"jointinparent", K::kJoint},
           {"tendon", K::kTendon},
           {"slidersite", K::kSite},
           {"cranksite", K::kSite},
           {"site", K::kSite},
           {"refsite", K::kSite},
           {"body", K::kBody}});
    }

    // sensor
    for (const char* tag : {"touch", "accelerometer", "velocimeter", "gyro", "force", "torque",
                            "magnetometer", "rangefinder"}) {
      add("sensor", "*", tag, K::kSensor, {{"site", K::kSite}});
    }
    for (const char* tag : {"jointpos", "jointvel", "ballquat", "ballangvel", "jointlimitpos",
                            "jointlimitvel", "jointlimitfrc"}) {
      add("sensor", "*", tag, K::kSensor, {{"joint", K::kJoint}});
    }
    for (const char* tag :
         {"tendonpos", "tendonvel", "tendonlimitpos", "tendonlimitvel", "tendonlimitfrc"}) {
      add("sensor", "*", tag, K::kSensor, {{"tendon", K::kTendon}});
    }
    for (const char* tag : {"actuatorpos", "actuatorvel", "actuatorfrc"}) {
      add("sensor", "*", tag, K::kSensor, {{"actuator", K::kActuator}});
    }
    for (const char* tag : {"subtreecom", "subtreelinvel", "subtreeangmom"}) {
      add("sensor", "*", tag, K::kSensor, {{"body", K::kBody}});
    }
    for (const char* tag : {"framepos", "framequat", "framexaxis", "frameyaxis", "framezaxis",
                            "framelinvel", "frameangvel", "framelinacc", "frameangacc", "user"}) {
      add("sensor", "*", tag, K::kSensor, {}, /*objref=*/true);
    }
    add("sensor", "*", "clock", K::kSensor);

    // keyframe, custom
    add("keyframe", "*", "key", K::kKey);
    add("custom", "*", "numeric", K::kNumeric);
    add("custom", "*", "text", K::kText);
    add("custom", "tuple", "element", std::nullopt, {}, /*objref=*/true);
    add("custom", "*", "tuple", K::kTuple);
    return t;
  }();
  return table;
}

}  // namespace

const char* KindName(NameKind kind) {
  static constexpr std::array<const char*, kNumNameKinds> kNames = {
      "body",   "joint",   "geom",     "site",  "camera",  "light",    "mesh",   "skin",
      "hfield", "texture", "material", "pair",  "exclude", "equality", "tendon", "actuator",
      "sensor", "numeric", "text",     "tuple", "key",     "class"};
  return kNames[static_cast<int>(kind)];
}

std::optional<NameKind> KindFromObjType(const std::string& objtype) {
  static const std::vector<std::pair<std::string, NameKind>> kMap = {
      {"body", K::kBody},       {"xbody", K::kBody},        {"joint", K::kJoint},
      {"geom", K::kGeom},       {"site", K::kSite},         {"camera", K::kCamera},
      {"light", K::kLight},     {"mesh", K::kMesh},         {"skin", K::kSkin},
      {"hfield", K::kHField},   {"texture", K::kTexture},   {"material", K::kMaterial},
      {"pair", K::kPair},       {"exclude", K::kExclude},   {"equality", K::kEquality},
      {"tendon", K::kTendon},   {"actuator", K::kActuator}, {"sensor", K::kSensor},
      {"numeric", K::kNumeric}, {"text", K::kText},         {"tuple", K::kTuple},
      {"key", K::kKey}};
  for (const auto& [word, kind] : kMap) {
    if (word == objtype) return kind;
  }
  return std::nullopt;
}

const ElementSpec* FindElementSpec(const std::string& section, const std::string& parent,
                                   const std::string& tag) {
  for (const ElementSpec& s : Table()) {
    if (section == s.section && tag == s.tag &&
        (std::string(s.parent) == "*" || parent == s.parent)) {
      return &s;
    }
  }
  return nullptr;
}

const std::vector<std::string>& KnownSections() {
  static const std::vector<std::string> sections = {
      "compiler",  "option",  "size",     "visual", "statistic", "default", "custom",  "asset",
      "worldbody", "contact", "equality", "tendon", "actuator",  "sensor",  "keyframe"};
  return sections;
}

bool IsActuatorTag(const std::string& tag) {
  for (const char* t : {"general", "motor", "position", "velocity", "intvelocity", "damper",
                        "cylinder", "muscle", "adhesion"}) {
    if (tag == t) return true;
  }
  return false;
}

}  // namespace penumbra::compose

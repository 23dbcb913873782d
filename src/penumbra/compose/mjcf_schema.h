#pragma once
// the explicit table of which MJCF 2.2.2 element defines a name of which kind and
// which of its attributes refer to names of which kind. the composer prefixes exactly
// these attributes; anything not in the table is left alone, and an element not in
// the table is an error (MuJoCo's schema would reject it too).
// source: MJCF schema of MuJoCo 2.2.2 (src/xml/xml_native_reader.cc) and the XML
// reference. internal to src/penumbra/compose.

#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace penumbra::compose {

/// a namespace of MJCF names (MuJoCo mjtObj, plus default classes).
enum class NameKind {
  kBody,
  kJoint,
  kGeom,
  kSite,
  kCamera,
  kLight,
  kMesh,
  kSkin,
  kHField,
  kTexture,
  kMaterial,
  kPair,
  kExclude,
  kEquality,
  kTendon,
  kActuator,
  kSensor,
  kNumeric,
  kText,
  kTuple,
  kKey,
  kClass,
};
constexpr int kNumNameKinds = static_cast<int>(NameKind::kClass) + 1;

/// lowercase MJCF word of a kind ("body", "joint", ..., "class").
const char* KindName(NameKind kind);

/// kind of an objtype/reftype keyword (MuJoCo mju_str2Type: "body", "xbody", "geom",
/// ...); nullopt for keywords without names ("dof", unknown words).
std::optional<NameKind> KindFromObjType(const std::string& objtype);

/// what one element (in one context) names and refers to.
struct ElementSpec {
  const char* section;  ///< top-level section: "worldbody", "asset", "default", ...
  const char* parent;   ///< parent element name, "*" = any (the first matching entry wins)
  const char* tag;      ///< element name
  std::optional<NameKind> defines;  ///< kind of the name it defines (attribute name_attr)
  const char* name_attr;            ///< "name", or "class" for <default>
  std::vector<std::pair<const char*, NameKind>> refs;  ///< attribute -> kind referred to
  bool objref = false;  ///< objtype/objname (and reftype/refname) refer to a name
};

/// the entry for `tag` under `parent` in `section`, or nullptr if MJCF has no such element.
const ElementSpec* FindElementSpec(const std::string& section, const std::string& parent,
                                   const std::string& tag);

/// the top-level sections the composer understands, in MuJoCo's parse order.
const std::vector<std::string>& KnownSections();

/// actuator element names (all share one default slot in MJCF <default>).
bool IsActuatorTag(const std::string& tag);

}  // namespace penumbra::compose

#pragma once
// the <default> class tree of one MJCF model, for looking up the value an element
// inherits (MuJoCo 2.2.2: a class starts as a copy of its parent, the top-level
// <default> sections all write into the root class, an element uses its class=,
// else the childclass of the nearest enclosing body, else the root class).
// internal to src/penumbra/compose.

#include <tinyxml2.h>

#include <optional>
#include <string>
#include <vector>

#include "penumbra/compose/mjcf_source.h"

namespace penumbra::compose {

class DefaultTree {
 public:
  /// collects the top-level <default> sections of `src`.
  /// @throws ConfigError for nested classes without a name or with a repeated name.
  static DefaultTree Build(const MjcfSource& src);

  /// index of the root class (always 0).
  static constexpr int kRoot = 0;

  /// name of the root class ("main" unless the top-level <default class=...> renames it).
  const std::string& root_name() const { return classes_[kRoot].name; }
  /// class index by name, or nullopt.
  std::optional<int> Find(const std::string& name) const;
  /// the <default> elements that make up the root class (in document order).
  const std::vector<tinyxml2::XMLElement*>& root_sections() const {
    return classes_[kRoot].sections;
  }
  /// every element default <tag> of every class (e.g. all geom defaults).
  std::vector<tinyxml2::XMLElement*> AllElementDefaults(const char* tag) const;

  /// value of `attr` that an element default <tag> gives to class `cls`: the nearest
  /// class on the path cls -> root that sets it; nullptr if none does.
  const char* Lookup(int cls, const char* tag, const char* attr) const;

  /// parent class of class `cls` (-1 for the root).
  int Parent(int cls) const { return classes_[cls].parent; }
  /// the <default> elements that make up class `cls` (in document order).
  const std::vector<tinyxml2::XMLElement*>& Sections(int cls) const {
    return classes_[cls].sections;
  }

  /// true if the actuator default slot of class `cls` ends with activation dynamics
  /// (MJCF shares one actuator default among general/motor/...: the last one written
  /// sets dyntype; general sets it only with an explicit dyntype=).
  bool DefaultActuatorHasDynamics(int cls) const;

  /// class that element `elem` of section `section` uses (class=, else enclosing body
  /// childclass for worldbody elements, else the root).
  /// @throws ConfigError for an unknown class name
  int ClassOf(const tinyxml2::XMLElement* elem, bool in_worldbody, const MjcfSource& src) const;

 private:
  struct Class {
    std::string name;
    int parent = -1;
    std::vector<tinyxml2::XMLElement*> sections;  // <default> elements of this class
  };
  void AddNested(tinyxml2::XMLElement* section, int parent, const MjcfSource& src);

  std::vector<Class> classes_;
};

}  // namespace penumbra::compose

#pragma once
// the scene composer: merges the MJCF and URDF models of a world into one MJCF
// document that MuJoCo 2.2.2 loads (mj_loadXML) from any working directory.
//
// what it does to model M (name "M", see ModelConfig):
//  - resolves <include file> recursively (relative to the including file, then to
//    the main model file as MuJoCo 2.2.2 does) and makes every asset file path
//    absolute (mesh/skin/hfield file, texture file and the six cube-face files),
//    honouring compiler meshdir, texturedir, assetdir and strippath;
//  - prefixes every name with "M/" (bodies, joints, geoms, sites, cameras, lights,
//    assets, tendons, actuators, sensors, equalities, contact pairs/excludes,
//    keyframes, custom numeric/text/tuple, default classes) and every reference
//    to a name, using an explicit (section, element, attribute) -> kind table
//    (mjcf_schema.h); a reference to an undefined name is an error. the world
//    body "world" is never prefixed.
//  - moves M's top-level <default> into a class "M/<root>" ("M/main" normally) under
//    the composed root default, and sets childclass/class on M's top-level worldbody
//    elements and class on its assets, tendons, actuators, equalities and pairs that
//    had none, so M's defaults never reach another model;
//  - rewrites every angle into radians and every euler into quat (using M's
//    compiler angle and eulerseq), so the composed compiler is angle="radian" with
//    the default eulerseq; slide joints and camera fovy / light cutoff (always
//    degrees in MJCF) are not touched;
//  - applies the model pose X_WM to the top-level worldbody elements (bodies keep
//    their free joints at the top level): pos/quat, geom and site fromto, light
//    pos/dir, composite offset;
//  - adds the world file's sites of M (ModelConfig::sites, compose/world_sites.h) to M's
//    bodies as "M/<site>";
//  - URDF files (a .urdf file, or any file whose root element is <robot>) go through
//    ComposeOptions::urdf_to_mjcf first and are then composed like MJCF.
//
// sections: <option>, <visual>, <statistic> come from the first model that has them
// (later differing <option>/<statistic> give a warning naming the attributes; the world
// file's physics options override and silence those they cover); <size> is combined
// (njmax/nconmax summed with MuJoCo's defaults 500/100 for models without them,
// nuser_* and nuserdata maximum; nstack left automatic unless a model sets it, then
// the sum of the explicit sizes and, for the other models, an estimate of MuJoCo
// 2.2.2's automatic size 5 njmax^2 + 10 nv njmax + 10^4);
// compiler attributes other than angle/eulerseq/paths must agree, except
// autolimits (true wins, which is safe: a model valid without it is unchanged),
// usethread (any) and inertiafromgeom true vs auto (reconciled by dropping the
// <inertial> of the "true" model).
// actuators: MuJoCo 2.2.2 wants stateless actuators before stateful ones, so the
// composed <actuator> lists every model's stateless actuators, then every model's
// stateful ones (each group in model order); look actuators up by name.
// keyframes: each key K of model M becomes "M/K"
// with full-length vectors: M's slice from K (free-joint and mocap poses placed by
// M's pose), every other model at its reference configuration (qpos0, zero
// velocity, act and ctrl, placed mocap poses). keys are dropped with a warning when
// the vector sizes cannot be derived from the XML (e.g. <composite>).
//
// MJCF semantics follow the MuJoCo 2.2.2 XML reference and its reader
// (src/xml/xml_native_reader.cc, src/user/user_objects.cc, mjCAlternative::Set).

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <unordered_map>
#include <vector>

#include "penumbra/world/world_config.h"

namespace tinyxml2 {
class XMLDocument;
class XMLElement;
}  // namespace tinyxml2

namespace penumbra {

class ConfigError;

/// where an element of the composed document was written: a model file (or a file it
/// includes) and the 1-based line of the element's start tag there.
struct SourceLocation {
  std::string file;
  int line = 0;
};

/// options of ComposeWorld.
struct ComposeOptions {
  /// converts a URDF file into MJCF text (MuJoCo's own converter: mj_loadXML on the URDF,
  /// then mj_saveLastXML); provided by the physics module, which owns mujoco.h. the
  /// returned text's relative asset paths resolve against the URDF's folder. may throw
  /// ConfigError. required only when a model is URDF.
  std::function<std::string(const std::string& urdf_path)> urdf_to_mjcf;
  /// overrides <option timestep> of the composed model (s, in [kMinTimestepSec,
  /// kMaxTimestepSec] of scene/scene_limits.h). without it the first model with an <option>
  /// decides, and its timestep must be in that range too.
  std::optional<double> timestep_sec;
  /// the world file's physics options (world/world_config.h): each one set overrides the
  /// composed <option>'s integrator, gravity, iterations or cone, and later models'
  /// differing values of it no longer warn.
  PhysicsOptions physics;
  /// adds a ground: an infinite plane at z = 0 (geom "ground", material "ground", texture
  /// "ground_grid": a 1 m grey checker) unless a model already has a plane somewhere in its
  /// worldbody. WorldConfig::ground_plane (bare URDF runs) sets it.
  bool ground_plane = false;
};

/// the result of ComposeWorld: one MJCF document, kept as a tinyxml2 document so that the
/// later composition steps (compose/imu_injection.h, compose/agent_bodies.h) edit it in place;
/// it becomes text once, with Xml(), when it is written or compiled. copies are deep.
struct ComposedScene {
  ComposedScene();
  ComposedScene(const ComposedScene& other);
  ComposedScene& operator=(const ComposedScene& other);
  ComposedScene(ComposedScene&&) noexcept;
  ComposedScene& operator=(ComposedScene&&) noexcept;
  ~ComposedScene();

  /// one self-contained MJCF document: absolute asset paths, no <include>,
  /// compiler angle="radian". never null.
  std::unique_ptr<tinyxml2::XMLDocument> document;
  /// the models' names in input order; model M's MJCF names start with "M/".
  std::vector<std::string> model_names;
  /// things that were composed with a compromise (dropped keyframes, conflicting
  /// <option> or <statistic> of later models, MuJoCo-3 keywords rewritten for 2.2.2, ...),
  /// one line each.
  std::vector<std::string> warnings;
  /// the source map: for each element of `document` that came from a model file, where it
  /// was written (elements added later, e.g. injected IMU sites, have no entry). copies
  /// map their own elements.
  std::unordered_map<const tinyxml2::XMLElement*, SourceLocation> sources;

  /// the document as MJCF text (tinyxml2's indented printing).
  std::string Xml() const;

  /// where the element that starts on 1-based line `xml_line` of Xml() (or, when none
  /// starts there, the last one that starts before it) was written; nullopt when that
  /// element was not copied from a model file or the line is out of range.
  std::optional<SourceLocation> SourceOfLine(int xml_line) const;
};

/// `error` of MuJoCo loading Xml() (its line is a line of the composed text) restated for
/// the user: file and line of the model element that the line came from (the composed
/// line is kept in the message, "composed.xml line N"), plus a hint when MuJoCo rejected a
/// keyword that is newer than MuJoCo 2.2.2. an error without a line, or whose line has no
/// source, keeps its file and line and only gets the hint.
ConfigError LocateComposedError(const ComposedScene& scene, const ConfigError& error);

/// merges `models` (in order) into one MJCF document.
/// @throws ConfigError naming the model file, line (when known), element/attribute and
///         what was expected: empty or duplicate model names, names containing '/',
///         missing model/include/asset files, XML syntax errors, unsupported elements,
///         undefined names, compiler attributes that differ and cannot be reconciled.
ComposedScene ComposeWorld(const std::vector<ModelConfig>& models, const ComposeOptions& options);

/// writes scene.Xml() to `path` (e.g. "<output_dir>/composed.xml"), whole under a
/// temporary name and then renamed into place (core/output_file.h).
/// @throws Error naming the path when the file cannot be written.
void WriteComposedScene(const ComposedScene& scene, const std::string& path);

}  // namespace penumbra

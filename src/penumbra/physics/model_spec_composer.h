#pragma once
// composition of model files through MuJoCo's model-editing API (mjSpec, MuJoCo's
// programming/modeledit.rst): each model file is parsed by MuJoCo (mj_parseXML; a URDF's text
// prepared by the caller), checked by compiling it alone, and attached (mjs_attach) to one
// world spec inside a frame at the model's pose, with every name prefixed "M/". what Penumbra
// adds to a model is a spec edit: the world file's sites (mjs_addSite, at a body's frame or at
// a geom's centre read from the compiled model), a URDF floating base (mjs_addFreeJoint on the
// root link), its keyframes' free joints and mocap bodies placed by the model pose. the result
// is MuJoCo's own mj_saveXMLString text of the world spec (compiler savecompiled="false": the
// spec as written, every number exactly, so the text compiles to the same model).
//
// global settings: the first model that writes an <option> decides the world's (a later model
// whose <option> differs gets a warning naming the fields), the first with a <visual> decides
// that; the rest (<size>, <statistic>) follow MuJoCo's attach rules with compiler
// conflict="merge" (modeledit.rst, "Attribute Merging"). SpecOptionOverrides win over all.
// physics-internal use by the session's composition step; the only place besides the loader
// that turns model files into MuJoCo objects.

#include <array>
#include <deque>
#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/physics/physics_options.h"

struct mjSpec_;
struct mjModel_;

namespace penumbra {

/// a site added to a model (the world file's `sites:`).
struct SpecSite {
  std::string name;  ///< model-local name; becomes "M/<name>"
  std::string body;  ///< model-local body ("world" = the model's world body); or
  std::string geom;  ///< model-local geom: the site goes on its body, at its centre
  /// X_PS: the site in the body's frame (body), or offset from the geom's centre along the
  /// body's axes (geom); metres and a unit quaternion (w, x, y, z).
  std::array<double, 3> pos{0, 0, 0};
  std::array<double, 4> quat{1, 0, 0, 0};
  std::string key;  ///< key path for errors ("robots[0].sites[1]")
};

/// one model file placed in the world.
struct SpecModel {
  std::string name;  ///< prefix of every name of the model ("M" gives "M/...")
  std::string file;  ///< the MJCF or URDF file (named in errors)
  /// MJCF or URDF text parsed instead of the file's content (a URDF prepared by
  /// physics/urdf_converter.h PrepareUrdfForMujoco); relative asset paths resolve against
  /// `file`'s folder. "" = parse `file`.
  std::string text;
  bool from_urdf = false;
  /// X_WM: the model frame in the world (m; unit quaternion w, x, y, z).
  std::array<double, 3> pos{0, 0, 0};
  std::array<double, 4> quat{1, 0, 0, 0};
  /// a free joint "floating_base" on the root link (top-level body) of a URDF model.
  bool floating_base = false;
  std::vector<SpecSite> sites;
  std::string key;  ///< key path of the model in the world file ("robots[1]"), for errors
  /// for a mesh file MuJoCo cannot read (by its absolute path): the file to use instead, or
  /// "" to keep it; may throw ConfigError. unset: every mesh file is kept.
  std::function<std::string(const std::string& mesh_file)> convert_mesh;
};

/// world-file <option> values that override every model's.
struct SpecOptionOverrides {
  std::optional<double> timestep_sec;
  std::optional<std::string> integrator;  ///< MJCF keyword: Euler, RK4, implicit, implicitfast
  std::optional<std::array<double, 3>> gravity_mps2;
  std::optional<int> solver_iterations;
  std::optional<std::string> cone;  ///< pyramidal or elliptic
  ContactOptions contact;           ///< NoSlip iterations, speculative contacts
};

/// builds one world spec from Penumbra's own MJCF and model files.
class ModelSpecComposer {
 public:
  /// parses `base_xml`, Penumbra's own world pieces, as the world spec. unless
  /// `world_sets_timestep`, the deciding model's <option timestep> must be in
  /// [kMinTimestepSec, kMaxTimestepSec] (core/magnitude_limits.h).
  /// @throws Error if MuJoCo cannot parse it (a bug: the text is generated).
  ModelSpecComposer(const std::string& base_xml, bool world_sets_timestep);
  ~ModelSpecComposer();
  ModelSpecComposer(const ModelSpecComposer&) = delete;
  ModelSpecComposer& operator=(const ModelSpecComposer&) = delete;

  /// parses, checks and attaches `model` (see the file comment).
  /// @throws ConfigError(model file, line from MuJoCo's message, "", MuJoCo's message) when
  ///         MuJoCo cannot parse or compile the model; ConfigError("", 0, "<key>.sites[i]...",
  ///         ...) for a site naming an unknown body or geom or a name the model has;
  ///         ConfigError("", 0, "<key>.floating_base", ...) for floating_base on MJCF or a
  ///         URDF without a root body; ConfigError(model file, 0, "option.timestep", ...) for
  ///         a timestep out of range (see the constructor).
  void Attach(const SpecModel& model);

  /// applies `overrides` and compiles the world: the model MuJoCo makes of the spec in
  /// memory (owned by the caller: mj_deleteModel). SaveXml's text compiles to the same model.
  /// @throws ConfigError naming the model file and line of the element MuJoCo names
  ///         ("Element name 'M/...', line N") when compiling the world fails.
  mjModel_* Compile(const SpecOptionOverrides& overrides);

  /// Compile(overrides), then MuJoCo's MJCF text of the world (mj_saveXMLString).
  /// @throws as Compile; Error if MuJoCo cannot save it.
  std::string SaveXml(const SpecOptionOverrides& overrides);

  /// MuJoCo's warnings so far (attach conflicts, compiler warnings), one line each.
  const std::vector<std::string>& warnings() const { return warnings_; }

 private:
  // the first model that sets <option> decides the world's, later ones warn when they differ;
  // the first with <visual> decides it (MuJoCo's attach then finds no conflict to merge)
  void AgreeGlobals(const SpecModel& model, mjSpec_* child);

  mjSpec_* world_ = nullptr;
  bool world_sets_timestep_ = false;
  std::deque<SpecModel> models_;  // deque: option_owner_ points into it
  const SpecModel* option_owner_ = nullptr;
  bool visual_owner_ = false;
  std::vector<std::string> warnings_;
};

}  // namespace penumbra

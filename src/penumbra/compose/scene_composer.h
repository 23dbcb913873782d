#pragma once
// the composed scene: the MJCF document of a world, the seam between the composition step
// (session/world_composer.h: every model file attached through MuJoCo's model-editing API,
// physics/model_spec_composer.h), Penumbra's own additions to it (a ground plane here, the
// world's IMUs in compose/imu_injection.h, the agents' bodies in compose/agent_bodies.h) and
// the compile (physics/simulation.h). this module holds what needs no MuJoCo: the checks of
// the world-level plan (model names, timestep) and the document with Penumbra's pieces.

#include <functional>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/world/world_config.h"

namespace tinyxml2 {
class XMLDocument;
}  // namespace tinyxml2

namespace penumbra {

class ConfigError;

/// options of ComposeWorld (session/world_composer.h).
struct ComposeOptions {
  /// the text of a URDF file for MuJoCo's own URDF parser (physics/urdf_converter.h
  /// PrepareUrdfForMujoco: import options, meshes it cannot read converted to STL files beside
  /// the composed model). relative asset paths resolve against the URDF's folder. may throw
  /// ConfigError. unset: PrepareUrdfForMujoco(urdf_path, "") (the temporary folder).
  std::function<std::string(const std::string& urdf_path)> prepare_urdf;
  /// for an MJCF <mesh file> that MuJoCo cannot read (glTF, FBX, COLLADA, PLY): the file to use
  /// instead (assets/mjcf_mesh_conversion.h), or "" to keep it. unset: kept (MuJoCo's error).
  std::function<std::string(const std::string& mesh_file)> convert_mesh;
  /// overrides every model's <option timestep> (s, in [kMinTimestepSec, kMaxTimestepSec] of
  /// core/magnitude_limits.h). without it the first model with an <option> decides, and its
  /// timestep must be in that range too.
  std::optional<double> timestep_sec;
  /// the world file's physics options (world/world_config.h): each one set overrides the
  /// composed <option>'s integrator, gravity, iterations or cone.
  PhysicsOptions physics;
  /// adds a ground: an infinite plane at z = 0 (geom "ground", material "ground", texture
  /// "ground_grid": a 1 m grey checker) unless a model already has a plane somewhere in its
  /// worldbody. WorldConfig::ground_plane (bare URDF runs) sets it.
  bool ground_plane = false;
};

/// the result of ComposeWorld: one MJCF document, MuJoCo's own text of the composed spec
/// (mj_saveXMLString) parsed into a tinyxml2 document so that Penumbra's additions
/// (compose/imu_injection.h, compose/agent_bodies.h) edit it in place; it becomes text once,
/// with Xml(), when it is written or compiled. copies are deep.
struct ComposedScene {
  ComposedScene();
  ComposedScene(const ComposedScene& other);
  ComposedScene& operator=(const ComposedScene& other);
  ComposedScene(ComposedScene&&) noexcept;
  ComposedScene& operator=(ComposedScene&&) noexcept;
  ~ComposedScene();

  /// one self-contained MJCF document: absolute asset paths, no <include>. never null.
  std::unique_ptr<tinyxml2::XMLDocument> document;
  /// the models' names in input order; model M's MJCF names start with "M/".
  std::vector<std::string> model_names;
  /// things that were composed with a compromise (a later model's differing <option>, MuJoCo's
  /// attach conflicts and compiler warnings), one line each.
  std::vector<std::string> warnings;

  /// the document as MJCF text (tinyxml2's indented printing).
  std::string Xml() const;
};

/// checks the world-level plan before any model is read.
/// @throws ConfigError naming the key: empty or duplicate model names, names containing '/',
///         empty files, options.timestep_sec out of range.
void CheckComposeInput(const std::vector<ModelConfig>& models, const ComposeOptions& options);

/// the composed scene of MuJoCo's text `xml` of the composed models, with a ground plane when
/// options.ground_plane asks for one and no model has a plane.
/// @throws Error if `xml` is not an MJCF document (a bug: MuJoCo wrote it).
ComposedScene MakeComposedScene(const std::string& xml, const std::vector<ModelConfig>& models,
                                std::vector<std::string> warnings, const ComposeOptions& options);

/// writes scene.Xml() to `path` (e.g. "<output_dir>/composed.xml"), whole under a
/// temporary name and then renamed into place (core/output_file.h).
/// @throws Error naming the path when the file cannot be written.
void WriteComposedScene(const ComposedScene& scene, const std::string& path);

}  // namespace penumbra

#pragma once
// the world file: a YAML document that says which models make up a world, how it
// is lit, which cameras watch it and for how long it runs. the full schema with
// defaults and ranges is in README.md ("World file reference"); this header is
// its in-memory form. every struct has defaults and ValidateOrThrow().

#include <Eigen/Core>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/control/controller_config.h"
#include "penumbra/core/pose.h"
#include "penumbra/effects/agent_path.h"
#include "penumbra/effects/effect_config.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/sensors/camera_sensor_config.h"
#include "penumbra/world/environment_config.h"
#include "penumbra/world/metrics_config.h"
#include "penumbra/world/sensors_reader.h"

namespace penumbra {

/// where a model is placed: translation (m) and roll/pitch/yaw (deg, REP-103).
struct PoseConfig {
  Eigen::Vector3d xyz{0, 0, 0};
  Eigen::Vector3d rpy_deg{0, 0, 0};
  Pose ToPose() const { return PoseFromXyzRpyDeg(xyz, rpy_deg); }
};

/// a site the world file adds to a model (`sites:` of a robot or model entry), e.g. a foot
/// point or tool centre point the model lacks. its MJCF name is "<model>/<name>".
struct SiteConfig {
  std::string name;  ///< model-local, unique among the model's sites
  std::string body;  ///< model-local parent body ("world" = the world body); or
  std::string geom;  ///< model-local geom: the site goes on its body, at its centre
  /// X_PS: the site in the parent body's frame (body), or offset from the geom's centre
  /// along the body's axes (geom).
  PoseConfig pose;
};

/// one MJCF or URDF file placed in the world under a unique name.
struct ModelConfig {
  std::string name;  ///< unique; prefixes every MJCF name of the model as "<name>/"
  std::string
      file;  ///< absolute path after loading (relative paths resolve against the world file)
  PoseConfig pose;
  bool is_robot = false;          ///< listed under `robots:` (may carry a controller)
  ControllerConfig controller;    ///< control/controller_config.h; type "" = none
  std::vector<SiteConfig> sites;  ///< `sites:` added to the model when composing
  /// `initial_keyframe:` a <key> of the model (its local name) the run starts from ("" =
  /// MuJoCo's reference configuration qpos0).
  std::string initial_keyframe;
  /// `floating_base:` (URDF only) the URDF's root link becomes a free body (joint
  /// "<model>/floating_base") instead of being welded to the world, as MuJoCo's importer does.
  bool floating_base = false;
  /// key path of the entry in the world file ("robots[1]"), for errors found later; "" for
  /// models not from a world file.
  std::string key;
  /// `environment:` (models only, instead of `file`): a generated building
  /// (world/environment_config.h). `file` stays "" until the session generates its MJCF
  /// (environment/environment_model.h) and points `file` at it.
  std::optional<EnvironmentConfig> environment;
};

/// world-file `physics:` options besides timestep_sec. each one that is set overrides the
/// composed MJCF's <option> attribute of the same meaning (MuJoCo 4.0 XML reference,
/// <option>); unset ones keep the models' <option> (compose/scene_composer.h).
struct PhysicsOptions {
  /// <option integrator>: "Euler", "RK4", "implicit" or "implicitfast" (implicit without the
  /// Coriolis and centripetal derivatives: cheaper, what MuJoCo recommends for robots).
  std::optional<std::string> integrator;
  /// <option gravity>, m/s^2 in the world frame W (z up); each component in [-1000, 1000].
  std::optional<Eigen::Vector3d> gravity_mps2;
  /// <option iterations>: the constraint solver's maximum iterations, in [1, 10000].
  std::optional<int> solver_iterations;
  /// <option cone>: the friction cone, "pyramidal" or "elliptic".
  std::optional<std::string> cone;
  /// <option noslip_iterations>: iterations of MuJoCo's NoSlip post-solver, in [0, 1000];
  /// 0 = off (physics/physics_options.h).
  std::optional<int> noslip_iterations;
  /// <option><flag speculative>: MuJoCo 4's speculative contacts (fast convex geoms do not
  /// tunnel through thin obstacles).
  std::optional<bool> speculative;

  bool empty() const {
    return !integrator && !gravity_mps2 && !solver_iterations && !cone && !noslip_iterations &&
           !speculative;
  }
};

/// a world-file light (see scene Light for units).
struct LightConfig {
  std::string name;
  Light::Type type = Light::Type::kPoint;  ///< "sun"/"directional", "point", "spot"
  std::string attach = "world";            ///< body name ("<model>/<body>") or "world"
  Eigen::Vector3d position{0, 0, 3};       ///< m, in the attach frame (point, spot)
  Eigen::Vector3d direction{0, 0, -1};     ///< direction the light travels (sun, spot)
  Eigen::Vector3f color{1, 1, 1};
  std::optional<double> illuminance_lux;  ///< sun / directional
  std::optional<double> intensity_cd;     ///< point / spot
  std::optional<double> power_w;  ///< point / spot, converted at 683 lm/W: I = 683 P / (4 pi)
  double inner_angle_deg = 30, outer_angle_deg = 45;  ///< spot cone half-angles
  double radius_m = 0;                                ///< emitter radius (soft shadows)
  double angular_diameter_deg = 0.53;                 ///< sun's apparent diameter (soft shadows)
  bool cast_shadow = true;
};

/// sky: "uniform" (colour x luminance) or "daylight" (Preetham analytic sky).
struct SkyConfig {
  Sky::Type type = Sky::Type::kUniform;
  Eigen::Vector3f color{0.6f, 0.7f, 0.8f};             ///< uniform: linear rgb tint
  double luminance_cd_m2 = 1000;                       ///< uniform: luminance of the sky
  double turbidity = 3;                                ///< daylight
  double sun_elevation_deg = 45, sun_azimuth_deg = 0;  ///< daylight; azimuth from +x towards +y
  double zenith_luminance_cd_m2 = 8000;                ///< daylight
};

/// a world-file camera, or overrides for an MJCF camera of the same name.
struct CameraConfig {
  std::string name;
  std::string attach = "world";  ///< body name ("<model>/<body>") or "world"
  /// pose of the camera body frame (REP-103: x forward, y left, z up) in the attach
  /// frame; the optical frame (OpenCV) is derived from it.
  PoseConfig pose;
  int width = 640, height = 480;
  std::optional<double> fovy_deg;              ///< default 60 when no intrinsics
  std::optional<CameraIntrinsics> intrinsics;  ///< fx fy cx cy (px)
  double rate_hz = 10;
  CameraOutputs outputs;
  /// near clipping distance (z-depth, m): nothing nearer is seen; [0, 10]
  double near_m = 0.01;
  bool is_mjcf_override = false;  ///< true: entry under `mjcf_cameras.overrides`
  /// true: pose chosen at load to frame the whole model (bare-model runs)
  bool auto_frame = false;
  /// `distortion:` Brown-Conrady k1 k2 p1 p2 k3 (OpenCV order; see CameraIntrinsics)
  double k1 = 0, k2 = 0, p1 = 0, p2 = 0, k3 = 0;
  /// exposure, motion blur, rolling shutter, noise, JPEG, droplets, depth noise, stereo
  CameraSensorConfig sensor;
};

/// `semantic_classes:` entry: geoms whose name, body name or material name matches one of the
/// glob patterns ('*' any run, '?' one character; MJCF names are "<model>/<name>") get class `id`.
/// the first matching entry in file order wins.
struct SemanticClassConfig {
  std::string name;                                   ///< class name (documentation, label files)
  int id = 0;                                         ///< 1..65535 (0 = unlabelled)
  std::vector<std::string> bodies, geoms, materials;  ///< glob patterns
};

/// defaults applied to every camera that an MJCF model declares.
struct MjcfCameraDefaults {
  bool enabled = true;
  int width = 640, height = 480;
  double rate_hz = 10;
  CameraOutputs outputs;
  /// `mjcf_cameras.profile`: the camera profile of every MJCF camera (overrides start from it).
  CameraProfile profile = CameraProfile::kIdeal;
  /// `mjcf_cameras.overrides`: per MJCF camera (prefixed name) width/height/fovy/
  /// intrinsics/rate/outputs; entries have is_mjcf_override = true.
  std::vector<CameraConfig> overrides;
};

/// world-file override of a material, by (prefixed) MJCF material name.
struct MaterialOverride {
  std::string name;
  std::optional<Eigen::Vector3f> base_color;
  std::optional<float> roughness, metallic, specular;
  std::optional<Eigen::Vector3f> emission;  ///< cd/m^2 per channel
};

/// world-file `record:`: write a run log of the run (runlog/, docs/run-log.md).
struct RecordConfig {
  /// the log file, ending in ".plog"; "" = no log. a relative path is relative to the
  /// run's output folder (`record: {file: run.plog}` writes <output.dir>/run.plog).
  std::string file;
  /// also record each camera image, LiDAR scan and IMU / sensor row (--record-sensors).
  bool sensors = false;
};

class LineTable;
class ConfigError;

/// a whole world file.
struct WorldConfig {
  std::string file;  ///< path of the world file ("" for a bare model)
  uint64_t seed = 0;
  double duration_sec = 10;
  std::optional<double> timestep_sec;  ///< overrides the MJCF <option timestep>
  PhysicsOptions physics;              ///< `physics:` integrator, gravity, iterations, cone
  std::vector<ModelConfig> models;     ///< robots first, then static models, in file order
  std::vector<LightConfig> lights;
  bool default_lights = false;  ///< add a default sun + sky fill (bare-model runs)
  /// add a ground plane at z = 0 when no model has a plane (bare URDF runs: a URDF has no
  /// floor of its own; compose/scene_composer.h, ComposeOptions::ground_plane).
  bool ground_plane = false;
  SkyConfig sky;
  std::vector<CameraConfig> cameras;
  MjcfCameraDefaults mjcf_cameras;
  std::vector<MaterialOverride> materials;
  std::vector<SemanticClassConfig> semantic_classes;  ///< `semantic_classes:` in file order
  RenderSettings render;  ///< `render:` block (render/render_settings.h); seed copied from `seed`
  /// `sensors:` (LiDAR, IMU, MuJoCo sensors, ground truth; world/sensors_reader.h), top-level
  /// entries first, then each robot's own list in robot order.
  std::vector<SensorConfig> sensors;
  std::string output_dir = "out";
  /// `record:` the run log (--record overrides it).
  RecordConfig record;
  /// `effects:` adverse conditions (effects/effect_config.h; parsed by world/effects_reader.h).
  std::vector<EffectConfig> effects;
  /// `agents:` NPC people and vehicles on waypoint paths (effects/agent_path.h).
  std::vector<AgentConfig> agents;
  /// `adversity:` preset spec: a bundled preset name (worlds/adversity/presets.yaml) or a
  /// preset file path (absolute after loading), "" = none (world/adversity_preset.h).
  std::string adversity;
  int adversity_line = 0;  ///< line of the `adversity` key (0 = unknown / command line)
  /// `metrics:` time series recorded while the world runs (world/metrics_config.h).
  MetricsConfig metrics;
  /// 1-based line of every key path of the world file (null for a bare model); lets errors
  /// found after loading (by a stage) still name the line: see LocateInWorld.
  std::shared_ptr<const LineTable> lines;

  /// throws ConfigError naming the file, key and the expected range.
  void ValidateOrThrow() const;
};

/// reads and validates a world file. relative paths in it resolve against its folder.
/// @throws ConfigError for unknown keys, wrong types, missing files, out-of-range values,
///         naming the file, line, key path and what was expected.
WorldConfig LoadWorldFile(const std::string& path);

/// parses world-file text; `file_name` is used in messages and to resolve relative paths.
WorldConfig ParseWorld(const std::string& yaml_text, const std::string& file_name);

/// `e` with the world file and the line of its key filled in, when `e` names no file (or the
/// world file without a line) and its key is a world-file key path (e.g. "effects[2].light",
/// raised by a stage after loading); otherwise `e` unchanged. errors about command-line flags (keys
/// starting with '-') and errors of bare-model runs (no world file) keep their origin.
ConfigError LocateInWorld(const WorldConfig& world, const ConfigError& e);

/// a world around one bare MJCF or URDF file: a default camera framing the model,
/// default lights and sky (penumbra run MODEL.xml).
WorldConfig WorldForBareModel(const std::string& model_path);

}  // namespace penumbra

#include "penumbra/world/world_validation.h"

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <map>
#include <set>

#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/scene/scene_limits.h"
#include "penumbra/world/mesh_import_config.h"

namespace penumbra {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

// an interval of valid values; open ends exclude the bound.
struct Range {
  double lo = -kInf, hi = kInf;
  bool lo_open = false, hi_open = false;

  static Range Closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range OpenClosed(double lo, double hi) { return {lo, hi, true, false}; }
  static Range Open(double lo, double hi) { return {lo, hi, true, true}; }
  static Range AtLeast(double lo) { return {lo, kInf, false, true}; }
  static Range Above(double lo) { return {lo, kInf, true, true}; }
  static Range Finite() { return {-kInf, kInf, true, true}; }

  bool Contains(double v) const {
    if (!std::isfinite(v)) return false;
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  std::string ToString() const {
    if (lo == -kInf && hi == kInf) return "a finite number";
    if (hi == kInf) return (lo_open ? "> " : ">= ") + FormatNumber(lo);
    return std::string(lo_open ? "(" : "[") + FormatNumber(lo) + ", " + FormatNumber(hi) +
           (hi_open ? ")" : "]");
  }
};

const Range kUnit = Range::Closed(0, 1);
const Range kImageSize = Range::Closed(1, 16384);
const Range kRate = Range::OpenClosed(0, 10000);
const Range kNearClip = Range::Closed(0, 10);
const Range kFovy = {kMinFovyDeg, kMaxFovyDeg, false, true};  // [0.1, 179)
// positions given in the world file (scene/scene_limits.h: Embree's float precision)
const Range kPosition = Range::Closed(-kMaxPositionM, kMaxPositionM);

bool EndsWithNoCase(const std::string& s, const std::string& suffix) {
  if (s.size() < suffix.size()) return false;
  for (size_t i = 0; i < suffix.size(); ++i) {
    if (std::tolower(static_cast<unsigned char>(s[s.size() - suffix.size() + i])) != suffix[i])
      return false;
  }
  return true;
}

class Validator {
 public:
  Validator(const WorldConfig& w, const LineTable& lines) : w_(w), lines_(lines) {}

  void Run() {
    Check("duration_sec", w_.duration_sec, Range::OpenClosed(0, kMaxDurationSec));
    if (w_.timestep_sec)
      Check("physics.timestep_sec", *w_.timestep_sec,
            Range::Closed(kMinTimestepSec, kMaxTimestepSec));
    if (w_.physics.gravity_mps2)
      Check3("physics.gravity_mps2", *w_.physics.gravity_mps2, Range::Closed(-1000, 1000));
    if (w_.physics.solver_iterations)
      Check("physics.solver_iterations", *w_.physics.solver_iterations, Range::Closed(1, 10000));
    // physics/physics_options.h kMaxNoslipIterations
    if (w_.physics.noslip_iterations)
      Check("physics.noslip_iterations", *w_.physics.noslip_iterations, Range::Closed(0, 1000));
    if (w_.physics.integrator && *w_.physics.integrator != "Euler" &&
        *w_.physics.integrator != "RK4" && *w_.physics.integrator != "implicit" &&
        *w_.physics.integrator != "implicitfast")
      Fail("physics.integrator", "unknown value '" + *w_.physics.integrator +
                                     "'; expected one of: Euler, RK4, implicit, implicitfast");
    if (w_.physics.cone && *w_.physics.cone != "pyramidal" && *w_.physics.cone != "elliptic")
      Fail("physics.cone",
           "unknown value '" + *w_.physics.cone + "'; expected one of: pyramidal, elliptic");
    CheckRender();
    CheckSky();
    CheckModels();
    for (size_t i = 0; i < w_.lights.size(); ++i) CheckLight(i);
    CheckCameras();
    CheckMjcfCameras();
    CheckMaterials();
    if (w_.output_dir.empty()) Fail("output.dir", "empty; expected a folder name");
    CheckRecord();
    // metrics: keys of the section's own checks get the file and line here
    try {
      w_.metrics.ValidateOrThrow();
    } catch (const ConfigError& e) {
      Fail(e.key(), e.problem());
    }
  }

 private:
  // `record:` (a run log): a .plog file name, or nothing recorded
  void CheckRecord() const {
    const std::string& f = w_.record.file;
    if (f.empty()) {
      if (w_.record.sensors)
        Fail("record.sensors", "true without record.file; expected record: {file: NAME.plog}");
      return;
    }
    if (f.size() <= 5 || f.compare(f.size() - 5, 5, ".plog") != 0 || f.back() == '/')
      Fail("record.file", "'" + f + "'; expected a file name ending in .plog");
  }

  [[noreturn]] void Fail(const std::string& path, const std::string& problem) const {
    throw ConfigError(w_.file, lines_.Find(path), path, problem);
  }

  void Check(const std::string& path, double v, const Range& r) const {
    if (!r.Contains(v)) Fail(path, "got " + FormatNumber(v) + "; expected " + r.ToString());
  }

  template <typename V>
  void Check3(const std::string& path, const V& v, const Range& r) const {
    for (int i = 0; i < 3; ++i) {
      if (!r.Contains(v[i])) {
        Fail(path, "component " + std::to_string(i) + " is " + FormatNumber(v[i]) +
                       "; expected each of the 3 numbers in " + r.ToString());
      }
    }
  }

  // world-level names: models, lights, cameras.
  void CheckName(const std::string& path, const std::string& name) const {
    if (name.empty()) Fail(path, "required; expected a name of letters, digits, '_' or '-'");
    if (auto problem = NameLengthProblem(name)) Fail(path, *problem);
    if (!IsValidWorldName(name)) {
      Fail(path, "'" + Excerpt(name) + "' has characters other than letters, digits, '_' or '-'");
    }
  }

  std::string ModelList() const {
    std::string s;
    for (const ModelConfig& m : w_.models) s += (s.empty() ? "" : ", ") + m.name;
    return s.empty() ? "(no models)" : s;
  }

  bool HasModel(const std::string& name) const {
    return std::any_of(w_.models.begin(), w_.models.end(),
                       [&](const ModelConfig& m) { return m.name == name; });
  }

  // "<model>/<rest>" with a model of this world.
  void CheckPrefixed(const std::string& path, const std::string& name,
                     const std::string& what) const {
    size_t slash = name.find('/');
    if (slash == std::string::npos || slash == 0 || slash + 1 == name.size()) {
      const std::string example = w_.models.empty() ? "rover" : w_.models.front().name;
      Fail(path, "'" + name + "' is not a prefixed name; expected \"<model>/<" + what +
                     ">\", e.g. \"" + example + "/" + what + "\"");
    }
    const std::string model = name.substr(0, slash);
    if (!HasModel(model)) {
      Fail(path,
           "'" + name + "' names unknown model '" + model + "'; expected one of: " + ModelList());
    }
  }

  void CheckAttach(const std::string& path, const std::string& attach) const {
    if (attach == "world") return;
    size_t slash = attach.find('/');
    if (slash == std::string::npos || slash == 0 || slash + 1 == attach.size()) {
      Fail(path, "'" + attach + "'; expected \"world\" or a body as \"<model>/<body>\"");
    }
    CheckPrefixed(path, attach, "body");
  }

  void CheckPose(const std::string& path, const PoseConfig& p) const {
    Check3(path + ".xyz", p.xyz, kPosition);
    // every rotation is within one turn; 1e308 deg has no digits left for the angle
    Check3(path + ".rpy_deg", p.rpy_deg, Range::Closed(-360, 360));
  }

  void CheckOutputs(const std::string& path, const CameraOutputs& o) const {
    if (o.empty()) {
      std::string names;
      for (const ImageKindInfo& k : kImageKinds)
        names += (names.empty() ? "" : ", ") + std::string(k.name);
      Fail(path, "no output selected; expected a non-empty list of: " + names);
    }
  }

  // the same ranges as RenderSettings::ValidateOrThrow (render/), with world-file lines
  void CheckRender() const {
    using R = RenderSettings;
    const R& r = w_.render;
    Check("render.samples_per_pixel", r.samples_per_pixel,
          Range::Closed(1, R::kMaxSamplesPerPixel));
    Check("render.max_bounces", r.max_bounces, Range::Closed(1, R::kMaxBounces));
    Check("render.threads", r.threads, Range::Closed(0, R::kMaxThreads));
    Check("render.max_anisotropy", r.max_anisotropy, Range::Closed(1, R::kMaxAnisotropy));
    Check("render.exposure.ev100", r.ev100, Range::Closed(R::kMinEv100, R::kMaxEv100));
    Check("render.exposure.compensation_ev", r.exposure_compensation_ev,
          Range::Closed(-R::kMaxCompensationEv, R::kMaxCompensationEv));
  }

  void CheckSky() const {
    const SkyConfig& s = w_.sky;
    Check3("sky.color", s.color, kUnit);
    Check("sky.luminance_cd_m2", s.luminance_cd_m2, Range::Closed(0, kMaxLuminanceCdM2));
    Check("sky.turbidity", s.turbidity, Range::Closed(1.7, 10));
    Check("sky.sun_elevation_deg", s.sun_elevation_deg, Range::Closed(-90, 90));
    Check("sky.sun_azimuth_deg", s.sun_azimuth_deg, Range::Closed(-360, 360));
    Check("sky.zenith_luminance_cd_m2", s.zenith_luminance_cd_m2,
          Range::Closed(0, kMaxLuminanceCdM2));
  }

  // key path of w_.models[i]: robots come first, then static models.
  std::string ModelPath(size_t i) const {
    size_t robots_before = 0, models_before = 0;
    for (size_t j = 0; j < i; ++j) (w_.models[j].is_robot ? robots_before : models_before)++;
    return w_.models[i].is_robot ? "robots[" + std::to_string(robots_before) + "]"
                                 : "models[" + std::to_string(models_before) + "]";
  }

  void CheckModels() const {
    std::map<std::string, std::string> seen;  // name -> key path
    for (size_t i = 0; i < w_.models.size(); ++i) {
      const ModelConfig& m = w_.models[i];
      const std::string path = ModelPath(i);
      CheckName(path + ".name", m.name);
      auto [it, inserted] = seen.emplace(m.name, path + ".name");
      if (!inserted) {
        Fail(path + ".name", "duplicate name '" + m.name + "' (also " + it->second + ", line " +
                                 std::to_string(lines_.Find(it->second)) +
                                 "); expected names unique across robots and models");
      }
      if (m.environment) {
        // generated by the session (environment/environment_model.h); checked when read
        CheckPose(path + ".pose", m.pose);
        continue;
      }
      if (m.file.empty())
        Fail(path + ".file", "required; expected an MJCF (.xml) or URDF (.urdf) file");
      if (!EndsWithNoCase(m.file, ".xml") && !EndsWithNoCase(m.file, ".urdf") &&
          !IsMeshModelFile(m.file)) {
        Fail(path + ".file", "'" + m.file +
                                 "' has an unknown extension; expected an MJCF (.xml) "
                                 "or URDF (.urdf) file, or a mesh (.obj, .gltf, .glb, .fbx, "
                                 ".dae, .stl, .ply)");
      }
      std::error_code ec;
      if (!std::filesystem::is_regular_file(m.file, ec)) {
        Fail(path + ".file", "file not found: " + m.file +
                                 " (relative paths resolve against the world file's folder)");
      }
      CheckPose(path + ".pose", m.pose);
      if (!m.is_robot && !m.controller.type.empty()) {
        Fail(path + ".controller", "static models take no controller; expected it under robots:");
      }
    }
  }

  void CheckLight(size_t i) const {
    const LightConfig& l = w_.lights[i];
    const std::string path = "lights[" + std::to_string(i) + "]";
    CheckName(path + ".name", l.name);
    for (size_t j = 0; j < i; ++j) {
      if (w_.lights[j].name == l.name) {
        const std::string other = "lights[" + std::to_string(j) + "].name";
        Fail(path + ".name", "duplicate name '" + l.name + "' (also " + other + ", line " +
                                 std::to_string(lines_.Find(other)) +
                                 "); expected unique light names");
      }
    }
    CheckAttach(path + ".attach", l.attach);
    Check3(path + ".color", l.color, kUnit);
    const bool directional = l.type == Light::Type::kDirectional;
    if (directional) {
      if (!l.illuminance_lux) {
        Fail(path + ".illuminance_lux",
             "required for sun and directional lights; expected lux > 0");
      }
      Check(path + ".illuminance_lux", *l.illuminance_lux,
            Range::OpenClosed(0, kMaxIlluminanceLux));
      if (l.intensity_cd || l.power_w) {
        Fail(path + (l.intensity_cd ? ".intensity_cd" : ".power_w"),
             "does not apply to sun and directional lights; expected illuminance_lux");
      }
      Check(path + ".angular_diameter_deg", l.angular_diameter_deg, Range::Closed(0, 20));
    } else {
      if (l.illuminance_lux) {
        Fail(path + ".illuminance_lux",
             "does not apply to point and spot lights; expected intensity_cd or power_w");
      }
      if (l.intensity_cd.has_value() == l.power_w.has_value()) {
        Fail(l.intensity_cd ? path + ".power_w" : path,
             std::string(l.intensity_cd ? "both intensity_cd and power_w given"
                                        : "neither intensity_cd nor power_w given") +
                 "; expected exactly one of them for point and spot lights");
      }
      if (l.intensity_cd)
        Check(path + ".intensity_cd", *l.intensity_cd, Range::OpenClosed(0, kMaxIntensityCd));
      if (l.power_w) Check(path + ".power_w", *l.power_w, Range::OpenClosed(0, kMaxLightPowerW));
      Check(path + ".radius_m", l.radius_m, Range::Closed(0, kMaxLightRadiusM));
      Check3(path + ".position", l.position, kPosition);
    }
    if (l.type == Light::Type::kSpot) {
      Check(path + ".inner_angle_deg", l.inner_angle_deg, Range::OpenClosed(0, 90));
      Check(path + ".outer_angle_deg", l.outer_angle_deg, Range::OpenClosed(0, 90));
      if (l.inner_angle_deg > l.outer_angle_deg) {
        Fail(path + ".inner_angle_deg",
             "inner_angle_deg " + FormatNumber(l.inner_angle_deg) + " exceeds outer_angle_deg " +
                 FormatNumber(l.outer_angle_deg) + "; expected 0 < inner <= outer <= 90");
      }
    }
    if (l.type != Light::Type::kPoint) {
      Check3(path + ".direction", l.direction,
             Range::Closed(-kMaxDirectionComponent, kMaxDirectionComponent));
      if (l.direction.norm() == 0)
        Fail(path + ".direction", "zero vector; expected a non-zero direction");
    }
  }

  void CheckCameraCommon(const std::string& path, const CameraConfig& c) const {
    Check(path + ".width", c.width, kImageSize);
    Check(path + ".height", c.height, kImageSize);
    if (c.fovy_deg && c.intrinsics) {
      Fail(path + ".intrinsics", "fovy_deg and intrinsics both given; expected one of them");
    }
    if (c.fovy_deg) {
      Check(path + ".fovy_deg", *c.fovy_deg, kFovy);
      // square pixels: a very wide or very tall image stretches the other axis
      const CameraIntrinsics k = CameraIntrinsics::FromFovy(c.width, c.height, *c.fovy_deg);
      if (auto problem = FindIntrinsicsProblem(k))
        Fail(path + ".fovy_deg", "fovy_deg " + FormatNumber(*c.fovy_deg) + " at " +
                                     std::to_string(c.width) + " x " + std::to_string(c.height) +
                                     " px: " + *problem +
                                     " (square pixels; expected another fovy_deg or image size, or "
                                     "intrinsics)");
    }
    if (c.intrinsics) {
      const CameraIntrinsics& k = *c.intrinsics;
      Check(path + ".intrinsics.fx", k.fx, Range::Above(0));
      Check(path + ".intrinsics.fy", k.fy, Range::Above(0));
      Check(path + ".intrinsics.cx", k.cx, Range::Finite());
      Check(path + ".intrinsics.cy", k.cy, Range::Finite());
      CameraIntrinsics sized = k;
      sized.width = c.width;
      sized.height = c.height;
      if (auto problem = FindIntrinsicsProblem(sized)) Fail(path + ".intrinsics", *problem);
      if (k.width != c.width || k.height != c.height) {
        Fail(path + ".intrinsics", "image size " + std::to_string(k.width) + "x" +
                                       std::to_string(k.height) + " differs from the camera's " +
                                       std::to_string(c.width) + "x" + std::to_string(c.height) +
                                       "; expected equal sizes");
      }
    }
    Check(path + ".rate_hz", c.rate_hz, kRate);
    Check(path + ".near_m", c.near_m, kNearClip);
    CheckOutputs(path + ".outputs", c.outputs);
  }

  void CheckCameras() const {
    for (size_t i = 0; i < w_.cameras.size(); ++i) {
      const CameraConfig& c = w_.cameras[i];
      const std::string path = "cameras[" + std::to_string(i) + "]";
      CheckName(path + ".name", c.name);
      for (size_t j = 0; j < i; ++j) {
        if (w_.cameras[j].name == c.name) {
          const std::string other = "cameras[" + std::to_string(j) + "].name";
          Fail(path + ".name", "duplicate name '" + c.name + "' (also " + other + ", line " +
                                   std::to_string(lines_.Find(other)) +
                                   "); expected unique camera names");
        }
      }
      CheckAttach(path + ".attach", c.attach);
      CheckPose(path + ".pose", c.pose);
      CheckCameraCommon(path, c);
    }
  }

  void CheckMjcfCameras() const {
    const MjcfCameraDefaults& m = w_.mjcf_cameras;
    Check("mjcf_cameras.width", m.width, kImageSize);
    Check("mjcf_cameras.height", m.height, kImageSize);
    Check("mjcf_cameras.rate_hz", m.rate_hz, kRate);
    CheckOutputs("mjcf_cameras.outputs", m.outputs);
    std::set<std::string> seen;
    for (const CameraConfig& c : m.overrides) {
      const std::string path = "mjcf_cameras.overrides." + c.name;
      CheckPrefixed(path, c.name, "camera");
      if (!seen.insert(c.name).second) Fail(path, "camera overridden twice; expected one entry");
      CheckCameraCommon(path, c);
    }
  }

  void CheckMaterials() const {
    std::set<std::string> seen;
    for (const MaterialOverride& m : w_.materials) {
      const std::string path = "materials." + m.name;
      CheckPrefixed(path, m.name, "material");
      if (!seen.insert(m.name).second) Fail(path, "material overridden twice; expected one entry");
      if (m.base_color) Check3(path + ".base_color", *m.base_color, kUnit);
      if (m.roughness) Check(path + ".roughness", *m.roughness, kUnit);
      if (m.metallic) Check(path + ".metallic", *m.metallic, kUnit);
      if (m.specular) Check(path + ".specular", *m.specular, kUnit);
      if (m.emission) Check3(path + ".emission", *m.emission, Range::Closed(0, kMaxLuminanceCdM2));
    }
  }

  const WorldConfig& w_;
  const LineTable& lines_;
};

}  // namespace

bool IsValidWorldName(const std::string& name) {
  if (name.empty()) return false;
  return std::all_of(name.begin(), name.end(), [](char ch) {
    return std::isalnum(static_cast<unsigned char>(ch)) || ch == '_' || ch == '-';
  });
}

void ValidateWorld(const WorldConfig& world, const LineTable& lines) {
  Validator(world, lines).Run();
}

void WorldConfig::ValidateOrThrow() const { ValidateWorld(*this, LineTable()); }

}  // namespace penumbra

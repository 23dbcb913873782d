#include "penumbra/world/world_config.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "penumbra/config/param_reader.h"
#include "penumbra/config/yaml_document.h"
#include "penumbra/core/error.h"
#include "penumbra/core/input_file.h"
#include "penumbra/core/output_path_policy.h"
#include "penumbra/core/text_match.h"
#include "penumbra/scene/scene_limits.h"
#include "penumbra/sensors/camera_profile.h"
#include "penumbra/world/adversity_preset.h"
#include "penumbra/world/agents_reader.h"
#include "penumbra/world/camera_config_reader.h"
#include "penumbra/world/effects_reader.h"
#include "penumbra/world/mesh_import_config.h"
#include "penumbra/world/procedural_material_config.h"
#include "penumbra/world/ros_config.h"
#include "penumbra/world/world_validation.h"

namespace fs = std::filesystem;

namespace penumbra {

namespace {

// reads one world-file document into a WorldConfig: structure, types and enum
// values here; ranges and cross-field rules in ValidateWorld (world_validation.cc).
class WorldParser {
 public:
  WorldParser(const std::string& file_name, LineTable* lines) : file_(file_name), lines_(lines) {
    std::error_code ec;
    fs::path abs = file_name.empty() ? fs::current_path(ec) / "world.yaml"
                                     : fs::absolute(fs::path(file_name), ec);
    base_dir_ = abs.parent_path();
  }

  WorldConfig Parse(const ConfigValue& root) {
    ParamReader r(root, file_, lines_);
    const std::vector<std::string_view> keys = {
        "seed",      "duration_sec", "physics", "render",    "sky",
        "robots",    "models",       "lights",  "cameras",   "mjcf_cameras",
        "materials", "output",       "agents",  "adversity", "semantic_classes",
        "effects",   "sensors",      "record",  "metrics",   "ros"};
    if (root.IsNull() || !root.IsDefined()) {
      r.Fail("the world file is empty; expected a mapping with some of the keys: " +
             JoinNames(keys));
    }
    r.ExpectMap(keys);

    WorldConfig w;
    w.file = file_;
    if (const auto found = r.Find("seed")) w.seed = found->Uint64();
    if (const auto found = r.Find("duration_sec")) w.duration_sec = found->Double();
    if (const auto physics = r.Find("physics")) {
      // each key read once; ReportUnused names any other key with the keys read
      const ParamReader& p = *physics;
      p.ExpectMapAnyKeys();
      if (const auto found = p.Find("timestep_sec")) w.timestep_sec = found->Double();
      if (const auto found = p.Find("integrator"))
        w.physics.integrator = found->Enum({"Euler", "RK4", "implicit", "implicitfast"});
      if (const auto found = p.Find("gravity_mps2")) w.physics.gravity_mps2 = found->Vector3();
      if (const auto found = p.Find("solver_iterations"))
        w.physics.solver_iterations = found->Int();
      if (const auto found = p.Find("cone"))
        w.physics.cone = found->Enum({"pyramidal", "elliptic"});
      if (const auto found = p.Find("noslip_iterations"))
        w.physics.noslip_iterations = found->Int();
      if (const auto found = p.Find("speculative")) w.physics.speculative = found->Bool();
      p.ReportUnused();
    }
    if (const auto found = r.Find("render")) ReadRender(*found, &w.render);
    w.render.seed = w.seed;
    if (const auto found = r.Find("sky")) ReadSky(*found, &w.sky);
    // robots first, then static models, each in file order
    if (r.Has("robots")) {
      for (const ParamReader& m : r.Child("robots").List()) w.models.push_back(ReadModel(m, true));
    }
    if (r.Has("models")) {
      for (const ParamReader& m : r.Child("models").List()) w.models.push_back(ReadModel(m, false));
    }
    if (const auto found = r.Find("sensors")) w.sensors = ReadSensors(*found, file_, "");
    if (r.Has("robots")) {
      for (const ParamReader& m : r.Child("robots").List())
        if (m.Has("sensors")) {
          const auto robot = ReadSensors(m.Child("sensors"), file_, m.Child("name").String());
          w.sensors.insert(w.sensors.end(), robot.begin(), robot.end());
        }
    }
    ValidateSensorNames(w.sensors);
    if (r.Has("lights")) {
      for (const ParamReader& l : r.Child("lights").List()) w.lights.push_back(ReadLight(l));
    }
    if (r.Has("cameras")) {
      const ParamReader cameras = r.Child("cameras");
      // counted before any is read (scene/scene_limits.h)
      if (cameras.node().IsSequence() && cameras.size() > static_cast<size_t>(kMaxCameras))
        cameras.Fail(std::to_string(cameras.size()) + " cameras; expected at most " +
                     std::to_string(kMaxCameras) + " (world-file and MJCF cameras together)");
      for (const ParamReader& c : cameras.List()) w.cameras.push_back(ReadCamera(c));
    }
    if (const auto found = r.Find("mjcf_cameras")) ReadMjcfCameras(*found, &w.mjcf_cameras);
    if (r.Has("materials")) {
      for (auto& [name, m] : r.Child("materials").Entries())
        w.materials.push_back(ReadMaterial(name, m));
    }
    if (r.Has("output")) {
      ParamReader o = r.Child("output");
      o.ExpectMap({"dir"});
      if (const auto found = o.Find("dir")) w.output_dir = found->String();
    }
    if (r.Has("record")) {
      ParamReader rec = r.Child("record");
      rec.ExpectMap({"file", "sensors"});
      if (!rec.Has("file")) rec.Fail("no 'file'; expected record: {file: NAME.plog}");
      w.record.file = rec.Child("file").String();
      // `record: {file: ""}` used to record nothing without a word
      if (w.record.file.empty())
        rec.Child("file").Fail("empty; expected a file name ending in .plog");
      // a world file may come from anyone: its log goes inside the output folder only
      try {
        CheckClientPath(w.record.file, ".plog");
      } catch (const OutputPathError& e) {
        rec.Child("file").Fail("'" + SanitizeForMessage(w.record.file, 300) + "' " + e.rule() +
                               "; expected a file name ending in .plog, relative to the output "
                               "folder and inside it");
      }
      if (const auto found = rec.Find("sensors")) w.record.sensors = found->Bool();
    }
    if (r.Has("semantic_classes"))
      w.semantic_classes = ReadSemanticClasses(r.Child("semantic_classes"));
    if (const auto found = r.Find("agents")) w.agents = ReadAgents(*found, file_);
    if (const auto found = r.Find("effects")) w.effects = ReadEffects(*found, file_);
    if (const auto found = r.Find("metrics")) w.metrics = ReadMetrics(*found);
    // `ros:` is checked here and read again by the ROS module (world/ros_config.h)
    if (r.Has("ros")) {
      const RosConfig ros = ReadRosConfig(r.Child("ros"));
      try {
        ros.ValidateOrThrow();
        ValidateRosReferences(ros, w);
      } catch (const ConfigError& e) {
        throw ConfigError(file_, lines_ ? lines_->Find(e.key()) : 0, e.key(), e.problem());
      }
    }
    if (r.Has("adversity")) {
      const ParamReader a = r.Child("adversity");
      w.adversity = ResolveAdversitySpec(a.String(), base_dir_.string(), file_, a.line());
      w.adversity_line = a.line();
    }
    return w;
  }

 private:
  // absolute, lexically normalised path; relative paths resolve against the world file's folder.
  std::string Resolve(const std::string& path) const {
    if (path.empty()) return path;
    fs::path p(path);
    if (p.is_relative()) p = base_dir_ / p;
    return p.lexically_normal().string();
  }

  static void ReadPose(const ParamReader& r, PoseConfig* pose) {
    r.ExpectMap({"xyz", "rpy_deg"});
    if (const auto found = r.Find("xyz")) pose->xyz = found->Vector3();
    if (const auto found = r.Find("rpy_deg")) pose->rpy_deg = found->Vector3();
  }

  static Eigen::Vector3f Vector3f(const ParamReader& r) { return r.Vector3().cast<float>(); }

  static void ReadRender(const ParamReader& r, RenderSettings* s) {
    r.ExpectMap({"backend", "tier", "samples_per_pixel", "max_bounces", "denoise", "threads",
                 "exposure", "tone_map", "max_anisotropy"});
    // cpu (also spelt embree, its ray tracer), cuda or auto (docs/gpu.md): Enum names them in
    // the error for any other value
    if (r.Has("backend")) {
      s->backend = RenderSettings::BackendFromName(
          r.Child("backend").Enum({"cpu", "embree", "cuda", "auto"}));
    }
    if (r.Has("tier")) {
      s->tier = r.Child("tier").Enum({"realtime", "pathtraced"}) == "realtime"
                    ? RenderSettings::Tier::kRealtime
                    : RenderSettings::Tier::kPathtraced;
    }
    if (const auto found = r.Find("samples_per_pixel")) s->samples_per_pixel = found->Int();
    if (const auto found = r.Find("max_bounces")) s->max_bounces = found->Int();
    if (const auto found = r.Find("denoise")) s->denoise = found->Bool();
    if (const auto found = r.Find("threads")) s->threads = found->Int();
    if (const auto found = r.Find("max_anisotropy")) s->max_anisotropy = found->Int();
    if (r.Has("exposure")) {
      ParamReader e = r.Child("exposure");
      e.ExpectMap({"mode", "ev100", "compensation_ev"});
      if (const auto found = e.Find("mode"))
        s->auto_exposure = found->Enum({"auto", "manual"}) == "auto";
      if (const auto found = e.Find("ev100")) s->ev100 = found->Double();
      if (e.Has("compensation_ev")) {
        s->exposure_compensation_ev = e.Child("compensation_ev").Double();
      }
    }
    if (r.Has("tone_map")) {
      s->tone_map = r.Child("tone_map").Enum({"filmic", "linear"}) == "filmic"
                        ? RenderSettings::ToneMap::kFilmic
                        : RenderSettings::ToneMap::kLinear;
    }
  }

  static void ReadSky(const ParamReader& r, SkyConfig* s) {
    r.ExpectMap({"type", "color", "luminance_cd_m2", "turbidity", "sun_elevation_deg",
                 "sun_azimuth_deg", "zenith_luminance_cd_m2"});
    if (r.Has("type")) {
      s->type = r.Child("type").Enum({"uniform", "daylight"}) == "uniform" ? Sky::Type::kUniform
                                                                           : Sky::Type::kDaylight;
    }
    if (const auto found = r.Find("color")) s->color = Vector3f(*found);
    if (const auto found = r.Find("luminance_cd_m2")) s->luminance_cd_m2 = found->Double();
    if (const auto found = r.Find("turbidity")) s->turbidity = found->Double();
    if (const auto found = r.Find("sun_elevation_deg")) s->sun_elevation_deg = found->Double();
    if (const auto found = r.Find("sun_azimuth_deg")) s->sun_azimuth_deg = found->Double();
    if (r.Has("zenith_luminance_cd_m2")) {
      s->zenith_luminance_cd_m2 = r.Child("zenith_luminance_cd_m2").Double();
    }
  }

  ModelConfig ReadModel(const ParamReader& r, bool is_robot) const {
    std::vector<std::string_view> keys = {"name", "file", "pose"};
    if (is_robot) keys.insert(keys.end(), {"controller", "sensors"});
    if (!is_robot) keys.push_back("environment");
    keys.insert(keys.end(), {"sites", "initial_keyframe", "floating_base"});
    keys.insert(keys.end(), MeshImportKeys().begin(), MeshImportKeys().end());
    r.ExpectMap(keys);
    ModelConfig m;
    m.is_robot = is_robot;
    m.key = r.path();
    m.name = r.Child("name").String();
    if (r.Has("environment")) {
      // a generated building: no file, no mesh keys, no sites (nothing to name yet)
      if (const auto found = r.Find("file"))
        found->Fail("expected either file or environment, not both");
      for (std::string_view k : {"sites", "initial_keyframe", "floating_base"})
        if (r.Has(k)) r.Child(k).Fail("not allowed with environment: (a generated building)");
      for (std::string_view k : MeshImportKeys())
        if (r.Has(k)) r.Child(k).Fail("applies to mesh files only, not to environment:");
      m.environment = ReadEnvironmentConfig(r.Child("environment"));
      if (const auto found = r.Find("pose")) ReadPose(*found, &m.pose);
      return m;
    }
    if (!r.Has("file") && !is_robot)
      r.Fail("expected file (an MJCF, URDF or mesh file) or environment (a generated building)");
    m.file = Resolve(r.Child("file").String());
    // checked here, read again by the session (world/mesh_import_config.h)
    MeshImportConfig mesh;
    ReadMeshImportKeys(r, IsMeshModelFile(m.file), &mesh);
    if (const auto found = r.Find("pose")) ReadPose(*found, &m.pose);
    if (const auto found = r.Find("floating_base")) m.floating_base = found->Bool();
    if (r.Has("initial_keyframe")) {
      m.initial_keyframe = r.Child("initial_keyframe").String();
      if (m.initial_keyframe.empty())
        r.Child("initial_keyframe").Fail("empty; expected the name of one of the model's <key>s");
    }
    if (r.Has("sites")) {
      for (const ParamReader& s : r.Child("sites").List()) {
        s.ExpectMap({"name", "body", "geom", "pose"});
        SiteConfig site;
        site.name = s.Child("name").String();
        if (auto problem = NameLengthProblem(site.name)) s.Child("name").Fail(*problem);
        if (site.name.empty() || site.name.find('/') != std::string::npos)
          s.Child("name").Fail("'" + site.name + "'; expected a non-empty name without '/'");
        if (s.Has("body") == s.Has("geom"))
          s.Fail(
              "expected exactly one of body (the parent body) and geom (a geom whose centre "
              "the site marks)");
        if (const auto found = s.Find("body")) site.body = found->String();
        if (const auto found = s.Find("geom")) site.geom = found->String();
        if (const auto found = s.Find("pose")) ReadPose(*found, &site.pose);
        for (const SiteConfig& other : m.sites)
          if (other.name == site.name)
            s.Child("name").Fail("duplicate site '" + site.name + "'; expected unique names");
        m.sites.push_back(site);
      }
    }
    if (const auto found = r.Find("controller")) m.controller = ReadController(*found);
    return m;
  }

  // `type` picks the controller; the rest of the mapping stays YAML nodes for it.
  static ControllerConfig ReadController(const ParamReader& r) {
    r.ExpectMapAnyKeys();
    ControllerConfig c;
    c.type = r.Child("type").String();
    if (c.type.empty()) r.Child("type").Fail("empty; expected a controller type name");
    c.line = r.line();
    c.params = WithoutEntry(r.node(), "type");
    return c;
  }

  static LightConfig ReadLight(const ParamReader& r) {
    r.ExpectMapAnyKeys();
    LightConfig l;
    const std::string type =
        r.Has("type") ? r.Child("type").Enum({"sun", "directional", "point", "spot"}) : "point";
    std::vector<std::string_view> keys = {"name", "type", "attach", "color", "cast_shadow"};
    if (type == "sun") {
      l.type = Light::Type::kDirectional;
      keys.insert(keys.end(), {"direction", "illuminance_lux", "angular_diameter_deg"});
    } else if (type == "directional") {
      l.type = Light::Type::kDirectional;
      l.angular_diameter_deg = 0;  // an ideal distant source: hard shadows
      keys.insert(keys.end(), {"direction", "illuminance_lux"});
    } else if (type == "point") {
      l.type = Light::Type::kPoint;
      keys.insert(keys.end(), {"position", "intensity_cd", "power_w", "radius_m"});
    } else {
      l.type = Light::Type::kSpot;
      keys.insert(keys.end(), {"position", "direction", "intensity_cd", "power_w", "radius_m",
                               "inner_angle_deg", "outer_angle_deg"});
    }
    // a key of another light type gets a more helpful message than "unknown key"
    const std::vector<std::string_view> any_light_key = {
        "position", "direction",       "illuminance_lux", "intensity_cd",        "power_w",
        "radius_m", "inner_angle_deg", "outer_angle_deg", "angular_diameter_deg"};
    for (auto& [key, child] : r.Entries()) {
      const bool known =
          std::find(any_light_key.begin(), any_light_key.end(), key) != any_light_key.end();
      const bool allowed = std::find(keys.begin(), keys.end(), key) != keys.end();
      if (known && !allowed) {
        child.Fail("does not apply to a " + type + " light; expected one of: " + JoinNames(keys));
      }
    }
    r.ExpectMap(keys);

    l.name = r.Child("name").String();
    if (const auto found = r.Find("attach")) l.attach = found->String();
    if (const auto found = r.Find("position")) l.position = found->Vector3();
    if (const auto found = r.Find("direction")) l.direction = found->Vector3();
    if (const auto found = r.Find("color")) l.color = Vector3f(*found);
    if (const auto found = r.Find("illuminance_lux")) l.illuminance_lux = found->Double();
    if (const auto found = r.Find("intensity_cd")) l.intensity_cd = found->Double();
    if (const auto found = r.Find("power_w")) l.power_w = found->Double();
    if (const auto found = r.Find("inner_angle_deg")) l.inner_angle_deg = found->Double();
    if (const auto found = r.Find("outer_angle_deg")) l.outer_angle_deg = found->Double();
    if (const auto found = r.Find("radius_m")) l.radius_m = found->Double();
    if (r.Has("angular_diameter_deg")) {
      l.angular_diameter_deg = r.Child("angular_diameter_deg").Double();
    }
    if (const auto found = r.Find("cast_shadow")) l.cast_shadow = found->Bool();
    return l;
  }

  static CameraOutputs ReadOutputs(const ParamReader& r) {
    CameraOutputs o = CameraOutputs::None();
    std::vector<std::string_view> names;
    for (const ImageKindInfo& k : kImageKinds) names.push_back(k.name);
    for (const ParamReader& e : r.List()) {
      const std::string v = e.Enum(names);
      bool& flag = *o.Flag(v);
      if (flag) e.Fail("'" + v + "' is listed twice; expected each output once");
      flag = true;
    }
    return o;
  }

  // width, height, fovy_deg / intrinsics, rate_hz, outputs: shared by world cameras
  // and MJCF camera overrides.
  static void ReadCameraOptics(const ParamReader& r, CameraConfig* c) {
    if (const auto found = r.Find("width")) c->width = found->Int();
    if (const auto found = r.Find("height")) c->height = found->Int();
    if (const auto found = r.Find("fovy_deg")) c->fovy_deg = found->Double();
    if (r.Has("intrinsics")) {
      ParamReader k = r.Child("intrinsics");
      if (c->fovy_deg) k.Fail("fovy_deg and intrinsics both given; expected one of them");
      k.ExpectMap({"fx", "fy", "cx", "cy"});
      CameraIntrinsics in;
      in.width = c->width;
      in.height = c->height;
      in.fx = k.Child("fx").Double();
      in.fy = k.Child("fy").Double();
      // principal point defaults to the image centre (pixel centres at integers)
      in.cx = k.Has("cx") ? k.Child("cx").Double() : 0.5 * (c->width - 1);
      in.cy = k.Has("cy") ? k.Child("cy").Double() : 0.5 * (c->height - 1);
      c->intrinsics = in;
    }
    if (const auto found = r.Find("rate_hz")) c->rate_hz = found->Double();
    if (const auto found = r.Find("outputs")) c->outputs = ReadOutputs(*found);
    if (const auto found = r.Find("near_m")) c->near_m = found->Double();
  }

  static CameraConfig ReadCamera(const ParamReader& r) {
    std::vector<std::string_view> keys = {"name",     "attach",     "pose",    "width",   "height",
                                          "fovy_deg", "intrinsics", "rate_hz", "outputs", "near_m"};
    keys.insert(keys.end(), CameraSensorKeys().begin(), CameraSensorKeys().end());
    r.ExpectMap(keys);
    CameraConfig c;
    c.name = r.Child("name").String();
    if (const auto found = r.Find("attach")) c.attach = found->String();
    if (const auto found = r.Find("pose")) ReadPose(*found, &c.pose);
    ReadCameraOptics(r, &c);
    if (!c.fovy_deg && !c.intrinsics) c.fovy_deg = 60;
    ReadCameraSensorKeys(r, &c);
    return c;
  }

  static void ReadMjcfCameras(const ParamReader& r, MjcfCameraDefaults* m) {
    r.ExpectMap({"enabled", "width", "height", "rate_hz", "outputs", "profile", "overrides"});
    if (const auto found = r.Find("enabled")) m->enabled = found->Bool();
    if (const auto found = r.Find("profile")) m->profile = ReadCameraProfile(*found, "");
    if (const auto found = r.Find("width")) m->width = found->Int();
    if (const auto found = r.Find("height")) m->height = found->Int();
    if (const auto found = r.Find("rate_hz")) m->rate_hz = found->Double();
    if (const auto found = r.Find("outputs")) m->outputs = ReadOutputs(*found);
    if (!r.Has("overrides")) return;
    const ParamReader overrides = r.Child("overrides");
    if (overrides.node().IsMap() && overrides.size() > static_cast<size_t>(kMaxCameras))
      overrides.Fail(std::to_string(overrides.size()) + " camera overrides; expected at most " +
                     std::to_string(kMaxCameras) + " (the most cameras a world may have)");
    for (auto& [name, o] : overrides.Entries()) {
      std::vector<std::string_view> keys = {"width",    "height",     "rate_hz", "outputs",
                                            "fovy_deg", "intrinsics", "near_m"};
      keys.insert(keys.end(), CameraSensorKeys().begin(), CameraSensorKeys().end());
      o.ExpectMap(keys);
      // unset fields inherit the mjcf_cameras defaults; an unset fovy keeps the MJCF one
      CameraConfig c;
      c.name = name;
      c.is_mjcf_override = true;
      c.width = m->width;
      c.height = m->height;
      c.rate_hz = m->rate_hz;
      c.outputs = m->outputs;
      c.sensor = CameraProfileConfig(m->profile);
      ReadCameraOptics(o, &c);
      ReadCameraSensorKeys(o, &c);
      m->overrides.push_back(c);
    }
  }

  static MaterialOverride ReadMaterial(const std::string& name, const ParamReader& r) {
    r.ExpectMap({"base_color", "roughness", "metallic", "specular", "emission", "procedural"});
    MaterialOverride m;
    m.name = name;
    // checked here, read again by the session (world/procedural_material_config.h)
    if (const auto found = r.Find("procedural")) ReadProceduralMaterial(*found);
    if (const auto found = r.Find("base_color")) m.base_color = Vector3f(*found);
    if (const auto found = r.Find("roughness")) m.roughness = static_cast<float>(found->Double());
    if (const auto found = r.Find("metallic")) m.metallic = static_cast<float>(found->Double());
    if (const auto found = r.Find("specular")) m.specular = static_cast<float>(found->Double());
    if (const auto found = r.Find("emission")) m.emission = Vector3f(*found);
    return m;
  }

  std::string file_;
  LineTable* lines_;
  fs::path base_dir_;
};

std::string LowerExtension(const fs::path& p) {
  std::string ext = p.extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char ch) { return static_cast<char>(std::tolower(ch)); });
  return ext;
}

bool HasModelExtension(const fs::path& p) {
  const std::string ext = LowerExtension(p);
  return ext == ".xml" || ext == ".urdf";
}

}  // namespace

WorldConfig ParseWorld(const std::string& yaml_text, const std::string& file_name) {
  auto lines = std::make_shared<LineTable>();
  // a world file is one YAML document: a second one would be silently ignored
  YamlParseOptions options;
  options.what = "the world";
  const ConfigValue root = ParseYaml(yaml_text, file_name, options);
  WorldConfig w = WorldParser(file_name, lines.get()).Parse(root);
  ValidateWorld(w, *lines);
  w.lines = std::move(lines);
  // directions are stored as unit vectors (ValidateWorld rejected zero vectors)
  for (LightConfig& l : w.lights) {
    if (l.type != Light::Type::kPoint) l.direction.normalize();
  }
  return w;
}

WorldConfig LoadWorldFile(const std::string& path) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    throw ConfigError(
        path, 0, "",
        "world file not found: " + fs::absolute(path, ec).lexically_normal().string() +
            "; expected an existing YAML file");
  }
  return ParseWorld(ReadInputFile(path, "world file"), path);
}

ConfigError LocateInWorld(const WorldConfig& world, const ConfigError& e) {
  // errors a stage raised with no file, or with the world file but no line
  const bool unplaced = e.file().empty() || (e.file() == world.file && e.line() == 0);
  if (!unplaced || world.file.empty() || e.key().empty() || e.key().front() == '-') return e;
  const int line = world.lines ? world.lines->Find(e.key()) : 0;
  return ConfigError(world.file, line, e.key(), e.problem());
}

WorldConfig WorldForBareModel(const std::string& model_path) {
  std::error_code ec;
  const fs::path abs = fs::absolute(fs::path(model_path), ec).lexically_normal();
  if (!HasModelExtension(abs)) {
    throw ConfigError(model_path, 0, "",
                      "unknown model file extension; expected an MJCF (.xml) or URDF (.urdf) file "
                      "or a world file (.yaml)");
  }
  if (!fs::is_regular_file(abs, ec)) {
    throw ConfigError(model_path, 0, "",
                      "file not found: " + abs.string() + "; expected an existing model file");
  }

  WorldConfig w;
  w.duration_sec = 10;
  ModelConfig m;
  // the name prefixes every MJCF name: keep [A-Za-z0-9_-] of the file stem
  m.name = abs.stem().string();
  for (char& ch : m.name) {
    if (!std::isalnum(static_cast<unsigned char>(ch)) && ch != '_' && ch != '-') ch = '_';
  }
  if (m.name.empty()) m.name = "model";
  m.file = abs.string();
  m.is_robot = false;
  w.models.push_back(m);

  w.default_lights = true;
  // a URDF has no floor: give it one (a bare MJCF brings its own, or floats on purpose)
  w.ground_plane = LowerExtension(abs) == ".urdf";
  w.sky.type = Sky::Type::kDaylight;
  w.sky.turbidity = 3;
  w.sky.sun_elevation_deg = 45;
  // 60 deg to the left of the auto-framed camera (azimuth 31 deg, session/scene_assembly.h):
  // the model is lit from the front-left and its shadow falls to its right, in view.
  w.sky.sun_azimuth_deg = -29;
  w.sky.zenith_luminance_cd_m2 = 8000;

  CameraConfig cam;
  cam.name = "default";
  cam.attach = "world";
  cam.auto_frame = true;
  cam.width = 640;
  cam.height = 480;
  cam.fovy_deg = 45;
  cam.rate_hz = 30;
  cam.outputs = CameraOutputs{ImageKind::kRgb, ImageKind::kDepth, ImageKind::kSegmentation};
  w.cameras.push_back(cam);

  w.mjcf_cameras.enabled = true;
  w.render.seed = w.seed;
  w.ValidateOrThrow();
  return w;
}

}  // namespace penumbra

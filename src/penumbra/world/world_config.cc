#include "penumbra/world/world_config.h"

#include <yaml-cpp/eventhandler.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <fstream>
#include <optional>
#include <sstream>

#include "penumbra/core/error.h"
#include "penumbra/core/text_match.h"
#include "penumbra/world/adversity_preset.h"
#include "penumbra/world/agents_reader.h"
#include "penumbra/world/camera_config_reader.h"
#include "penumbra/world/effects_reader.h"
#include "penumbra/world/mesh_import_config.h"
#include "penumbra/world/procedural_material_config.h"
#include "penumbra/world/ros_config.h"
#include "penumbra/world/world_validation.h"
#include "penumbra/world/yaml_reader.h"

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

  WorldConfig Parse(const YAML::Node& root) {
    YamlReader r(root, file_, lines_);
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
    if (r.Has("seed")) w.seed = r.Child("seed").Uint64();
    if (r.Has("duration_sec")) w.duration_sec = r.Child("duration_sec").Double();
    if (r.Has("physics")) {
      YamlReader p = r.Child("physics");
      p.ExpectMap({"timestep_sec", "integrator", "gravity_mps2", "solver_iterations", "cone"});
      if (p.Has("timestep_sec")) w.timestep_sec = p.Child("timestep_sec").Double();
      if (p.Has("integrator")) {
        const YamlReader i = p.Child("integrator");
        if (i.String() == "implicitfast") {
          i.Fail(
              "'implicitfast' is newer than MuJoCo 2.2.2 (Penumbra's physics); expected one of: "
              "Euler, RK4, implicit (implicit is implicitfast with the Coriolis terms kept)");
        }
        w.physics.integrator = i.Enum({"Euler", "RK4", "implicit"});
      }
      if (p.Has("gravity_mps2")) w.physics.gravity_mps2 = p.Child("gravity_mps2").Vector3();
      if (p.Has("solver_iterations")) {
        w.physics.solver_iterations = p.Child("solver_iterations").Int();
      }
      if (p.Has("cone")) w.physics.cone = p.Child("cone").Enum({"pyramidal", "elliptic"});
    }
    if (r.Has("render")) ReadRender(r.Child("render"), &w.render);
    w.render.seed = w.seed;
    if (r.Has("sky")) ReadSky(r.Child("sky"), &w.sky);
    // robots first, then static models, each in file order
    if (r.Has("robots")) {
      for (const YamlReader& m : r.Child("robots").List()) w.models.push_back(ReadModel(m, true));
    }
    if (r.Has("models")) {
      for (const YamlReader& m : r.Child("models").List()) w.models.push_back(ReadModel(m, false));
    }
    if (r.Has("sensors")) w.sensors = ReadSensors(r.Child("sensors"), file_, "");
    if (r.Has("robots")) {
      for (const YamlReader& m : r.Child("robots").List())
        if (m.Has("sensors")) {
          const auto robot = ReadSensors(m.Child("sensors"), file_, m.Child("name").String());
          w.sensors.insert(w.sensors.end(), robot.begin(), robot.end());
        }
    }
    ValidateSensorNames(w.sensors);
    if (r.Has("lights")) {
      for (const YamlReader& l : r.Child("lights").List()) w.lights.push_back(ReadLight(l));
    }
    if (r.Has("cameras")) {
      for (const YamlReader& c : r.Child("cameras").List()) w.cameras.push_back(ReadCamera(c));
    }
    if (r.Has("mjcf_cameras")) ReadMjcfCameras(r.Child("mjcf_cameras"), &w.mjcf_cameras);
    if (r.Has("materials")) {
      for (auto& [name, m] : r.Child("materials").Entries())
        w.materials.push_back(ReadMaterial(name, m));
    }
    if (r.Has("output")) {
      YamlReader o = r.Child("output");
      o.ExpectMap({"dir"});
      if (o.Has("dir")) w.output_dir = o.Child("dir").String();
    }
    if (r.Has("record")) {
      YamlReader rec = r.Child("record");
      rec.ExpectMap({"file", "sensors"});
      if (!rec.Has("file")) rec.Fail("no 'file'; expected record: {file: NAME.plog}");
      w.record.file = rec.Child("file").String();
      // `record: {file: ""}` used to record nothing without a word
      if (w.record.file.empty())
        rec.Child("file").Fail("empty; expected a file name ending in .plog");
      if (rec.Has("sensors")) w.record.sensors = rec.Child("sensors").Bool();
    }
    if (r.Has("semantic_classes"))
      w.semantic_classes = ReadSemanticClasses(r.Child("semantic_classes"));
    if (r.Has("agents")) w.agents = ReadAgents(r.Child("agents"), file_);
    if (r.Has("effects")) w.effects = ReadEffects(r.Child("effects"), file_);
    if (r.Has("metrics")) w.metrics = ReadMetrics(r.Child("metrics"));
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
      const YamlReader a = r.Child("adversity");
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

  static void ReadPose(const YamlReader& r, PoseConfig* pose) {
    r.ExpectMap({"xyz", "rpy_deg"});
    if (r.Has("xyz")) pose->xyz = r.Child("xyz").Vector3();
    if (r.Has("rpy_deg")) pose->rpy_deg = r.Child("rpy_deg").Vector3();
  }

  static Eigen::Vector3f Vector3f(const YamlReader& r) { return r.Vector3().cast<float>(); }

  static void ReadRender(const YamlReader& r, RenderSettings* s) {
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
    if (r.Has("samples_per_pixel")) s->samples_per_pixel = r.Child("samples_per_pixel").Int();
    if (r.Has("max_bounces")) s->max_bounces = r.Child("max_bounces").Int();
    if (r.Has("denoise")) s->denoise = r.Child("denoise").Bool();
    if (r.Has("threads")) s->threads = r.Child("threads").Int();
    if (r.Has("max_anisotropy")) s->max_anisotropy = r.Child("max_anisotropy").Int();
    if (r.Has("exposure")) {
      YamlReader e = r.Child("exposure");
      e.ExpectMap({"mode", "ev100", "compensation_ev"});
      if (e.Has("mode")) s->auto_exposure = e.Child("mode").Enum({"auto", "manual"}) == "auto";
      if (e.Has("ev100")) s->ev100 = e.Child("ev100").Double();
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

  static void ReadSky(const YamlReader& r, SkyConfig* s) {
    r.ExpectMap({"type", "color", "luminance_cd_m2", "turbidity", "sun_elevation_deg",
                 "sun_azimuth_deg", "zenith_luminance_cd_m2"});
    if (r.Has("type")) {
      s->type = r.Child("type").Enum({"uniform", "daylight"}) == "uniform" ? Sky::Type::kUniform
                                                                           : Sky::Type::kDaylight;
    }
    if (r.Has("color")) s->color = Vector3f(r.Child("color"));
    if (r.Has("luminance_cd_m2")) s->luminance_cd_m2 = r.Child("luminance_cd_m2").Double();
    if (r.Has("turbidity")) s->turbidity = r.Child("turbidity").Double();
    if (r.Has("sun_elevation_deg")) s->sun_elevation_deg = r.Child("sun_elevation_deg").Double();
    if (r.Has("sun_azimuth_deg")) s->sun_azimuth_deg = r.Child("sun_azimuth_deg").Double();
    if (r.Has("zenith_luminance_cd_m2")) {
      s->zenith_luminance_cd_m2 = r.Child("zenith_luminance_cd_m2").Double();
    }
  }

  ModelConfig ReadModel(const YamlReader& r, bool is_robot) const {
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
      if (r.Has("file")) r.Child("file").Fail("expected either file or environment, not both");
      for (std::string_view k : {"sites", "initial_keyframe", "floating_base"})
        if (r.Has(k)) r.Child(k).Fail("not allowed with environment: (a generated building)");
      for (std::string_view k : MeshImportKeys())
        if (r.Has(k)) r.Child(k).Fail("applies to mesh files only, not to environment:");
      m.environment = ReadEnvironmentConfig(r.Child("environment"));
      if (r.Has("pose")) ReadPose(r.Child("pose"), &m.pose);
      return m;
    }
    if (!r.Has("file") && !is_robot)
      r.Fail("expected file (an MJCF, URDF or mesh file) or environment (a generated building)");
    m.file = Resolve(r.Child("file").String());
    // checked here, read again by the session (world/mesh_import_config.h)
    MeshImportConfig mesh;
    ReadMeshImportKeys(r, IsMeshModelFile(m.file), &mesh);
    if (r.Has("pose")) ReadPose(r.Child("pose"), &m.pose);
    if (r.Has("floating_base")) m.floating_base = r.Child("floating_base").Bool();
    if (r.Has("initial_keyframe")) {
      m.initial_keyframe = r.Child("initial_keyframe").String();
      if (m.initial_keyframe.empty())
        r.Child("initial_keyframe").Fail("empty; expected the name of one of the model's <key>s");
    }
    if (r.Has("sites")) {
      for (const YamlReader& s : r.Child("sites").List()) {
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
        if (s.Has("body")) site.body = s.Child("body").String();
        if (s.Has("geom")) site.geom = s.Child("geom").String();
        if (s.Has("pose")) ReadPose(s.Child("pose"), &site.pose);
        for (const SiteConfig& other : m.sites)
          if (other.name == site.name)
            s.Child("name").Fail("duplicate site '" + site.name + "'; expected unique names");
        m.sites.push_back(site);
      }
    }
    if (r.Has("controller")) m.controller = ReadController(r.Child("controller"));
    return m;
  }

  // `type` picks the controller; the rest of the mapping stays YAML nodes for it.
  static ControllerConfig ReadController(const YamlReader& r) {
    r.ExpectMapAnyKeys();
    ControllerConfig c;
    c.type = r.Child("type").String();
    if (c.type.empty()) r.Child("type").Fail("empty; expected a controller type name");
    c.line = r.line();
    c.params = YAML::Node(YAML::NodeType::Map);
    for (auto it = r.node().begin(); it != r.node().end(); ++it)
      if (it->first.Scalar() != "type") c.params.node().force_insert(it->first, it->second);
    return c;
  }

  static LightConfig ReadLight(const YamlReader& r) {
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
    if (r.Has("attach")) l.attach = r.Child("attach").String();
    if (r.Has("position")) l.position = r.Child("position").Vector3();
    if (r.Has("direction")) l.direction = r.Child("direction").Vector3();
    if (r.Has("color")) l.color = Vector3f(r.Child("color"));
    if (r.Has("illuminance_lux")) l.illuminance_lux = r.Child("illuminance_lux").Double();
    if (r.Has("intensity_cd")) l.intensity_cd = r.Child("intensity_cd").Double();
    if (r.Has("power_w")) l.power_w = r.Child("power_w").Double();
    if (r.Has("inner_angle_deg")) l.inner_angle_deg = r.Child("inner_angle_deg").Double();
    if (r.Has("outer_angle_deg")) l.outer_angle_deg = r.Child("outer_angle_deg").Double();
    if (r.Has("radius_m")) l.radius_m = r.Child("radius_m").Double();
    if (r.Has("angular_diameter_deg")) {
      l.angular_diameter_deg = r.Child("angular_diameter_deg").Double();
    }
    if (r.Has("cast_shadow")) l.cast_shadow = r.Child("cast_shadow").Bool();
    return l;
  }

  static CameraOutputs ReadOutputs(const YamlReader& r) {
    CameraOutputs o = CameraOutputs::None();
    std::vector<std::string_view> names;
    for (const ImageKindInfo& k : kImageKinds) names.push_back(k.name);
    for (const YamlReader& e : r.List()) {
      const std::string v = e.Enum(names);
      bool& flag = *o.Flag(v);
      if (flag) e.Fail("'" + v + "' is listed twice; expected each output once");
      flag = true;
    }
    return o;
  }

  // width, height, fovy_deg / intrinsics, rate_hz, outputs: shared by world cameras
  // and MJCF camera overrides.
  static void ReadCameraOptics(const YamlReader& r, CameraConfig* c) {
    if (r.Has("width")) c->width = r.Child("width").Int();
    if (r.Has("height")) c->height = r.Child("height").Int();
    if (r.Has("fovy_deg")) c->fovy_deg = r.Child("fovy_deg").Double();
    if (r.Has("intrinsics")) {
      YamlReader k = r.Child("intrinsics");
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
    if (r.Has("rate_hz")) c->rate_hz = r.Child("rate_hz").Double();
    if (r.Has("outputs")) c->outputs = ReadOutputs(r.Child("outputs"));
    if (r.Has("near_m")) c->near_m = r.Child("near_m").Double();
  }

  static CameraConfig ReadCamera(const YamlReader& r) {
    std::vector<std::string_view> keys = {"name",     "attach",     "pose",    "width",   "height",
                                          "fovy_deg", "intrinsics", "rate_hz", "outputs", "near_m"};
    keys.insert(keys.end(), CameraSensorKeys().begin(), CameraSensorKeys().end());
    r.ExpectMap(keys);
    CameraConfig c;
    c.name = r.Child("name").String();
    if (r.Has("attach")) c.attach = r.Child("attach").String();
    if (r.Has("pose")) ReadPose(r.Child("pose"), &c.pose);
    ReadCameraOptics(r, &c);
    if (!c.fovy_deg && !c.intrinsics) c.fovy_deg = 60;
    ReadCameraSensorKeys(r, &c);
    return c;
  }

  static void ReadMjcfCameras(const YamlReader& r, MjcfCameraDefaults* m) {
    r.ExpectMap({"enabled", "width", "height", "rate_hz", "outputs", "overrides"});
    if (r.Has("enabled")) m->enabled = r.Child("enabled").Bool();
    if (r.Has("width")) m->width = r.Child("width").Int();
    if (r.Has("height")) m->height = r.Child("height").Int();
    if (r.Has("rate_hz")) m->rate_hz = r.Child("rate_hz").Double();
    if (r.Has("outputs")) m->outputs = ReadOutputs(r.Child("outputs"));
    if (!r.Has("overrides")) return;
    for (auto& [name, o] : r.Child("overrides").Entries()) {
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
      ReadCameraOptics(o, &c);
      ReadCameraSensorKeys(o, &c);
      m->overrides.push_back(c);
    }
  }

  static MaterialOverride ReadMaterial(const std::string& name, const YamlReader& r) {
    r.ExpectMap({"base_color", "roughness", "metallic", "specular", "emission", "procedural"});
    MaterialOverride m;
    m.name = name;
    // checked here, read again by the session (world/procedural_material_config.h)
    if (r.Has("procedural")) ReadProceduralMaterial(r.Child("procedural"));
    if (r.Has("base_color")) m.base_color = Vector3f(r.Child("base_color"));
    if (r.Has("roughness")) m.roughness = static_cast<float>(r.Child("roughness").Double());
    if (r.Has("metallic")) m.metallic = static_cast<float>(r.Child("metallic").Double());
    if (r.Has("specular")) m.specular = static_cast<float>(r.Child("specular").Double());
    if (r.Has("emission")) m.emission = Vector3f(r.Child("emission"));
    return m;
  }

  std::string file_;
  LineTable* lines_;
  fs::path base_dir_;
};

int ConfigMarkLine(const YAML::Mark& mark) { return mark.is_null() ? 0 : mark.line + 1; }

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

// counts the documents of a YAML stream without building nodes; a document that holds only a
// null (a trailing '---') does not count
class YamlDocumentCounter : public YAML::EventHandler {
 public:
  void OnDocumentStart(const YAML::Mark&) override { content_ = false; }
  void OnDocumentEnd() override {
    if (content_) marks.push_back(mark_);
  }
  void OnNull(const YAML::Mark&, YAML::anchor_t) override {}
  void OnAlias(const YAML::Mark& mark, YAML::anchor_t) override { Content(mark); }
  void OnScalar(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                const std::string&) override {
    Content(mark);
  }
  void OnSequenceStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                       YAML::EmitterStyle::value) override {
    Content(mark);
  }
  void OnSequenceEnd() override {}
  void OnMapStart(const YAML::Mark& mark, const std::string&, YAML::anchor_t,
                  YAML::EmitterStyle::value) override {
    Content(mark);
  }
  void OnMapEnd() override {}

  /// where the root node of each document with content starts
  std::vector<YAML::Mark> marks;

 private:
  void Content(const YAML::Mark& mark) {
    if (!content_) mark_ = mark;
    content_ = true;
  }
  YAML::Mark mark_;
  bool content_ = false;
};

// where the second YAML document with content starts, if there is one. at most
// kMaxYamlDocuments documents are read (an endless stream of empty documents is cut there)
std::optional<YAML::Mark> SecondYamlDocument(const std::string& text) {
  std::istringstream in(text);
  YAML::Parser parser(in);
  YamlDocumentCounter counter;
  for (int d = 0; d < kMaxYamlDocuments && counter.marks.size() < 2; ++d)
    if (!parser.HandleNextDocument(counter)) break;
  if (counter.marks.size() >= 2) return counter.marks[1];
  return std::nullopt;
}

}  // namespace

WorldConfig ParseWorld(const std::string& yaml_text, const std::string& file_name) {
  auto lines = std::make_shared<LineTable>();
  WorldConfig w;
  try {
    // a world file is one YAML document: a second one would be silently ignored. the
    // documents are counted with a bounded loop, not YAML::LoadAll: yaml-cpp 0.7's LoadAll
    // never ends on some 7-byte inputs (",sn\xd4 !:" yields empty documents for ever, found by
    // fuzz/world_fuzz.cc), taking all memory
    if (const std::optional<YAML::Mark> second = SecondYamlDocument(yaml_text))
      throw ConfigError(file_name, ConfigMarkLine(*second), "",
                        "a second YAML document (after '---'); expected the world in one "
                        "document");
    RefuseYamlTags(yaml_text, file_name);
    const YAML::Node root = YAML::Load(yaml_text);
    w = WorldParser(file_name, lines.get()).Parse(root);
  } catch (const YAML::ParserException& e) {
    throw ConfigError(file_name, ConfigMarkLine(e.mark), "", "YAML syntax error: " + e.msg);
  } catch (const YAML::Exception& e) {
    // any other yaml-cpp failure still names the file (and line when yaml-cpp knows it)
    throw ConfigError(file_name, ConfigMarkLine(e.mark), "",
                      "cannot read the YAML document: " + e.msg);
  }
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
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in) throw ConfigError(path, 0, "", "cannot read the world file; expected a readable file");
  return ParseWorld(text.str(), path);
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

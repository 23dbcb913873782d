#include "penumbra/world/effects_reader.h"

#include <filesystem>

#include "penumbra/core/error.h"

namespace fs = std::filesystem;

namespace penumbra {

namespace {

const std::vector<std::string_view> kCommonKeys = {
    "name", "type", "start_sec", "stop_sec", "fade_in_sec", "fade_out_sec", "region"};
const std::vector<std::string_view> kFluidKeys = {
    "resolution",        "dt_sec",        "jacobi_iterations",     "buoyancy_m_s2",  "weight_m_s2",
    "dissipation_per_s", "cooling_per_s", "ambient_temperature_k", "turbulence_m_s", "emitters"};

// the parameter keys of each type, in EffectType order.
std::vector<std::string_view> TypeKeys(EffectType t) {
  auto with_fluid = [](std::vector<std::string_view> k) {
    k.insert(k.end(), kFluidKeys.begin(), kFluidKeys.end());
    return k;
  };
  switch (t) {
    case EffectType::kFog:
      return {"sigma_t_per_m", "mor_m", "albedo", "g", "height_falloff_per_m", "base_height_m"};
    case EffectType::kDust:
      return {"sigma_t_per_m", "mor_m", "color", "g", "height_falloff_per_m", "base_height_m"};
    case EffectType::kSmoke:
      return with_fluid({"mode", "density_scale_per_m", "albedo", "g", "wind_m_s",
                         "noise_resolution", "noise_scale_m", "octaves", "coverage",
                         "evolution_per_s"});
    case EffectType::kVdbSmoke:
      return {"file", "grid", "max_resolution", "density_scale_per_m", "albedo", "g"};
    case EffectType::kFire:
      return with_fluid({"density_scale_per_m", "absorption_per_m", "albedo",
                         "min_emission_temperature_k", "glow_light", "glow_light_radius_m"});
    case EffectType::kRain:
      return {
          "rate_mm_h",     "wind_m_s", "min_diameter_mm", "max_diameter_mm", "box_half_extents_m",
          "max_particles", "color"};
    case EffectType::kSnow:
      return {"rate_mm_h",          "flake_diameter_mm", "flake_density_kg_m3",
              "wind_m_s",           "turbulence_m_s",    "drift_frequency_hz",
              "box_half_extents_m", "max_particles",     "color"};
    case EffectType::kSparks:
      return {"fire",         "position",     "rate_per_s", "speed_m_s",     "spread_deg",
              "lifetime_sec", "gravity_m_s2", "radius_m",   "temperature_k", "luminance_cd_m2"};
    case EffectType::kLightEvent:
      return {"light",     "mode",        "frequency_hz",
              "depth",     "duty_cycle",  "failure_probability",
              "min_scale", "recovery_sec"};
    case EffectType::kFlashlight:
      return {"waypoints",       "attach",          "position", "direction", "intensity_cd",
              "inner_angle_deg", "outer_angle_deg", "color",    "radius_m"};
    case EffectType::kSun:
      return {"latitude_deg", "longitude_deg", "year", "month", "day", "time_utc_h", "time_scale"};
    case EffectType::kWetness:
      return {"rain", "wetting_time_sec", "drying_time_sec", "max_wetness"};
  }
  return {};
}

// typed reads of optional keys that also remember each key's line.
class EntryReader {
 public:
  EntryReader(const YamlReader& r, LineTable* lines) : r_(r), lines_(lines) {}
  const YamlReader& reader() const { return r_; }

  bool Has(std::string_view k) const { return r_.Has(k); }
  YamlReader Child(std::string_view k) const {
    YamlReader c = r_.Child(k);
    lines_->Record(c.path(), c.line());
    return c;
  }
  void Num(std::string_view k, double* v) const {
    if (Has(k)) *v = Child(k).Double();
  }
  void Int(std::string_view k, int* v) const {
    if (Has(k)) *v = Child(k).Int();
  }
  void Vec(std::string_view k, Eigen::Vector3d* v) const {
    if (Has(k)) *v = Child(k).Vector3();
  }
  void Str(std::string_view k, std::string* v) const {
    if (Has(k)) *v = Child(k).String();
  }
  void Bool(std::string_view k, bool* v) const {
    if (Has(k)) *v = Child(k).Bool();
  }
  void Extinction(ExtinctionSpec* e) const {
    if (Has("sigma_t_per_m")) e->sigma_t_per_m = Child("sigma_t_per_m").Double();
    if (Has("mor_m")) e->mor_m = Child("mor_m").Double();
  }
  void Fluid(FluidParams* f) const {
    Int("resolution", &f->resolution);
    Num("dt_sec", &f->dt_sec);
    Int("jacobi_iterations", &f->jacobi_iterations);
    Num("buoyancy_m_s2", &f->buoyancy_m_s2);
    Num("weight_m_s2", &f->weight_m_s2);
    Num("dissipation_per_s", &f->dissipation_per_s);
    Num("cooling_per_s", &f->cooling_per_s);
    Num("ambient_temperature_k", &f->ambient_temperature_k);
    Num("turbulence_m_s", &f->turbulence_m_s);
    if (Has("emitters")) {
      f->emitters.clear();
      for (const YamlReader& er : Child("emitters").List()) {
        lines_->Record(er.path(), er.line());
        er.ExpectMap({"position", "radius_m", "rate", "temperature_k"});
        EntryReader e(er, lines_);
        PlumeEmitter em;
        if (!e.Has("position")) e.Child("position");  // throws "required key is missing"
        e.Vec("position", &em.position_W);
        e.Num("radius_m", &em.radius_m);
        e.Num("rate", &em.rate);
        e.Num("temperature_k", &em.temperature_k);
        f->emitters.push_back(em);
      }
    }
  }

 private:
  YamlReader r_;
  LineTable* lines_;
};

EffectConfig ReadEffect(const YamlReader& r, const fs::path& base_dir, LineTable* lines) {
  r.ExpectMapAnyKeys();
  lines->Record(r.path(), r.line());
  EntryReader e(r, lines);
  EffectConfig c;
  c.name = e.Child("name").String();
  std::vector<std::string_view> type_names;
  for (const std::string& n : EffectTypeNames()) type_names.push_back(n);
  const std::string type = e.Child("type").Enum(type_names);
  for (size_t t = 0; t < type_names.size(); ++t)
    if (type_names[t] == type) c.type = static_cast<EffectType>(t);
  std::vector<std::string_view> keys = kCommonKeys;
  const std::vector<std::string_view> tk = TypeKeys(c.type);
  keys.insert(keys.end(), tk.begin(), tk.end());
  r.ExpectMap(keys);

  e.Num("start_sec", &c.start_sec);
  e.Num("stop_sec", &c.stop_sec);
  e.Num("fade_in_sec", &c.fade_in_sec);
  e.Num("fade_out_sec", &c.fade_out_sec);
  if (e.Has("region")) {
    const YamlReader rr = e.Child("region");
    rr.ExpectMap({"min", "max"});
    EntryReader re(rr, lines);
    BoxRegion b;
    b.min_W = re.Child("min").Vector3();
    b.max_W = re.Child("max").Vector3();
    c.region = b;
  }

  switch (c.type) {
    case EffectType::kFog:
      e.Extinction(&c.fog.extinction);
      e.Vec("albedo", &c.fog.albedo);
      e.Num("g", &c.fog.g);
      e.Num("height_falloff_per_m", &c.fog.height_falloff_per_m);
      e.Num("base_height_m", &c.fog.base_height_m);
      break;
    case EffectType::kDust:
      e.Extinction(&c.dust.extinction);
      e.Vec("color", &c.dust.color);
      e.Num("g", &c.dust.g);
      e.Num("height_falloff_per_m", &c.dust.height_falloff_per_m);
      e.Num("base_height_m", &c.dust.base_height_m);
      break;
    case EffectType::kSmoke: {
      SmokeParams& s = c.smoke;
      if (e.Has("mode")) {
        s.mode = e.Child("mode").Enum({"noise", "plume"}) == "noise" ? SmokeParams::Mode::kNoise
                                                                     : SmokeParams::Mode::kPlume;
      }
      e.Num("density_scale_per_m", &s.density_scale_per_m);
      e.Vec("albedo", &s.albedo);
      e.Num("g", &s.g);
      e.Vec("wind_m_s", &s.wind_m_s);
      e.Int("noise_resolution", &s.noise_resolution);
      e.Num("noise_scale_m", &s.noise_scale_m);
      e.Int("octaves", &s.octaves);
      e.Num("coverage", &s.coverage);
      e.Num("evolution_per_s", &s.evolution_per_s);
      e.Fluid(&s.fluid);
      break;
    }
    case EffectType::kVdbSmoke: {
      VdbSmokeParams& v = c.vdb_smoke;
      e.Str("file", &v.file);
      if (!v.file.empty()) {
        fs::path p(v.file);
        if (p.is_relative()) p = base_dir / p;
        v.file = p.lexically_normal().string();
      }
      e.Str("grid", &v.grid);
      e.Int("max_resolution", &v.max_resolution);
      e.Num("density_scale_per_m", &v.density_scale_per_m);
      e.Vec("albedo", &v.albedo);
      e.Num("g", &v.g);
      break;
    }
    case EffectType::kFire: {
      FireParams& f = c.fire;
      e.Fluid(&f.fluid);
      e.Num("density_scale_per_m", &f.density_scale_per_m);
      e.Num("absorption_per_m", &f.absorption_per_m);
      e.Vec("albedo", &f.albedo);
      e.Num("min_emission_temperature_k", &f.min_emission_temperature_k);
      e.Bool("glow_light", &f.glow_light);
      e.Num("glow_light_radius_m", &f.glow_light_radius_m);
      break;
    }
    case EffectType::kRain: {
      RainParams& p = c.rain;
      e.Num("rate_mm_h", &p.rate_mm_h);
      e.Vec("wind_m_s", &p.wind_m_s);
      e.Num("min_diameter_mm", &p.min_diameter_mm);
      e.Num("max_diameter_mm", &p.max_diameter_mm);
      e.Vec("box_half_extents_m", &p.box_half_extents_m);
      e.Int("max_particles", &p.max_particles);
      e.Vec("color", &p.color);
      break;
    }
    case EffectType::kSnow: {
      SnowParams& p = c.snow;
      e.Num("rate_mm_h", &p.rate_mm_h);
      e.Num("flake_diameter_mm", &p.flake_diameter_mm);
      e.Num("flake_density_kg_m3", &p.flake_density_kg_m3);
      e.Vec("wind_m_s", &p.wind_m_s);
      e.Num("turbulence_m_s", &p.turbulence_m_s);
      e.Num("drift_frequency_hz", &p.drift_frequency_hz);
      e.Vec("box_half_extents_m", &p.box_half_extents_m);
      e.Int("max_particles", &p.max_particles);
      e.Vec("color", &p.color);
      break;
    }
    case EffectType::kSparks: {
      SparksParams& p = c.sparks;
      e.Str("fire", &p.fire);
      e.Vec("position", &p.position_W);
      e.Num("rate_per_s", &p.rate_per_s);
      e.Num("speed_m_s", &p.speed_m_s);
      e.Num("spread_deg", &p.spread_deg);
      e.Num("lifetime_sec", &p.lifetime_sec);
      e.Num("gravity_m_s2", &p.gravity_m_s2);
      e.Num("radius_m", &p.radius_m);
      e.Num("temperature_k", &p.temperature_k);
      e.Num("luminance_cd_m2", &p.luminance_cd_m2);
      break;
    }
    case EffectType::kLightEvent: {
      LightEventParams& p = c.light_event;
      p.light = e.Child("light").String();
      if (e.Has("mode")) {
        const std::string m = e.Child("mode").Enum({"flicker", "failing", "strobe", "blackout"});
        p.mode = m == "flicker"   ? LightEventParams::Mode::kFlicker
                 : m == "failing" ? LightEventParams::Mode::kFailing
                 : m == "strobe"  ? LightEventParams::Mode::kStrobe
                                  : LightEventParams::Mode::kBlackout;
      }
      e.Num("frequency_hz", &p.frequency_hz);
      e.Num("depth", &p.depth);
      e.Num("duty_cycle", &p.duty_cycle);
      e.Num("failure_probability", &p.failure_probability);
      e.Num("min_scale", &p.min_scale);
      e.Num("recovery_sec", &p.recovery_sec);
      break;
    }
    case EffectType::kFlashlight: {
      FlashlightParams& p = c.flashlight;
      if (e.Has("waypoints")) {
        for (const YamlReader& wr : e.Child("waypoints").List()) {
          lines->Record(wr.path(), wr.line());
          wr.ExpectMap({"t_sec", "position", "direction"});
          EntryReader w(wr, lines);
          FlashlightWaypoint wp;
          wp.t_sec = w.Child("t_sec").Double();
          wp.position_W = w.Child("position").Vector3();
          w.Vec("direction", &wp.direction_W);
          p.waypoints.push_back(wp);
        }
      }
      e.Str("attach", &p.attach);
      e.Vec("position", &p.position_B);
      e.Vec("direction", &p.direction_B);
      e.Num("intensity_cd", &p.intensity_cd);
      e.Num("inner_angle_deg", &p.inner_angle_deg);
      e.Num("outer_angle_deg", &p.outer_angle_deg);
      e.Vec("color", &p.color);
      e.Num("radius_m", &p.radius_m);
      break;
    }
    case EffectType::kSun: {
      SunParams& p = c.sun;
      e.Num("latitude_deg", &p.latitude_deg);
      e.Num("longitude_deg", &p.longitude_deg);
      e.Int("year", &p.year);
      e.Int("month", &p.month);
      e.Int("day", &p.day);
      e.Num("time_utc_h", &p.time_utc_h);
      e.Num("time_scale", &p.time_scale);
      break;
    }
    case EffectType::kWetness: {
      WetnessParams& p = c.wetness;
      e.Str("rain", &p.rain);
      e.Num("wetting_time_sec", &p.wetting_time_sec);
      e.Num("drying_time_sec", &p.drying_time_sec);
      e.Num("max_wetness", &p.max_wetness);
      break;
    }
  }
  return c;
}

}  // namespace

std::vector<EffectConfig> ReadEffects(const YamlReader& list, const std::string& file) {
  std::error_code ec;
  const fs::path abs =
      file.empty() ? fs::current_path(ec) / "world.yaml" : fs::absolute(fs::path(file), ec);
  const fs::path base_dir = abs.parent_path();
  LineTable lines;
  lines.Record(list.path(), list.line());
  std::vector<EffectConfig> out;
  for (const YamlReader& r : list.List()) out.push_back(ReadEffect(r, base_dir, &lines));
  // ranges and cross-effect rules, with the line of the offending key
  ValidateEffectsOrThrow(out, file, [&](const std::string& key) { return lines.Find(key); });
  return out;
}

}  // namespace penumbra

#include "penumbra/effects/effect_config.h"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <filesystem>
#include <map>
#include <sstream>

#include "penumbra/core/error.h"

namespace penumbra {

namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();

std::string Num(double v) {
  char buf[64];
  auto r = std::to_chars(buf, buf + sizeof(buf), v);
  return std::string(buf, r.ptr);
}

std::string Vec(const Eigen::Vector3d& v) {
  std::string s = "[";
  s += Num(v[0]);
  s += ", ";
  s += Num(v[1]);
  s += ", ";
  s += Num(v[2]);
  s += "]";
  return s;
}

// an interval of valid values; open ends exclude the bound.
struct Range {
  double lo = -kInf, hi = kInf;
  bool lo_open = true, hi_open = true;

  static Range Closed(double lo, double hi) { return {lo, hi, false, false}; }
  static Range OpenClosed(double lo, double hi) { return {lo, hi, true, false}; }
  static Range ClosedOpen(double lo, double hi) { return {lo, hi, false, true}; }
  static Range Open(double lo, double hi) { return {lo, hi, true, true}; }
  static Range AtLeast(double lo) { return {lo, kInf, false, true}; }
  static Range Above(double lo) { return {lo, kInf, true, true}; }
  static Range Finite() { return {-kInf, kInf, true, true}; }

  bool Contains(double v) const {
    if (std::isnan(v)) return false;
    if (std::isinf(v) && !(v == hi && !hi_open)) return false;
    return (lo_open ? v > lo : v >= lo) && (hi_open ? v < hi : v <= hi);
  }
  std::string ToString() const {
    if (lo == -kInf && hi == kInf) return "a finite number";
    if (hi == kInf) return (lo_open ? "> " : ">= ") + Num(lo);
    return std::string(lo_open ? "(" : "[") + Num(lo) + ", " + Num(hi) + (hi_open ? ")" : "]");
  }
};

// collects the first problem of an effect.
class Checker {
 public:
  bool ok() const { return !problem_; }
  std::optional<EffectConfig::Problem> problem() const { return problem_; }

  void Fail(const std::string& key, const std::string& message) {
    if (!problem_) problem_ = EffectConfig::Problem{key, message};
  }
  void In(const std::string& key, double v, Range r) {
    if (!r.Contains(v)) Fail(key, Num(v) + " is out of range; expected " + r.ToString());
  }
  void In3(const std::string& key, const Eigen::Vector3d& v, Range r) {
    for (int i = 0; i < 3; ++i) {
      if (!r.Contains(v[i])) {
        Fail(key, Vec(v) + " is out of range; expected 3 numbers, each " + r.ToString());
        return;
      }
    }
  }
  void Extinction(const std::string& prefix, const ExtinctionSpec& e) {
    if (e.sigma_t_per_m && e.mor_m) {
      Fail(prefix + ".mor_m", "both sigma_t_per_m and mor_m are set; expected exactly one");
    } else if (!e.sigma_t_per_m && !e.mor_m) {
      Fail(prefix + ".mor_m",
           "neither sigma_t_per_m nor mor_m is set; expected exactly one (extinction 1/m or "
           "meteorological optical range m)");
    } else if (e.sigma_t_per_m) {
      In(prefix + ".sigma_t_per_m", *e.sigma_t_per_m, Range::OpenClosed(0, 1e3));
    } else {
      In(prefix + ".mor_m", *e.mor_m, Range::AtLeast(1e-3));
    }
  }
  void Phase(const std::string& key, double g) { In(key, g, Range::Open(-1, 1)); }
  void Fluid(const std::string& p, const FluidParams& f, const std::optional<BoxRegion>& region) {
    In(p + ".resolution", f.resolution, Range::Closed(8, 128));
    In(p + ".dt_sec", f.dt_sec, Range::Closed(FluidParams::kMinDtSec, FluidParams::kMaxDtSec));
    In(p + ".jacobi_iterations", f.jacobi_iterations, Range::Closed(1, 200));
    In(p + ".buoyancy_m_s2", f.buoyancy_m_s2, Range::AtLeast(0));
    In(p + ".weight_m_s2", f.weight_m_s2, Range::AtLeast(0));
    In(p + ".dissipation_per_s", f.dissipation_per_s, Range::AtLeast(0));
    In(p + ".cooling_per_s", f.cooling_per_s, Range::AtLeast(0));
    In(p + ".ambient_temperature_k", f.ambient_temperature_k, Range::Closed(200, 400));
    In(p + ".turbulence_m_s", f.turbulence_m_s, Range::Closed(0, 20));
    if (f.emitters.empty()) {
      Fail(p + ".emitters", "no emitters; expected a list of at least one emitter");
    }
    for (size_t i = 0; i < f.emitters.size(); ++i) {
      const PlumeEmitter& e = f.emitters[i];
      const std::string k = p + ".emitters[" + std::to_string(i) + "]";
      In3(k + ".position", e.position_W, Range::Finite());
      In(k + ".radius_m", e.radius_m, Range::Above(0));
      In(k + ".rate", e.rate, Range::AtLeast(0));
      In(k + ".temperature_k", e.temperature_k, Range::Closed(300, 4000));
      if (ok() && region) {
        const Eigen::Vector3d& p0 = e.position_W;
        if ((p0.array() < region->min_W.array()).any() ||
            (p0.array() > region->max_W.array()).any()) {
          Fail(k + ".position", "emitter lies outside the effect's region; expected a point in [" +
                                    Num(region->min_W.x()) + ", " + Num(region->max_W.x()) +
                                    "] x [" + Num(region->min_W.y()) + ", " +
                                    Num(region->max_W.y()) + "] x [" + Num(region->min_W.z()) +
                                    ", " + Num(region->max_W.z()) + "]");
        }
      }
    }
  }

 private:
  std::optional<EffectConfig::Problem> problem_;
};

bool IsValidName(const std::string& name) {
  if (name.empty()) return false;
  return std::all_of(name.begin(), name.end(), [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-';
  });
}

}  // namespace

const std::vector<std::string>& EffectTypeNames() {
  static const std::vector<std::string> kNames = {"fog",         "dust",       "smoke", "vdb_smoke",
                                                  "fire",        "rain",       "snow",  "sparks",
                                                  "light_event", "flashlight", "sun",   "wetness"};
  return kNames;
}

const char* EffectTypeName(EffectType type) {
  return EffectTypeNames()[static_cast<size_t>(type)].c_str();
}

double ExtinctionSpec::SigmaT() const {
  if (sigma_t_per_m) return *sigma_t_per_m;
  if (mor_m) return -std::log(0.05) / *mor_m;
  return 0;
}

double EffectConfig::Weight(double t) const {
  if (!(t >= start_sec) || t > stop_sec) return 0;
  double w = 1;
  if (fade_in_sec > 0) w *= std::clamp((t - start_sec) / fade_in_sec, 0.0, 1.0);
  if (fade_out_sec > 0 && std::isfinite(stop_sec)) {
    w *= std::clamp((stop_sec - t) / fade_out_sec, 0.0, 1.0);
  }
  return w;
}

std::optional<EffectConfig::Problem> EffectConfig::Validate() const {
  Checker c;
  if (!IsValidName(name)) {
    c.Fail("name", "'" + name +
                       "' is not a valid effect name; expected a non-empty name of "
                       "the characters A-Z a-z 0-9 _ -");
  }
  c.In("start_sec", start_sec, Range::AtLeast(0));
  if (c.ok() && !(stop_sec > start_sec)) {
    c.Fail("stop_sec",
           Num(stop_sec) + " is out of range; expected > start_sec (" + Num(start_sec) + ")");
  }
  c.In("fade_in_sec", fade_in_sec, Range::AtLeast(0));
  c.In("fade_out_sec", fade_out_sec, Range::AtLeast(0));
  if (region) {
    c.In3("region.min", region->min_W, Range::Finite());
    c.In3("region.max", region->max_W, Range::Finite());
    if (c.ok() && (region->min_W.array() >= region->max_W.array()).any()) {
      c.Fail("region.min", "region min " + Vec(region->min_W) + " is not below max " +
                               Vec(region->max_W) + "; expected min < max on every axis");
    }
  }
  if (!c.ok()) return c.problem();

  switch (type) {
    case EffectType::kFog:
      c.Extinction("fog", fog.extinction);
      c.In3("fog.albedo", fog.albedo, Range::Closed(0, 1));
      c.Phase("fog.g", fog.g);
      c.In("fog.height_falloff_per_m", fog.height_falloff_per_m, Range::AtLeast(0));
      c.In("fog.base_height_m", fog.base_height_m, Range::Finite());
      break;
    case EffectType::kDust:
      c.Extinction("dust", dust.extinction);
      c.In3("dust.color", dust.color, Range::Closed(0, 1));
      c.Phase("dust.g", dust.g);
      c.In("dust.height_falloff_per_m", dust.height_falloff_per_m, Range::AtLeast(0));
      c.In("dust.base_height_m", dust.base_height_m, Range::Finite());
      break;
    case EffectType::kSmoke:
      if (!region)
        c.Fail("region", "smoke needs a region; expected region: {min: [x, y, z], max: [x, y, z]}");
      c.In("smoke.density_scale_per_m", smoke.density_scale_per_m, Range::OpenClosed(0, 1e3));
      c.In3("smoke.albedo", smoke.albedo, Range::Closed(0, 1));
      c.Phase("smoke.g", smoke.g);
      c.In3("smoke.wind_m_s", smoke.wind_m_s, Range::Closed(-100, 100));
      if (smoke.mode == SmokeParams::Mode::kNoise) {
        c.In("smoke.noise_resolution", smoke.noise_resolution, Range::Closed(8, 256));
        c.In("smoke.noise_scale_m", smoke.noise_scale_m, Range::Above(0));
        c.In("smoke.octaves", smoke.octaves, Range::Closed(1, 8));
        c.In("smoke.coverage", smoke.coverage, Range::Closed(0, 1));
        c.In("smoke.evolution_per_s", smoke.evolution_per_s, Range::AtLeast(0));
      } else {
        c.Fluid("smoke", smoke.fluid, region);
      }
      break;
    case EffectType::kVdbSmoke:
      if (vdb_smoke.file.empty())
        c.Fail("vdb_smoke.file", "no file; expected the path of a .vdb file");
      // checked at load so the error names the world file's line (the grid is read later)
      if (std::error_code ec; !std::filesystem::is_regular_file(vdb_smoke.file, ec))
        c.Fail("vdb_smoke.file", "file not found: " + vdb_smoke.file +
                                     " (relative paths resolve against the world file's "
                                     "folder); expected an existing .vdb file");
      if (vdb_smoke.grid.empty())
        c.Fail("vdb_smoke.grid", "empty grid name; expected e.g. density");
      c.In("vdb_smoke.max_resolution", vdb_smoke.max_resolution, Range::Closed(4, 512));
      c.In("vdb_smoke.density_scale_per_m", vdb_smoke.density_scale_per_m,
           Range::OpenClosed(0, 1e3));
      c.In3("vdb_smoke.albedo", vdb_smoke.albedo, Range::Closed(0, 1));
      c.Phase("vdb_smoke.g", vdb_smoke.g);
      break;
    case EffectType::kFire:
      if (!region)
        c.Fail("region", "fire needs a region; expected region: {min: [x, y, z], max: [x, y, z]}");
      c.Fluid("fire", fire.fluid, region);
      c.In("fire.density_scale_per_m", fire.density_scale_per_m, Range::OpenClosed(0, 1e3));
      c.In("fire.absorption_per_m", fire.absorption_per_m, Range::OpenClosed(0, 1e3));
      c.In3("fire.albedo", fire.albedo, Range::Closed(0, 1));
      c.In("fire.min_emission_temperature_k", fire.min_emission_temperature_k,
           Range::Closed(300, 4000));
      c.In("fire.glow_light_radius_m", fire.glow_light_radius_m, Range::AtLeast(0));
      break;
    case EffectType::kRain:
      c.In("rain.rate_mm_h", rain.rate_mm_h, Range::OpenClosed(0, 500));
      c.In3("rain.wind_m_s", rain.wind_m_s, Range::Closed(-100, 100));
      c.In("rain.min_diameter_mm", rain.min_diameter_mm, Range::ClosedOpen(0.1, 6));
      c.In("rain.max_diameter_mm", rain.max_diameter_mm, Range::OpenClosed(0.1, 6));
      if (c.ok() && !(rain.max_diameter_mm > rain.min_diameter_mm)) {
        c.Fail("rain.max_diameter_mm", Num(rain.max_diameter_mm) +
                                           " is out of range; expected > min_diameter_mm (" +
                                           Num(rain.min_diameter_mm) + ") and <= 6");
      }
      c.In3("rain.box_half_extents_m", rain.box_half_extents_m, Range::OpenClosed(0, 1e3));
      c.In("rain.max_particles", rain.max_particles, Range::Closed(1, 5e6));
      c.In3("rain.color", rain.color, Range::Closed(0, 1));
      break;
    case EffectType::kSnow:
      c.In("snow.rate_mm_h", snow.rate_mm_h, Range::OpenClosed(0, 100));
      c.In("snow.flake_diameter_mm", snow.flake_diameter_mm, Range::Closed(0.5, 30));
      c.In("snow.flake_density_kg_m3", snow.flake_density_kg_m3, Range::Closed(20, 900));
      c.In3("snow.wind_m_s", snow.wind_m_s, Range::Closed(-100, 100));
      c.In("snow.turbulence_m_s", snow.turbulence_m_s, Range::Closed(0, 20));
      c.In("snow.drift_frequency_hz", snow.drift_frequency_hz, Range::OpenClosed(0, 100));
      c.In3("snow.box_half_extents_m", snow.box_half_extents_m, Range::OpenClosed(0, 1e3));
      c.In("snow.max_particles", snow.max_particles, Range::Closed(1, 5e6));
      c.In3("snow.color", snow.color, Range::Closed(0, 1));
      break;
    case EffectType::kSparks:
      c.In3("sparks.position", sparks.position_W, Range::Finite());
      c.In("sparks.rate_per_s", sparks.rate_per_s, Range::OpenClosed(0, 1e5));
      c.In("sparks.speed_m_s", sparks.speed_m_s, Range::Closed(0, 100));
      c.In("sparks.spread_deg", sparks.spread_deg, Range::Closed(0, 90));
      c.In("sparks.lifetime_sec", sparks.lifetime_sec, Range::OpenClosed(0, 60));
      c.In("sparks.gravity_m_s2", sparks.gravity_m_s2, Range::Closed(-100, 100));
      c.In("sparks.radius_m", sparks.radius_m, Range::OpenClosed(0, 0.1));
      c.In("sparks.temperature_k", sparks.temperature_k, Range::Closed(800, 4000));
      c.In("sparks.luminance_cd_m2", sparks.luminance_cd_m2, Range::AtLeast(0));
      if (c.ok() && sparks.rate_per_s * sparks.lifetime_sec > 1e6) {
        c.Fail("sparks.rate_per_s",
               Num(sparks.rate_per_s) + " x lifetime_sec " + Num(sparks.lifetime_sec) +
                   " is too many live sparks; expected rate x lifetime <= 1e6");
      }
      break;
    case EffectType::kLightEvent:
      if (light_event.light.empty()) {
        c.Fail("light_event.light", "no target light; expected a scene light name or \"*\"");
      }
      c.In("light_event.frequency_hz", light_event.frequency_hz, Range::OpenClosed(0, 1000));
      c.In("light_event.depth", light_event.depth, Range::Closed(0, 1));
      c.In("light_event.duty_cycle", light_event.duty_cycle, Range::Open(0, 1));
      c.In("light_event.failure_probability", light_event.failure_probability, Range::Closed(0, 1));
      c.In("light_event.min_scale", light_event.min_scale, Range::ClosedOpen(0, 1));
      c.In("light_event.recovery_sec", light_event.recovery_sec, Range::AtLeast(0));
      break;
    case EffectType::kFlashlight: {
      const FlashlightParams& f = flashlight;
      if (f.attach.empty()) {
        if (f.waypoints.empty()) {
          c.Fail("flashlight.waypoints",
                 "no waypoints and no attach body; expected a list of {t_sec, position, "
                 "direction} or attach: <body name>");
        }
        for (size_t i = 0; i < f.waypoints.size(); ++i) {
          const std::string k = "flashlight.waypoints[" + std::to_string(i) + "]";
          c.In(k + ".t_sec", f.waypoints[i].t_sec, Range::AtLeast(0));
          if (c.ok() && i > 0 && !(f.waypoints[i].t_sec > f.waypoints[i - 1].t_sec)) {
            c.Fail(k + ".t_sec", Num(f.waypoints[i].t_sec) +
                                     " is out of range; expected t_sec increasing along the list");
          }
          c.In3(k + ".position", f.waypoints[i].position_W, Range::Finite());
          c.In3(k + ".direction", f.waypoints[i].direction_W, Range::Finite());
          if (c.ok() && f.waypoints[i].direction_W.norm() < 1e-9) {
            c.Fail(k + ".direction", "zero vector; expected a non-zero direction");
          }
        }
      } else {
        c.In3("flashlight.position", f.position_B, Range::Finite());
        c.In3("flashlight.direction", f.direction_B, Range::Finite());
        if (c.ok() && f.direction_B.norm() < 1e-9) {
          c.Fail("flashlight.direction", "zero vector; expected a non-zero direction");
        }
      }
      c.In("flashlight.intensity_cd", f.intensity_cd, Range::Above(0));
      c.In("flashlight.inner_angle_deg", f.inner_angle_deg, Range::Open(0, 90));
      c.In("flashlight.outer_angle_deg", f.outer_angle_deg, Range::Open(0, 90));
      if (c.ok() && f.inner_angle_deg > f.outer_angle_deg) {
        c.Fail("flashlight.inner_angle_deg", Num(f.inner_angle_deg) +
                                                 " is out of range; expected <= outer_angle_deg (" +
                                                 Num(f.outer_angle_deg) + ")");
      }
      c.In3("flashlight.color", f.color, Range::Closed(0, 1));
      if (c.ok() && f.color.maxCoeff() <= 0) {
        c.Fail("flashlight.color", "black; expected a colour with a component > 0");
      }
      c.In("flashlight.radius_m", f.radius_m, Range::AtLeast(0));
      break;
    }
    case EffectType::kSun: {
      c.In("sun.latitude_deg", sun.latitude_deg, Range::Closed(-90, 90));
      c.In("sun.longitude_deg", sun.longitude_deg, Range::Closed(-180, 180));
      c.In("sun.year", sun.year, Range::Closed(1900, 2100));
      c.In("sun.month", sun.month, Range::Closed(1, 12));
      if (c.ok()) {
        static const int kDays[12] = {31, 28, 31, 30, 31, 30, 31, 31, 30, 31, 30, 31};
        const bool leap = (sun.year % 4 == 0 && sun.year % 100 != 0) || sun.year % 400 == 0;
        const int dim = kDays[sun.month - 1] + (sun.month == 2 && leap ? 1 : 0);
        c.In("sun.day", sun.day, Range::Closed(1, dim));
      }
      c.In("sun.time_utc_h", sun.time_utc_h, Range::ClosedOpen(0, 24));
      c.In("sun.time_scale", sun.time_scale, Range::Closed(0, 1e6));
      break;
    }
    case EffectType::kWetness:
      c.In("wetness.wetting_time_sec", wetness.wetting_time_sec, Range::Above(0));
      c.In("wetness.drying_time_sec", wetness.drying_time_sec, Range::Above(0));
      c.In("wetness.max_wetness", wetness.max_wetness, Range::Closed(0, 1));
      break;
  }
  // keys name the world-file key: the type's parameters sit next to name and type
  std::optional<Problem> p = c.problem();
  const std::string type_prefix = std::string(EffectTypeName(type)) + ".";
  if (p && p->key.rfind(type_prefix, 0) == 0) p->key = p->key.substr(type_prefix.size());
  return p;
}

namespace {

[[noreturn]] void ThrowProblem(const EffectConfig& e, const std::string& prefix,
                               const EffectConfig::Problem& p, const std::string& file,
                               const std::function<int(const std::string&)>& line_of) {
  const std::string key = prefix + "." + p.key;
  throw ConfigError(file, line_of ? line_of(key) : 0, key,
                    "effect '" + e.name + "' (" + EffectTypeName(e.type) + "): " + p.message);
}

}  // namespace

void EffectConfig::ValidateOrThrow(const std::string& key_prefix) const {
  if (auto p = Validate()) {
    ThrowProblem(*this, key_prefix.empty() ? "effects['" + name + "']" : key_prefix, *p, "", {});
  }
}

void ValidateEffectsOrThrow(const std::vector<EffectConfig>& effects, const std::string& file,
                            const std::function<int(const std::string&)>& line_of) {
  std::map<std::string, size_t> names;
  for (size_t i = 0; i < effects.size(); ++i) {
    const EffectConfig& e = effects[i];
    const std::string prefix = "effects[" + std::to_string(i) + "]";
    if (auto p = e.Validate()) ThrowProblem(e, prefix, *p, file, line_of);
    auto [it, inserted] = names.emplace(e.name, i);
    if (!inserted) {
      ThrowProblem(e, prefix,
                   {"name", "name '" + e.name + "' is also used by effects[" +
                                std::to_string(it->second) + "]; expected unique effect names"},
                   file, line_of);
    }
  }
  // references between effects
  auto find = [&](const std::string& name, EffectType type) {
    for (const EffectConfig& e : effects)
      if (e.name == name && e.type == type) return true;
    return false;
  };
  for (size_t i = 0; i < effects.size(); ++i) {
    const EffectConfig& e = effects[i];
    const std::string prefix = "effects[" + std::to_string(i) + "]";
    if (e.type == EffectType::kWetness) {
      if (e.wetness.rain.empty()
              ? !std::any_of(effects.begin(), effects.end(),
                             [](const EffectConfig& o) { return o.type == EffectType::kRain; })
              : !find(e.wetness.rain, EffectType::kRain)) {
        ThrowProblem(e, prefix,
                     {"rain", "no rain effect '" + e.wetness.rain +
                                          "'; expected the name of a rain effect of this world"},
                     file, line_of);
      }
    }
    if (e.type == EffectType::kSparks && !e.sparks.fire.empty() &&
        !find(e.sparks.fire, EffectType::kFire)) {
      ThrowProblem(e, prefix,
                   {"fire", "no fire effect '" + e.sparks.fire +
                                       "'; expected the name of a fire effect of this world"},
                   file, line_of);
    }
  }
}

}  // namespace penumbra

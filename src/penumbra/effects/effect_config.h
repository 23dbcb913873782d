#pragma once
// configuration of the adverse-condition effects (issue 4): one EffectConfig per entry of
// the world file's `effects:` list (parsed by world/effects_reader.h, reference in
// docs/effects.md). every struct has defaults, documented units and valid ranges, and
// EffectConfig::ValidateOrThrow() checks them.
//
// frames and units: world frame W (REP-103/REP-105: x east, y north, z up; metres,
// seconds); colours linear Rec.709 rgb; `_deg`, `_hz`, `_sec`, `_mm_h` as named.
//
// time window: an effect is active for start_sec <= t <= stop_sec. its weight
//   w(t) = clamp((t - start_sec) / fade_in_sec, 0, 1) * clamp((stop_sec - t) / fade_out_sec, 0, 1)
// (a zero fade time is a hard switch) scales media extinction, precipitation rate (by
// deterministic thinning of particles), emission, and blends light multipliers towards 1.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "penumbra/scene/effects_frame.h"

namespace penumbra {

/// the kinds of effect; names as in the world file.
enum class EffectType {
  kFog,         ///< "fog": homogeneous scattering medium, optional height falloff
  kDust,        ///< "dust": coloured absorbing haze
  kSmoke,       ///< "smoke": procedural noise advected by wind, or a grid-fluid plume
  kVdbSmoke,    ///< "vdb_smoke": density grid from an OpenVDB file
  kFire,        ///< "fire": grid-fluid flame with blackbody emission and a glow light
  kRain,        ///< "rain": Marshall-Palmer drops around the viewer
  kSnow,        ///< "snow": flakes with turbulent drift around the viewer
  kSparks,      ///< "sparks": ballistic embers from a point (or a fire)
  kLightEvent,  ///< "light_event": flicker / failing / strobe / blackout of a scene light
  kFlashlight,  ///< "flashlight": a spot light on waypoints or attached to a body
  kSun,         ///< "sun": sun direction and sky level from date, time and place
  kWetness,     ///< "wetness": surface wetness that follows a rain effect
};

/// world-file name of a type ("fog", "vdb_smoke", ...).
const char* EffectTypeName(EffectType type);
/// every world-file type name, in EffectType order.
const std::vector<std::string>& EffectTypeNames();

/// extinction given either directly or as meteorological optical range (MOR, WMO No. 8,
/// 2018: distance at which the contrast of a black object falls to 5%):
///   sigma_t = -ln(0.05) / MOR = 2.996 / MOR  (Koschmieder's law).
/// exactly one of the two must be set.
struct ExtinctionSpec {
  std::optional<double> sigma_t_per_m;  ///< extinction coefficient, 1/m, > 0 (<= 1e3)
  std::optional<double> mor_m;          ///< MOR, m, > 0 (>= 1e-3)
  /// sigma_t in 1/m (throws nothing; call after validation).
  double SigmaT() const;
};

/// fog: sigma_t(p) = sigma_t * exp(-height_falloff_per_m * max(0, p.z - base_height_m)).
struct FogParams {
  ExtinctionSpec extinction;                 ///< required (sigma_t_per_m or mor_m)
  Eigen::Vector3d albedo{0.95, 0.95, 0.95};  ///< single-scattering albedo per channel, [0, 1]
  double g = 0.8;  ///< Henyey-Greenstein asymmetry, (-1, 1); water fog is strongly forward (~0.8)
  double height_falloff_per_m = 0;  ///< >= 0, 0 = uniform
  double base_height_m = 0;         ///< finite; full density below this height
};

/// dust: a coloured, absorbing haze. the colour is the single-scattering albedo per
/// channel (blue absorbed more than red gives the brown cast of mineral dust).
struct DustParams {
  ExtinctionSpec extinction;                ///< required
  Eigen::Vector3d color{0.75, 0.55, 0.35};  ///< albedo per channel, [0, 1]
  double g = 0.6;                           ///< (-1, 1)
  double height_falloff_per_m = 0;          ///< >= 0
  double base_height_m = 0;
};

/// one smoke / fire source of the grid fluid.
struct PlumeEmitter {
  Eigen::Vector3d position_W{0, 0, 0};  ///< centre, world frame, must lie inside the region
  double radius_m = 0.2;  ///< > 0; voxels whose centres are within it receive the source
  /// mass injected per second (density x m^3 per s), >= 0. density 1 = sigma_t of density_scale.
  double rate = 0.5;
  /// temperature of the injected gas, K, [300, 4000] (fire: drives emission and buoyancy).
  double temperature_k = 600;
};

/// grid fluid after Stam, "Stable Fluids", SIGGRAPH 1999 (semi-Lagrangian advection,
/// pressure projection by Jacobi iterations) with the buoyancy of Fedkiw, Stam, Jensen,
/// "Visual Simulation of Smoke", SIGGRAPH 2001: f_z = buoyancy_m_s2 * (T - T_amb) / T_amb
/// - weight_m_s2 * density.
struct FluidParams {
  int resolution = 48;                    ///< voxels along the longest region axis, [8, 128]
  /// range of dt_sec: the state at time t takes floor(t / dt_sec) steps from t = 0, so the
  /// lower end caps the work at 1000 steps per simulated second (13 ms each at resolution 48,
  /// docs/effects.md) instead of letting a tiny step hang the run.
  static constexpr double kMinDtSec = 1e-3, kMaxDtSec = 0.1;
  double dt_sec = 1.0 / 30.0;             ///< fixed internal step, [kMinDtSec, kMaxDtSec]
  int jacobi_iterations = 20;             ///< pressure iterations per step, [1, 200]
  double buoyancy_m_s2 = 9.81;            ///< >= 0, thermal buoyancy scale
  double weight_m_s2 = 0.0;               ///< >= 0, downward pull per unit density
  double dissipation_per_s = 0.1;         ///< density decay rate k (d rho/dt = -k rho), >= 0
  double cooling_per_s = 1.5;             ///< temperature excess decay rate, >= 0
  double ambient_temperature_k = 293.15;  ///< [200, 400]
  /// random horizontal velocity kick per step at each emitter, uniform in [-t, t] m/s per
  /// axis from the seed (breaks the symmetry, makes flames flicker), [0, 20].
  double turbulence_m_s = 0.5;
  std::vector<PlumeEmitter> emitters;  ///< at least one
};

/// smoke: `noise` = fBm value noise translated by the wind (stateless), `plume` = grid fluid.
struct SmokeParams {
  enum class Mode { kNoise, kPlume };
  Mode mode = Mode::kNoise;
  double density_scale_per_m = 2.0;       ///< sigma_t at density 1, 1/m, > 0
  Eigen::Vector3d albedo{0.6, 0.6, 0.6};  ///< [0, 1]
  double g = 0.0;                         ///< (-1, 1)
  Eigen::Vector3d wind_m_s{0.5, 0, 0};    ///< noise: translation speed; plume: inflow wind
  // noise mode
  int noise_resolution = 48;     ///< voxels along the longest region axis, [8, 256]
  double noise_scale_m = 1.0;    ///< feature size of the first octave, > 0
  int octaves = 4;               ///< [1, 8]
  double coverage = 0.5;         ///< fraction of the volume with smoke, [0, 1]
  double evolution_per_s = 0.1;  ///< rate the pattern changes shape, >= 0
  // plume mode
  FluidParams fluid;
};

/// vdb_smoke: a `density` float grid from an OpenVDB file, resampled (trilinear) to a
/// dense GridMedium. placement: if the effect has a region, the grid's active bounding
/// box is stretched to fill it; otherwise the file's own transform (world frame, metres)
/// is used.
struct VdbSmokeParams {
  std::string file;                       ///< .vdb path (absolute after loading a world file)
  std::string grid = "density";           ///< float grid name
  int max_resolution = 128;               ///< cap of voxels per axis after resampling, [4, 512]
  double density_scale_per_m = 1.0;       ///< sigma_t at density 1, > 0
  Eigen::Vector3d albedo{0.7, 0.7, 0.7};  ///< [0, 1]
  double g = 0.0;                         ///< (-1, 1)
};

/// fire: a grid-fluid flame (FluidParams, emitters at temperature_k ~ 1200-1800 K).
/// emission per unit length j = absorption_per_m * density * L_bb(T) in the colour of
/// BlackbodyLinearSrgb(T), L_bb = blackbody luminance (blackbody.h); extinction
/// sigma_t = density_scale_per_m * density (soot). the glow is also added as a point
/// light in extra_lights at the emission centroid with intensity
///   I = sum_voxels j_Y dV  (cd)   (optically thin: luminous flux 4 pi sum j_Y dV over 4 pi sr),
/// coloured by the emission-weighted mean colour c (max component 1), stored as
/// Light::intensity = I / Y(c) since the renderer multiplies intensity by the tint. the
/// light follows the fire's emitted power, so it flickers with the flame.
struct FireParams {
  FluidParams fluid;
  double density_scale_per_m = 1.0;         ///< soot extinction at density 1, > 0
  double absorption_per_m = 2.0;            ///< emitting absorption at density 1, > 0
  Eigen::Vector3d albedo{0.2, 0.2, 0.2};    ///< soot albedo, [0, 1]
  double min_emission_temperature_k = 800;  ///< voxels below emit nothing, [300, 4000]
  bool glow_light = true;                   ///< add the point light
  double glow_light_radius_m = 0.1;         ///< >= 0
};

/// rain after Marshall & Palmer, "The distribution of raindrops with size", J. Meteor. 5,
/// 1948: N(D) = N0 exp(-Lambda D), N0 = 8000 m^-3 mm^-1, Lambda = 4.1 R^-0.21 mm^-1
/// (R in mm/h), truncated to [min_diameter_mm, max_diameter_mm] (drops below 0.1 mm are
/// drizzle/mist, above 6 mm they break up). terminal velocity: Atlas, Srivastava, Sekhon,
/// Rev. Geophys. 11, 1973, v(D) = 9.65 - 10.3 exp(-0.6 D) m/s (D in mm), a fit of the
/// measurements of Gunn & Kinzer, J. Meteor. 6, 1949 (clamped at >= 0).
struct RainParams {
  double rate_mm_h = 5;               ///< (0, 500]
  Eigen::Vector3d wind_m_s{0, 0, 0};  ///< horizontal wind added to every drop (z ignored)
  double min_diameter_mm = 0.1;       ///< [0.1, 6)
  double max_diameter_mm = 6.0;       ///< (min, 6]
  /// half size of the box around the viewer that is filled with drops, m, each > 0.
  Eigen::Vector3d box_half_extents_m{4, 4, 3};
  /// cap on the drop count; when the box would hold more, it is shrunk uniformly so the
  /// number density is kept. [1, 5e6]
  int max_particles = 200000;
  Eigen::Vector3d color{0.85, 0.9, 1.0};  ///< drop tint (albedo), [0, 1]
};

/// snow: flakes of diameter flake_diameter_mm (+-30% uniform per flake), bulk density
/// flake_density_kg_m3, falling at the aggregate speed of Locatelli & Hobbs, J. Geophys.
/// Res. 79, 1974: v = 0.81 D^0.16 m/s (D in mm). the number density follows from the
/// water-equivalent rate: n = (rho_w R) / (m_flake v) with m_flake = rho_f pi D^3 / 6.
/// turbulent drift: each flake adds turbulence_m_s * (sin(2 pi f t + phi_x), sin(2 pi f t +
/// phi_y), 0.3 sin(2 pi f t + phi_z)) with f drawn in [0.5, 1.5] drift_frequency_hz.
struct SnowParams {
  double rate_mm_h = 1;                         ///< water equivalent, (0, 100]
  double flake_diameter_mm = 5;                 ///< [0.5, 30]
  double flake_density_kg_m3 = 100;             ///< [20, 900]
  Eigen::Vector3d wind_m_s{0, 0, 0};            ///< horizontal (z ignored)
  double turbulence_m_s = 0.3;                  ///< >= 0
  double drift_frequency_hz = 0.5;              ///< > 0
  Eigen::Vector3d box_half_extents_m{4, 4, 3};  ///< each > 0
  int max_particles = 200000;                   ///< [1, 5e6]
  Eigen::Vector3d color{0.95, 0.95, 0.97};      ///< [0, 1]
};

/// sparks: embers born at rate_per_s at `position_W` (or at the first emitter of the fire
/// named `fire`), with initial speed speed_m_s in a cone of spread_deg around +z, moving
/// ballistically (drag-free) under gravity_m_s2 (gravity minus buoyancy); each lives
/// lifetime_sec and its radius shrinks linearly to 0 as it burns out. emission: the
/// blackbody colour of temperature_k times luminance_cd_m2 (0 = the blackbody luminance).
struct SparksParams {
  std::string fire;                     ///< name of a fire effect to sit on, or ""
  Eigen::Vector3d position_W{0, 0, 0};  ///< used when fire is ""
  double rate_per_s = 20;               ///< (0, 1e5]
  double speed_m_s = 2.5;               ///< >= 0
  double spread_deg = 25;               ///< [0, 90]
  double lifetime_sec = 1.5;            ///< (0, 60]
  double gravity_m_s2 = 4.0;            ///< net downward acceleration (gravity - buoyancy)
  double radius_m = 0.004;              ///< (0, 0.1]
  double temperature_k = 1600;          ///< [800, 4000]
  double luminance_cd_m2 = 0;           ///< 0 = blackbody luminance of temperature_k, else > 0
};

/// light_event: changes the intensity multiplier of the scene light named `light` ("*" =
/// every light of the scene); several events on one light multiply.
///  flicker: s = 1 - depth * n(t), n = smooth value noise in [0, 1] at frequency_hz.
///  failing: time is cut into slots of 1 / frequency_hz; a slot is off (s = min_scale)
///           with probability failure_probability, else s = 1 - 0.5 depth n(t).
///  strobe:  s = 1 while frac((t - start_sec) frequency_hz) < duty_cycle, else min_scale.
///  blackout: s = min_scale in [start, stop], then a linear ramp to 1 over recovery_sec.
struct LightEventParams {
  enum class Mode { kFlicker, kFailing, kStrobe, kBlackout };
  std::string light;  ///< scene light name or "*", required
  Mode mode = Mode::kFlicker;
  double frequency_hz = 8;           ///< (0, 1000]
  double depth = 0.5;                ///< [0, 1]
  double duty_cycle = 0.5;           ///< (0, 1)
  double failure_probability = 0.3;  ///< [0, 1]
  double min_scale = 0;              ///< [0, 1)
  double recovery_sec = 2;           ///< >= 0 (blackout)
};

/// one pose sample of a flashlight path (linear in position, normalised-lerp in direction).
struct FlashlightWaypoint {
  double t_sec = 0;  ///< sim time, strictly increasing along the list
  Eigen::Vector3d position_W{0, 0, 1};
  Eigen::Vector3d direction_W{1, 0, 0};  ///< beam direction, non-zero
};

/// flashlight: a spot light moving along waypoints (held at the ends) or attached to a
/// body (`attach` = body name of SceneDescription::bodies; its pose comes from the
/// caller's X_WB at Evaluate).
struct FlashlightParams {
  std::vector<FlashlightWaypoint> waypoints;  ///< used when attach is ""
  std::string attach;                         ///< body name, or "" for waypoints
  Eigen::Vector3d position_B{0, 0, 0};        ///< attached: position in the body frame
  Eigen::Vector3d direction_B{1, 0, 0};       ///< attached: beam direction in the body frame
  double intensity_cd = 300;                  ///< on-axis luminous intensity, > 0
  double inner_angle_deg = 10, outer_angle_deg = 20;  ///< 0 < inner <= outer < 90
  Eigen::Vector3d color{1.0, 0.95, 0.85};             ///< tint, [0, 1], max component > 0
  double radius_m = 0.02;                             ///< >= 0
};

/// sun: sun position from the NOAA solar calculator equations (after Meeus, "Astronomical
/// Algorithms", 1991; accuracy ~0.01 deg for 1800-2100). world x = east, y = north, z = up.
/// the clock runs at time_scale x sim time from the given start. below the horizon the
/// sky is scaled by a twilight model (sun.h).
struct SunParams {
  double latitude_deg = 48.14;   ///< [-90, 90], north positive
  double longitude_deg = 11.58;  ///< [-180, 180], east positive
  int year = 2024;               ///< [1900, 2100]
  int month = 6;                 ///< [1, 12]
  int day = 21;                  ///< [1, days in month]
  double time_utc_h = 12;        ///< hours UTC at sim time 0, [0, 24)
  double time_scale = 1;         ///< clock seconds per sim second, >= 0 (60 = 1 h per minute)
};

/// wetness after rain: w rises as 1 - exp(-t / wetting_time_sec) while the rain effect is
/// active (scaled by its weight at the start) and decays as exp(-t / drying_time_sec)
/// after it stops; capped at max_wetness.
struct WetnessParams {
  std::string rain;              ///< name of the rain effect; "" = the first rain effect
  double wetting_time_sec = 60;  ///< > 0
  double drying_time_sec = 600;  ///< > 0
  double max_wetness = 1;        ///< [0, 1]
};

/// one entry of the world file's `effects:` list.
struct EffectConfig {
  std::string name;  ///< unique among effects; [A-Za-z0-9_-]+
  EffectType type = EffectType::kFog;
  double start_sec = 0;                                       ///< >= 0
  double stop_sec = std::numeric_limits<double>::infinity();  ///< > start_sec (inf = never)
  double fade_in_sec = 0;                                     ///< >= 0
  double fade_out_sec = 0;                                    ///< >= 0
  /// where the effect lives, world frame. fog/dust: the medium's box (nullopt = everywhere);
  /// smoke/fire: the simulation grid box (required); vdb_smoke: fit box (optional);
  /// rain/snow: drops only inside it (nullopt = everywhere); others: unused.
  std::optional<BoxRegion> region;

  // the parameters of `type` (the others keep their defaults and are ignored)
  FogParams fog;
  DustParams dust;
  SmokeParams smoke;
  VdbSmokeParams vdb_smoke;
  FireParams fire;
  RainParams rain;
  SnowParams snow;
  SparksParams sparks;
  LightEventParams light_event;
  FlashlightParams flashlight;
  SunParams sun;
  WetnessParams wetness;

  /// weight w(t) in [0, 1] of the time window and fades (see the file header).
  double Weight(double time_sec) const;

  /// a problem found by Validate(): the world-file key relative to the effect entry
  /// ("rate_mm_h", "region.min", "emitters[0].position"; a type's parameters sit next to
  /// name and type) and the message with the valid range.
  struct Problem {
    std::string key;
    std::string message;
  };
  /// the first problem of this effect's values, or nullopt. does not touch files.
  std::optional<Problem> Validate() const;

  /// @param key_prefix prefix of key paths in the error ("effects[2]"); "" = "effects['<name>']".
  /// @throws ConfigError("", 0, "<prefix>.<key>", "effect '<name>' (<type>): <problem>; expected
  ///         <range>") for the first out-of-range or inconsistent value.
  void ValidateOrThrow(const std::string& key_prefix = "") const;
};

/// validates every effect (keys "effects[i].<key>") and the cross-effect rules: unique
/// names, wetness.rain and sparks.fire naming effects of that type.
/// @param file     file named in errors ("" = none)
/// @param line_of  optional: 1-based line of a key path, or 0 when unknown
/// @throws ConfigError(file, line_of(key), key, problem) on the first violation.
void ValidateEffectsOrThrow(const std::vector<EffectConfig>& effects, const std::string& file = "",
                            const std::function<int(const std::string&)>& line_of = {});

}  // namespace penumbra

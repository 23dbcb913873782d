#pragma once
// the adverse-condition state of a world at one instant: participating media,
// particles and lighting changes, computed by the effects stage (src/penumbra/effects)
// from sim time and the world seed, and drawn by the renderer. it sits between the
// physics snapshot and the renderer in the data flow and never feeds back into physics
// (NPC agents are mocap bodies, posed by physics, not by this frame).
//
// units: metres, seconds; colours are linear Rec.709 rgb; radiance in cd/m^2 per channel
// (the renderer's photometric convention, see scene_description.h).
//
// media model (Pharr, Jakob, Humphreys, "Physically Based Rendering", 4th ed., ch. 11):
// extinction sigma_t = sigma_a + sigma_s (1/m), single-scattering albedo
// rho = sigma_s / sigma_t, Henyey-Greenstein phase function with asymmetry g; media add
// their coefficients where they overlap.

#include <Eigen/Core>
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// axis-aligned box in the world frame (min <= max per axis).
struct BoxRegion {
  Eigen::Vector3d min_W{0, 0, 0};
  Eigen::Vector3d max_W{0, 0, 0};
};

/// homogeneous fog / haze / dust, optionally with height falloff:
/// sigma_t(p) = sigma_t_per_m * exp(-height_falloff_per_m * max(0, p.z - base_height_m)).
struct HomogeneousMedium {
  Eigen::Vector3f sigma_t_per_m{0, 0, 0};  ///< extinction coefficient per rgb channel, 1/m
  Eigen::Vector3f albedo{1, 1, 1};         ///< single-scattering albedo per channel in [0, 1]
  float g = 0.0f;                          ///< Henyey-Greenstein asymmetry in (-1, 1)
  float height_falloff_per_m = 0.0f;       ///< 0 = uniform density; > 0 = height fog
  float base_height_m = 0.0f;              ///< height (world z) below which density is full
  /// where the medium is; nullopt = a layer unbounded in x and y below layer_top_m.
  std::optional<BoxRegion> region;
  /// world z (m) of the top of the layer an unbounded medium (no region) fills; light from
  /// above (sun, sky) crosses only the part of its path below it. +inf = no top (the medium
  /// fills the whole world, and the sun and sky behind it are never reached). ignored with a
  /// region.
  float layer_top_m = std::numeric_limits<float>::infinity();
};

/// a voxel grid on a box: smoke, steam, fire. the grid spans the box
/// [-half_extents_m, +half_extents_m] in frame G; voxel (i, j, k) is centred at
/// -half + (i + 0.5, j + 0.5, k + 0.5) * 2 half / (nx, ny, nz); values between voxel centres
/// are trilinear; outside the box density and emission are 0.
struct GridMedium {
  Pose X_WG = Pose::Identity();  ///< pose of the grid box in the world
  Eigen::Vector3d half_extents_m{0.5, 0.5, 0.5};
  int nx = 0, ny = 0, nz = 0;
  /// (nz x ny x nx) density, index (k * ny + j) * nx + i, >= 0, dimensionless.
  std::shared_ptr<const std::vector<float>> density;
  Eigen::Vector3f sigma_t_per_m{1, 1, 1};    ///< extinction at density 1, 1/m per channel
  Eigen::Vector3f albedo{0.9f, 0.9f, 0.9f};  ///< single-scattering albedo per channel
  float g = 0.0f;                            ///< Henyey-Greenstein asymmetry
  /// (nz x ny x nx x 3) emitted radiance per unit length, cd/m^2 per m per channel, or null
  /// (fire: blackbody colour of the temperature field x emissivity, computed by effects).
  /// a ray segment ds through it gains emission * ds (attenuated like any radiance).
  std::shared_ptr<const std::vector<float>> emission;
  /// the largest density value of the grid (majorant for delta / ratio tracking).
  float max_density = 0.0f;
};

/// kind of a particle set; decides how it is drawn.
enum class ParticleKind {
  kRain,   ///< water drops: transparent, drawn as motion streaks over the exposure
  kSnow,   ///< flakes: diffuse white, streaked
  kSpark,  ///< embers: emissive, streaked
};

/// particles at the frame's time. each is a sphere of radius_m moving at velocity_W;
/// a camera with exposure time T sees the segment position_W + [0, T] * velocity_W
/// (motion streak) with coverage reduced by the time the particle spends on each pixel.
struct ParticleSet {
  ParticleKind kind = ParticleKind::kRain;
  std::vector<Eigen::Vector3f> position_W;  ///< (N) centre at the frame's time, m
  std::vector<Eigen::Vector3f> velocity_W;  ///< (N) m/s
  std::vector<float> radius_m;              ///< (N) m
  Eigen::Vector3f color{1, 1, 1};           ///< albedo (rain, snow) in [0, 1]
  Eigen::Vector3f emission{0, 0, 0};        ///< cd/m^2 per channel (sparks)
  /// rain and snow: true = not drawn where static geometry is above
  /// (render/particles/shelter_map.h); false = drawn everywhere. sparks are never sheltered.
  bool sheltered = true;
};

/// everything the effects stage adds to one frame. empty by default = clear conditions.
struct EffectsFrame {
  /// the time it was evaluated at, s (in a run the episode's time: session/effects_stage.h)
  double time_sec = 0;
  std::vector<HomogeneousMedium> homogeneous_media;
  std::vector<GridMedium> grid_media;
  std::vector<ParticleSet> particles;
  /// per SceneDescription::lights entry: multiplier on its intensity (flicker, strobe,
  /// blackout: 0); empty = all 1.
  std::vector<float> light_intensity_scale;
  /// lights that exist only through effects (fire glow, flashlight), world-frame (body 0).
  std::vector<Light> extra_lights;
  /// daylight sky: sun direction from time of day and latitude; nullopt = the scene's.
  std::optional<Eigen::Vector3d> sun_direction_W;
  float sky_luminance_scale = 1.0f;  ///< multiplier on sky radiance (dusk, blackout)
  /// surface wetness in [0, 1] applied to every upward-facing surface exposed to rain:
  /// darker albedo and lower roughness (Lagarde, "Water drop 2b - Dynamic rain and its
  /// effects", 2013).
  float surface_wetness = 0.0f;

  /// true when nothing is set (the renderer can skip all effects work).
  bool empty() const {
    return homogeneous_media.empty() && grid_media.empty() && particles.empty() &&
           light_intensity_scale.empty() && extra_lights.empty() && !sun_direction_W &&
           sky_luminance_scale == 1.0f && surface_wetness == 0.0f;
  }
};

}  // namespace penumbra

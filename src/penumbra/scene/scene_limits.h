#pragma once
// penumbra's limits on magnitudes and times, checked when a world is loaded so that absurd but
// finite input (a pose of 1e19 m, a sphere of radius 1e30 m, a timestep of 1e-300 s) is refused
// with a message instead of aborting in Embree or hanging. docs/world-file.md ("Input limits")
// lists them with the reasons; world/world_validation.cc applies them to world files,
// session/scene_assembly.cc to compiled MJCF models, and render/embree/ray_scene.cc never traces a
// ray outside kMaxRayComponent.
//
// why these values: Embree traces in 32-bit floats. the spacing of floats is 7.8 mm at
// 1e5 m and 0.5 m at 1e7 m, so geometry much farther out than 1e5 m cannot be rendered
// faithfully, and Embree's own ray check (|origin|, |direction| <= 1.844e18 per component)
// is hit long before a double overflows. MuJoCo itself calls a state with |qpos| > 1e10
// diverged.

#include <optional>
#include <string>

#include "penumbra/core/magnitude_limits.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra {

// kMaxPositionM, kMinTimestepSec, kMaxTimestepSec and kMaxDurationSec: core/magnitude_limits.h
/// range (m) of a primitive geom's size parameters (sphere radius, box half-sizes, ...), of
/// |mesh vertex coordinates| and of height-field sizes. planes may also have size 0 (infinite).
inline constexpr double kMinGeomSizeM = 1e-6;
inline constexpr double kMaxGeomSizeM = 1e5;
/// vertical field of view (deg) of a camera given by fovy (world file, MJCF) is in
/// [kMinFovyDeg, kMaxFovyDeg); with explicit intrinsics every pixel's ray stays within
/// kMaxFovyDeg / 2 of the optical axis horizontally and vertically, and the image spans at
/// least kMinFovyDeg both ways. below 0.1 deg neighbouring pixels' rays differ by less than
/// ~1e-5 (fy > 573 x height): a fovy_deg of 1e-300 gave fx = 2.75e303 and one colour.
inline constexpr double kMinFovyDeg = 0.1;
inline constexpr double kMaxFovyDeg = 179;
/// the principal point (cx, cy) of explicit intrinsics lies within 10 image sizes of the image:
/// cx in [-10 width, 11 width], cy in [-10 height, 11 height] (px). an off-centre crop keeps its
/// principal point near the image; cx = 1e6 for 640 px is a typo.
inline constexpr double kMaxPrincipalPointOffset = 10.0;
/// largest light levels a world file may give (the renderer works in 32-bit floats, so 1e308
/// became infinity): sun / directional illuminance (lx; direct sunlight is ~1.2e5), point and
/// spot luminous intensity (cd; a lighthouse is ~1e7), their power (W), and luminance (cd/m^2)
/// of the sky and of emissive materials (the sun's disk is ~1.6e9).
inline constexpr double kMaxIlluminanceLux = 1e6;
inline constexpr double kMaxIntensityCd = 1e9;
inline constexpr double kMaxLightPowerW = 1e7;
inline constexpr double kMaxLuminanceCdM2 = 1e10;
/// largest emitter radius of a point or spot light (m), as geom sizes.
inline constexpr double kMaxLightRadiusM = 1e5;
/// largest |k1|, |k2|, |k3| (radial) and |p1|, |p2| (tangential) Brown-Conrady distortion
/// coefficients of a camera (world-file `distortion`). calibrations of real lenses give |k|
/// below ~10 and |p| below ~0.1; k1 = 1e6 squeezed a 60 deg view into about 1 deg.
inline constexpr double kMaxRadialDistortion = 100;
inline constexpr double kMaxTangentialDistortion = 1;
/// largest |component| of a direction vector given at load (lights, flashlights): its square
/// must not overflow when it is normalised (a direction of [1e308, 0, 0] became zero).
inline constexpr double kMaxDirectionComponent = 1e5;
/// most cameras of a world: world-file `cameras` and the MJCF cameras `mjcf_cameras` enables,
/// together. each camera is set up, given its own output folder and sink, and renders its
/// first frame before the first physics step ends: 5000 cameras took more than 10 s before a
/// SIGTERM was seen.
inline constexpr int kMaxCameras = 256;
/// most NPC agents of a run: the world file's `agents`, an adversity preset's people and
/// vehicles and a live run's parked reserve together. each is a MuJoCo mocap body per part (a
/// person 9, a vehicle 5), and MuJoCo's collision detection takes nbody (nbody - 1) / 2 ints
/// of its arena every step: MuJoCo 4.0's automatic arena (15-20 MB for such models) holds that
/// up to about 2,800 bodies and 5,000 overflow it ("mj_stackAlloc: out of memory" at
/// mj_collision); MuJoCo 2.2.2's stack held about 1,650 (200 people). the bound keeps a run
/// well inside either.
inline constexpr int kMaxAgents = 150;
/// most LiDAR beams per scan (rings x columns; livox_mid40: points per scan): 128 rings x
/// 32768 columns. a scan's buffers take about 100 bytes per beam (docs/sensors.md).
inline constexpr int kMaxLidarBeamsPerScan = 1 << 22;
/// largest |component| of a traced ray's origin and direction (Embree 3 asserts on
/// components above FLT_LARGE = 1.844e18); rays beyond it, or with NaN/Inf, are misses.
inline constexpr float kMaxRayComponent = 1e18f;

/// what is wrong with pinhole intrinsics, or nothing: fx, fy finite and > 0, cx, cy finite and
/// within 10 image sizes of the image (kMaxPrincipalPointOffset), every pixel centre's ray
/// within kMaxFovyDeg / 2 of the optical axis, i.e. max(|0 - cx|, |width - 1 - cx|) / fx <=
/// tan(kMaxFovyDeg / 2) and the same for y, and the image at least kMinFovyDeg wide and tall,
/// i.e. fx <= width / (2 tan(kMinFovyDeg / 2)) (573 x width) and the same for fy, height.
/// the message names the failing value and the accepted range (px).
std::optional<std::string> FindIntrinsicsProblem(const CameraIntrinsics& k);

/// a value of a compiled scene outside the limits above.
struct SceneLimitProblem {
  std::string object;   ///< e.g. "geom 'rover/wheel'", "MJCF camera 'rover/head'"
  std::string body;     ///< name of the body it belongs to ("" = world / unknown)
  std::string problem;  ///< "size[0] is 1e+30 m; expected [1e-06, 100000] m"
};

/// checks a compiled MJCF scene (physics/scene_extractor.h) at its initial poses: every visible
/// and invisible geom's size parameters (kMinGeomSizeM..kMaxGeomSizeM for the ones its shape
/// uses; planes 0 or in range), mesh vertices and height-field sizes (<= kMaxGeomSizeM), geom
/// centres, MJCF camera and light positions (|coordinate| <= kMaxPositionM) and MJCF camera
/// fovy (in (0, kMaxFovyDeg), as world-file fovy_deg; read back from the extracted intrinsics,
/// so call it before the cameras are resized).
/// `initial` must hold X_WB for every body, X_W_mjcam and light_position_W for every MJCF
/// camera and light (Simulation::Snapshot). `mjcf_cameras` false skips the MJCF cameras (a
/// world that disables them). returns the first problem, or nothing.
std::optional<SceneLimitProblem> FindSceneLimitProblem(const SceneDescription& scene,
                                                       const WorldSnapshot& initial,
                                                       bool mjcf_cameras = true);

}  // namespace penumbra

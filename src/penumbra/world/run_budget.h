#pragma once
// what a run will cost, estimated before anything big is allocated: memory per camera and
// LiDAR (refused above the machine's physical memory, exit 2) and the total work (physics
// steps, frames, image bytes, LiDAR rays, fluid steps; a warning above stated thresholds).
// docs/world-file.md ("Input limits") gives the figures; docs/performance.md the measurements
// behind the constants below.

#include <cstdint>
#include <optional>
#include <string>

#include "penumbra/scene/scene_description.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// resident memory (bytes per pixel) that one camera adds to a run: the peak RSS difference
/// of one-frame runs at 1024 x 1024 and 2048 x 2048 (run.json peak_resident_memory_mib;
/// figures in docs/performance.md). realtime tier, rgb only:
inline constexpr double kCameraBytesPerPixelRealtime = 42;
/// pathtraced tier (1 spp), rgb only:
inline constexpr double kCameraBytesPerPixelPathtraced = 108;
/// added per output image beyond the first (realtime tier, from a run with all 7 outputs):
inline constexpr double kCameraBytesPerPixelPerOutput = 7;
/// resident memory (bytes) per beam of a LiDAR scan: the pattern, the scanner's per-beam
/// buffers, the scan's points and the PCD text being written; rounded up from the measured
/// value (docs/performance.md) to leave room for scans where every beam returns.
inline constexpr double kLidarBytesPerBeam = 100;

/// work above which a run gets a warning (EstimateRunWork / DescribeRunWork).
inline constexpr double kWarnPhysicsSteps = 1e7;
inline constexpr double kWarnCameraFrames = 1e5;
inline constexpr double kWarnImageBytes = 1e10;
inline constexpr double kWarnLidarRays = 1e10;
inline constexpr double kWarnFluidSteps = 1e5;
/// pathtraced tier: pixels x samples_per_pixel x frames (x motion_blur_samples), summed over
/// the cameras (docs/performance.md gives the measured samples per second).
inline constexpr double kWarnPathSamples = 1e9;

/// estimated resident memory (bytes) of camera `camera` for the render `tier`.
double EstimateCameraMemoryBytes(const CameraSpec& camera, RenderSettings::Tier tier);

/// the machine's physical memory in bytes (sysconf(_SC_PHYS_PAGES) x page size; 0 if unknown).
double PhysicalMemoryBytes();

/// refuses a run whose cameras and LiDARs would need more than `limit_bytes` of memory
/// (e.g. PhysicalMemoryBytes(); <= 0 = no limit), before the renderer allocates anything.
/// `scene` is the assembled scene (session/scene_assembly.h): its cameras have their final sizes.
/// @throws ConfigError naming the world file and the camera's key (cameras[i].width,
///         mjcf_cameras.width, mjcf_cameras.overrides.<name>.width) or the LiDAR's
///         (sensors[...].columns), with the estimate and the limit.
void CheckRunMemory(const WorldConfig& world, const SceneDescription& scene, double limit_bytes);

/// how much a run does, from its duration, timestep, cameras, LiDARs and fluid effects.
struct RunWork {
  double physics_steps = 0;  ///< duration / timestep
  double camera_frames = 0;  ///< sum over cameras of rate x duration
  double image_bytes = 0;    ///< uncompressed bytes of every output image written
  double lidar_rays = 0;     ///< sum over LiDARs of beams per scan x scans
  double fluid_steps = 0;    ///< smoke plume and fire grid steps (duration / dt_sec each)
  /// pathtraced tier: camera paths traced, pixels x samples_per_pixel x frames (x motion blur
  /// sub-frames); 0 in the realtime tier.
  double path_samples = 0;
};

/// estimates a run's work. `timestep_sec` is the physics timestep that the run uses.
RunWork EstimateRunWork(const WorldConfig& world, const SceneDescription& scene,
                        double timestep_sec);

/// a one-line warning when any figure of `work` is above its kWarn* threshold, e.g.
/// "this run will take ~1e+08 physics steps and 3e+06 frames (~2e+11 bytes of images) ...";
/// nothing otherwise.
std::optional<std::string> DescribeRunWork(const RunWork& work);

}  // namespace penumbra

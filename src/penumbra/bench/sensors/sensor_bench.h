#pragma once
// `penumbra bench sensors`: LiDAR rays/s and wall time per scan, IMU / MuJoCo-sensor /
// ground-truth overhead, on the default world (or --world). a benchmark, never a test.

#include <string>

#include "penumbra/scene/scene_description.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// options of `penumbra bench sensors`.
struct SensorBenchOptions {
  std::string world_file;  ///< default: the bundled default world
  int scans = 20;          ///< timed scans per LiDAR preset
  double seconds = 5;      ///< simulated seconds for the IMU / MuJoCo overhead
};

/// prints the sensor benchmark tables. returns 0.
int BenchSensors(const SensorBenchOptions& options);

/// hook for camera image formation: frames/s per camera noise option (to be filled in by
/// the camera sensor work; prints what it measures). `scene` is the assembled scene of
/// `world`.
void BenchCameraNoiseOptions(const WorldConfig& world, const SceneDescription& scene);

}  // namespace penumbra

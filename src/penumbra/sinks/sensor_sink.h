#pragma once
// the run's sensors as a pipeline sink (pipeline/sink.h): every world-file sensor (`sensors:`,
// world/sensors_reader.h) on its own schedule (sensors/sensor_schedule.h), fed with physics
// snapshots, writing its outputs:
//
//   <out>/lidar/<name>/scan_<k>.pcd and index.csv, <out>/imu/<name>.csv and <name>_truth.csv,
//   <out>/sensors/<name>.csv, <out>/ground_truth/<name>.csv and <name>_contacts.csv
//   <out>/rig.json: the mount of every camera (not MJCF cameras), IMU and LiDAR, written at
//   construction: {"cameras"|"imus"|"lidars": {name: {"body", "X_BS", "rigid_body", "X_RS"}}}
//   with X_BS the sensor frame S in its body B, X_RS the same frame in the rigid body R it moves
//   with (B, or the first ancestor of B that has a joint, or "world"), each as {"xyz": [m],
//   "qwxyz": unit quaternion}; cameras' S is the OpenCV optical frame; IMUs also carry rate_hz
//   and their noise parameters (Kalibr names: gyroscope_noise_density, ..._random_walk,
//   accelerometer_noise_density, ..._random_walk).
//
// the sensor models (sensors/) return records (a LidarScan, an ImuSample, MuJoCo sensor values,
// the snapshot's poses and contacts); output/sensor_writers.h writes them (columns, units and
// number formats are documented there).
//
// stamps: capture_time_sec is the sim time of the physics step the sample was taken at,
// delivery_time_sec = capture + latency_sec. rows are written in capture order, which for
// one sensor (constant latency) is also its delivery order; both stamps are in every row.
// a LiDAR scan k covers [capture_k, capture_{k+1}): it is traced when scan k + 1's snapshot
// arrives, with the sensor pose interpolated between the two snapshots (motion distortion);
// the scan still open when the run ends is not written.
//
// episodes: the sink follows the simulation's controller episode start (a `reset`:
// Simulation::ResetControllers). at a new episode every schedule restarts on the episode's
// clock (steps since the episode start; the samples due before the loop's step pass), noise
// is keyed by the sample's index k within the episode (an IMU's bias walks from its stream's
// start), and the scan open at the reset is not written. written indices go on (index = the
// next one of the run + k - the episode's first k) and stamps are in run time. the first
// episode (no reset) samples and writes as before episodes existed.
//
// threading and determinism: the loop thread only decides which steps need a snapshot and
// evaluates the effects a LiDAR sees at the start of each scan (in step order, as the effects
// engine wants); the sensor models, the LiDAR ray tracing and every file write run on the
// sink's own thread (pipeline/sink_worker.h), one snapshot after the other in step order. each
// sensor draws noise from its own stream SensorStreamSeed(seed, name), so the outputs do not
// depend on thread timing.

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/physics/simulation.h"
#include "penumbra/pipeline/sink.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"
#include "penumbra/sensors/lidar_scanner.h"
#include "penumbra/sensors/sensor_schedule.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// the effects seen by a sensor at world position p_W (e.g. EffectsStage::Evaluate); may
/// return null for clear conditions. called on the loop thread only.
using SensorEffectsAt = std::function<std::shared_ptr<const EffectsFrame>(
    const WorldSnapshot& snapshot, const Eigen::Vector3d& p_W)>;

/// receives each output a sensor wrote: the sensor's name, the kind ("points.pcd" for a LiDAR
/// scan, "imu.csv" / "sensor.csv" for a row of an IMU / MuJoCo sensor stream), the physics step
/// and sim time of its capture, and the bytes written (the PCD file, the CSV row with '\n').
/// called on the sensor sink's thread, in step order. ground truth is not passed on (it is a
/// function of the simulation state).
using SensorOutputCallback = std::function<void(const std::string& sensor, const std::string& kind,
                                                int64_t step, double time_sec, std::string bytes)>;

/// one sample of a world-file sensor as its model produced it (what the files hold, unformatted),
/// for bridges (command/run_bridge.h).
struct SensorSample {
  std::string sensor;   ///< the sensor's name in the world file
  SensorKind kind = SensorKind::kImu;  ///< kImu, kLidar or kMujoco (sensors/sensor_types.h)
  int64_t index = 0;    ///< sample (scan) index k
  int64_t step = 0;     ///< physics step of the capture (a LiDAR scan: its start)
  double time_sec = 0;  ///< sim time of that step, s
  /// imu: accel x y z (m/s^2, specific force) then gyro x y z (rad/s), IMU frame, with noise;
  /// mujoco: the set's values with noise, in `columns` order; lidar: empty.
  std::vector<double> values;
  /// mujoco: one name per value (MujocoSensorSet::ColumnNames); otherwise empty.
  std::shared_ptr<const std::vector<std::string>> columns;
  /// lidar: the completed scan (sensor frame at each beam's firing time); otherwise null.
  std::shared_ptr<const LidarScan> scan;
};

/// receives every sensor sample; called on the sensor sink's thread, in step order.
using SensorSampleCallback = std::function<void(const SensorSample& sample)>;

/// all world-file sensors of one run.
class SensorSink : public Sink {
 public:
  /// resolves every sensor against the composed model (IMUs need compose/imu_injection.h's
  /// AddImuSensors applied to the model first) and opens the output files under `out_dir`.
  /// `scene` must outlive the stage (LiDARs ray trace it).
  /// @throws ConfigError naming the sensor's file, line and key (e.g. sensors[1].body) for a
  ///         body, site, MuJoCo sensor or preset setting that does not resolve.
  SensorSink(const WorldConfig& world, const Simulation& sim, const SceneDescription& scene,
             const std::string& out_dir, SensorEffectsAt effects_at = {});
  ~SensorSink() override;

  /// `on_output` receives every sensor output written from now on (set before the loop
  /// starts; e.g. a run log's sensor records); empty = none. the files do not change.
  void set_on_output(SensorOutputCallback on_output);

  /// `on_sample` receives every IMU, MuJoCo sensor and LiDAR sample from now on, as values
  /// (set before the loop starts); empty = none.
  void set_on_sample(SensorSampleCallback on_sample);

  /// loop thread, while the loop runs: blocks until every snapshot handed over so far is
  /// processed (its samples written and given to the callbacks).
  void Drain();

  /// true when the world has no sensors.
  bool empty() const;

  /// starts the sink's thread. a loop that starts at a later step (a replay from --from)
  /// samples what a run from step 0 samples from that step on, with the same indices.
  void OnStart(const LoopStart& start) override;
  /// advances the schedules to `step` (once per step, in order); kFull if any sensor is due.
  SnapshotContent Wants(int64_t step, double time_sec) override;
  /// the snapshot of a step Wants found sensors due at: queued for the sensors due (other
  /// snapshots are ignored).
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override;
  /// waits for the queued work, writes the buffered rows and closes the files.
  /// @throws Error naming the first file that could not be written (all are closed).
  void OnFinish(const LoopFinish& finish) override;

  /// samples (scans) written per sensor (read after OnFinish).
  std::map<std::string, int64_t> samples() const;
  /// wall time spent per sensor type (its SensorKindName: "lidar", "imu", ...), s; also
  /// "lidar_effects" (evaluating the effects a LiDAR sees, on the loop thread, part of "lidar")
  /// and "lidar_cpu" (thread CPU time of the LiDAR work). read after OnFinish.
  std::map<std::string, double> busy_sec() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace penumbra

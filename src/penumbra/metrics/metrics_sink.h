#pragma once
// the world file's `metrics:` (world/metrics_config.h) as a pipeline sink (pipeline/sink.h):
// named time series written to CSV at their rates, and end-of-run summaries for run.json.
//
//   <out>/metrics/<name>.csv            step,time_sec,<columns...>: one row per sample; column
//                                       names carry their unit ("go1/trunk_x_m",
//                                       "go1/FR_calf_N_m", "normal_force_N"; docs/metrics.md)
//   <out>/metrics/<name>_episodes.csv   contacts metrics: one row per collision episode, with
//                                       each side's speed towards the other at its start
//                                       (MetricsModel::BodyMovers; docs/metrics.md)
//
// a series samples at the first physics step whose time is at least k / rate_hz (k = 0, 1,
// ...); a contacts metric also looks at every physics step (detect_hz = 0) or at its detection
// rate to count collisions (metrics/collision_counter.h). values are read from the snapshot
// alone, so the same sink runs on live physics and on a recorded run:
//   - kinematic (MetricsMode::kKinematic, e.g. a replay without physics): body_pose,
//     body_twist, joint_position, joint_velocity, distance. body twists come from the snapshot's
//     V_WB when it has them, else from qvel for bodies moved by a free joint (MuJoCo's free
//     joint qvel: linear velocity of the body origin in world axes, angular in body axes).
//   - dynamics (MetricsMode::kDynamics, `penumbra run`, resimulation): also joint_torque
//     (WorldSnapshot::qfrc_actuator), sensor (sensordata), tracking_error and contacts. in
//     kinematic mode these are skipped with a warning and run.json says "unavailable".
//
// threading: Wants/OnSnapshot run on the loop thread and only decide what is due; values are
// read, summarised and written on the sink's own thread (pipeline/sink_worker.h).

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/control/model_info.h"
#include "penumbra/metrics/collision_counter.h"
#include "penumbra/pipeline/sink.h"
#include "penumbra/pipeline/sink_worker.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/sensor_description.h"
#include "penumbra/world/metrics_config.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

class Simulation;

/// which quantities the snapshots of a run can give (see the file comment).
enum class MetricsMode {
  kDynamics,   ///< live or resimulated physics: every metric
  kKinematic,  ///< poses and joint states only (no contacts, forces, sensors, controllers)
};

/// what the sink needs to know about the composed model: names and index maps.
struct MetricsModel {
  std::vector<std::string> body_names;     ///< by body index (0 = world)
  std::vector<int> body_parent;            ///< by body index: parent body (-1 for the world)
  std::vector<std::string> geom_names;     ///< by MuJoCo geom id ("" if unnamed)
  std::vector<int> geom_body;              ///< body index of each geom
  std::vector<JointInfo> joints;           ///< by MuJoCo joint id (control/model_info.h)
  std::vector<SensorDescription> sensors;  ///< by MuJoCo sensor id
  /// the simulation's controllers in order: the robot each drives and the labels of its
  /// tracking error (Controller::tracking_error_labels); WorldSnapshot::tracking_error holds
  /// their values concatenated in this order.
  struct ControllerTracking {
    std::string robot;
    std::string type;
    std::vector<std::string> labels;
  };
  std::vector<ControllerTracking> controllers;
  /// false when the simulation runs none of the world's controllers (a replay without them):
  /// tracking_error metrics are then unavailable, not an error.
  bool has_controllers = true;

  /// by body index: the body whose origin stands for the body's motion in contact attribution
  /// (its *mover*): the topmost ancestor below the world (a robot's root link), except that a
  /// world child named "<w>/<part>" where "<w>" is also a world child moves with "<w>" (an NPC
  /// agent's limbs and wheels move with its root, compose/agent_bodies.h). 0 for the world.
  std::vector<int> BodyMovers() const;

  /// from a composed, loaded world: scene bodies and geoms, joints, sensors, and the
  /// controllers of `world`'s robots (in Session's order: robots with a controller, in file
  /// order) when `sim` has exactly those, else none.
  static MetricsModel FromSimulation(const WorldConfig& world, const Simulation& sim);
};

/// records a world's metrics (see the file comment).
class MetricsSink : public Sink {
 public:
  /// resolves every name of `config` in `model` and creates `out_dir`/metrics/ with one CSV
  /// (header written) per metric available in `mode`.
  /// @throws ConfigError("", 0, key path e.g. "metrics.series[1].joints[0]", problem) for a
  ///         name that matches nothing (listing some that exist), a distance body or goal body
  ///         that does not exist, a tracking_error robot without a controller that reports one,
  ///         a body_twist body without a free joint in kinematic mode (LocateInWorld adds the
  ///         world file's line); Error naming the path if a file cannot be created.
  MetricsSink(const MetricsConfig& config, MetricsModel model, const std::string& out_dir,
              MetricsMode mode);
  ~MetricsSink() override;

  void OnStart(const LoopStart& start) override;
  /// the richest content of the metrics due at `step` (kNone when none is).
  SnapshotContent Wants(int64_t step, double time_sec) override;
  /// queues the due metrics of the snapshot of the step last asked for.
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override;
  /// writes the queued rows, closes open collision episodes and the files.
  /// @throws Error if a write failed.
  void OnFinish(const LoopFinish& finish) override;

  /// the run.json "metrics" object as JSON text (call after OnFinish): per metric its type,
  /// file, rows, rate_hz and per column {min, mean, max} over the finite samples (null when
  /// none); distance adds final_distance_m; contacts add collisions, collisions_by_pair
  /// ("<a> | <b>": count), peak_force_N and the episodes file; metrics unavailable in the
  /// mode give {"type", "unavailable": reason}.
  std::string SummaryJson() const;

  /// the CSV header columns of metric `name` (after step,time_sec); empty if not recorded.
  std::vector<std::string> Columns(const std::string& name) const;

 private:
  struct Series;
  void Process(const WorldSnapshot& s, const std::vector<uint8_t>& rows,
               const std::vector<uint8_t>& detect);

  void AppendEpisode(Series* s, const CollisionEpisode& e);
  std::pair<double, double> ApproachSpeeds(const ContactPairKey& pair,
                                           const Eigen::Vector3d& p_contact_W,
                                           const Eigen::Vector3d& n_ab, bool geom_pairs,
                                           const std::vector<Eigen::Vector3d>& mover_W,
                                           const std::vector<Eigen::Vector3d>* prev_mover_W,
                                           double dt) const;

  MetricsModel model_;
  std::vector<int> mover_;  // model_.BodyMovers()
  MetricsMode mode_;
  std::vector<std::unique_ptr<Series>> series_;
  std::vector<uint8_t> due_rows_, due_detect_;  // of the step last asked for
  int64_t due_step_ = -1;
  SinkWorker worker_;
};

/// the MetricsSink of `world` for a loaded simulation, or nullptr when the world has no
/// `metrics:`. `mode`: kDynamics for `penumbra run` and resimulation, kKinematic for a replay
/// that only moves the bodies. errors as MetricsSink's constructor.
std::unique_ptr<MetricsSink> MakeMetricsSink(const WorldConfig& world, const Simulation& sim,
                                             const std::string& out_dir, MetricsMode mode);

}  // namespace penumbra

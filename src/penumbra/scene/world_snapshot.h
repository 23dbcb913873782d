#pragma once
// the moving part of a world at one instant: what the renderer and sensors need to
// draw a frame, copied out of the physics state so that rendering can run on
// another thread, or later from a recording, without the physics engine. a snapshot is never
// changed once made (shared as std::shared_ptr<const WorldSnapshot> between threads); what a
// viewer sees beyond it (media, particles, light changes: scene/effects_frame.h) depends on the
// viewer and travels beside it.

#include <Eigen/Core>
#include <cstdint>
#include <vector>

#include "penumbra/core/pose.h"
#include "penumbra/scene/sim_state.h"

namespace penumbra {

/// state of a world at one simulation step: its SimState (step, time_sec and the state vectors,
/// scene/sim_state.h: what a bit-exact continuation needs, for recorders; filled by
/// PhysicsSource for every snapshot content, SnapshotContent::kState and up, and empty when a
/// source does not have them) and what is derived from it for renderers, sensors and metrics.
/// the SimState part is a SimState: `SimState s = snapshot;` copies exactly the state.
struct WorldSnapshot : SimState {
  /// the step the snapshot's episode started at (Simulation::controller_episode_start: the
  /// last `reset`; 0 in the first episode and for a snapshot not made by a Simulation). time
  /// in the episode is SimTimeOfStep(step - episode_start_step, timestep); effects and agents
  /// follow it (session/effects_stage.h).
  int64_t episode_start_step = 0;
  /// X_WB for every body of SceneDescription::bodies (index 0 = world = identity).
  std::vector<Pose> X_WB;
  /// X_W_mjcam: pose of every MJCF camera in MuJoCo's camera convention (x right,
  /// y up, looking along -z), after tracking modes are applied, by MuJoCo camera id.
  std::vector<Pose> X_W_mjcam;
  /// position and direction (unit) of every MJCF light in the world frame, by MuJoCo light id.
  std::vector<Eigen::Vector3d> light_position_W;
  std::vector<Eigen::Vector3d> light_direction_W;
  /// one unbroken run of a tendon's wrap points (MuJoCo wrap_xpos), in the world frame, m:
  /// a tendon is drawn as capsules between consecutive points; a pulley splits a tendon's path
  /// into several runs.
  struct TendonPath {
    int tendon = 0;                    ///< index into SceneDescription::tendons
    std::vector<Eigen::Vector3d> p_W;  ///< at least two points
  };
  /// the paths of SceneDescription::tendons at this instant (empty if the model has none).
  std::vector<TendonPath> tendon_paths;
  /// MuJoCo sensordata at this instant (Simulation::Snapshot evaluates the model's sensors
  /// for the snapshot's own state on a scratch copy); index with the adr/dim of
  /// scene/sensor_description.h. empty if the model has no sensors.
  std::vector<double> sensordata;
  /// V_WB of every body (index as X_WB): (angular rad/s; linear m/s) velocity of the body
  /// frame's origin, both in world-frame axes (MuJoCo mj_objectVelocity, flg_local = 0).
  std::vector<Eigen::Matrix<double, 6, 1>> V_WB;
  /// one active contact (MuJoCo d->contact and mj_contactForce).
  struct Contact {
    int geom1 = -1, geom2 = -1;         ///< MuJoCo geom ids
    int body1 = -1, body2 = -1;         ///< body indices
    Eigen::Vector3d p_W{0, 0, 0};       ///< contact point, m
    Eigen::Vector3d normal_W{0, 0, 1};  ///< unit normal, from geom1 towards geom2
    double distance_m = 0;              ///< signed distance (< 0 = penetration)
    /// force in the contact frame (normal, tangent 1, tangent 2), N; normal >= 0 pushes apart.
    Eigen::Vector3d force_N{0, 0, 0};
  };
  /// active contacts at this instant (ground truth for evaluation).
  std::vector<Contact> contacts;
  /// (nv) MuJoCo qfrc_actuator: the generalized force the actuators apply at each degree of
  /// freedom (N m at hinge dofs, N at slide dofs), index as qvel. filled with contacts.
  std::vector<double> qfrc_actuator;
  /// every controller's tracking error at its last update (control/controller.h,
  /// Controller::AppendTrackingError), concatenated in the simulation's controller order;
  /// filled with contacts.
  std::vector<double> tracking_error;
};

}  // namespace penumbra

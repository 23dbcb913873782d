#pragma once
// policy: runs a learned policy (an ONNX network, control/onnx_policy_network.h) on the control
// thread: at every policy update it assembles the observation vector from terms
// (control/policy_observation.h), runs the network and turns its output into joint targets
// (control/policy_action.h), which the actuators track at every physics step. docs/policies.md
// is the user guide.
//
// world-file block (robot-local names get the "<robot>/" prefix):
//   controller:
//     type: policy
//     model: policies/go1_flat.onnx  # ONNX file, relative to the world file's folder
//     preset: isaac_lab              # optional: a framework's observation / action convention
//                                    # (control/policy_preset.h): legged_gym,
//                                    # legged_gym_rough, isaac_lab, isaac_lab_rough, mjlab
//     base_body: trunk               # the floating base the base_* terms read
//     joints: [FL_hip, FR_hip, ...]  # the policy's joints in its training order (MJCF names);
//                                    # the model's order does not matter
//     default_joint_pos: [0.1, ...]  # one per joint (rad or m), or a mapping of regular
//                                    # expressions (ECMAScript, full match on the joint
//                                    # name) to values, the first matching entry wins:
//                                    # {".*L_hip": 0.1, ".*R_hip": -0.1, ".*_calf": -1.5};
//                                    # joints without a value default to 0
//     rate_hz: 50                    # policy rate on simulated time, a whole number of
//     decimation: 4                  # physics steps; or the number of physics steps per
//                                    # policy update (at most one of the two; default: the
//                                    # preset's rate, else 50 Hz)
//     seed: 0                        # seed of the observation noise (default 0)
//     observations: [...]            # the terms (control/policy_observation.h); with a
//                                    # preset, replaces the preset's list when given
//     action: {...}                  # control/policy_action.h; with a preset, each given
//                                    # field overrides the preset's
//     commands: [...]                # velocity commands (control/twist_command.h), like
//     waypoints: [...]               # trot_gait's: script, route and the `twist` /
//                                    # `waypoints` requests of the bridges, the viewer's
//                                    # teleop and the navigation baseline
//
// timing: the controller runs at every physics step (rate_hz() = 0). the policy runs at the
// steps k = 0, d, 2d, ... (d = decimation = round(1 / (rate_hz dt))): it reads the state
// and the command in force at that step, so a policy trained with PD at every physics step
// (legged_gym, Isaac Lab's explicit actuators) sees the same loop; the PD law of the action
// runs at every step with the latest targets.
//
// determinism: the network is float32 on one CPU thread of OpenCV's pool per output element
// (see control/onnx_policy_network.h); the noise stream is seeded by `seed`.

#include <Eigen/Core>
#include <array>
#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/control/controller.h"
#include "penumbra/control/controller_capabilities.h"
#include "penumbra/control/controller_params.h"
#include "penumbra/control/policy_action.h"
#include "penumbra/control/policy_network.h"
#include "penumbra/control/policy_observation.h"
#include "penumbra/control/terrain_ray_caster.h"
#include "penumbra/control/twist_command.h"

namespace penumbra {

/// one `default_joint_pos` mapping entry: a regular expression and its value.
struct JointDefaultPattern {
  std::string pattern;  ///< ECMAScript regex, full match on the robot-local joint name
  double value = 0;     ///< rad or m
};

/// parameters of a PolicyController (see the file comment).
struct PolicyParams {
  std::string model_path;                 ///< resolved against the world file's folder
  std::string preset;                     ///< "" = none
  std::string base_body;                  ///< full name
  std::vector<std::string> joints;        ///< full names, policy order
  std::vector<std::string> local_joints;  ///< the same without the robot prefix
  std::vector<double> default_joint_pos;  ///< (n) when given as a list
  std::vector<JointDefaultPattern> default_joint_patterns;  ///< when given as a mapping
  double rate_hz = 50;                                      ///< used when decimation is 0
  int decimation = 0;                                       ///< > 0 overrides rate_hz
  uint64_t seed = 0;
  std::vector<ObservationTermConfig> observations;
  PolicyActionParams action;
  TwistScriptParams script;

  /// reads the keys of the file comment; names get `name_prefix`.
  /// @throws ConfigError naming the key for missing, unknown or bad keys, and (naming the
  ///         ONNX file) for a model file that does not exist.
  static PolicyParams Parse(ControllerParams& params, const std::string& name_prefix);
  /// the default position (policy order) of each joint.
  /// @throws ConfigError (in `context`) for a list of the wrong length or a bad pattern.
  std::vector<double> DefaultPositions(const ControllerContext& context) const;
};

/// the policy controller (see the file comment).
class PolicyController final : public Controller,
                               public TwistTarget,
                               public WaypointTarget,
                               public TerrainRayCasterUser {
 public:
  /// @throws ConfigError for inconsistent params.
  PolicyController(PolicyParams params, ControllerContext context);
  ~PolicyController() override;

  std::string type() const override { return "policy"; }
  double rate_hz() const override { return 0; }
  std::vector<NameRequirement> RequiredNames() const override;
  void Compute(const ControlInput& input, std::span<double> ctrl) override;
  /// forgets the observation histories (their noise streams restart from the seed), the last
  /// action and target, the decimation count, the twist override and SetWaypoints (the
  /// configured route restarts).
  void Reset() override;
  /// command tracking at the last policy update: the command minus the base's velocity in
  /// its heading frame (m/s) and its yaw rate (rad/s).
  std::vector<std::string> tracking_error_labels() const override {
    return {"vx_error_m_s", "vy_error_m_s", "yaw_rate_error_rad_s"};
  }
  void AppendTrackingError(std::vector<double>* out) const override {
    out->insert(out->end(), tracking_.begin(), tracking_.end());
  }

  void SetTwist(const TrotCommand& command) override { source_.SetCommand(command); }
  void ClearTwist() override { source_.ClearCommand(); }
  /// a legged base moves sideways.
  bool lateral() const override { return true; }
  void SetWaypoints(std::vector<Eigen::Vector2d> waypoints, bool loop) override;

  /// the terrain ray caster of height_scan terms (not owned; must outlive the controller).
  void SetTerrainRayCaster(const TerrainRayCaster* caster) override {
    observation_.SetRayCaster(caster);
  }
  /// whether an observation term casts rays onto the terrain.
  bool needs_terrain_ray_caster() const override { return observation_.needs_ray_caster(); }

  const PolicyParams& params() const { return params_; }
  /// physics steps per policy update (valid after Initialize).
  int decimation() const { return decimation_; }
  /// the observation assembler (sizes valid after Initialize).
  const PolicyObservation& observation() const { return observation_; }
  /// the last observation vector given to the network (float32).
  const std::vector<float>& last_observation() const { return obs_; }
  /// the last raw network output after the action clip.
  const std::vector<double>& last_action() const { return action_; }
  /// the joint targets of the last update (rad, rad/s or N m by action type; policy order).
  const Eigen::VectorXd& targets() const { return target_; }
  /// the command in force at the last policy update.
  const TrotCommand& command() const { return command_; }
  /// default joint positions in policy order (valid after Initialize).
  const Eigen::VectorXd& default_positions() const { return default_q_; }

 protected:
  void OnInitialize(const ModelInfo& model, const std::vector<int>& ids) override;

 private:
  PolicyParams params_;
  PolicyObservation observation_;
  TwistCommandSource source_;
  std::unique_ptr<PolicyNetwork> network_;
  int decimation_ = 1;
  int base_ = -1;
  std::vector<int> qpos_, dof_;
  std::vector<ActuatorInfo> actuator_;
  std::vector<int> act_;
  Eigen::VectorXd default_q_, scale_, kp_, kd_, target_;
  bool servo_ = false;  ///< position / velocity servos take the target directly
  std::vector<float> obs_, out_;
  std::vector<double> action_;
  TrotCommand command_;
  int64_t step_ = 0;
  std::array<double, 3> tracking_ = {NAN, NAN, NAN};
};

}  // namespace penumbra

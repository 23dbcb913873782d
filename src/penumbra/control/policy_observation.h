#pragma once
// the observation vector of a learned policy (control/policy_controller.h), assembled from an
// ordered list of terms, as the manager-based frameworks (Isaac Lab, mjlab) and legged_gym build
// theirs. world-file form (inside the policy controller block):
//   observations:
//     - {term: base_ang_vel, scale: 0.25, clip: 100, noise: 0.2, history: 1}
//     - {term: velocity_command, scale: [2, 2, 0.25]}
//     - {term: height_scan, size_m: [1.6, 1.0], resolution_m: 0.1, offset_m: 0.5, order: xy}
//     - {term: contact, sensors: [FR_foot_touch, FL_foot_touch], threshold_n: 1}
//     - {term: phase, period_sec: 0.5}
//     - {term: sensor, name: imu_gyro}
//
// terms (values before noise / scale / clip; B = the base body's frame, W = world):
//   base_lin_vel       (3) R_WB^T v_WB: the base origin's linear velocity in B (m/s)
//   base_ang_vel       (3) R_WB^T w_WB: the base's angular velocity in B (rad/s)
//   projected_gravity  (3) R_WB^T (0, 0, -1): the unit gravity direction in B
//   velocity_command   (3) (vx, vy, yaw_rate) of the command in force (control/twist_command.h)
//   joint_pos          (n) q_j - q_default,j for the policy's joints, in the policy's order
//   joint_vel          (n) qdot_j (the default velocity is 0), in the policy's order
//   last_action        (m) the policy's previous output after its clip (0 before the first)
//   height_scan        (nx ny) z_base - z_hit - offset_m at a grid of vertical rays: grid
//                      points x_i = -size_x/2 + i resolution (i = 0 .. floor(size_x/res)), same
//                      for y, in the base's yaw frame (roll and pitch ignored: "yaw-aligned"),
//                      cast from start_m (default 20) above the base origin down within
//                      max_distance_m (default 50); `order: xy` lists x fastest (Isaac Lab's
//                      GridPatternCfg ordering "xy"), `order: yx` y fastest (legged_gym's
//                      torch.meshgrid(x, y)). a miss reads as a hit at the end of the ray.
//                      needs the session's terrain ray caster (control/terrain_ray_caster.h).
//   contact            (k) 1 when MuJoCo touch sensor k reads more than threshold_n (N), else 0
//   phase              (2) (sin 2 pi t / T, cos 2 pi t / T) with T = period_sec, t = sim time
//   sensor             (dim) the MuJoCo sensor's values (sensordata), e.g. an IMU gyro
//
// per term, at each policy update: v = value + noise, noise_k uniform in [-noise_k, noise_k]
// (one number or one per element; 0 = none); then v = scale v (one number or one per element);
// then v is clamped to [-clip, clip] when clip is given. with history h > 1 the term
// contributes its last h processed vectors, oldest first (Isaac Lab's flattened
// history_length); all h slots hold the first vector until h updates have passed. the noise is
// drawn from a 64-bit Mersenne Twister (std::mt19937_64) seeded with the controller's `seed`,
// term by term and element by element: the same world and seed give the same noise.

#include <Eigen/Core>
#include <cstdint>
#include <deque>
#include <optional>
#include <random>
#include <span>
#include <string>
#include <vector>

#include "penumbra/config/config_value.h"
#include "penumbra/control/control_input.h"
#include "penumbra/control/controller.h"
#include "penumbra/control/controller_params.h"
#include "penumbra/control/terrain_ray_caster.h"
#include "penumbra/control/twist_command.h"

namespace penumbra {

/// the observation terms (see the file comment).
enum class ObservationTermKind {
  kBaseLinVel,
  kBaseAngVel,
  kProjectedGravity,
  kVelocityCommand,
  kJointPos,
  kJointVel,
  kLastAction,
  kHeightScan,
  kContact,
  kPhase,
  kSensor,
};

/// the largest |scale| of an observation term, checked at load (clip and noise: at most 1e6).
inline constexpr double kObservationMaxScale = 1e4;

/// the world-file name of a term kind, e.g. "base_lin_vel".
const char* ObservationTermName(ObservationTermKind kind);
/// the kind named `name`, or nullopt.
std::optional<ObservationTermKind> ObservationTermFromName(const std::string& name);
/// every term name, in enum order, comma-separated (for messages).
std::string ObservationTermNames();

/// the grid of a height_scan term.
struct HeightScanGrid {
  double size_x_m = 1.6;       ///< extent along the base's heading (m, >= 0)
  double size_y_m = 1.0;       ///< extent to its left (m, >= 0)
  double resolution_m = 0.1;   ///< spacing (m, > 0)
  double offset_m = 0.5;       ///< subtracted from z_base - z_hit (m)
  double start_m = 20;         ///< ray origins this far above the base origin (m, > 0)
  double max_distance_m = 50;  ///< ray length (m, > 0)
  bool x_fastest = true;       ///< order "xy" (true) or "yx"

  int nx() const;  ///< floor(size_x / resolution + 1e-9) + 1
  int ny() const;
};

/// one observation term as configured.
struct ObservationTermConfig {
  ObservationTermKind kind = ObservationTermKind::kBaseLinVel;
  std::vector<double> scale = {1.0};  ///< 1 value or one per element
  std::optional<double> clip;         ///< > 0: clamp to [-clip, clip] after scaling
  std::vector<double> noise = {0.0};  ///< >= 0, 1 value or one per element (before scaling)
  int history = 1;                    ///< >= 1
  std::vector<std::string> sensors;   ///< contact: touch sensors; sensor: one (full names)
  double threshold_n = 1.0;           ///< contact threshold (N)
  double period_sec = 1.0;            ///< phase period (s, > 0)
  HeightScanGrid grid;                ///< height_scan

  /// reads one `observations[i]` mapping (`key` is its key path for errors); sensor names
  /// get `name_prefix`.
  /// @throws ConfigError naming key.<field> for unknown fields, unknown terms and bad values.
  static ObservationTermConfig Parse(ControllerParams& params, const ConfigValue& node,
                                     const std::string& key, const std::string& name_prefix);
};

/// names element `index` of an assembled observation vector whose terms are `terms` with
/// (per term, before history) `term_sizes`, e.g. "observations[2] (joint_vel) element 3,
/// history frame 0 of 1"; "element <index> (past the terms' N values)" when out of range.
std::string DescribeObservationElement(const std::vector<ObservationTermConfig>& terms,
                                       const std::vector<int>& term_sizes, int64_t index);

/// what an observation update reads besides the ControlInput.
struct ObservationContext {
  const ControlInput* input = nullptr;
  TrotCommand command;                  ///< the velocity command in force
  std::span<const double> last_action;  ///< (action size) the previous policy output
};

/// assembles observation vectors from terms (see the file comment). not thread-safe.
class PolicyObservation {
 public:
  /// @throws ConfigError (in `context`, key "observations[i]...") for inconsistent terms.
  PolicyObservation(std::vector<ObservationTermConfig> terms, uint64_t seed,
                    const ControllerContext& context);

  /// appends the sensors the terms name (key "observations[i].sensors[k]" / ".name").
  void AppendRequiredNames(std::vector<NameRequirement>* reqs) const;
  /// binds to the model. `base_body` is the base's body index; `joint_qpos` / `joint_dof` the
  /// qpos / qvel index of each policy joint (policy order); `default_q` (n) their default
  /// positions; `action_size` the length of last_action; `sensor_ids` the ids of the names
  /// AppendRequiredNames appended, in order.
  /// @throws ConfigError if a contact sensor is not 1-dimensional or a per-element scale /
  ///         noise list has the wrong length for its term.
  void Bind(const ModelInfo& model, int base_body, std::vector<int> joint_qpos,
            std::vector<int> joint_dof, Eigen::VectorXd default_q, int action_size,
            std::span<const int> sensor_ids);

  /// the terrain ray caster for height_scan terms (not owned; must outlive this object).
  void SetRayCaster(const TerrainRayCaster* caster) { caster_ = caster; }
  /// whether a term needs SetRayCaster.
  bool needs_ray_caster() const;

  /// length of the assembled vector (after Bind): sum of term size x history.
  int size() const { return size_; }
  /// (terms) each term's size before history (after Bind).
  const std::vector<int>& term_sizes() const { return term_sizes_; }
  const std::vector<ObservationTermConfig>& terms() const { return terms_; }

  /// the raw value of term `i` (before noise, scale, clip and history) into `out`
  /// (term_sizes()[i] values).
  /// @throws Error if a height_scan term has no ray caster.
  void RawTerm(int i, const ObservationContext& ctx, std::span<double> out) const;
  /// one update: processes every term, pushes its history and writes the vector (size()).
  void Assemble(const ObservationContext& ctx, std::span<float> out);
  /// forgets the histories and restarts the noise stream.
  void Reset();

 private:
  std::vector<ObservationTermConfig> terms_;
  uint64_t seed_ = 0;
  ControllerContext context_;
  std::mt19937_64 rng_;
  int base_ = -1;
  std::vector<int> joint_qpos_, joint_dof_;
  Eigen::VectorXd default_q_;
  std::vector<std::vector<int>> sensor_adr_;  ///< per term: sensordata address of each sensor
  std::vector<std::vector<int>> sensor_dim_;
  std::vector<int> term_sizes_;
  int size_ = 0;
  const TerrainRayCaster* caster_ = nullptr;
  std::vector<std::deque<std::vector<double>>> history_;  ///< per term, oldest first
  mutable std::vector<Eigen::Vector3d> ray_origins_;
  mutable std::vector<double> ray_hits_;
  std::vector<double> scratch_;
};

}  // namespace penumbra

// observation assembly of the policy controller, term by term, against vectors computed by
// hand for known poses (control/policy_observation.h).

#include "penumbra/control/policy_observation.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>

#include "control/policy_fake.h"
#include "penumbra/control/policy_controller.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using policy_fake::QuadInput;
using policy_fake::QuadModel;

ObservationTermConfig ObsTerm(ObservationTermKind kind) {
  ObservationTermConfig t;
  t.kind = kind;
  return t;
}

// binds `obs` to QuadModel with the policy joints `order` (indices of j0..j11) and defaults
void BindObs(PolicyObservation* obs, const ModelInfo& m, const std::vector<int>& order,
             const std::vector<double>& defaults, std::vector<int> sensor_ids = {}) {
  std::vector<int> qpos, dof;
  for (int i : order) {
    qpos.push_back(7 + i);
    dof.push_back(6 + i);
  }
  obs->Bind(m, 1, qpos, dof, Eigen::Map<const Eigen::VectorXd>(defaults.data(), defaults.size()),
            static_cast<int>(order.size()), sensor_ids);
}

std::vector<float> AssembleOnce(PolicyObservation* obs, const QuadInput& in,
                                const TrotCommand& cmd = {},
                                std::span<const double> last_action = {}) {
  std::vector<float> out(obs->size());
  ObservationContext ctx;
  ctx.input = &in;
  ctx.command = cmd;
  ctx.last_action = last_action;
  obs->Assemble(ctx, out);
  return out;
}

const ControllerContext kObsContext{"world.yaml", 3, "robots[q].controller"};

TEST(PolicyObservationTest, ProjectedGravityOnTiltedBase) {
  const ModelInfo m = QuadModel();
  QuadInput in(m);
  PolicyObservation obs({ObsTerm(ObservationTermKind::kProjectedGravity)}, 0, kObsContext);
  BindObs(&obs, m, {0}, {0.0});
  // pitched 20 deg nose down (rotation about y) and yawed 90 deg: yaw does not change the
  // gravity direction in the body frame; R_y(p)^T (0, 0, -1) = (sin p, 0, -cos p)
  in.X_WB_.linear() = (Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()) *
                       Eigen::AngleAxisd(20 * M_PI / 180, Eigen::Vector3d::UnitY()))
                          .toRotationMatrix();
  std::vector<float> g = AssembleOnce(&obs, in);
  EXPECT_NEAR(g[0], 0.3420201, 1e-6);
  EXPECT_NEAR(g[1], 0.0, 1e-6);
  EXPECT_NEAR(g[2], -0.9396926, 1e-6);
  // rolled 30 deg: R_x(r)^T (0, 0, -1) = (0, -sin r, -cos r)
  in.X_WB_.linear() = Eigen::AngleAxisd(M_PI / 6, Eigen::Vector3d::UnitX()).toRotationMatrix();
  g = AssembleOnce(&obs, in);
  EXPECT_NEAR(g[0], 0.0, 1e-6);
  EXPECT_NEAR(g[1], -0.5, 1e-6);
  EXPECT_NEAR(g[2], -0.8660254, 1e-6);
}

TEST(PolicyObservationTest, BaseVelocitiesInBodyFrame) {
  const ModelInfo m = QuadModel();
  QuadInput in(m);
  PolicyObservation obs(
      {ObsTerm(ObservationTermKind::kBaseLinVel), ObsTerm(ObservationTermKind::kBaseAngVel)}, 0,
      kObsContext);
  BindObs(&obs, m, {0}, {0.0});
  // yawed +90 deg: world x is the body's -y, world y its +x
  in.X_WB_.linear() = Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  in.V_WB_ << 0.1, 0.2, 0.3, 1.0, 2.0, 0.5;  // (angular, linear) in world coordinates
  const std::vector<float> v = AssembleOnce(&obs, in);
  const std::vector<double> expected = {2.0, -1.0, 0.5, 0.2, -0.1, 0.3};
  ASSERT_EQ(v.size(), expected.size());
  for (size_t k = 0; k < v.size(); ++k) EXPECT_NEAR(v[k], expected[k], 1e-6) << k;
}

TEST(PolicyObservationTest, JointTermsFollowThePolicyOrderByName) {
  const ModelInfo m = QuadModel();
  QuadInput in(m);
  PolicyObservation obs(
      {ObsTerm(ObservationTermKind::kJointPos), ObsTerm(ObservationTermKind::kJointVel)}, 0,
      kObsContext);
  // the policy's order: j2, j0, j1 (model order j0, j1, j2); defaults in policy order
  BindObs(&obs, m, {2, 0, 1}, {0.3, 0.1, 0.2});
  in.q_[7] = 0.15;   // j0
  in.q_[8] = 0.5;    // j1
  in.q_[9] = -0.4;   // j2
  in.qd_[6] = 1.0;   // j0
  in.qd_[7] = 2.0;   // j1
  in.qd_[8] = -3.0;  // j2
  const std::vector<float> v = AssembleOnce(&obs, in);
  // joint_pos: (j2 - 0.3, j0 - 0.1, j1 - 0.2); joint_vel: (j2, j0, j1)
  const std::vector<double> expected = {-0.7, 0.05, 0.3, -3.0, 1.0, 2.0};
  ASSERT_EQ(v.size(), expected.size());
  for (size_t k = 0; k < v.size(); ++k) EXPECT_NEAR(v[k], expected[k], 1e-6) << k;
}

TEST(PolicyObservationTest, CommandLastActionContactPhaseAndSensor) {
  const ModelInfo m = QuadModel();
  QuadInput in(m);
  ObservationTermConfig contact = ObsTerm(ObservationTermKind::kContact);
  contact.sensors = {"q/touch0", "q/touch1", "q/touch2", "q/touch3"};
  contact.threshold_n = 1.0;
  ObservationTermConfig phase = ObsTerm(ObservationTermKind::kPhase);
  phase.period_sec = 0.5;
  ObservationTermConfig gyro = ObsTerm(ObservationTermKind::kSensor);
  gyro.sensors = {"q/gyro"};
  PolicyObservation obs({ObsTerm(ObservationTermKind::kVelocityCommand),
                         ObsTerm(ObservationTermKind::kLastAction), contact, phase, gyro},
                        0, kObsContext);
  BindObs(&obs, m, {0, 1}, {0.0, 0.0}, {0, 1, 2, 3, 4});
  EXPECT_EQ(obs.size(), 3 + 2 + 4 + 2 + 3);
  in.t_ = 0.125;  // a quarter period: (sin, cos) = (1, 0)
  in.sd_ = {0.0, 5.0, 1.0, 1.5, 0.1, -0.2, 0.3};
  const std::vector<double> last = {0.25, -0.75};
  const std::vector<float> v = AssembleOnce(&obs, in, TrotCommand{0.5, -0.1, 0.7}, last);
  // contact: touch readings 0, 5, 1 (not above the 1 N threshold), 1.5
  const std::vector<double> expected = {0.5, -0.1, 0.7, 0.25, -0.75, 0,    1,
                                        0,   1,    1,   0,    0.1,   -0.2, 0.3};
  ASSERT_EQ(v.size(), expected.size());
  for (size_t k = 0; k < v.size(); ++k) EXPECT_NEAR(v[k], expected[k], 1e-6) << k;
}

TEST(PolicyObservationTest, ScaleThenClipAndHistoryOldestFirst) {
  const ModelInfo m = QuadModel();
  QuadInput in(m);
  ObservationTermConfig w = ObsTerm(ObservationTermKind::kBaseAngVel);
  w.scale = {0.25, 0.5, 1.0};
  w.clip = 0.6;
  w.history = 3;
  PolicyObservation obs({w}, 0, kObsContext);
  BindObs(&obs, m, {0}, {0.0});
  ASSERT_EQ(obs.size(), 9);
  // first update: every history slot holds it
  in.V_WB_ << 1.0, 1.0, 1.0, 0, 0, 0;
  std::vector<float> v = AssembleOnce(&obs, in);
  for (int h = 0; h < 3; ++h) {
    EXPECT_NEAR(v[3 * h + 0], 0.25, 1e-7);
    EXPECT_NEAR(v[3 * h + 1], 0.5, 1e-7);
    EXPECT_NEAR(v[3 * h + 2], 0.6, 1e-7);  // 1.0 scaled, then clipped to 0.6
  }
  in.V_WB_ << 2.0, -2.0, 0.2, 0, 0, 0;
  v = AssembleOnce(&obs, in);
  // oldest first: [first, first, second]
  EXPECT_NEAR(v[0], 0.25, 1e-7);
  EXPECT_NEAR(v[3], 0.25, 1e-7);
  EXPECT_NEAR(v[6], 0.5, 1e-7);
  EXPECT_NEAR(v[7], -0.6, 1e-7);
  EXPECT_NEAR(v[8], 0.2, 1e-7);
}

TEST(PolicyObservationTest, NoiseIsSeededAndBounded) {
  const ModelInfo m = QuadModel();
  QuadInput in(m);
  ObservationTermConfig g = ObsTerm(ObservationTermKind::kProjectedGravity);
  g.noise = {0.05};
  g.scale = {2.0};
  auto run = [&](uint64_t seed) {
    PolicyObservation obs({g}, seed, kObsContext);
    BindObs(&obs, m, {0}, {0.0});
    std::vector<float> all;
    for (int k = 0; k < 50; ++k) {
      const std::vector<float> v = AssembleOnce(&obs, in);
      all.insert(all.end(), v.begin(), v.end());
    }
    return all;
  };
  const std::vector<float> a = run(7), b = run(7), c = run(8);
  EXPECT_EQ(a, b);
  EXPECT_NE(a, c);
  // noise before scaling: (0, 0, -1) + u, |u| <= 0.05, times 2
  double spread = 0;
  for (size_t k = 0; k < a.size(); ++k) {
    const double clean = k % 3 == 2 ? -2.0 : 0.0;
    EXPECT_LE(std::abs(a[k] - clean), 0.1 + 1e-6);
    spread = std::max(spread, std::abs(a[k] - clean));
  }
  EXPECT_GT(spread, 0.05);  // it does add noise
}

// a terrain that is the plane z = 0.1 x + 0.02, for the grid geometry
class SlopeCaster final : public TerrainRayCaster {
 public:
  void CastDown(std::span<const Eigen::Vector3d> origins, double max_distance_m,
                std::span<double> hit_z) const override {
    for (size_t k = 0; k < origins.size(); ++k) {
      const double z = 0.1 * origins[k].x() + 0.02;
      hit_z[k] = origins[k].z() - z <= max_distance_m ? z : NAN;
    }
  }
};

TEST(PolicyObservationTest, HeightScanGridInTheYawFrame) {
  const ModelInfo m = QuadModel();
  QuadInput in(m);
  ObservationTermConfig h = ObsTerm(ObservationTermKind::kHeightScan);
  h.grid.size_x_m = 0.2;
  h.grid.size_y_m = 0.1;
  h.grid.resolution_m = 0.1;
  h.grid.offset_m = 0.5;
  h.grid.x_fastest = true;
  PolicyObservation obs({h}, 0, kObsContext);
  BindObs(&obs, m, {0}, {0.0});
  EXPECT_TRUE(obs.needs_ray_caster());
  ASSERT_EQ(obs.size(), 3 * 2);
  // no caster: a clear error, not a crash
  EXPECT_THROW(AssembleOnce(&obs, in), Error);
  SlopeCaster caster;
  obs.SetRayCaster(&caster);
  // base at (1, 2, 0.4), yawed +90 deg and pitched 10 deg (the pitch is ignored): a grid
  // point (x, y) in the yaw frame is at world (1 - y, 2 + x); value = 0.4 - z_hit - 0.5 with
  // z_hit = 0.1 (1 - y) + 0.02. points: x in {-0.1, 0, 0.1} (fastest), y in {-0.05, 0.05}
  in.X_WB_.translation() << 1, 2, 0.4;
  in.X_WB_.linear() = (Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ()) *
                       Eigen::AngleAxisd(0.17, Eigen::Vector3d::UnitY()))
                          .toRotationMatrix();
  const std::vector<float> v = AssembleOnce(&obs, in);
  // y = -0.05: z_hit = 0.125 -> -0.225 (three times); y = 0.05: z_hit = 0.115 -> -0.215
  const std::vector<double> expected = {-0.225, -0.225, -0.225, -0.215, -0.215, -0.215};
  for (size_t k = 0; k < v.size(); ++k) EXPECT_NEAR(v[k], expected[k], 1e-6) << k;

  // y fastest (legged_gym) with no yaw: world point (1 + x, 2 + y), z_hit = 0.1 (1 + x) + 0.02
  h.grid.x_fastest = false;
  PolicyObservation yx({h}, 0, kObsContext);
  BindObs(&yx, m, {0}, {0.0});
  yx.SetRayCaster(&caster);
  in.X_WB_.linear().setIdentity();
  const std::vector<float> w = AssembleOnce(&yx, in);
  // x = -0.1: z_hit 0.11 -> -0.21 (for both y); x = 0: -0.22; x = 0.1: -0.23
  const std::vector<double> expected_yx = {-0.21, -0.21, -0.22, -0.22, -0.23, -0.23};
  for (size_t k = 0; k < w.size(); ++k) EXPECT_NEAR(w[k], expected_yx[k], 1e-6) << k;
}

TEST(PolicyObservationTest, PerElementListsMustMatchTheTermSize) {
  const ModelInfo m = QuadModel();
  ObservationTermConfig j = ObsTerm(ObservationTermKind::kJointPos);
  j.scale = {1.0, 2.0};  // 2 values for 3 joints
  PolicyObservation obs({j}, 0, kObsContext);
  try {
    BindObs(&obs, m, {0, 1, 2}, {0, 0, 0});
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("observations[0].scale"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("expected 1 value or 3"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace penumbra

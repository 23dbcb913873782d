// the bundled quadrotor model as the multirotor controller reads it (mass properties and
// rotor allocation from ModelInfo), the prioritised mixer, and the path reference.

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/control/multirotor_mixer.h"
#include "penumbra/control/multirotor_model.h"
#include "penumbra/control/multirotor_path.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

const std::string kModel = std::string(PENUMBRA_SOURCE_DIR) + "/worlds/models/quadrotor.xml";
const std::vector<std::string> kRotors = {"thrust_fr", "thrust_rl", "thrust_fl", "thrust_rr"};

MultirotorModel Airframe(const ModelInfo& mi) {
  std::vector<int> ids;
  std::vector<std::string> keys;
  for (size_t i = 0; i < kRotors.size(); ++i) {
    ids.push_back(mi.Find(ModelObject::kActuator, kRotors[i]));
    keys.push_back("rotor_actuators[" + std::to_string(i) + "]");
  }
  return BuildMultirotorModel(mi, mi.Find(ModelObject::kBody, "base"), ids, keys, {});
}

TEST(QuadrotorModel, ModelInfoCarriesMassPropertiesSitesAndGear) {
  Simulation sim = Simulation::LoadFromFile(kModel);
  const ModelInfo& mi = sim.model_info();
  const int base = mi.Find(ModelObject::kBody, "base");
  const int mount = mi.Find(ModelObject::kBody, "camera_mount");
  ASSERT_GE(base, 0);
  ASSERT_GE(mount, 0);
  EXPECT_DOUBLE_EQ(mi.body_mass[base], 1.25);
  EXPECT_DOUBLE_EQ(mi.body_mass[mount], 0.05);
  EXPECT_NEAR(mi.body_inertia[base].x(), 0.0056, 1e-12);
  EXPECT_NEAR(mi.body_inertia[base].y(), 0.0071, 1e-12);
  EXPECT_NEAR(mi.body_inertia[base].z(), 0.0121, 1e-12);
  EXPECT_TRUE(mi.body_X_PB[mount].translation().isApprox(Eigen::Vector3d(0.15, 0, -0.02)));
  EXPECT_TRUE(mi.body_X_BI[mount].translation().isApprox(Eigen::Vector3d(-0.016, 0, 0)));
  const int a = mi.Find(ModelObject::kActuator, "thrust_fl");
  const int s = mi.Find(ModelObject::kSite, "rotor_fl");
  ASSERT_GE(a, 0);
  EXPECT_EQ(mi.actuators[a].site, s);
  EXPECT_EQ(mi.actuators[a].joint, -1);
  EXPECT_DOUBLE_EQ(mi.actuators[a].gear[2], 1.0);
  EXPECT_DOUBLE_EQ(mi.actuators[a].gear[5], 0.016);
  EXPECT_TRUE(mi.site_X_BS[s].translation().isApprox(Eigen::Vector3d(0.1273, 0.1273, 0.04)));
  EXPECT_EQ(mi.site_body[s], base);
  // bundled names the docs promise
  for (const char* n : {"imu_accel", "imu_gyro"}) EXPECT_GE(mi.Find(ModelObject::kSensor, n), 0);
  EXPECT_GE(mi.Find(ModelObject::kSite, "imu"), 0);
  EXPECT_GE(mi.Find(ModelObject::kJoint, "root"), 0);
}

TEST(QuadrotorModel, AirframeMassInertiaAndAllocation) {
  Simulation sim = Simulation::LoadFromFile(kModel);
  const MultirotorModel af = Airframe(sim.model_info());
  EXPECT_NEAR(af.mass_kg, 1.30, 1e-12);
  // centre of mass: the 0.05 kg camera at (0.134, 0, -0.02) pulls it forward and down
  const Eigen::Vector3d r_cam(0.134, 0, -0.02);
  const Eigen::Vector3d c = 0.05 * r_cam / 1.30;
  EXPECT_TRUE(af.com_B.isApprox(c, 1e-12)) << af.com_B.transpose();
  // parallel-axis theorem by hand for the two point-offset bodies
  auto shift = [](double m, const Eigen::Vector3d& r) -> Eigen::Matrix3d {
    return m * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  };
  const Eigen::Matrix3d J = Eigen::Vector3d(0.0056, 0.0071, 0.0121).asDiagonal().toDenseMatrix() +
                            shift(1.25, -c) + 1e-5 * Eigen::Matrix3d::Identity() +
                            shift(0.05, r_cam - c);
  EXPECT_TRUE(af.inertia_B.isApprox(J, 1e-12)) << af.inertia_B;
  EXPECT_GT(af.inertia_B(2, 2), af.inertia_B(1, 1));
  EXPECT_GT(af.inertia_B(1, 1), af.inertia_B(0, 0));

  ASSERT_EQ(af.num_rotors(), 4);
  for (int i = 0; i < 4; ++i) {
    EXPECT_DOUBLE_EQ(af.allocation(0, i), 1.0);  // thrust along +z
    EXPECT_DOUBLE_EQ(af.min_thrust_n[i], 0.0);
    EXPECT_DOUBLE_EQ(af.max_thrust_n[i], 7.0);
  }
  // rotor 0 = front right (x > 0, y < 0): negative roll torque (lifts the right side), negative
  // pitch torque (lifts the nose), counter-clockwise propeller -> yaw torque -0.016
  EXPECT_NEAR(af.allocation(1, 0), -0.1273 - c.y(), 1e-12);
  EXPECT_NEAR(af.allocation(2, 0), -(0.1273 - c.x()), 1e-12);
  EXPECT_NEAR(af.allocation(3, 0), -0.016, 1e-12);
  EXPECT_NEAR(af.allocation(3, 2), 0.016, 1e-12);  // front left, clockwise

  // thrust-to-weight ratio 28 N / 12.75 N = 2.2
  EXPECT_NEAR(4 * 7.0 / (1.30 * 9.81), 2.2, 0.01);
}

TEST(QuadrotorModel, AirframeErrorsNameTheRotorKey) {
  // an actuator on a joint is not a rotor; a rotor with no ctrl limit has no thrust range
  const std::string xml = R"(<mujoco>
  <worldbody>
    <body name="base">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.02" mass="1"/>
      <site name="r0" pos="0.1 0.1 0"/><site name="r1" pos="-0.1 0.1 0"/>
      <site name="r2" pos="-0.1 -0.1 0"/><site name="r3" pos="0.1 -0.1 0"/>
      <body name="flap" pos="0 0 -0.05"><joint name="hinge" axis="0 1 0"/>
        <geom type="box" size="0.01 0.01 0.01" mass="0.01"/></body>
    </body>
  </worldbody>
  <actuator>
    <motor name="m0" site="r0" gear="0 0 1 0 0 0.01" ctrllimited="true" ctrlrange="0 5"/>
    <motor name="m1" site="r1" gear="0 0 1 0 0 -0.01" ctrllimited="true" ctrlrange="0 5"/>
    <motor name="m2" site="r2" gear="0 0 1 0 0 0.01"/>
    <motor name="m3" joint="hinge"/>
    <motor name="sideways" site="r3" gear="1 0 0 0 0 0" ctrllimited="true" ctrlrange="0 5"/>
  </actuator>
</mujoco>)";
  Simulation sim = Simulation::LoadFromString(xml);
  const ModelInfo& mi = sim.model_info();
  const int base = mi.Find(ModelObject::kBody, "base");
  auto message = [&](const std::vector<std::string>& names) {
    std::vector<int> ids;
    std::vector<std::string> keys;
    for (size_t i = 0; i < names.size(); ++i) {
      ids.push_back(mi.Find(ModelObject::kActuator, names[i]));
      keys.push_back("rotor_actuators[" + std::to_string(i) + "]");
    }
    try {
      BuildMultirotorModel(mi, base, ids, keys, {"w.yaml", 3, "robots[x].controller"});
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string("no error");
  };
  EXPECT_NE(message({"m0", "m1", "m3", "m2"})
                .find("rotor_actuators[2]: actuator 'm3' does not "
                      "act on a site"),
            std::string::npos);
  EXPECT_NE(message({"m0", "m1", "m2", "m0"})
                .find("rotor_actuators[2]: actuator 'm2' has ctrl "
                      "range"),
            std::string::npos);
  EXPECT_NE(message({"sideways", "m0", "m1"})
                .find("rotor_actuators[0]: actuator 'sideways' "
                      "pushes along (1, 0, 0)"),
            std::string::npos);
  // three rotors can't control four axes
  EXPECT_NE(message({"m0", "m1", "m0"}).find("allocation rank < 4"), std::string::npos);
}

class QuadrotorMixerTest : public ::testing::Test {
 protected:
  void SetUp() override {
    Simulation sim = Simulation::LoadFromFile(kModel);
    af_ = Airframe(sim.model_info());
    mixer_ = MultirotorMixer(af_.allocation, af_.min_thrust_n, af_.max_thrust_n);
  }
  // mixes and checks every rotor is within [0, 7] N; returns the delivered wrench
  Eigen::Vector4d MixChecked(double T, const Eigen::Vector3d& tau, MixResult* r) {
    std::vector<double> f(4);
    *r = mixer_.Mix(T, tau, f);
    for (double fi : f) {
      EXPECT_GE(fi, 0.0);
      EXPECT_LE(fi, 7.0);
    }
    return mixer_.Wrench(f);
  }
  MultirotorModel af_;
  MultirotorMixer mixer_;
};

TEST_F(QuadrotorMixerTest, UnsaturatedMixIsExact) {
  MixResult r;
  const Eigen::Vector4d w = MixChecked(12.75, {0.1, -0.2, 0.03}, &r);
  EXPECT_TRUE(w.isApprox(Eigen::Vector4d(12.75, 0.1, -0.2, 0.03), 1e-12)) << w.transpose();
  EXPECT_FALSE(r.saturated());
  // hover: the weight shared so that there is no torque about the centre of mass, which the
  // camera pulls 5 mm forward: the front rotors (0 = front right, 2 = front left) carry more
  std::vector<double> f(4);
  mixer_.Mix(1.30 * 9.81, Eigen::Vector3d::Zero(), f);
  EXPECT_NEAR(f[0] + f[1] + f[2] + f[3], 1.30 * 9.81, 1e-12);
  EXPECT_NEAR(f[0], f[2], 1e-12);
  EXPECT_NEAR(f[1], f[3], 1e-12);
  // moments about the COM's y axis balance: front lever 0.1273 - c_x, rear 0.1273 + c_x
  const double cx = af_.com_B.x();
  EXPECT_NEAR(f[0] * (0.1273 - cx), f[1] * (0.1273 + cx), 1e-12);
  EXPECT_GT(f[0], f[1]);
}

TEST_F(QuadrotorMixerTest, YawGivesWayFirst) {
  // hover thrust with a yaw torque beyond what the rotors can add: thrust, roll and pitch
  // stay exact, yaw is cut to the headroom (every rotor at a limit)
  MixResult r;
  const Eigen::Vector4d w = MixChecked(12.75, {0.05, 0.05, 0.5}, &r);
  EXPECT_NEAR(w[0], 12.75, 1e-9);
  EXPECT_NEAR(w[1], 0.05, 1e-9);
  EXPECT_NEAR(w[2], 0.05, 1e-9);
  EXPECT_LT(w[3], 0.5);
  EXPECT_GT(w[3], 0.05);
  EXPECT_NEAR(r.roll_pitch_scale, 1.0, 1e-12);
  EXPECT_LT(r.yaw_scale, 1.0);
  EXPECT_FALSE(r.collective_limited);
}

TEST_F(QuadrotorMixerTest, CollectiveGivesWayToRollAndPitch) {
  // near full thrust with a roll torque: the collective drops so the roll is delivered
  MixResult r;
  const Eigen::Vector4d w = MixChecked(26.0, {0.5, 0.0, 0.0}, &r);
  EXPECT_NEAR(w[1], 0.5, 1e-9);
  EXPECT_LT(w[0], 26.0);
  EXPECT_NEAR(w[0], r.collective_n, 1e-9);
  EXPECT_TRUE(r.collective_limited);
  EXPECT_NEAR(r.roll_pitch_scale, 1.0, 1e-12);
  // at zero thrust the collective rises so the roll is still delivered ("air mode")
  const Eigen::Vector4d w0 = MixChecked(0.0, {0.0, -0.3, 0.0}, &r);
  EXPECT_NEAR(w0[2], -0.3, 1e-9);
  EXPECT_GT(w0[0], 0.0);
}

TEST_F(QuadrotorMixerTest, RollPitchScaledKeepingDirection) {
  // more roll/pitch torque than the rotors have: scaled down, the ratio kept
  MixResult r;
  const Eigen::Vector4d w = MixChecked(12.75, {3.0, -1.5, 0.2}, &r);
  EXPECT_LT(r.roll_pitch_scale, 1.0);
  EXPECT_NEAR(w[1] / w[2], -2.0, 1e-9);
  EXPECT_NEAR(w[1], 3.0 * r.roll_pitch_scale, 1e-9);
  EXPECT_NEAR(w[3], 0.2 * r.yaw_scale, 1e-9);
  // the largest deliverable: rotors 0..3 at their limits in the roll/pitch pattern
  const double max_roll = 2 * 7.0 * 0.1273;  // two rotors on one side at 7 N, two at 0
  EXPECT_GT(std::abs(w[1]), 0.6 * max_roll);
}

TEST(QuadrotorPath, HarmonicTrapezoidThroughCorners) {
  const MultirotorPath path({0, 0, 1}, {{4, 0, 1}, {4, 4, 1}, {4, 4, 1.05}}, 1.0, 2.0);
  // per 4 m segment: two ramps of pi v / (2 a) = 0.785 s covering 0.785 m, 3.215 s cruise
  const double t_ramp = M_PI / 4;
  const double t_seg = 2 * t_ramp + (4 - t_ramp) / 1.0;
  // 5 cm segment: triangle peaking at sqrt(2 a L / pi)
  const double v_short = std::sqrt(2 * 2.0 * 0.05 / M_PI);
  EXPECT_NEAR(path.duration_sec(), 2 * t_seg + 2 * M_PI * v_short / 4, 1e-12);
  double max_speed = 0, max_acc = 0;
  PathSample prev = path.Sample(0);
  for (double t = 0.001; t < path.duration_sec() + 0.5; t += 0.001) {
    const PathSample s = path.Sample(t);
    max_speed = std::max(max_speed, s.velocity.norm());
    max_acc = std::max(max_acc, s.acceleration.norm());
    // continuous position, velocity and acceleration (finite jerk)
    EXPECT_LT((s.position - prev.position).norm(), 1.001e-3 + 1e-12);
    EXPECT_LT((s.velocity - prev.velocity).norm(), 2.01e-3);
    EXPECT_LT((s.acceleration - prev.acceleration).norm(), 0.05);  // jerk <= 45 m/s^3
    // on the polyline
    const Eigen::Vector3d& p = s.position;
    const bool on = (std::abs(p.y()) < 1e-12 && std::abs(p.z() - 1) < 1e-12) ||
                    (std::abs(p.x() - 4) < 1e-12 && std::abs(p.z() - 1) < 1e-12) ||
                    (std::abs(p.x() - 4) < 1e-12 && std::abs(p.y() - 4) < 1e-12);
    EXPECT_TRUE(on) << p.transpose();
    prev = s;
  }
  EXPECT_NEAR(max_speed, 1.0, 1e-9);
  EXPECT_NEAR(max_acc, 2.0, 1e-5);
  // rest at each corner
  EXPECT_LT(path.Sample(t_seg).velocity.norm(), 1e-12);
  EXPECT_TRUE(path.Sample(t_seg).position.isApprox(Eigen::Vector3d(4, 0, 1)));
  EXPECT_TRUE(path.Sample(1e9).position.isApprox(Eigen::Vector3d(4, 4, 1.05)));
  EXPECT_EQ(path.Sample(1e9).velocity.norm(), 0.0);
}

}  // namespace
}  // namespace penumbra

// every MuJoCo-native sensor of an inline MJCF is readable by name with its dimension,
// unit and value.
#include "penumbra/sensors/mujoco_sensors.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

// a 2 kg box resting on the floor with a touch site; an arm on a vertical hinge with a
// slide joint whose 0.01 kg carriage carries a 0.5 kg weight down to the joint limit, with a
// force/torque site on the carriage; rangefinders on a fixed body pointing down (0.3 m
// above the floor) and up (nothing).
constexpr const char* kModel = R"(
<mujoco>
  <option timestep="0.002"/>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <body name="mast" pos="2 0 0.3">
      <site name="down" zaxis="0 0 -1"/>
      <site name="up" zaxis="0 0 1"/>
    </body>
    <body name="box" pos="0 0 0.1">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.1" mass="2"/>
      <site name="pad" type="box" size="0.11 0.11 0.02" pos="0 0 -0.1"/>
    </body>
    <body name="arm" pos="0 1 2">
      <joint name="hinge" type="hinge" axis="0 0 1" damping="1"/>
      <geom type="capsule" fromto="0 0 0 0.3 0 0" size="0.02" mass="0.1"/>
      <body name="carriage" pos="0.3 0 0">
        <joint name="slider" type="slide" axis="0 0 1" limited="true" range="-0.2 0.2" damping="5"/>
        <geom type="box" size="0.02 0.02 0.02" mass="0.01"/>
        <site name="ft" pos="0 0 -0.05"/>
        <body name="weight" pos="0 0 -0.1">
          <geom type="sphere" size="0.03" mass="0.5"/>
        </body>
      </body>
    </body>
  </worldbody>
  <sensor>
    <touch name="touch" site="pad"/>
    <force name="force" site="ft"/>
    <torque name="torque" site="ft"/>
    <jointpos name="hinge_pos" joint="hinge"/>
    <jointpos name="slider_pos" joint="slider"/>
    <jointvel name="hinge_vel" joint="hinge"/>
    <framepos name="box_pos" objtype="body" objname="box"/>
    <framequat name="box_quat" objtype="body" objname="box"/>
    <rangefinder name="range_down" site="down"/>
    <rangefinder name="range_up" site="up"/>
    <accelerometer name="box_acc" site="pad"/>
    <gyro name="box_gyro" site="pad"/>
    <subtreecom name="arm_com" body="arm"/>
    <clock name="clock"/>
  </sensor>
</mujoco>)";

TEST(MujocoSensorsTest, EverySensorReadableByNameWithDimensionUnitAndValue) {
  Simulation sim = Simulation::LoadFromString(kModel);
  for (int i = 0; i < 1000; ++i) sim.Step();  // 2 s: box settled, arm hanging still
  const WorldSnapshot snap = sim.Snapshot();
  const std::vector<SensorDescription>& info = sim.sensor_info();
  ASSERT_EQ(info.size(), 14u);
  struct Expect {
    const char* name;
    const char* type;
    int dim;
    const char* unit;
    const char* object;
  };
  const Expect expect[] = {{"touch", "touch", 1, "N", "pad"},
                           {"force", "force", 3, "N", "ft"},
                           {"torque", "torque", 3, "N m", "ft"},
                           {"hinge_pos", "jointpos", 1, "rad", "hinge"},
                           {"slider_pos", "jointpos", 1, "m", "slider"},
                           {"hinge_vel", "jointvel", 1, "rad/s", "hinge"},
                           {"box_pos", "framepos", 3, "m", "box"},
                           {"box_quat", "framequat", 4, "1", "box"},
                           {"range_down", "rangefinder", 1, "m", "down"},
                           {"range_up", "rangefinder", 1, "m", "up"},
                           {"box_acc", "accelerometer", 3, "m/s^2", "pad"},
                           {"box_gyro", "gyro", 3, "rad/s", "pad"},
                           {"arm_com", "subtreecom", 3, "m", "arm"},
                           {"clock", "clock", 1, "s", ""}};
  for (const Expect& e : expect) {
    const int i = FindSensor(info, e.name);
    ASSERT_GE(i, 0) << e.name;
    EXPECT_EQ(info[i].type, e.type) << e.name;
    EXPECT_EQ(info[i].dim, e.dim) << e.name;
    EXPECT_EQ(info[i].unit, e.unit) << e.name;
    EXPECT_EQ(info[i].object_name, e.object) << e.name;
  }
  const auto v = [&](const char* name) {
    return MujocoSensorValues(snap, info[FindSensor(info, name)]);
  };
  const double g = 9.81;
  EXPECT_NEAR(v("touch")[0], 2 * g, 0.02);  // the resting box's weight
  // force between the carriage and its parent: carriage + weight, 0.51 kg
  EXPECT_NEAR(std::abs(v("force")[2]), 0.51 * g, 0.02);
  EXPECT_NEAR(std::hypot(v("force")[0], v("force")[1]), 0.0, 0.02);
  EXPECT_NEAR(Eigen::Vector3d(v("torque")[0], v("torque")[1], v("torque")[2]).norm(), 0.0, 0.01);
  EXPECT_DOUBLE_EQ(v("hinge_pos")[0], snap.qpos[7]);
  EXPECT_DOUBLE_EQ(v("slider_pos")[0], snap.qpos[8]);
  EXPECT_DOUBLE_EQ(v("hinge_vel")[0], snap.qvel[6]);
  EXPECT_NEAR(v("slider_pos")[0], -0.2, 0.01);  // the weight pulls the slider to its limit
  for (int k = 0; k < 3; ++k) EXPECT_DOUBLE_EQ(v("box_pos")[k], snap.X_WB[2].translation()[k]);
  const Eigen::Quaterniond q(snap.X_WB[2].linear());
  EXPECT_NEAR(std::abs(v("box_quat")[0]), std::abs(q.w()), 1e-9);
  EXPECT_NEAR(v("range_down")[0], 0.3, 1e-9);
  EXPECT_EQ(v("range_up")[0], -1.0);
  EXPECT_NEAR(v("box_acc")[2], g, 0.01);
  EXPECT_NEAR(v("box_gyro")[0], 0.0, 1e-3);
  EXPECT_DOUBLE_EQ(v("clock")[0], snap.time_sec);

  MujocoSensorSet set(info, {"touch", "force", "box_quat", "slider_pos", "box_acc"});
  EXPECT_EQ(set.size(), 1 + 3 + 4 + 1 + 3);
  const std::vector<std::string> cols = set.ColumnNames();
  EXPECT_EQ(cols[0], "touch_N");
  EXPECT_EQ(cols[1], "force_x_N");
  EXPECT_EQ(cols[4], "box_quat_w");
  EXPECT_EQ(cols[8], "slider_pos_m");
  EXPECT_EQ(cols[9], "box_acc_x_m_s2");
  std::vector<double> values;
  set.Read(snap, &values);
  EXPECT_EQ(values[0], v("touch")[0]);
  EXPECT_THROW(MujocoSensorSet(info, {"nope"}), Error);
  EXPECT_EQ(UnitSuffix("N m"), "N_m");
  EXPECT_EQ(UnitSuffix("rad/s^2"), "rad_s2");
}

}  // namespace
}  // namespace penumbra

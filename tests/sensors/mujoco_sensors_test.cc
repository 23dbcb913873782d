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

// the sensor types MuJoCo added after 2.2.2: an 8 kg box resting on the floor inside a zone
// site, a 0.1 m ball resting 1 m away along +x, a camera 2 m behind them.
constexpr const char* kNewTypesModel = R"(
<mujoco>
  <option timestep="0.002"/>
  <asset><mesh name="plate" builtin="plate" params="3 3" scale="0.04 0.04 0.005"/></asset>
  <worldbody>
    <geom name="floor" type="plane" size="5 5 0.1"/>
    <site name="zone" type="box" size="0.5 0.5 0.5" pos="0 0 0.5"/>
    <camera name="cam" pos="0 -2 0.1" xyaxes="1 0 0 0 0 1" resolution="64 48"/>
    <body name="box" pos="0 0 0.1">
      <freejoint/>
      <geom name="box_geom" type="box" size="0.1 0.1 0.1" mass="8"/>
      <geom name="skin" type="mesh" mesh="plate" contype="0" conaffinity="0" mass="0"
            pos="0 0 0.1"/>
      <site name="center" zaxis="0 0 -1"/>
    </body>
    <body name="ball" pos="1 0 0.1">
      <freejoint/>
      <geom name="ball_geom" type="sphere" size="0.1" mass="1"/>
    </body>
  </worldbody>
  <sensor>
    <contact name="feet" geom1="box_geom" geom2="floor" num="2" data="found force dist"
             reduce="mindist"/>
    <contact name="net" body1="box" reduce="netforce" data="force pos"/>
    <insidesite name="inside" objtype="body" objname="box" site="zone"/>
    <insidesite name="outside" objtype="body" objname="ball" site="zone"/>
    <distance name="gap" geom1="box_geom" geom2="ball_geom" cutoff="2"/>
    <normal name="gap_dir" geom1="box_geom" geom2="ball_geom" cutoff="2"/>
    <fromto name="gap_seg" geom1="box_geom" geom2="ball_geom" cutoff="2"/>
    <camprojection name="pixel" site="center" camera="cam"/>
    <rangefinder name="ray" site="center" data="dist point normal"/>
    <e_potential name="potential"/>
    <e_kinetic name="kinetic"/>
    <tactile name="taxels" geom="skin" mesh="plate"/>
  </sensor>
</mujoco>)";

TEST(MujocoSensorsTest, SensorTypesNewerThanMujoco2ReadWithTheirLayoutAndUnits) {
  Simulation sim = Simulation::LoadFromString(kNewTypesModel);
  for (int i = 0; i < 500; ++i) sim.Step();  // 1 s: both at rest on the floor
  const WorldSnapshot snap = sim.Snapshot();
  const std::vector<SensorDescription>& info = sim.sensor_info();
  ASSERT_EQ(info.size(), 12u);
  struct Expect {
    const char* name;
    const char* type;
    int dim;
    const char* unit;
  };
  const Expect expect[] = {{"feet", "contact", 2 * 5, ""},   {"net", "contact", 6, ""},
                           {"inside", "insidesite", 1, "1"}, {"outside", "insidesite", 1, "1"},
                           {"gap", "distance", 1, "m"},      {"gap_dir", "normal", 3, "1"},
                           {"gap_seg", "fromto", 6, "m"},    {"pixel", "camprojection", 2, "px"},
                           {"ray", "rangefinder", 7, ""},    {"potential", "e_potential", 1, "J"},
                           {"kinetic", "e_kinetic", 1, "J"}, {"taxels", "tactile", 27, ""}};
  for (const Expect& e : expect) {
    const int i = FindSensor(info, e.name);
    ASSERT_GE(i, 0) << e.name;
    EXPECT_EQ(info[i].type, e.type) << e.name;
    EXPECT_EQ(info[i].dim, e.dim) << e.name;
    EXPECT_EQ(info[i].unit, e.unit) << e.name;
    EXPECT_EQ(static_cast<int>(info[i].components.size()), e.dim) << e.name;
  }
  const auto v = [&](const char* name) {
    return MujocoSensorValues(snap, info[FindSensor(info, name)]);
  };
  const double g = 9.81;
  // contact slots: found = number of box-floor contacts (4 corners), each carrying a quarter
  // of the weight along its normal (the contact frame's x)
  EXPECT_EQ(v("feet")[0], 4.0);
  EXPECT_EQ(v("feet")[5], 4.0);
  EXPECT_NEAR(v("feet")[1], 8 * g / 4, 0.5);
  EXPECT_NEAR(v("feet")[4], 0.0, 1e-3);  // penetration of a resting contact, m
  // the net contact wrench on the box carries its weight; its point lies under the box
  EXPECT_NEAR(Eigen::Vector3d(v("net")[0], v("net")[1], v("net")[2]).norm(), 8 * g, 0.1);
  EXPECT_NEAR(v("net")[5], 0.0, 1e-3);
  EXPECT_EQ(v("inside")[0], 1.0);
  EXPECT_EQ(v("outside")[0], 0.0);
  // box face at x = 0.1, ball surface at x = 0.9
  EXPECT_NEAR(v("gap")[0], 0.8, 1e-3);
  EXPECT_NEAR(v("gap_dir")[0], 1.0, 1e-6);
  EXPECT_NEAR(v("gap_seg")[0], 0.1, 1e-3);
  EXPECT_NEAR(v("gap_seg")[3], 0.9, 1e-3);
  // the box's centre seen by a camera level with it straight ahead: the image centre
  EXPECT_NEAR(v("pixel")[0], 32.0, 0.05);
  EXPECT_NEAR(v("pixel")[1], 24.0, 0.05);
  // a ray from the box's centre down to the floor (its own geoms excluded)
  EXPECT_NEAR(v("ray")[0], 0.1, 1e-3);
  EXPECT_NEAR(v("ray")[3], 0.0, 1e-3);
  EXPECT_NEAR(v("ray")[6], 1.0, 1e-9);
  EXPECT_NEAR(v("potential")[0], 9 * g * 0.1, 0.02);
  EXPECT_NEAR(v("kinetic")[0], 0.0, 1e-3);

  // labels carry the units of values with several
  const SensorDescription& feet = info[FindSensor(info, "feet")];
  EXPECT_EQ(feet.components[0], "0_found");
  EXPECT_EQ(feet.components[1], "0_force_x_N");
  EXPECT_EQ(feet.components[4], "0_dist_m");
  EXPECT_EQ(feet.components[5], "1_found");
  const SensorDescription& ray = info[FindSensor(info, "ray")];
  EXPECT_EQ(ray.components[0], "dist_m");
  EXPECT_EQ(ray.components[1], "point_x_m");
  EXPECT_EQ(ray.components[6], "normal_z");
  const SensorDescription& taxels = info[FindSensor(info, "taxels")];
  EXPECT_EQ(taxels.components[0], "depth_0_m");
  EXPECT_EQ(taxels.components[9], "slip1_0_m_s");
  EXPECT_EQ(taxels.components[26], "slip2_8_m_s");
  MujocoSensorSet set(info, {"net", "pixel"});
  const std::vector<std::string> cols = set.ColumnNames();
  ASSERT_EQ(cols.size(), 8u);
  EXPECT_EQ(cols[0], "net_0_force_x_N");
  EXPECT_EQ(cols[3], "net_0_pos_x_m");
  EXPECT_EQ(cols[6], "pixel_u_px");
}

// a MuJoCo-delayed sensor reads in snapshots what the undelayed one read `delay` earlier:
// its history buffer is part of the state the snapshot copies
TEST(MujocoSensorsTest, DelayedSensorReadsItsValueOfDelayEarlier) {
  const std::string model = R"(
<mujoco>
  <option timestep="0.002"/>
  <worldbody><body name="b" pos="0 0 10"><freejoint/><geom size="0.1"/></body></worldbody>
  <sensor>
    <framepos name="now" objtype="body" objname="b"/>
    <framepos name="late" objtype="body" objname="b" nsample="3" delay="0.004"/>
  </sensor>
</mujoco>)";
  Simulation sim = Simulation::LoadFromString(model);
  const std::vector<SensorDescription>& info = sim.sensor_info();
  std::vector<double> now;
  for (int k = 0; k < 10; ++k) {
    sim.Step();
    const WorldSnapshot snap = sim.Snapshot();
    now.push_back(MujocoSensorValues(snap, info[FindSensor(info, "now")])[2]);
    const double late = MujocoSensorValues(snap, info[FindSensor(info, "late")])[2];
    // two steps of 2 ms behind (falling: each step's height differs)
    if (k >= 2) EXPECT_EQ(late, now[k - 2]) << "step " << k;
  }
  EXPECT_LT(now.back(), now.front());
}

}  // namespace
}  // namespace penumbra

// the MuJoCo 3/4 contact settings of physics/physics_options.h change what MuJoCo does: NoSlip
// stops the creep of a box resting on a slope, speculative contacts stop a fast ball at a thin
// plate it otherwise passes through; bad values are refused naming the key.
#include "penumbra/physics/physics_options.h"

#include <gtest/gtest.h>
#include <mujoco/mujoco.h>

#include <cmath>
#include <string>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

struct Model {
  mjModel* m = nullptr;
  mjData* d = nullptr;
  explicit Model(const char* xml) {
    char error[1000] = "";
    mjSpec* spec = mj_parseXMLString(xml, nullptr, error, sizeof(error));
    EXPECT_NE(spec, nullptr) << error;
    m = mj_compile(spec, nullptr);
    mj_deleteSpec(spec);
    d = mj_makeData(m);
  }
  ~Model() {
    mj_deleteData(d);
    mj_deleteModel(m);
  }
};

// a 1 kg box at rest on a 20 degree slope with friction 0.6 (tan 20 deg = 0.36: it sticks)
constexpr const char* kSlope = R"(
<mujoco>
  <option timestep="0.002"/>
  <worldbody>
    <geom type="plane" size="5 5 0.1" euler="0 0.35 0" friction="0.6"/>
    <body pos="0 0 0.1" euler="0 0.35 0">
      <freejoint/>
      <geom type="box" size="0.1 0.1 0.1" mass="1"/>
    </body>
  </worldbody>
</mujoco>)";

// how far the box creeps in 2 s after settling for 0.5 s, m
double Creep(const ContactOptions& options) {
  Model s(kSlope);
  ApplyContactOptions(options, &s.m->opt);
  for (int i = 0; i < 250; ++i) mj_step(s.m, s.d);
  const double x0 = s.d->qpos[0], z0 = s.d->qpos[2];
  for (int i = 0; i < 1000; ++i) mj_step(s.m, s.d);
  return std::hypot(s.d->qpos[0] - x0, s.d->qpos[2] - z0);
}

TEST(ContactOptions, NoslipStopsTheCreepOfSoftContacts) {
  const double soft = Creep({});
  ContactOptions noslip;
  noslip.noslip_iterations = 10;
  const double held = Creep(noslip);
  std::printf("[ measured ] creep in 2 s: %.3g m without NoSlip, %.3g m with 10 iterations\n", soft,
              held);
  EXPECT_GT(soft, 1e-5);
  EXPECT_LT(held, soft / 20);
}

// a 2 cm ball at 40 m/s towards a 4 mm plate 0.5 m away, no gravity, 2 ms steps (8 cm a step)
constexpr const char* kThinPlate = R"(
<mujoco>
  <option timestep="0.002" gravity="0 0 0"/>
  <worldbody>
    <geom type="box" size="0.5 0.5 0.002" pos="0 0 1"/>
    <body pos="0 0 0.5">
      <freejoint/>
      <geom type="sphere" size="0.02" mass="0.1"/>
    </body>
  </worldbody>
</mujoco>)";

double BallHeightAfter(const ContactOptions& options, int steps) {
  Model s(kThinPlate);
  ApplyContactOptions(options, &s.m->opt);
  s.d->qvel[2] = 40;
  for (int i = 0; i < steps; ++i) mj_step(s.m, s.d);
  return s.d->qpos[2];
}

TEST(ContactOptions, SpeculativeContactsStopAFastBallAtAThinPlate) {
  EXPECT_GT(BallHeightAfter({}, 100), 1.0);  // tunnelled through
  ContactOptions speculative;
  speculative.speculative = true;
  EXPECT_LT(BallHeightAfter(speculative, 100), 1.0 - 0.002);  // stopped below the plate
  ContactOptions off;
  off.speculative = false;
  Model s(kThinPlate);
  s.m->opt.enableflags |= mjENBL_SPECULATIVE;
  ApplyContactOptions(off, &s.m->opt);
  EXPECT_EQ(s.m->opt.enableflags & mjENBL_SPECULATIVE, 0);
}

TEST(ContactOptions, UnsetKeepsTheModelsOptionAndBadValuesNameTheKey) {
  Model s(kSlope);
  s.m->opt.noslip_iterations = 7;
  ApplyContactOptions({}, &s.m->opt);
  EXPECT_EQ(s.m->opt.noslip_iterations, 7);
  for (int bad : {-1, kMaxNoslipIterations + 1}) {
    ContactOptions o;
    o.noslip_iterations = bad;
    try {
      ApplyContactOptions(o, &s.m->opt);
      ADD_FAILURE() << bad;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), "physics.noslip_iterations");
      EXPECT_NE(std::string(e.what()).find(std::to_string(bad)), std::string::npos);
    }
    EXPECT_EQ(s.m->opt.noslip_iterations, 7);
  }
}

}  // namespace
}  // namespace penumbra

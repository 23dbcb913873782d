// the smoke grid fluid: positivity, mass balance, buoyant rise, determinism.
#include "penumbra/effects/grid_fluid.h"

#include <gtest/gtest.h>

#include <cmath>

namespace penumbra {
namespace {

FluidParams SmallPlume() {
  FluidParams f;
  f.resolution = 20;
  f.dt_sec = 1.0 / 30.0;
  f.jacobi_iterations = 20;
  f.dissipation_per_s = 0.2;
  PlumeEmitter e;
  e.position_W = {0, 0, 0.3};
  e.radius_m = 0.2;
  e.rate = 0.5;
  e.temperature_k = 600;
  f.emitters = {e};
  return f;
}

BoxRegion Box() { return BoxRegion{{-1, -1, 0}, {1, 1, 2}}; }

TEST(GridFluidTest, MassFollowsEmissionMinusDissipationInAClosedBox) {
  const FluidParams params = SmallPlume();
  GridFluid f(params, Box(), Eigen::Vector3d::Zero(), 11);
  const double E = 0.5, k = 0.2, dt = params.dt_sec;
  double m_discrete = 0;
  for (int s = 1; s <= 90; ++s) {
    f.Step(1.0);
    m_discrete = (m_discrete + E * dt) * std::exp(-k * dt);
    if (s % 30 == 0) {
      const double t = s * dt;
      const double m_cont = E / k * (1 - std::exp(-k * t));
      std::printf("t %.2f s: mass %.5f, discrete %.5f, continuous %.5f\n", t, f.TotalMass(),
                  m_discrete, m_cont);
      EXPECT_NEAR(f.TotalMass(), m_discrete, 1e-3 * m_discrete);
      EXPECT_NEAR(f.TotalMass(), m_cont, 0.03 * m_cont);
    }
  }
  for (int k2 = 0; k2 < f.nz(); ++k2)
    for (int j = 0; j < f.ny(); ++j)
      for (int i = 0; i < f.nx(); ++i) ASSERT_GE(f.density(i, j, k2), 0.0f);
}

TEST(GridFluidTest, BuoyantPlumeRises) {
  GridFluid f(SmallPlume(), Box(), Eigen::Vector3d::Zero(), 11);
  for (int s = 0; s < 15; ++s) f.Step(1.0);
  const double z_early = f.CentreOfMass().z();
  for (int s = 0; s < 30; ++s) f.Step(1.0);
  const double z_late = f.CentreOfMass().z();
  std::printf("centre of mass z: %.3f m at 0.5 s, %.3f m at 1.5 s (emitter 0.3 m)\n", z_early,
              z_late);
  EXPECT_GT(z_early, 0.3);
  EXPECT_GT(z_late, z_early + 0.2);
  // without buoyancy it stays low
  FluidParams cold = SmallPlume();
  cold.buoyancy_m_s2 = 0;
  GridFluid g(cold, Box(), Eigen::Vector3d::Zero(), 11);
  for (int s = 0; s < 45; ++s) g.Step(1.0);
  EXPECT_LT(g.CentreOfMass().z(), z_late - 0.2);
}

TEST(GridFluidTest, DeterministicPerKey) {
  GridFluid a(SmallPlume(), Box(), Eigen::Vector3d::Zero(), 5);
  GridFluid b(SmallPlume(), Box(), Eigen::Vector3d::Zero(), 5);
  GridFluid c(SmallPlume(), Box(), Eigen::Vector3d::Zero(), 6);
  for (int s = 0; s < 20; ++s) {
    a.Step(1.0);
    b.Step(1.0);
    c.Step(1.0);
  }
  EXPECT_EQ(a.DensityGrid(), b.DensityGrid());
  EXPECT_NE(a.DensityGrid(), c.DensityGrid());
  a.Reset();
  EXPECT_EQ(a.TotalMass(), 0.0);
  EXPECT_EQ(a.steps(), 0);
}

TEST(GridFluidTest, WindBlowsSmokeOutOfTheBox) {
  FluidParams p = SmallPlume();
  p.dissipation_per_s = 0;
  GridFluid f(p, Box(), Eigen::Vector3d(3, 0, 0), 11);
  for (int s = 0; s < 60; ++s) f.Step(1.0);
  // 2 s of emission at 0.5 /s = 1.0 injected; much of it left downwind
  EXPECT_LT(f.TotalMass(), 0.8);
  EXPECT_GT(f.CentreOfMass().x(), 0.2);
}

}  // namespace
}  // namespace penumbra

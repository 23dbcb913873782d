// the realtime tier's light from lamps with an extent: a white ceiling next
// to a small spherical lamp without per-pixel noise at one frame, the same picture every frame,
// the analytic horizon-clipped sphere irradiance (render/light/lamp_math.h), no sky light leaking
// into the foot of a box standing on a floor slab, and the tile loop's skip of a light wholly
// below a run's horizon: a lamp straddling the floor's horizon still lights it, a lamp behind a
// wall adds exactly nothing to it.

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/light/lamp_math.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

// optical frame at `p` looking straight up (world +z); image x = world +x, image y = world +y.
Pose LampTestCameraLookingUp(const Eigen::Vector3d& p) {
  Pose X = Pose::Identity();
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d(1, 0, 0);
  R.col(1) = Eigen::Vector3d(0, 1, 0);
  R.col(2) = Eigen::Vector3d(0, 0, 1);
  X.linear() = R;
  X.translation() = p;
  return X;
}

// a white Lambertian ceiling (underside at z = 2.7) and one 400 cd spherical lamp of radius
// 5 cm at z = 2.58, as the bundled worlds' ceiling lamps; with `housing`, the fixture's 25 cm
// disc between the lamp and the ceiling (z in [2.64, 2.66]) hides the lamp from part of it.
SceneDescription LampTestCeiling(bool housing) {
  SceneDescription s = EmptyScene();
  const int white = AddMaterial(&s, Eigen::Vector3f::Constant(0.8f));
  AddGeom(&s, GeomShape::kBox, {3, 3, 0.05}, Translation(0, 0, 2.75), 0, white);
  if (housing)
    AddGeom(&s, GeomShape::kCylinder, {0.25, 0.01, 0}, Translation(0, 0, 2.65), 0, white);
  AddPointLamp(&s, {0, 0, 2.58}, 400, 0.05);
  return s;
}

struct LampTestNoise {
  double mean = 0;      // mean green radiance of the patch
  double residual = 0;  // rms of (pixel - mean of its 3x3 neighbours) over the patch
  int pixels = 0;
};

// per-pixel noise over the ceiling pixels whose hit point lies r_min..r_max m (horizontally)
// from the lamp: the rms difference between a pixel and the mean of its 8 neighbours (which
// removes the smooth fall-off, linear over 3 pixels), relative to the patch's mean.
LampTestNoise LampTestCeilingNoise(const RenderedFrame& f, const CameraView& view, int ceiling_id,
                                   double r_min, double r_max) {
  const CameraIntrinsics& k = view.intrinsics;
  const double cam_to_ceiling = 2.7 - view.X_WO.translation().z();
  double sum = 0, sq = 0;
  int n = 0;
  for (int v = 1; v + 1 < f.radiance.height; ++v)
    for (int u = 1; u + 1 < f.radiance.width; ++u) {
      bool all = true;
      for (int dv = -1; dv <= 1 && all; ++dv)
        for (int du = -1; du <= 1; ++du)
          if (*f.geom_id.at(u + du, v + dv) != ceiling_id) all = false;
      if (!all) continue;
      const double x = (u + 0.5 - k.cx) / k.fx * cam_to_ceiling;
      const double y = (v + 0.5 - k.cy) / k.fy * cam_to_ceiling;
      const double r = std::hypot(x, y);
      if (r < r_min || r > r_max) continue;
      double nb = 0;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du)
          if (du != 0 || dv != 0) nb += f.radiance.at(u + du, v + dv)[1];
      const double L = f.radiance.at(u, v)[1];
      sum += L;
      sq += (L - nb / 8) * (L - nb / 8);
      ++n;
    }
  LampTestNoise out;
  out.pixels = n;
  out.mean = n > 0 ? sum / n : 0;
  out.residual = n > 0 ? std::sqrt(sq / n) : 0;
  return out;
}

TEST(LampLightingTest, WhiteCeilingNextToASmallLampIsNoiseFreeInOneFrame) {
  // the ceiling seen from 1.2 m below the lamp, 0.6-1.2 m from it (where the fall-off is
  // smooth enough for the 3x3 residual: 0.3 % from its curvature): the lamp, 6-11 degrees
  // below the ceiling's horizon and 2-5 degrees wide, used to be sampled by one random point
  // per pixel, and the cosine over its cone varies by a factor of 1.5-2.5 there.
  const SceneDescription s = LampTestCeiling(false);
  auto r = MakeRenderer(s, TestSettings());
  const CameraView view = MakeView(LampTestCameraLookingUp({0, 0, 1.4}), 160, 160, 90);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  const LampTestNoise noise = LampTestCeilingNoise(f, view, 100, 0.6, 1.2);
  RecordProperty("residual_percent_of_mean", std::to_string(100 * noise.residual / noise.mean));
  ASSERT_GT(noise.pixels, 3000);
  ASSERT_GT(noise.mean, 0);
  EXPECT_LT(noise.residual, 0.01 * noise.mean) << "mean " << noise.mean;
}

TEST(LampLightingTest, CeilingInTheFixturesPenumbraIsNoiseFreeInOneFrame) {
  // the fixture's disc hides part of the lamp from the ceiling around it: a penumbra 0.3-1.2 m
  // wide, where one shadow ray per pixel made salt-and-pepper noise. the residual here also
  // holds what the shared visibility leaves: steps of a few % along the penumbra.
  const SceneDescription s = LampTestCeiling(true);
  auto r = MakeRenderer(s, TestSettings());
  const CameraView view = MakeView(LampTestCameraLookingUp({0, 0, 1.4}), 160, 160, 90);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  const LampTestNoise noise = LampTestCeilingNoise(f, view, 100, 0.35, 1.1);
  RecordProperty("residual_percent_of_mean", std::to_string(100 * noise.residual / noise.mean));
  ASSERT_GT(noise.pixels, 3000);
  ASSERT_GT(noise.mean, 0);
  // measured 2.7 % (main: 113 %); the bare ceiling above: 0.2 %, the fall-off's curvature
  // (main: 26 %).
  EXPECT_LT(noise.residual, 0.05 * noise.mean) << "mean " << noise.mean;
}

TEST(LampLightingTest, LampLightIsTheSameEveryFrame) {
  // no random numbers in the lamps' light: frames 0 and 7 of a still scene are identical.
  const SceneDescription s = LampTestCeiling(true);
  auto r = MakeRenderer(s, TestSettings());
  CameraView view = MakeView(LampTestCameraLookingUp({0.3, 0.2, 1.4}), 96, 96, 90);
  RenderedFrame a, b;
  view.frame_index = 0;
  r->Render(IdentitySnapshot(s), view, &a);
  view.frame_index = 7;
  r->Render(IdentitySnapshot(s), view, &b);
  ASSERT_EQ(a.radiance.data.size(), b.radiance.data.size());
  EXPECT_TRUE(a.radiance.data == b.radiance.data);
}

TEST(LampLightingTest, PenumbraBudgetFollowsTheLightsShare) {
  // one lattice point moves the pixel's luminance by about share / points: at most 1/64.
  int last = 0;
  for (float share = 0; share <= 1.0f; share += 1.0f / 256) {
    const int points = PenumbraLatticePoints(share);
    EXPECT_LE(share / points, 1.0f / 64 + 1e-6f) << share;
    EXPECT_GE(points, last) << share;  // never fewer for a larger share
    last = points;
  }
  EXPECT_EQ(PenumbraLatticePoints(1.0f), kLightStrata * kLightPenumbraRays);
  EXPECT_EQ(PenumbraLatticePoints(0.01f), kLightPenumbraRays);
  EXPECT_EQ(PenumbraLatticePoints(std::nanf("")), kLightPenumbraRays);
  // a pixel's points: distinct, its own point first, spread over the cone (every quarter of
  // u1 = 1 - cos, i.e. of the cone's solid angle, holds points / 4 of them).
  for (int points : {4, 16, 32, 64})
    for (int stratum = 0; stratum < kLightStrata; ++stratum) {
      const int first = kLightPenumbraRays * stratum;
      std::vector<int> seen(kLightStrata * kLightPenumbraRays, 0);
      int quarter[4] = {0, 0, 0, 0};
      for (int r = 0; r < points; ++r) {
        const int index = PenumbraLatticeIndex(first, r, points);
        ASSERT_GE(index, 0);
        ASSERT_LT(index, kLightStrata * kLightPenumbraRays);
        if (r == 0) {
          EXPECT_EQ(index, first);
        }
        EXPECT_EQ(seen[index]++, 0) << points << " " << stratum;
        float u1, u2;
        LightStratumUniforms(index, kLightStrata * kLightPenumbraRays, &u1, &u2);
        ++quarter[std::min(3, static_cast<int>(u1 * 4))];
      }
      for (int q = 0; q < 4; ++q) EXPECT_EQ(quarter[q], points / 4) << points << " " << q;
    }
}

TEST(LampLightingTest, FaintLampsPenumbraTakesFewerRays) {
  // a pixel in a lamp's penumbra traces as many lattice points as the lamp's share of
  // its light asks for (PenumbraLatticePoints). the fixture's penumbra on the ceiling, lit by the
  // lamp alone (A: 64 points per window, all 64 on a tile's edge pixels) and with a 20 000 cd
  // point light 2.2 m below the ceiling beside it (B: there the lamp gives 1-10 % of a pixel's
  // light: 4-16 points): the lamp's rays drop to less than half, its light does not change.
  // on main the lamp traced the same rays in both (B - C = A).
  const SceneDescription a = LampTestCeiling(true);
  SceneDescription b = a;
  Light bright;
  bright.type = Light::Type::kPoint;
  bright.position_B = {0, 0, 0.5};
  bright.intensity = 20000;
  b.lights.push_back(bright);
  SceneDescription c = b;  // the bright light alone
  c.lights.erase(c.lights.begin());
  SceneDescription dark = a;  // no light
  dark.lights.clear();
  const CameraView view = MakeView(LampTestCameraLookingUp({0, 0, 1.4}), 160, 160, 90);
  RenderedFrame fa, fb, fc, fd;
  MakeRenderer(a, TestSettings())->Render(IdentitySnapshot(a), view, &fa);
  MakeRenderer(b, TestSettings())->Render(IdentitySnapshot(b), view, &fb);
  MakeRenderer(c, TestSettings())->Render(IdentitySnapshot(c), view, &fc);
  MakeRenderer(dark, TestSettings())->Render(IdentitySnapshot(dark), view, &fd);
  const int64_t lamp_rays_alone = fa.rays, lamp_rays_beside = fb.rays - fc.rays;
  RecordProperty("lamp_rays_alone", std::to_string(lamp_rays_alone));
  RecordProperty("lamp_rays_beside_bright_light", std::to_string(lamp_rays_beside));
  EXPECT_LT(lamp_rays_beside, lamp_rays_alone / 2);
  // the lamp's light over the penumbra patch: B - C against A - dark, green channel.
  const LampTestNoise na = LampTestCeilingNoise(fa, view, 100, 0.35, 1.1);
  const LampTestNoise nb = LampTestCeilingNoise(fb, view, 100, 0.35, 1.1);
  const LampTestNoise nc = LampTestCeilingNoise(fc, view, 100, 0.35, 1.1);
  const LampTestNoise nd = LampTestCeilingNoise(fd, view, 100, 0.35, 1.1);
  ASSERT_GT(na.pixels, 3000);
  const double lamp_alone = na.mean - nd.mean, lamp_beside = nb.mean - nc.mean;
  ASSERT_GT(lamp_alone, 0);
  EXPECT_NEAR(lamp_beside, lamp_alone, 0.02 * lamp_alone);
  // the lamp stays below a tenth of the light there (else the test would not test the budget).
  EXPECT_LT(lamp_beside, 0.1 * nb.mean);
}

TEST(LampLightingTest, SphereLightCosineMatchesNumericalIntegration) {
  // E d^2 / I of a uniform sphere (radiance I / (pi r^2)) against a midpoint-rule integral of
  // L cos over the part of its cone above the horizon, for angles across the horizon.
  for (double sin_sigma : {0.05, 0.3, 0.7}) {
    for (double theta_deg : {0.0, 40.0, 80.0, 88.0, 92.0, 100.0, 120.0}) {
      const double th = theta_deg * M_PI / 180, cos_s = std::sqrt(1 - sin_sigma * sin_sigma);
      // directions in the cone around w = (sin th, 0, cos th), normal (0, 0, 1).
      constexpr int kN = 800;
      double e = 0;
      for (int i = 0; i < kN; ++i) {
        const double c = 1 - (i + 0.5) / kN * (1 - cos_s), sn = std::sqrt(1 - c * c);
        for (int j = 0; j < kN; ++j) {
          const double ph = 2 * M_PI * (j + 0.5) / kN;
          // local (sn cos ph, sn sin ph, c) rotated about y by th.
          const double z = -sn * std::cos(ph) * std::sin(th) + c * std::cos(th);
          if (z > 0) e += z;
        }
      }
      const double solid = 2 * M_PI * (1 - cos_s);
      // L = 1 / (pi sin^2 sigma) in units of I / d^2.
      const double expected = e * solid / (kN * kN) / (M_PI * sin_sigma * sin_sigma);
      const float got = SphereLightCosine(static_cast<float>(std::cos(th)),
                                          static_cast<float>(sin_sigma * sin_sigma));
      EXPECT_NEAR(got, expected, 2e-3 + 2e-3 * expected) << sin_sigma << " " << theta_deg;
    }
  }
}

TEST(LampLightingTest, NoSkyLightLeaksIntoTheFootOfABoxOnAFloorSlab) {
  // a closed 8 x 8 x 3 m room (floor slab 2 cm thick, walls, ceiling; no ground below it)
  // under a bright uniform sky, a box standing on the floor and no lamp: every surface inside
  // is dark. the sky irradiance volume's probes under the floor see the sky from below, and
  // its visibility tolerance (0.1 spacing, about 4.5 cm here) is wider than the slab: they
  // used to light the foot of the box through it.
  SceneDescription s = EmptyScene();
  s.sky.radiance = {1000, 1000, 1000};
  const int grey = AddMaterial(&s, Eigen::Vector3f::Constant(0.7f));
  AddGeom(&s, GeomShape::kBox, {4.2, 4.2, 0.01}, Translation(0, 0, -0.01), 0, grey);  // floor
  AddGeom(&s, GeomShape::kBox, {4.2, 4.2, 0.05}, Translation(0, 0, 3.05), 0, grey);   // ceiling
  AddGeom(&s, GeomShape::kBox, {0.05, 4.2, 1.55}, Translation(4.15, 0, 1.5), 0, grey);
  AddGeom(&s, GeomShape::kBox, {0.05, 4.2, 1.55}, Translation(-4.15, 0, 1.5), 0, grey);
  AddGeom(&s, GeomShape::kBox, {4.2, 0.05, 1.55}, Translation(0, 4.15, 1.5), 0, grey);
  AddGeom(&s, GeomShape::kBox, {4.2, 0.05, 1.55}, Translation(0, -4.15, 1.5), 0, grey);
  const int box = AddGeom(&s, GeomShape::kBox, {0.25, 0.6, 0.4}, Translation(1.5, 0, 0.4), 0,
                          grey);  // front face x = 1.25, on the floor
  auto r = MakeRenderer(s, TestSettings());
  const CameraView view = MakeView(CameraLookingAlongX({-1.0, 0, 0.3}), 160, 120, 60);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  int box_pixels = 0, floor_pixels = 0;
  float brightest = 0;
  for (int v = 0; v < f.radiance.height; ++v)
    for (int u = 0; u < f.radiance.width; ++u) {
      const int id = *f.geom_id.at(u, v);
      if (id == 100) ++floor_pixels;
      if (id != 100 + box && id != 100) continue;
      box_pixels += id == 100 + box ? 1 : 0;
      brightest = std::max(brightest, f.radiance.at(u, v)[1]);
    }
  ASSERT_GT(box_pixels, 500);
  ASSERT_GT(floor_pixels, 500);
  // the open sky would give 1000 x 0.7 / 2 = 350 on the box's vertical face.
  EXPECT_LT(brightest, 1.0f);
}

}  // namespace
}  // namespace penumbra

namespace penumbra {
namespace {

using namespace penumbra::testing;

// a white floor slab (top at z = 0) and a spherical lamp of radius 5 cm at `lamp_z`.
SceneDescription LampTestFloor(double lamp_z) {
  SceneDescription s = EmptyScene();
  const int white = AddMaterial(&s, Eigen::Vector3f::Constant(0.8f));
  AddGeom(&s, GeomShape::kBox, {3, 3, 0.05}, Translation(0, 0, -0.05), 0, white);
  AddPointLamp(&s, {0, 0, lamp_z}, 400, 0.05);
  return s;
}

TEST(LampLightingTest, ALampStraddlingTheFloorsHorizonLightsIt) {
  // the lamp's centre 2 cm below the floor's top: every floor point sees it below its horizon
  // (n . w < 0) but the top of the sphere above it, so the light straddles the horizon there.
  // the tile loop skips a light only for runs of pixels where it is wholly below the horizon;
  // straddling pixels must keep their (small, positive) share.
  const SceneDescription s = LampTestFloor(-0.02);
  auto r = MakeRenderer(s, TestSettings());
  const CameraView view = MakeView(CameraLookingDown({0, 0, 1.0}), 64, 64, 90);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  // the floor points more than 10 cm from the lamp's axis (those nearer lie inside the sphere)
  const CameraIntrinsics& k = view.intrinsics;
  int lit = 0, floor = 0;
  for (int v = 0; v < f.radiance.height; ++v)
    for (int u = 0; u < f.radiance.width; ++u) {
      const double x = (u - k.cx) / k.fx, y = (v - k.cy) / k.fy;  // at 1 m below the camera
      if (*f.geom_id.at(u, v) != 100 || std::hypot(x, y) < 0.1) continue;
      ++floor;
      lit += f.radiance.at(u, v)[1] > 0;
    }
  ASSERT_GT(floor, 3500);
  EXPECT_EQ(lit, floor);
}

TEST(LampLightingTest, ALampBehindAWallAddsExactlyNothingToIt) {
  // a wall facing away from lamp B (every pixel of it below B's horizon: the tile loop skips B
  // there) and lit by lamp A: its radiance is bit for bit that of the scene without B, and A's
  // light is there.
  auto scene = [](bool with_b) {
    SceneDescription s = EmptyScene();
    const int white = AddMaterial(&s, Eigen::Vector3f::Constant(0.8f));
    AddGeom(&s, GeomShape::kBox, {0.05, 2, 2}, Translation(1.05, 0, 0), 0, white);  // x 1..1.1
    AddPointLamp(&s, {2.0, 0.3, 0.2}, 400, 0.05);                                   // lamp A
    if (with_b) AddPointLamp(&s, {0.5, -0.2, 0.1}, 400, 0.05);                      // lamp B
    return s;
  };
  // from x = 2.5 looking along -x at the wall's face x = 1.1 (normal +x)
  Pose X = CameraLookingAlongX({2.5, 0, 0});
  X.linear() = Eigen::AngleAxisd(M_PI, Eigen::Vector3d::UnitZ()).toRotationMatrix() * X.linear();
  const CameraView view = MakeView(X, 48, 48, 60);
  RenderedFrame with_b, without_b;
  const SceneDescription s_b = scene(true), s_0 = scene(false);
  MakeRenderer(s_b, TestSettings())->Render(IdentitySnapshot(s_b), view, &with_b);
  MakeRenderer(s_0, TestSettings())->Render(IdentitySnapshot(s_0), view, &without_b);
  int wall = 0, lit = 0;
  for (int v = 0; v < with_b.radiance.height; ++v)
    for (int u = 0; u < with_b.radiance.width; ++u) {
      if (*with_b.geom_id.at(u, v) != 100) continue;
      ++wall;
      lit += with_b.radiance.at(u, v)[1] > 0;
      for (int c = 0; c < 3; ++c)
        ASSERT_EQ(with_b.radiance.at(u, v)[c], without_b.radiance.at(u, v)[c]) << u << " " << v;
    }
  ASSERT_GT(wall, 2000);
  EXPECT_EQ(lit, wall);
}

}  // namespace
}  // namespace penumbra

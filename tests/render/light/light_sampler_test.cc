// light samples: inverse-square law, spot cones, sun discs and lamp spheres, poses.

#include "penumbra/render/light/light_sampler.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"

namespace penumbra {
namespace {

constexpr double kDeg = M_PI / 180.0;

SceneDescription WithLights(std::vector<Light> lights, int extra_bodies = 0) {
  SceneDescription s;
  s.bodies.push_back({"world", -1, true});
  for (int i = 0; i < extra_bodies; ++i) s.bodies.push_back({"b" + std::to_string(i), 0, false});
  s.lights = std::move(lights);
  return s;
}

WorldSnapshot Snapshot(const SceneDescription& s) {
  WorldSnapshot w;
  w.X_WB.assign(s.bodies.size(), Pose::Identity());
  return w;
}

TEST(LightSamplerTest, PointLightInverseSquare) {
  Light l;
  l.type = Light::Type::kPoint;
  l.position_B = {1, 2, 3};
  l.intensity = 50;
  l.color = {1, 0.5f, 0.25f};
  const SceneDescription s = WithLights({l});
  LightSampler ls(s);
  ls.Update(Snapshot(s));
  LightSample x;
  ASSERT_TRUE(ls.Sample(0, {1, 2, 1}, 0.3f, 0.7f, &x));
  EXPECT_NEAR(x.distance, 2.0f, 1e-6);
  EXPECT_NEAR(x.E.x(), 50.0 / 4, 1e-5);
  EXPECT_NEAR(x.E.y(), 25.0 / 4, 1e-5);
  EXPECT_NEAR(x.E.z(), 12.5 / 4, 1e-5);
  EXPECT_NEAR(x.wi.z(), 1.0f, 1e-6);
  ASSERT_TRUE(ls.Sample(0, {1, 2, -3}, 0.3f, 0.7f, &x));
  EXPECT_NEAR(x.E.x(), 50.0 / 36, 1e-5);
}

TEST(LightSamplerTest, SpotCone) {
  Light l;
  l.type = Light::Type::kSpot;
  l.position_B = {0, 0, 1};
  l.direction_B = {0, 0, -1};
  l.intensity = 100;
  l.spot_inner_deg = 10;
  l.spot_outer_deg = 30;
  const SceneDescription s = WithLights({l});
  LightSampler ls(s);
  ls.Update(Snapshot(s));
  LightSample x;
  auto at_angle = [&](double deg) {
    return Eigen::Vector3f(static_cast<float>(std::tan(deg * kDeg)), 0, 0);
  };
  ASSERT_TRUE(ls.Sample(0, at_angle(5), 0, 0, &x));
  EXPECT_NEAR(x.E.x(), 100 * std::pow(std::cos(5 * kDeg), 2), 1e-3);  // full intensity / d^2
  ASSERT_TRUE(ls.Sample(0, at_angle(20), 0, 0, &x));
  const double t =
      (std::cos(20 * kDeg) - std::cos(30 * kDeg)) / (std::cos(10 * kDeg) - std::cos(30 * kDeg));
  EXPECT_NEAR(x.E.x(), 100 * t * t * (3 - 2 * t) * std::pow(std::cos(20 * kDeg), 2), 1e-3);
  EXPECT_FALSE(ls.Sample(0, at_angle(35), 0, 0, &x));
  EXPECT_FALSE(ls.Sample(0, {0, 0, 2}, 0, 0, &x));  // behind the spot
}

TEST(LightSamplerTest, SunDiscSamplesStayInTheDisc) {
  Light l;
  l.type = Light::Type::kDirectional;
  l.direction_B = Eigen::Vector3d(1, 1, -2).normalized();
  l.intensity = 1e5f;
  l.angular_radius_deg = 3;
  const SceneDescription s = WithLights({l});
  LightSampler ls(s);
  ls.Update(Snapshot(s));
  const Eigen::Vector3f axis = -l.direction_B.cast<float>();
  Rng rng(5);
  Eigen::Vector3f mean = Eigen::Vector3f::Zero();
  double max_angle = 0;
  for (int k = 0; k < 5000; ++k) {
    LightSample x;
    ASSERT_TRUE(ls.Sample(0, {0, 0, 0}, rng.Uniform(), rng.Uniform(), &x));
    EXPECT_NEAR(x.wi.norm(), 1.0f, 1e-5);
    EXPECT_FLOAT_EQ(x.E.x(), 1e5f);
    EXPECT_TRUE(std::isinf(x.distance));
    max_angle = std::max(max_angle, std::acos(std::min(1.0, static_cast<double>(x.wi.dot(axis)))));
    mean += x.wi;
  }
  EXPECT_LE(max_angle, 3 * kDeg + 1e-4);
  EXPECT_GT(max_angle, 2.8 * kDeg);
  EXPECT_GT(mean.normalized().dot(axis), std::cos(0.1 * kDeg));
}

TEST(LightSamplerTest, LampSphereSamplesEndOnItsSurface) {
  Light l;
  l.type = Light::Type::kPoint;
  l.position_B = {0, 0, 2};
  l.intensity = 10;
  l.radius_m = 0.3f;
  const SceneDescription s = WithLights({l});
  LightSampler ls(s);
  ls.Update(Snapshot(s));
  const Eigen::Vector3f p(0.5f, 0, 0), c(0, 0, 2);
  const double d = (c - p).norm();
  Rng rng(9);
  for (int k = 0; k < 2000; ++k) {
    LightSample x;
    ASSERT_TRUE(ls.Sample(0, p, rng.Uniform(), rng.Uniform(), &x));
    EXPECT_NEAR((p + x.distance * x.wi - c).norm(), 0.3, 1e-4);
    EXPECT_LE(std::acos(std::min(1.0f, x.wi.dot((c - p).normalized()))), std::asin(0.3 / d) + 1e-4);
    EXPECT_NEAR(x.E.x(), 10 / (d * d), 1e-5);
  }
  LightSample x;
  EXPECT_FALSE(ls.Sample(0, {0, 0, 2.1f}, 0.5f, 0.5f, &x));  // inside the lamp
}

TEST(LightSamplerTest, PosesFromTheSnapshot) {
  Light body_light;
  body_light.type = Light::Type::kSpot;
  body_light.body = 1;
  body_light.position_B = {0, 0, 1};
  body_light.direction_B = {1, 0, 0};
  Light mjcf;
  mjcf.type = Light::Type::kDirectional;
  mjcf.mjcf_light = 0;
  const SceneDescription s = WithLights({body_light, mjcf}, 1);
  LightSampler ls(s);
  WorldSnapshot w = Snapshot(s);
  w.X_WB[1] = PoseFromXyzRpyDeg({1, 2, 3}, {0, 0, 90});
  w.light_position_W = {{5, 6, 7}};
  w.light_direction_W = {{0, 0, -2}};
  ls.Update(w);
  ASSERT_EQ(ls.size(), 2);
  EXPECT_NEAR((ls.lights()[0].position_W - Eigen::Vector3f(1, 2, 4)).norm(), 0, 1e-6);
  EXPECT_NEAR((ls.lights()[0].direction_W - Eigen::Vector3f(0, 1, 0)).norm(), 0, 1e-6);
  EXPECT_NEAR((ls.lights()[1].direction_W - Eigen::Vector3f(0, 0, -1)).norm(), 0, 1e-6);
  // an MJCF light id the snapshot does not have is an error.
  w.light_position_W.clear();
  w.light_direction_W.clear();
  EXPECT_THROW(ls.Update(w), Error);
}

TEST(LightSamplerTest, InactiveAndDarkLightsAreDropped) {
  Light off;
  off.active = false;
  Light dark;
  dark.intensity = 0;
  Light on;
  const SceneDescription s = WithLights({off, dark, on});
  EXPECT_EQ(LightSampler(s).size(), 1);
}

}  // namespace
}  // namespace penumbra

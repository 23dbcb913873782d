// the 16-lane shading code agrees with the scalar BSDF and light sampler.

#include "penumbra/render/shading_lanes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "penumbra/core/rng.h"
#include "penumbra/render/cpu/bsdf_lanes.h"
#include "penumbra/render/light/light_sampler.h"

namespace penumbra {
namespace {

Eigen::Vector3f RandomDir(Rng* rng) {
  const float z = 2 * rng->Uniform() - 1, phi = 6.2831853f * rng->Uniform();
  const float r = std::sqrt(std::max(0.0f, 1 - z * z));
  return {r * std::cos(phi), r * std::sin(phi), z};
}

// lane masks: comparisons per lane (NaN compares false), logic, counting, writes, selects.
TEST(ShadingLanesTest, LaneMaskComparisonsAndSelects) {
  Lanes a, b;
  for (int k = 0; k < kLanes; ++k) {
    a[k] = static_cast<float>(k % 5) - 2.0f;  // -2 .. 2
    b[k] = static_cast<float>(k % 3) - 1.0f;  // -1 .. 1
  }
  a[7] = std::nanf("");
  const LaneMask gt = GreaterThan(a, b), ge = GreaterEqual(a, b), pos = GreaterThan(a, 0.0f);
  int n_gt = 0;
  for (int k = 0; k < kLanes; ++k) {
    EXPECT_EQ(gt[k], a[k] > b[k]) << k;
    EXPECT_EQ(ge[k], a[k] >= b[k]) << k;
    EXPECT_EQ(pos[k], a[k] > 0.0f) << k;
    EXPECT_EQ((gt && pos)[k], a[k] > b[k] && a[k] > 0.0f) << k;
    EXPECT_EQ((gt || pos)[k], a[k] > b[k] || a[k] > 0.0f) << k;
    EXPECT_EQ((!gt)[k], !(a[k] > b[k])) << k;
    n_gt += a[k] > b[k];
  }
  EXPECT_FALSE(gt[7]);
  EXPECT_FALSE((!gt)[kLanes]);  // no lanes beyond kLanes
  EXPECT_EQ(gt.count(), n_gt);
  EXPECT_TRUE(LaneMask::Constant(true).all());
  EXPECT_EQ(LaneMask::Constant(true).count(), kLanes);
  EXPECT_FALSE(LaneMask().any());

  LaneMask m;
  m[3] = true;
  m[kLanes - 1] = true;
  m[3] = false;
  m[5] = true;
  EXPECT_EQ(m.count(), 2);
  EXPECT_TRUE(m[5] && m[kLanes - 1] && !m[3]);

  // selects keep the lane (inf and NaN included) or give +0.
  Lanes v = Lanes::Constant(3.0f);
  v[5] = std::numeric_limits<float>::infinity();
  v[6] = std::nanf("");
  const Lanes w = Where(m, v);
  for (int k = 0; k < kLanes; ++k) {
    if (m[k]) {
      EXPECT_EQ(w[k], v[k]) << k;
    } else {
      EXPECT_EQ(w[k], 0.0f) << k;
      EXPECT_FALSE(std::signbit(w[k])) << k;
    }
  }
}

TEST(ShadingLanesTest, SinCos2Pi) {
  for (int i = 0; i <= 4000; ++i) {
    const float u = std::min(i / 4000.0f, 0.99999994f);
    float s, c;
    SinCos2Pi(u, &s, &c);
    EXPECT_NEAR(s, std::sin(2 * M_PI * u), 1e-6) << u;
    EXPECT_NEAR(c, std::cos(2 * M_PI * u), 1e-6) << u;
  }
  Lanes u, s, c;
  for (int k = 0; k < kLanes; ++k) u[k] = k / 16.0f + 0.01f;
  SinCos2Pi(u, &s, &c);
  for (int k = 0; k < kLanes; ++k) {
    float ss, cc;
    SinCos2Pi(u[k], &ss, &cc);
    EXPECT_EQ(s[k], ss);
    EXPECT_EQ(c[k], cc);
  }
}

TEST(ShadingLanesTest, BsdfLanesAgreesWithBsdf) {
  Rng rng(21);
  for (int trial = 0; trial < 50; ++trial) {
    BsdfLanes lanes;
    PbrLanes pbr;
    Vec3Lanes wi;
    Bsdf* ref[kLanes];
    Eigen::Vector3f wis[kLanes];
    alignas(Bsdf) unsigned char storage[kLanes][sizeof(Bsdf)];
    for (int k = 0; k < kLanes; ++k) {
      PbrParams p;
      p.base_color = {rng.Uniform(), rng.Uniform(), rng.Uniform()};
      p.roughness = rng.Uniform();
      p.metallic = rng.Uniform() < 0.3f ? 1.0f : rng.Uniform();
      p.specular = rng.Uniform();
      const Eigen::Vector3f ng = RandomDir(&rng);
      Eigen::Vector3f ns = (ng + 0.3f * RandomDir(&rng)).normalized();
      Eigen::Vector3f wo = RandomDir(&rng);
      if (wo.dot(ng) < 0) wo = -wo;
      ref[k] = new (storage[k]) Bsdf(p, ns, ng, wo);
      // the realtime tier's path: frame per lane, then the coefficients of all lanes at once.
      lanes.SetFrame(k, UsableShadingNormal(ns, ng, wo), ng, wo);
      pbr.Set(k, p);
      wis[k] = RandomDir(&rng);
      if (rng.Uniform() < 0.7f && wis[k].dot(ng) < 0) wis[k] = -wis[k];
      wi.Set(k, wis[k]);
    }
    lanes.SetCoefficients(pbr);
    const Vec3Lanes f = lanes.Eval(wi);
    for (int k = 0; k < kLanes; ++k) {
      const Eigen::Vector3f e = ref[k]->Eval(wis[k]);
      EXPECT_NEAR((f.Lane(k) - e).norm(), 0.0f, 1e-4f * std::max(1.0f, e.norm()))
          << trial << " " << k;
      ref[k]->~Bsdf();
    }
  }
}

TEST(ShadingLanesTest, SampleLanesAgreesWithSample) {
  SceneDescription s;
  s.bodies.push_back({"world", -1, true});
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(0.2, -0.1, -1).normalized();
  sun.intensity = 1000;
  sun.angular_radius_deg = 2;
  Light lamp;
  lamp.type = Light::Type::kPoint;
  lamp.position_B = {0.3, 0.2, 1.5};
  lamp.intensity = 300;
  lamp.color = {1, 0.8f, 0.6f};
  lamp.radius_m = 0.2f;
  Light spot;
  spot.type = Light::Type::kSpot;
  spot.position_B = {0, 0, 2};
  spot.direction_B = {0, 0, -1};
  spot.intensity = 500;
  spot.spot_inner_deg = 15;
  spot.spot_outer_deg = 35;
  Light hard_spot = spot;
  hard_spot.spot_inner_deg = hard_spot.spot_outer_deg;
  s.lights = {sun, lamp, spot, hard_spot};
  LightSampler ls(s);
  WorldSnapshot w;
  w.X_WB = {Pose::Identity()};
  ls.Update(w);
  Rng rng(4);
  for (int j = 0; j < ls.size(); ++j) {
    Vec3Lanes p;
    Lanes u1, u2;
    for (int k = 0; k < kLanes; ++k) {
      p.Set(k, {2 * rng.Uniform() - 1, 2 * rng.Uniform() - 1, rng.Uniform()});
      u1[k] = rng.Uniform();
      u2[k] = rng.Uniform();
    }
    LightSampleLanes sl;
    ls.SampleLanes(j, p, u1, u2, &sl);
    int valid = 0;
    for (int k = 0; k < kLanes; ++k) {
      LightSample x;
      const bool ok = ls.Sample(j, p.Lane(k), u1[k], u2[k], &x);
      ASSERT_EQ(ok, static_cast<bool>(sl.valid[k])) << j << " " << k;
      if (!ok) continue;
      ++valid;
      // float rounding, amplified by the spot smoothstep's slope and the near-side root.
      EXPECT_NEAR((sl.wi.Lane(k) - x.wi).norm(), 0.0f, 1e-5f);
      EXPECT_NEAR((sl.E.Lane(k) - x.E).norm(), 0.0f, 2e-4f * x.E.norm());
      if (std::isinf(x.distance)) {
        EXPECT_TRUE(std::isinf(sl.distance[k]));
      } else {
        EXPECT_NEAR(sl.distance[k], x.distance, 1e-4f * x.distance);
      }
    }
    EXPECT_GT(valid, 0);
  }
}

}  // namespace
}  // namespace penumbra

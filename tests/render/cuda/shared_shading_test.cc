// the shared host/device shading formulas (render/light/brdf_math.h, light_math.h, film_math.h,
// texture_math.h) run on the CPU: their float instantiations (what the CUDA kernels run) agree
// with the CPU backend's lane code, which instantiates the same templates with SIMD lanes, to a
// few ulp (Eigen's vectorised square roots are not the correctly rounded ones), bit for bit
// with Film and the texture filtering, and with the scalar Bsdf and LightSampler::Sample to
// float rounding. no GPU needed.

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/render/cpu/bsdf_lanes.h"
#include "penumbra/render/film/film.h"
#include "penumbra/render/light/bsdf.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/material/material_eval.h"
#include "penumbra/render/material/texture_math.h"
#include "penumbra/scene/texture_image.h"

namespace penumbra {
namespace {

Eigen::Vector3f SharedUnit(Rng* rng) {
  for (;;) {
    const Eigen::Vector3f v(2 * rng->Uniform() - 1, 2 * rng->Uniform() - 1, 2 * rng->Uniform() - 1);
    if (v.squaredNorm() > 0.01f && v.squaredNorm() <= 1) return v.normalized();
  }
}

Float3 SharedF3(const Eigen::Vector3f& v) { return Float3{v.x(), v.y(), v.z()}; }

TEST(SharedShading, BrdfFloatFollowsTheLanesAndBsdf) {
  Rng rng(7);
  BsdfLanes lanes;
  PbrLanes pbr;
  std::vector<Eigen::Vector3f> n(kLanes), wo(kLanes), wi(kLanes);
  std::vector<PbrParams> params(kLanes);
  Vec3Lanes wi_lanes;
  for (int k = 0; k < kLanes; ++k) {
    n[k] = SharedUnit(&rng);
    do wo[k] = SharedUnit(&rng);
    while (wo[k].dot(n[k]) < 0.05f);
    do wi[k] = SharedUnit(&rng);
    while (wi[k].dot(n[k]) < 0.05f);
    params[k].base_color = Eigen::Vector3f(rng.Uniform(), rng.Uniform(), rng.Uniform());
    params[k].roughness = 0.05f + 0.95f * rng.Uniform();
    params[k].metallic = rng.Uniform();
    params[k].specular = rng.Uniform();
    lanes.SetFrame(k, n[k], n[k], wo[k]);
    pbr.Set(k, params[k]);
    wi_lanes.Set(k, wi[k]);
  }
  lanes.SetCoefficients(pbr);
  const Vec3Lanes f_lanes = lanes.Eval(wi_lanes);
  for (int k = 0; k < kLanes; ++k) {
    Float3 c_diff, f0;
    float alpha;
    BrdfCoefficientsOf<float, Float3>(SharedF3(params[k].base_color), params[k].roughness,
                                      params[k].metallic, params[k].specular, &c_diff, &f0, &alpha);
    const float n_v = pbm::Dot<float>(SharedF3(n[k]), SharedF3(wo[k]));
    const Float3 f = BrdfEvalWorld<float, Float3>(SharedF3(n[k]), SharedF3(n[k]), SharedF3(wo[k]),
                                                  n_v, c_diff, f0, alpha * alpha, SharedF3(wi[k]));
    EXPECT_NEAR(f.x, f_lanes.x[k], 1e-5f * (1 + f.x)) << k;
    EXPECT_NEAR(f.y, f_lanes.y[k], 1e-5f * (1 + f.y)) << k;
    EXPECT_NEAR(f.z, f_lanes.z[k], 1e-5f * (1 + f.z)) << k;
    const Bsdf bsdf(params[k], n[k], n[k], wo[k]);
    const Eigen::Vector3f g = bsdf.Eval(wi[k]);
    EXPECT_NEAR(f.x, g.x(), 2e-4f * (1 + g.x()));
    EXPECT_NEAR(f.y, g.y(), 2e-4f * (1 + g.y()));
    EXPECT_NEAR(f.z, g.z(), 2e-4f * (1 + g.z()));
    EXPECT_GT(f.x + f.y + f.z, 0.0f);
  }
}

TEST(SharedShading, EnvBrdfFloatFollowsTheLanes) {
  Vec3Lanes f0;
  Lanes n_v, rough;
  for (int k = 0; k < kLanes; ++k) {
    f0.Set(k, Eigen::Vector3f(0.04f, 0.5f, 0.9f) * (0.5f + k / 32.0f));
    n_v[k] = k / 15.0f;
    rough[k] = 1.0f - k / 15.0f;
  }
  const Vec3Lanes l = EnvBrdfApprox<Lanes, Vec3Lanes>(f0, n_v, rough);
  for (int k = 0; k < kLanes; ++k) {
    const Float3 s = EnvBrdfApprox<float, Float3>(SharedF3(f0.Lane(k)), n_v[k], rough[k]);
    // Eigen's vectorised exp and expf differ by a few ulp
    EXPECT_NEAR(s.x, l.x[k], 1e-6f);
    EXPECT_NEAR(s.y, l.y[k], 1e-6f);
    EXPECT_NEAR(s.z, l.z[k], 1e-6f);
    EXPECT_GE(s.x, 0.0f);
    EXPECT_LE(s.z, 1.0f);
  }
}

TEST(SharedShading, LightSampleFloatFollowsTheLanes) {
  SceneDescription scene;
  scene.bodies.resize(1);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(0.3, -0.2, -1).normalized();
  sun.intensity = 1000;
  sun.angular_radius_deg = 0.27f;
  Light spot;
  spot.type = Light::Type::kSpot;
  spot.position_B = Eigen::Vector3d(0.5, 0.2, 2.5);
  spot.direction_B = Eigen::Vector3d(0, 0, -1);
  spot.intensity = 300;
  spot.spot_inner_deg = 20;
  spot.spot_outer_deg = 40;
  spot.radius_m = 0.05f;
  Light lamp;
  lamp.type = Light::Type::kPoint;
  lamp.position_B = Eigen::Vector3d(-1, 1, 2);
  lamp.intensity = 100;
  scene.lights = {sun, spot, lamp};
  LightSampler sampler(scene);
  WorldSnapshot snap;
  snap.X_WB.assign(1, Pose::Identity());
  sampler.Update(snap);
  ASSERT_EQ(sampler.size(), 3);
  ASSERT_EQ(sampler.pods().size(), 3u);
  Rng rng(3);
  Vec3Lanes p;
  Lanes u1, u2;
  for (int k = 0; k < kLanes; ++k) {
    p.Set(k, Eigen::Vector3f(2 * rng.Uniform() - 1, 2 * rng.Uniform() - 1, 0.1f * rng.Uniform()));
    u1[k] = rng.Uniform();
    u2[k] = rng.Uniform();
  }
  for (int j = 0; j < sampler.size(); ++j) {
    LightSampleLanes s;
    sampler.SampleLanes(j, p, u1, u2, &s);
    int valid = 0;
    for (int k = 0; k < kLanes; ++k) {
      Float3 wi, E;
      float dist;
      bool ok;
      SampleLight<float, Float3, bool>(sampler.pods()[j], SharedF3(p.Lane(k)), u1[k], u2[k], &wi,
                                       &dist, &E, &ok);
      ASSERT_EQ(ok, s.valid[k]) << j << " " << k;
      if (!ok) continue;
      ++valid;
      EXPECT_NEAR(wi.x, s.wi.x[k], 2e-5f);
      EXPECT_NEAR(wi.y, s.wi.y[k], 2e-5f);
      EXPECT_NEAR(wi.z, s.wi.z[k], 2e-5f);
      if (std::isinf(dist))
        EXPECT_EQ(dist, s.distance[k]);
      else
        EXPECT_NEAR(dist, s.distance[k], 1e-4f * dist);
      EXPECT_NEAR(E.x, s.E.x[k], 1e-5f * E.x);
      EXPECT_NEAR(E.z, s.E.z[k], 1e-5f * E.z);
      // and the scalar sampler's model, to rounding
      LightSample ls;
      ASSERT_TRUE(sampler.Sample(j, p.Lane(k), u1[k], u2[k], &ls));
      EXPECT_NEAR(wi.x, ls.wi.x(), 1e-5f);
      EXPECT_NEAR(E.y, ls.E.y(), 1e-4f * (1 + ls.E.y()));
    }
    EXPECT_GT(valid, 0) << j;
  }
}

TEST(SharedShading, DevelopPixelGivesFilmsBytes) {
  for (const auto tone : {RenderSettings::ToneMap::kFilmic, RenderSettings::ToneMap::kLinear}) {
    RenderSettings settings;
    settings.tone_map = tone;
    const Film film(settings);
    ImageF radiance(37, 11, 3);
    Rng rng(11);
    for (float& v : radiance.data) v = 500.0f * rng.Uniform() * rng.Uniform();
    const double ev100 = film.Ev100(radiance, nullptr);
    ImageU8 rgb;
    film.Develop(radiance, ev100, nullptr, &rgb);
    const float e = static_cast<float>(ExposureFromEv100(ev100));
    const float exposure[3] = {e, e, e};
    for (int i = 0; i < 37 * 11; ++i) {
      const float* c = &radiance.data[3 * i];
      int32_t index[3];
      DevelopPixelIndices(c, exposure, film.filmic(), index);
      for (int k = 0; k < 3; ++k) ASSERT_EQ(film.oetf_lut()[index[k]], rgb.data[3 * i + k]) << i;
    }
    // the log-average from per-pixel terms gives Film's EV100
    double sum = 0;
    for (int i = 0; i < 37 * 11; ++i) sum += LogLuminanceTerm(&radiance.data[3 * i], kMinLuminance);
    EXPECT_NEAR(film.Ev100FromLogAverage(std::exp(sum / (37 * 11))), ev100, 1e-9);
  }
}

TEST(SharedShading, TextureFilteringMatchesMaterialEvaluator) {
  // a 2d texture with mip levels, looked up through the shared functions on a plain view
  std::vector<uint8_t> px(16 * 8 * 3);
  Rng rng(5);
  for (uint8_t& b : px) b = static_cast<uint8_t>(rng.Uniform() * 255.0f);
  SceneDescription scene;
  Texture tex;
  tex.name = "t";
  tex.image = std::make_shared<TextureImage>(16, 8, 1, px);
  scene.textures.push_back(tex);
  const MaterialEvaluator eval(scene);
  const TextureImage& im = *tex.image;
  for (int i = 0; i < 50; ++i) {
    const float s = 4 * rng.Uniform() - 2, t = 4 * rng.Uniform() - 2, lod = 5 * rng.Uniform() - 1;
    const Eigen::Vector3f want = eval.Sample2D(0, s, t, lod);
    int level[2];
    float weight[2];
    const int m = TrilinearLevels(im.num_levels(), lod, level, weight);
    Float3 got{0, 0, 0};
    for (int j = 0; j < m; ++j) {
      const TextureLevel& L = im.level(level[j]);
      got = got + weight[j] * BilinearWrap(TextureLevelView{L.rgb_srgb.data(), L.width, L.height},
                                           SrgbDecodeTable(), s, t);
    }
    EXPECT_EQ(got.x, want.x());
    EXPECT_EQ(got.y, want.y());
    EXPECT_EQ(got.z, want.z());
  }
  // anisotropic taps: more taps for a longer footprint, one for a round one
  EXPECT_EQ(TapsFor(16.0f, 16.0f, 16).n, 1);
  EXPECT_EQ(TapsFor(64.0f * 64.0f, 4.0f, 16).n, 16);
  EXPECT_EQ(TapsFor(36.0f, 4.0f, 16).n, 3);
}

}  // namespace
}  // namespace penumbra

// the pathtraced tier on the CPU (the transport's path chain over Embree, render/cpu/
// path_tiles.h): furnace tests, agreement with the realtime tier and with analytic values,
// multiple importance sampling against a quadrature reference, determinism across thread
// counts, and the stop request.

#include "penumbra/render/cpu/path_tiles.h"

#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>

#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/light/bsdf.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

constexpr double kPathPi = M_PI;

RenderSettings PathSettings(int spp, int max_bounces, int threads = 1) {
  RenderSettings r = TestSettings(threads);
  r.tier = RenderSettings::Tier::kPathtraced;
  r.samples_per_pixel = spp;
  r.max_bounces = max_bounces;
  r.denoise = false;
  return r;
}

RenderedFrame Render(const SceneDescription& s, const RenderSettings& settings,
                     const CameraView& view) {
  auto r = MakeRenderer(s, settings);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  return f;
}

// mean of channel c over the pixels whose geom id is `id`; writes the pixel count.
double MeanOver(const RenderedFrame& f, int id, int c, int* count) {
  double sum = 0;
  int n = 0;
  for (int v = 0; v < f.radiance.height; ++v)
    for (int u = 0; u < f.radiance.width; ++u)
      if (*f.geom_id.at(u, v) == id) sum += f.radiance.at(u, v)[c], ++n;
  *count = n;
  return n ? sum / n : 0.0;
}

TEST(PathtracedCpu, FurnaceDiffuseSphereInUniformSky) {
  // a white Lambertian-like sphere (base colour 1, roughness 1, no specular) in a uniform sky
  // of radiance L reflects L wherever it is seen (it never sees itself).
  SceneDescription s = EmptyScene();
  s.sky.radiance = {1.0f, 2.0f, 4.0f};
  const int m = AddMaterial(&s, Eigen::Vector3f::Ones());
  AddGeom(&s, GeomShape::kSphere, {0.5, 0, 0}, Translation(2, 0, 0), 0, m);
  const CameraView view = MakeView(CameraLookingAlongX(), 24, 24, 40);
  const RenderedFrame f = Render(s, PathSettings(64, 8), view);
  int count = 0;
  for (int c = 0; c < 3; ++c) {
    const double mean = MeanOver(f, 100, c, &count);
    EXPECT_NEAR(mean, s.sky.radiance[c], 0.02 * s.sky.radiance[c]) << "channel " << c;
    RecordProperty("mean_error_channel_" + std::to_string(c),
                   std::to_string(mean / s.sky.radiance[c] - 1));
  }
  ASSERT_GT(count, 200);
  // with enough samples every sphere pixel is within 2%, except at the silhouette, where
  // the Fresnel term of the glTF BRDF (F0 = 0 still reflects (1 - v.h)^5) changes the
  // directional albedo at grazing views.
  const CameraView small = MakeView(CameraLookingAlongX(), 12, 12, 40);
  const RenderedFrame g = Render(s, PathSettings(4096, 8), small);
  int checked = 0;
  double worst = 0;
  for (int v = 1; v < 11; ++v)
    for (int u = 1; u < 11; ++u) {
      bool interior = true;
      for (int dv = -1; dv <= 1; ++dv)
        for (int du = -1; du <= 1; ++du) interior &= *g.geom_id.at(u + du, v + dv) == 100;
      if (!interior) continue;
      ++checked;
      worst = std::max(worst, std::abs(g.radiance.at(u, v)[1] / 2.0 - 1));
      EXPECT_NEAR(g.radiance.at(u, v)[1], 2.0, 0.04) << u << "," << v;
    }
  EXPECT_GT(checked, 20);
  RecordProperty("worst_pixel_error", std::to_string(worst));
}

TEST(PathtracedCpu, FurnaceClosedEmissiveBox) {
  // inside a closed box whose walls have albedo rho and emission Le, radiance is
  // Le (1 + rho + rho^2 + ...) = Le / (1 - rho) everywhere; needs many bounces and unbiased
  // Russian roulette.
  const float rho = 0.5f, le = 10.0f;
  SceneDescription s = EmptyScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Constant(rho));
  s.materials[m].emission = Eigen::Vector3f::Constant(le);
  AddGeom(&s, GeomShape::kBox, {1, 1.2, 0.8}, Pose::Identity(), 0, m);
  const CameraView view = MakeView(CameraLookingAlongX({-0.3, 0.1, 0}), 16, 16, 90);
  const RenderedFrame f = Render(s, PathSettings(128, 64), view);
  int count = 0;
  const double mean = MeanOver(f, 100, 1, &count);
  EXPECT_EQ(count, 16 * 16);
  const double expected = le / (1 - rho);
  EXPECT_NEAR(mean, expected, 0.02 * expected);
  RecordProperty("mean_error", std::to_string(mean / expected - 1));
  // with max_bounces = 1 only the first reflection is gathered: Le (1 + rho) at most.
  const RenderedFrame f1 = Render(s, PathSettings(32, 1), view);
  const double mean1 = MeanOver(f1, 100, 1, &count);
  EXPECT_NEAR(mean1, le * (1 + rho), 0.02 * le * (1 + rho));
  RecordProperty("one_bounce_mean_error", std::to_string(mean1 / (le * (1 + rho)) - 1));
}

TEST(PathtracedCpu, LambertianPlaneUnderDirectionalLight) {
  const float rho = 0.6f, E = 1000.0f;
  for (double incidence_deg : {0.0, 50.0}) {
    SceneDescription s = EmptyScene();
    const int m = AddMaterial(&s, Eigen::Vector3f::Constant(rho));
    AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, m);
    Light sun;
    sun.type = Light::Type::kDirectional;
    const double a = incidence_deg * kPathPi / 180;
    sun.direction_B = Eigen::Vector3d(std::sin(a), 0, -std::cos(a));
    sun.intensity = E;
    s.lights.push_back(sun);
    const CameraView view = MakeView(CameraLookingDown({0, 0, 2}), 21, 21, 60);
    const RenderedFrame f = Render(s, PathSettings(4, 4), view);
    const double expected = E * std::cos(a) * rho / kPathPi;
    for (int v = 0; v < 21; v += 5)
      for (int u = 0; u < 21; u += 5)
        EXPECT_NEAR(f.radiance.at(u, v)[1], expected, 0.02 * expected) << u << "," << v;
  }
}

// a direct-lighting scene: floor and a glossy sphere under a point light, a spot light and a
// directional light, black sky; max_bounces = 1 (no interreflection).
SceneDescription DirectLightingScene() {
  SceneDescription s = EmptyScene();
  const int floor = AddMaterial(&s, {0.5f, 0.6f, 0.7f}, 0.8f, 0.0f, 0.5f);
  const int ball = AddMaterial(&s, {0.8f, 0.3f, 0.2f}, 0.4f, 0.0f, 0.5f);
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, floor);
  AddGeom(&s, GeomShape::kSphere, {0.3, 0, 0}, Translation(0.2, 0.1, 0.3), 0, ball);
  Light point;
  point.type = Light::Type::kPoint;
  point.position_B = {-0.5, 0.4, 1.2};
  point.intensity = 200;
  Light spot;
  spot.type = Light::Type::kSpot;
  spot.position_B = {0.6, -0.6, 1.0};
  spot.direction_B = Eigen::Vector3d(-0.4, 0.5, -1).normalized();
  spot.intensity = 500;
  spot.color = {1.0f, 0.8f, 0.6f};
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(0.3, 0.4, -1).normalized();
  sun.intensity = 300;
  s.lights = {point, spot, sun};
  return s;
}

TEST(PathtracedCpu, AgreesWithRealtimeTierOnDirectLighting) {
  // the path tracer averages each pixel's area (jittered camera rays); the realtime tier
  // samples the pixel centre, so it renders at 5x resolution and is box-downsampled.
  const SceneDescription s = DirectLightingScene();
  const int w = 48, k = 5;
  const RenderedFrame rt =
      Render(s, TestSettings(), MakeView(CameraLookingDown({0, 0, 2.5}), w * k, w * k, 60));
  const RenderedFrame pt =
      Render(s, PathSettings(64, 1), MakeView(CameraLookingDown({0, 0, 2.5}), w, w, 60));
  double sum_rt = 0, sum_pt = 0, worst = 0;
  int checked = 0;
  for (int v = 0; v < w; ++v)
    for (int u = 0; u < w; ++u) {
      // pixels that see a single geom and no shadow edge: the high-resolution samples
      // of the pixel and a ring around it vary by less than 10%.
      bool single = u > 0 && v > 0 && u < w - 1 && v < w - 1;
      float lo = std::numeric_limits<float>::infinity(), hi = 0;
      for (int dv = -1; single && dv <= k; ++dv)
        for (int du = -1; du <= k; ++du) {
          single &= *rt.geom_id.at(k * u + du, k * v + dv) == *pt.geom_id.at(u, v);
          const float g = rt.radiance.at(k * u + du, k * v + dv)[1];
          lo = std::min(lo, g), hi = std::max(hi, g);
        }
      single &= hi <= 1.1f * lo;
      for (int c = 0; c < 3; ++c) {
        double a = 0;
        for (int j = 0; j < k * k; ++j) a += rt.radiance.at(k * u + j % k, k * v + j / k)[c];
        a /= k * k;
        const double b = pt.radiance.at(u, v)[c];
        sum_rt += a, sum_pt += b;
        if (!single) continue;
        EXPECT_NEAR(b, a, 0.02 * a + 1e-3) << u << "," << v << " channel " << c;
        if (a > 1) worst = std::max(worst, std::abs(b / a - 1));
      }
      checked += single;
    }
  EXPECT_GT(checked, 1500);
  EXPECT_NEAR(sum_pt, sum_rt, 0.005 * sum_rt);
  RecordProperty("worst_pixel_error", std::to_string(worst));
  RecordProperty("image_sum_error", std::to_string(sum_pt / sum_rt - 1));
}

TEST(PathtracedCpu, ImagesDoNotDependOnThreadCount) {
  // every light kind, a daylight sky, an emissive box and several bounces.
  SceneDescription s = DirectLightingScene();
  s.sky.type = Sky::Type::kDaylight;
  s.sky.zenith_luminance = 2000;
  s.lights[0].radius_m = 0.1f;
  s.lights[2].angular_radius_deg = 2.0f;
  const int glow = AddMaterial(&s, Eigen::Vector3f::Constant(0.2f));
  s.materials[glow].emission = {300, 200, 100};
  AddGeom(&s, GeomShape::kBox, {0.1, 0.1, 0.1}, Translation(-0.4, -0.3, 0.1), 0, glow);
  const CameraView view = MakeView(CameraLookingDown({0, 0, 2.5}), 40, 30, 70);
  RenderSettings one = PathSettings(4, 4, 1), two = PathSettings(4, 4, 2),
                 three = PathSettings(4, 4, 3);
  one.denoise = two.denoise = three.denoise = true;
  const RenderedFrame a = Render(s, one, view), b = Render(s, two, view);
  ASSERT_EQ(a.radiance.data.size(), b.radiance.data.size());
  EXPECT_EQ(0, std::memcmp(a.radiance.data.data(), b.radiance.data.data(),
                           a.radiance.data.size() * sizeof(float)));
  EXPECT_EQ(a.rgb.data, b.rgb.data);
  // three threads take the 16x16 tiles in another order: the same bits
  const RenderedFrame d = Render(s, three, view);
  EXPECT_EQ(0, std::memcmp(a.radiance.data.data(), d.radiance.data.data(),
                           a.radiance.data.size() * sizeof(float)));
  EXPECT_EQ(a.rgb.data, d.rgb.data);
  // every pixel was traced: some light everywhere the camera looks (the floor fills the view)
  int dark = 0;
  for (float x : a.radiance.data) dark += !(x > 0);
  EXPECT_LT(dark, static_cast<int>(a.radiance.data.size()) / 10);
  // and a different frame index gives different noise.
  CameraView later = view;
  later.frame_index = 1;
  const RenderedFrame c = Render(s, one, later);
  EXPECT_NE(0, std::memcmp(a.radiance.data.data(), c.radiance.data.data(),
                           a.radiance.data.size() * sizeof(float)));
}

TEST(PathtracedCpu, SphereLampMatchesInverseSquareLaw) {
  // a lamp of radius r and intensity I is a sphere of radiance I / (pi r^2); on a Lambertian
  // floor it gives E = I cos(theta) / d^2 exactly (the sphere is above the horizon), and the
  // camera sees it at that radiance.
  const float rho = 0.5f, I = 300.0f;
  const double h = 0.8, r = 0.15;
  SceneDescription s = EmptyScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Constant(rho));
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, m);
  Light lamp;
  lamp.type = Light::Type::kPoint;
  lamp.position_B = {0, 0, h};
  lamp.intensity = I;
  lamp.radius_m = static_cast<float>(r);
  s.lights.push_back(lamp);
  const CameraView view = MakeView(CameraLookingDown({0.05, 0.02, 2}), 31, 31, 70);
  const RenderedFrame f = Render(s, PathSettings(256, 1), view);
  const CameraIntrinsics& k = view.intrinsics;
  int lamp_pixels = 0;
  for (int v = 0; v < 31; ++v)
    for (int u = 0; u < 31; ++u) {
      // the floor point the pixel centre sees (camera 2 m up, looking down).
      const double x = 0.05 + (u - k.cx) / k.fx * 2, y = 0.02 - (v - k.cy) / k.fy * 2;
      const double r2 = x * x + y * y + h * h;
      // pixels whose floor point is hidden by the lamp (seen within its disc) show the lamp.
      const double seen_x = 0.05 + (u - k.cx) / k.fx * (2 - h),
                   seen_y = 0.02 - (v - k.cy) / k.fy * (2 - h);
      if (std::hypot(seen_x, seen_y) < r * 1.3) {
        if (std::hypot(seen_x, seen_y) < r * 0.7) {
          ++lamp_pixels;
          EXPECT_NEAR(f.radiance.at(u, v)[1], I / (kPathPi * r * r), 1e-3 * I / (kPathPi * r * r));
        }
        continue;
      }
      const double expected = I * h / (r2 * std::sqrt(r2)) * rho / kPathPi;
      EXPECT_NEAR(f.radiance.at(u, v)[1], expected, 0.03 * expected) << u << "," << v;
    }
  EXPECT_GT(lamp_pixels, 0);
}

// reflected radiance towards wo at p from a sphere of radiance Le (centre c, radius r), by a
// dense quadrature over the cone the sphere subtends (reference for the MIS test).
double GlossyReference(const PbrParams& params, const Eigen::Vector3f& p, const Eigen::Vector3f& wo,
                       const Eigen::Vector3f& c, float r, float le) {
  const Bsdf bsdf(params, {0, 0, 1}, {0, 0, 1}, wo);
  const Eigen::Vector3f axis = (c - p).normalized();
  const double d = (c - p).norm();
  const double cos_max = std::sqrt(1 - r * r / (d * d));
  Eigen::Vector3f t = axis.unitOrthogonal(), b = axis.cross(t);
  const int nt = 600, np = 600;
  double sum = 0;
  for (int i = 0; i < nt; ++i) {
    const double c0 = 1 - (1 - cos_max) * i / nt, c1 = 1 - (1 - cos_max) * (i + 1) / nt;
    const double ct = 0.5 * (c0 + c1), st = std::sqrt(1 - ct * ct);
    for (int j = 0; j < np; ++j) {
      const double phi = 2 * kPathPi * (j + 0.5) / np;
      const Eigen::Vector3f wi =
          (st * std::cos(phi) * t + st * std::sin(phi) * b + ct * axis).cast<float>().normalized();
      sum += bsdf.Eval(wi).y() * (c0 - c1) * 2 * kPathPi / np;
    }
  }
  return sum * le;
}

TEST(PathtracedCpu, MisGlossyReflectionOfSmallEmissiveSphere) {
  // a small emissive sphere seen in a glossy floor: the MIS estimate (emitter sampling +
  // BSDF sampling) converges to the reflected radiance computed by quadrature.
  for (float roughness : {0.15f, 0.4f}) {
    SceneDescription s = EmptyScene();
    const int floor = AddMaterial(&s, {0.3f, 0.3f, 0.3f}, roughness, 0.0f, 0.5f);
    s.materials[floor].metallic = 0.5f;
    AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, floor);
    const int glow = AddMaterial(&s, Eigen::Vector3f::Zero());
    const float le = 1000.0f, r = 0.05f;
    s.materials[glow].emission = Eigen::Vector3f::Constant(le);
    const Eigen::Vector3f c(0.6f, 0.0f, 0.5f);
    AddGeom(&s, GeomShape::kSphere, {r, 0, 0}, Translation(c.x(), c.y(), c.z()), 0, glow);
    // camera at (-0.6, 0, 0.5) looking at the mirror point (0, 0, 0) of the sphere.
    const Eigen::Vector3d eye(-0.6, 0, 0.5);
    Pose X = Pose::Identity();
    const Eigen::Vector3d z = (-eye).normalized();
    const Eigen::Vector3d x = Eigen::Vector3d(0, -1, 0);
    X.linear().col(0) = x;
    X.linear().col(1) = z.cross(x);
    X.linear().col(2) = z;
    X.translation() = eye;
    CameraView view = MakeView(X, 9, 9, 0.5);
    const RenderedFrame f = Render(s, PathSettings(2048, 1), view);
    ASSERT_EQ(*f.geom_id.at(4, 4), 100);
    PbrParams params;
    params.base_color = s.materials[floor].base_color;
    params.roughness = roughness;
    params.metallic = 0.5f;
    params.specular = 0.5f;
    // the 3x3 centre pixels see floor points within 2 mm of the origin; compare their
    // mean to the reference at the origin.
    double mean = 0;
    for (int v = 3; v <= 5; ++v)
      for (int u = 3; u <= 5; ++u) mean += f.radiance.at(u, v)[1] / 9.0;
    const Eigen::Vector3f wo = eye.cast<float>().normalized();
    const double ref = GlossyReference(params, {0, 0, 0}, wo, c, r, le);
    EXPECT_NEAR(mean, ref, 0.03 * ref) << "roughness " << roughness;
    RecordProperty("error_roughness_" + std::to_string(roughness), std::to_string(mean / ref - 1));
  }
}

TEST(PathtracedCpu, AStopRequestEndsTheFrameUnfinished) {
  // a stop request already set: no tile traces a sample, the frame is marked stopped and not
  // developed; cleared, the same renderer renders the frame in full.
  SceneDescription s = DirectLightingScene();
  const CameraView view = MakeView(CameraLookingDown({0, 0, 2.5}), 40, 30, 70);
  auto r = MakeRenderer(s, PathSettings(64, 4, 2));
  std::atomic<int> stop{1};
  r->set_stop_request(&stop);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  EXPECT_TRUE(f.stopped);
  EXPECT_TRUE(f.rgb.data.empty());
  stop = 0;
  r->Render(IdentitySnapshot(s), view, &f);
  EXPECT_FALSE(f.stopped);
  EXPECT_EQ(f.rgb.width, 40);
  EXPECT_EQ(f.rgb.height, 30);
}

}  // namespace
}  // namespace penumbra

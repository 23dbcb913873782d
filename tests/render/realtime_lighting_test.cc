// radiometry of the realtime tier: Lambertian response, inverse-square falloff, spot cones,
// shadows, sky ambient.

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/render/backends/renderer_factory.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

constexpr double kPi = M_PI;

// a floor plane (z = 0, albedo rho, Lambertian: roughness 1, specular 0) seen from above.
SceneDescription Floor(float rho) {
  SceneDescription s = EmptyScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Constant(rho));
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, m);
  return s;
}

// linear radiance (green channel) at world floor point (x, y) seen by a camera 2 m above (0, 0).
class FloorProbe {
 public:
  explicit FloorProbe(const SceneDescription& s, int size = 101)
      : scene_(s), r_(MakeRenderer(scene_, TestSettings())), size_(size) {}
  const RenderedFrame& Render() {
    view_ = MakeView(CameraLookingDown({0, 0, 2}), size_, size_, 90, true, true, true);
    r_->Render(IdentitySnapshot(scene_), view_, &f_);
    return f_;
  }
  // radiance at the pixel that sees floor point (x, y).
  Eigen::Vector3f At(double x, double y) const {
    const CameraIntrinsics& k = view_.intrinsics;
    const int u = static_cast<int>(std::lround(k.fx * x / 2 + k.cx));
    const int v = static_cast<int>(std::lround(k.fy * -y / 2 + k.cy));
    const float* p = f_.radiance.at(u, v);
    return {p[0], p[1], p[2]};
  }
  // the floor point actually seen by the pixel nearest to (x, y).
  Eigen::Vector2d Seen(double x, double y) const {
    const CameraIntrinsics& k = view_.intrinsics;
    const double u = std::lround(k.fx * x / 2 + k.cx), v = std::lround(k.fy * -y / 2 + k.cy);
    return {(u - k.cx) / k.fx * 2, -(v - k.cy) / k.fy * 2};
  }

 private:
  SceneDescription scene_;
  std::unique_ptr<Renderer> r_;
  int size_;
  CameraView view_;
  RenderedFrame f_;
};

TEST(RealtimeLightingTest, LambertianPlaneUnderDirectionalLight) {
  for (double incidence_deg : {0.0, 30.0, 60.0}) {
    const float rho = 0.6f, E = 1000.0f;
    SceneDescription s = Floor(rho);
    Light sun;
    sun.type = Light::Type::kDirectional;
    const double a = incidence_deg * kPi / 180;
    sun.direction_B = Eigen::Vector3d(std::sin(a), 0, -std::cos(a));
    sun.intensity = E;
    s.lights.push_back(sun);
    FloorProbe probe(s);
    probe.Render();
    const double expected = E * std::cos(a) * rho / kPi;
    for (auto [x, y] : {std::pair{0.0, 0.0}, {0.5, 0.3}, {-0.8, -0.6}}) {
      const Eigen::Vector3f L = probe.At(x, y);
      EXPECT_NEAR(L.y(), expected, 0.02 * expected) << incidence_deg << " deg at " << x << "," << y;
      EXPECT_FLOAT_EQ(L.x(), L.z());
    }
  }
}

TEST(RealtimeLightingTest, PointLightFallsOffWithInverseSquare) {
  const float rho = 0.5f, I = 300.0f;
  for (double h : {0.5, 1.0, 1.5}) {
    SceneDescription s = Floor(rho);
    Light lamp;
    lamp.type = Light::Type::kPoint;
    lamp.position_B = {0, 0, h};
    lamp.intensity = I;
    s.lights.push_back(lamp);
    FloorProbe probe(s);
    probe.Render();
    for (auto [x, y] : {std::pair{0.0, 0.0}, {0.6, 0.0}, {-0.4, 0.7}}) {
      // E = I cos(theta) / r^2 = I h / r^3 at the floor point the pixel actually sees.
      const Eigen::Vector2d p = probe.Seen(x, y);
      const double r2 = p.squaredNorm() + h * h;
      const double expected = I * h / (r2 * std::sqrt(r2)) * rho / kPi;
      EXPECT_NEAR(probe.At(x, y).y(), expected, 0.02 * expected)
          << "h " << h << " at " << x << "," << y;
    }
  }
}

TEST(RealtimeLightingTest, SpotConeSmoothstep) {
  const float rho = 0.5f, I = 400.0f;
  const double h = 1.0;
  SceneDescription s = Floor(rho);
  Light spot;
  spot.type = Light::Type::kSpot;
  spot.position_B = {0, 0, h};
  spot.direction_B = {0, 0, -1};
  spot.intensity = I;
  spot.spot_inner_deg = 20;
  spot.spot_outer_deg = 40;
  s.lights.push_back(spot);
  FloorProbe probe(s);
  probe.Render();
  for (double x : {0.0, 0.2, 0.5, 0.6, 0.75, 0.9}) {
    const Eigen::Vector2d p = probe.Seen(x, 0);
    const double r2 = p.squaredNorm() + h * h;
    const double cos_axis = h / std::sqrt(r2);
    const double c0 = std::cos(40 * kPi / 180), c1 = std::cos(20 * kPi / 180);
    const double t = std::clamp((cos_axis - c0) / (c1 - c0), 0.0, 1.0);
    const double expected = I * t * t * (3 - 2 * t) * h / (r2 * std::sqrt(r2)) * rho / kPi;
    EXPECT_NEAR(probe.At(x, 0).y(), expected, 0.02 * expected + 1e-6) << "x " << x;
  }
  // outside the outer cone (40 deg -> 0.84 m) the floor is black.
  EXPECT_EQ(probe.At(0.95, 0).y(), 0.0f);
}

TEST(RealtimeLightingTest, OccluderCastsAShadow) {
  const float rho = 0.5f, E = 800.0f;
  SceneDescription s = Floor(rho);
  Light sun;
  sun.type = Light::Type::kDirectional;
  const double a = kPi / 4;
  sun.direction_B = Eigen::Vector3d(std::sin(a), 0, -std::cos(a));
  sun.intensity = E;
  s.lights.push_back(sun);
  // a thin 0.4 m square slab centred at (-0.5, 0, 0.5): with the sun at 45 degrees its shadow
  // covers the floor square x, y in [-0.2, 0.2], which the camera above (0, 0) sees.
  AddGeom(&s, GeomShape::kBox, {0.2, 0.2, 0.005}, Translation(-0.5, 0, 0.5));
  FloorProbe probe(s, 301);
  const RenderedFrame& f = probe.Render();
  const double lit = E * std::cos(a) * rho / kPi;
  EXPECT_NEAR(probe.At(0.5, 0).y(), lit, 0.02 * lit);
  EXPECT_NEAR(probe.At(0.3, -0.3).y(), lit, 0.02 * lit);
  EXPECT_EQ(probe.At(0.0, 0.0).y(), 0.0f);
  EXPECT_EQ(probe.At(0.1, -0.15).y(), 0.0f);
  EXPECT_EQ(probe.At(-0.15, 0.1).y(), 0.0f);
  // count shadowed floor pixels: the shadow's area matches the slab's (0.4 x 0.41 m: the slab's
  // thickness adds 1 cm at 45 degrees) within 10%.
  const double px_area = std::pow(2.0 / CameraIntrinsics::FromFovy(301, 301, 90).fx, 2);
  int dark = 0;
  for (int v = 0; v < f.radiance.height; ++v)
    for (int u = 0; u < f.radiance.width; ++u)
      if (*f.geom_id.at(u, v) == 100 && f.radiance.at(u, v)[1] == 0.0f) ++dark;
  EXPECT_NEAR(dark * px_area, 0.164, 0.0164);
}

TEST(RealtimeLightingTest, UniformSkyAmbientOnLambertianSurface) {
  // an unoccluded Lambertian plane under a uniform sky of radiance Ls reflects Ls rho.
  const float rho = 0.4f;
  SceneDescription s = Floor(rho);
  s.sky.radiance = {100, 200, 300};
  FloorProbe probe(s);
  probe.Render();
  const Eigen::Vector3f L = probe.At(0.3, 0.2);
  EXPECT_NEAR(L.x(), 100 * rho, 0.02 * 100 * rho);
  EXPECT_NEAR(L.y(), 200 * rho, 0.02 * 200 * rho);
  EXPECT_NEAR(L.z(), 300 * rho, 0.02 * 300 * rho);
}

TEST(RealtimeLightingTest, MissesSeeTheSkyAndEmissionAdds) {
  SceneDescription s = EmptyScene();
  s.sky.radiance = {1, 2, 3};
  const int m = AddMaterial(&s, Eigen::Vector3f::Zero());
  s.materials[m].emission = {50, 60, 70};
  AddGeom(&s, GeomShape::kSphere, {0.3, 0, 0}, Translation(2, 0, 0), 0, m);
  auto r = MakeRenderer(s, TestSettings());
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), MakeView(CameraLookingAlongX(), 31, 31, 60), &f);
  const float* sky = f.radiance.at(0, 0);
  EXPECT_FLOAT_EQ(sky[0], 1);
  EXPECT_FLOAT_EQ(sky[2], 3);
  const float* e = f.radiance.at(15, 15);
  // black (c_diff 0, F0 0) surface: emission only.
  EXPECT_NEAR(e[0], 50, 1e-3);
  EXPECT_NEAR(e[2], 70, 1e-3);
}

TEST(RealtimeLightingTest, SoftShadowPenumbraIsBetweenLitAndDark) {
  // a large sun disc and a thin pole: points near the shadow edge are partly lit on average.
  const float rho = 0.5f, E = 1000.0f;
  SceneDescription s = Floor(rho);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = {0, 0, -1};
  sun.intensity = E;
  sun.angular_radius_deg = 10;
  s.lights.push_back(sun);
  AddGeom(&s, GeomShape::kBox, {0.5, 0.5, 0.01}, Translation(-0.5, 0, 0.5));  // edge at x = 0
  auto r = MakeRenderer(s, TestSettings());
  CameraView view = MakeView(CameraLookingDown({0.0, 0, 0.2}), 201, 61, 60);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), view, &f);
  // average over pixels at the edge (x = 0): half the disc is hidden -> about E / 2. a fully
  // lit and a fully shadowed floor patch for reference.
  const CameraIntrinsics& k = view.intrinsics;
  auto mean_at = [&](double x) {
    const int u = static_cast<int>(std::lround(k.fx * x / 0.2 + k.cx));
    EXPECT_TRUE(u >= 1 && u + 1 < f.radiance.width);
    double sum = 0;
    for (int du = -1; du <= 1; ++du)
      for (int v = 0; v < 61; ++v) sum += f.radiance.at(u + du, v)[1];
    return sum / (3 * 61);
  };
  const double mean = mean_at(0.0);
  const double lit = E * rho / kPi;
  EXPECT_GT(mean, 0.25 * lit);
  EXPECT_LT(mean, 0.75 * lit);
  EXPECT_NEAR(mean_at(0.2), lit, 0.02 * lit);
  EXPECT_EQ(mean_at(-0.2), 0.0);
}

}  // namespace
}  // namespace penumbra

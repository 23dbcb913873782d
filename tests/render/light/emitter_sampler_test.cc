#include "penumbra/render/light/emitter_sampler.h"

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numbers>

#include "penumbra/core/rng.h"

namespace penumbra {
namespace {

// a scene with one body (the world) and the given emissive geoms (material 0 emits).
SceneDescription SceneWith(const std::vector<Geom>& geoms, const Eigen::Vector3f& le) {
  SceneDescription scene;
  scene.bodies.push_back(Body{"world", -1, true});
  Material m;
  m.name = "lamp";
  m.emission = le;
  scene.materials.push_back(m);
  Material dark;
  dark.name = "dark";
  scene.materials.push_back(dark);
  scene.geoms = geoms;
  for (size_t i = 0; i < scene.geoms.size(); ++i) scene.geoms[i].id = static_cast<int>(i);
  return scene;
}

Geom MakeGeom(GeomShape shape, const Eigen::Vector3d& size, const Pose& X, int material = 0) {
  Geom g;
  g.shape = shape;
  g.size = size;
  g.X_BG = X;
  g.material = material;
  return g;
}

// irradiance at p_W (normal n) from the emitters, estimated with Sample() (no occlusion).
Eigen::Vector3d EstimateIrradiance(const EmitterSampler& es, const std::vector<Pose>& X_WB,
                                   const Eigen::Vector3f& p, const Eigen::Vector3f& n, int count) {
  Rng rng(HashKeys(3, 4));
  Eigen::Vector3d sum(0, 0, 0);
  for (int i = 0; i < count; ++i) {
    EmitterSample s;
    if (!es.Sample(X_WB, p, rng.Uniform(), rng.Uniform(), rng.Uniform(), &s)) continue;
    EXPECT_NEAR(es.Pdf(X_WB, s.geom, p, s.p_W, s.n_W), s.pdf, 1e-3f * s.pdf);
    EXPECT_NEAR((s.p_W - p).norm(), s.distance, 1e-4f * s.distance);
    sum += (s.Le * std::max(0.0f, n.dot(s.wi)) / s.pdf).cast<double>();
  }
  return sum / count;
}

// dense quadrature of the irradiance from a rectangle [-a, a] x [-b, b] in the plane of pose X.
double RectangleIrradiance(const Pose& X, double a, double b, double le, const Eigen::Vector3d& p,
                           const Eigen::Vector3d& n, bool two_sided_normal = true) {
  const int k = 400;
  double sum = 0;
  const Eigen::Vector3d nl = X.linear() * Eigen::Vector3d::UnitZ();
  for (int i = 0; i < k; ++i)
    for (int j = 0; j < k; ++j) {
      const Eigen::Vector3d q =
          X * Eigen::Vector3d((-1 + (2 * i + 1.0) / k) * a, (-1 + (2 * j + 1.0) / k) * b, 0);
      const Eigen::Vector3d d = q - p;
      const double r2 = d.squaredNorm();
      const Eigen::Vector3d w = d / std::sqrt(r2);
      sum += std::max(0.0, n.dot(w)) * std::abs(nl.dot(w)) / r2;
    }
  return le * sum * (4 * a * b) / (k * k);
}

TEST(EmitterSamplerTest, SphereConeSamplingGivesExactIrradiance) {
  // a sphere of radius r at distance D on the normal: E = Le pi (r / D)^2.
  const SceneDescription scene = SceneWith(
      {MakeGeom(GeomShape::kSphere, {0.3, 0, 0}, PoseFromXyzRpyDeg({0, 0, 2}, {0, 0, 0}))},
      {100, 200, 300});
  const EmitterSampler es(scene);
  ASSERT_EQ(es.size(), 1);
  const std::vector<Pose> X_WB = {Pose::Identity()};
  const Eigen::Vector3d e = EstimateIrradiance(es, X_WB, {0, 0, 0}, {0, 0, 1}, 20000);
  for (int k = 0; k < 3; ++k) {
    const double ref = 100.0 * (k + 1) * std::numbers::pi * 0.3 * 0.3 / 4.0;
    EXPECT_NEAR(e[k], ref, 0.005 * ref);
  }
}

TEST(EmitterSamplerTest, AreaSamplingMatchesQuadrature) {
  const Pose X = PoseFromXyzRpyDeg({0.2, -0.1, 1.5}, {20, -10, 30});
  const Eigen::Vector3d p(0, 0, 0), n(0, 0, 1);
  const double ref = RectangleIrradiance(X, 0.4, 0.25, 50.0, p, n);
  // finite plane.
  {
    const SceneDescription scene =
        SceneWith({MakeGeom(GeomShape::kPlane, {0.4, 0.25, 0}, X)}, Eigen::Vector3f::Constant(50));
    const EmitterSampler es(scene);
    const Eigen::Vector3d e =
        EstimateIrradiance(es, {Pose::Identity()}, p.cast<float>(), n.cast<float>(), 200000);
    EXPECT_NEAR(e.x(), ref, 0.01 * ref);
  }
  // the same rectangle as a mesh of three unequal triangles, on a moving body.
  {
    SceneDescription scene = SceneWith({}, Eigen::Vector3f::Constant(50));
    scene.bodies.push_back(Body{"mover", 0, false});
    TriangleMesh mesh;
    mesh.vertices = {{-0.4f, -0.25f, 0},
                     {0.4f, -0.25f, 0},
                     {0.4f, 0.25f, 0},
                     {-0.4f, 0.25f, 0},
                     {0.1f, -0.25f, 0}};
    mesh.faces = {{0, 4, 3}, {4, 1, 2}, {4, 2, 3}};
    scene.meshes.push_back(mesh);
    Geom g = MakeGeom(GeomShape::kMesh, {0, 0, 0}, Pose::Identity());
    g.mesh = 0;
    g.body = 1;
    scene.geoms.push_back(g);
    const EmitterSampler es(scene);
    ASSERT_EQ(es.size(), 1);
    const Eigen::Vector3d e =
        EstimateIrradiance(es, {Pose::Identity(), X}, p.cast<float>(), n.cast<float>(), 200000);
    EXPECT_NEAR(e.x(), ref, 0.01 * ref);
  }
}

TEST(EmitterSamplerTest, BoxSamplingMatchesSumOfFaces) {
  // a box of half sizes (hx, hy, hz); without occlusion every face contributes.
  const Pose X = PoseFromXyzRpyDeg({0.3, 0.2, 1.2}, {15, 25, -40});
  const Eigen::Vector3d h(0.2, 0.15, 0.1);
  const Eigen::Vector3d p(0, 0, 0), n(0, 0, 1);
  double ref = 0;
  for (int axis = 0; axis < 3; ++axis)
    for (double sign : {1.0, -1.0}) {
      // face frame: z along the face normal, x/y along the other two axes.
      Eigen::Matrix3d r;
      const int a1 = (axis + 1) % 3, a2 = (axis + 2) % 3;
      r.col(0) = Eigen::Vector3d::Unit(a1);
      r.col(1) = Eigen::Vector3d::Unit(a2);
      r.col(2) = Eigen::Vector3d::Unit(axis);
      Pose face = Pose::Identity();
      face.linear() = r;
      face.translation() = sign * h[axis] * Eigen::Vector3d::Unit(axis);
      ref += RectangleIrradiance(X * face, h[a1], h[a2], 10.0, p, n);
    }
  const SceneDescription scene =
      SceneWith({MakeGeom(GeomShape::kBox, h, X), MakeGeom(GeomShape::kBox, h, X, 1)},
                Eigen::Vector3f::Constant(10));
  const EmitterSampler es(scene);
  ASSERT_EQ(es.size(), 1);  // the second box does not emit
  const Eigen::Vector3d e =
      EstimateIrradiance(es, {Pose::Identity()}, p.cast<float>(), n.cast<float>(), 200000);
  EXPECT_NEAR(e.x(), ref, 0.01 * ref);
  EXPECT_EQ(es.Pdf({Pose::Identity()}, 1, {0, 0, 0}, {0.3f, 0.2f, 1.1f}, {0, 0, 1}), 0.0f);
}

TEST(EmitterSamplerTest, CylinderAndCapsuleAreasAndPicking) {
  // two emitters of equal luminance: one is picked in proportion to its area.
  const SceneDescription scene = SceneWith(
      {MakeGeom(GeomShape::kCylinder, {0.1, 0.2, 0}, Pose::Identity()),
       MakeGeom(GeomShape::kCapsule, {0.1, 0.2, 0}, PoseFromXyzRpyDeg({3, 0, 0}, {0, 0, 0})),
       MakeGeom(GeomShape::kEllipsoid, {0.1, 0.2, 0.3}, Pose::Identity())},
      Eigen::Vector3f::Constant(1));
  const EmitterSampler es(scene);
  ASSERT_EQ(es.size(), 2);  // ellipsoids are not sampled
  const double a_cyl = 4 * std::numbers::pi * 0.1 * 0.2 + 2 * std::numbers::pi * 0.01;
  const double a_cap = 4 * std::numbers::pi * 0.1 * 0.2 + 4 * std::numbers::pi * 0.01;
  Rng rng(HashKeys(9, 9));
  int cyl = 0;
  const int count = 100000;
  for (int i = 0; i < count; ++i) {
    EmitterSample s;
    ASSERT_TRUE(
        es.Sample({Pose::Identity()}, {0, 5, 0}, rng.Uniform(), rng.Uniform(), rng.Uniform(), &s));
    // the sampled point lies on the surface.
    const Eigen::Vector3d q =
        s.p_W.cast<double>() - (s.geom == 0 ? Eigen::Vector3d(0, 0, 0) : Eigen::Vector3d(3, 0, 0));
    const double radial = std::hypot(q.x(), q.y());
    if (s.geom == 0) {
      ++cyl;
      EXPECT_TRUE(std::abs(radial - 0.1) < 1e-5 || std::abs(std::abs(q.z()) - 0.2) < 1e-5);
    } else {
      const double zc = std::clamp(q.z(), -0.2, 0.2);
      EXPECT_NEAR(std::hypot(radial, q.z() - zc), 0.1, 1e-5);
    }
  }
  EXPECT_NEAR(static_cast<double>(cyl) / count, a_cyl / (a_cyl + a_cap), 0.005);
}

}  // namespace
}  // namespace penumbra

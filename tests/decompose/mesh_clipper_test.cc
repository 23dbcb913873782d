// the plane cut: both sides are closed, outward-oriented solids whose volumes add up to the
// input's, for a cut through one loop (L), two loops (U posts) and a loop with a hole (torus
// cut through its axis plane gives two discs; cut across the ring gives an annulus).
#include "penumbra/decompose/mesh_clipper.h"

#include <gtest/gtest.h>

#include "penumbra/decompose/test_shapes.h"

namespace penumbra {
namespace {

void ExpectSplitsVolume(const SolidMesh& mesh, const CutPlane& plane, int expected_components) {
  const ClipResult clip = ClipMesh(mesh, plane, 1e-9);
  const double v = MeshVolume(mesh);
  int components = 0;
  double sum = 0;
  for (const SolidMesh* side : {&clip.below, &clip.above}) {
    for (const SolidMesh& c : ConnectedComponents(*side)) {
      EXPECT_NO_THROW(ValidateClosedMesh(c, "piece"));
      sum += MeshVolume(c);
      ++components;
    }
  }
  EXPECT_NEAR(sum, v, 1e-12 * std::max(1.0, v));
  EXPECT_EQ(components, expected_components);
}

TEST(MeshClipper, LCutInTwo) {
  CutPlane p;
  p.normal = Eigen::Vector3d::UnitX();
  p.offset = 0.55;
  ExpectSplitsVolume(MakeLShape(), p, 2);
}

TEST(MeshClipper, UPostsAreSeparateComponents) {
  CutPlane p;
  p.normal = Eigen::Vector3d::UnitY();
  p.offset = 0.5;
  ExpectSplitsVolume(MakeUShape(), p, 3);  // base, two posts
}

TEST(MeshClipper, TorusAcrossTheRingCapsAnAnnulus) {
  CutPlane p;
  p.normal = Eigen::Vector3d::UnitZ();
  p.offset = 0.01;
  ExpectSplitsVolume(MakeTorus(), p, 2);
  const ClipResult clip = ClipMesh(MakeTorus(), p, 1e-9);
  // the cap of the lower half is an annulus: area of ring minus hole, close to the
  // polygonal cross-section of the tube swept around
  double cap_area = 0;
  for (size_t t = 0; t < clip.below.triangles.size(); ++t)
    if (clip.below.IsCutFace(t)) {
      const auto& tri = clip.below.triangles[t];
      cap_area += 0.5 * (clip.below.vertices[tri[1]] - clip.below.vertices[tri[0]])
                            .cross(clip.below.vertices[tri[2]] - clip.below.vertices[tri[0]])
                            .norm();
    }
  const double half_width = std::sqrt(0.12 * 0.12 - 0.01 * 0.01);
  const double annulus = M_PI * (std::pow(0.35 + half_width, 2) - std::pow(0.35 - half_width, 2));
  EXPECT_NEAR(cap_area, annulus, 0.03 * annulus);
}

TEST(MeshClipper, TorusThroughTheAxisGivesTwoHalves) {
  CutPlane p;
  p.normal = Eigen::Vector3d(1, 1, 0).normalized();
  p.offset = 0.0;
  ExpectSplitsVolume(MakeTorus(), p, 2);
}

TEST(MeshClipper, PlaneThroughVerticesIsMovedOffThem) {
  CutPlane p;
  p.normal = Eigen::Vector3d::UnitX();
  p.offset = 0.4;  // the L's inner corner
  const ClipResult clip = ClipMesh(MakeLShape(), p, 1e-9);
  EXPECT_NE(clip.offset_used, 0.4);
  EXPECT_NEAR(clip.offset_used, 0.4, 1e-7);
  ExpectSplitsVolume(MakeLShape(), p, 2);
}

TEST(MeshClipper, PlaneMissingTheMeshKeepsItWhole) {
  CutPlane p;
  p.normal = Eigen::Vector3d::UnitZ();
  p.offset = 5;
  const ClipResult clip = ClipMesh(MakeBowl(), p, 1e-9);
  EXPECT_TRUE(clip.above.empty());
  EXPECT_EQ(clip.below.triangles.size(), MakeBowl().triangles.size());
}

}  // namespace
}  // namespace penumbra

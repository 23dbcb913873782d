// the convex hull is a pure function of the point set: facets with more than 3 vertices (a
// cylinder's caps, a box's sides) are triangulated the same way whatever the input order and
// wherever the hull library's nodes were allocated, so a decomposition gives the same parts in
// every process (before this, the torus gave 21 to 28 parts depending on what ran before it).
#include "penumbra/decompose/convex_hull.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <numbers>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/decompose/decomposition.h"
#include "penumbra/decompose/solid_mesh.h"
#include "penumbra/decompose/test_shapes.h"

namespace penumbra {
namespace {

// a cylinder's rim points: two 24-gons (each a facet of 24 vertices) and points inside
std::vector<Eigen::Vector3d> CylinderPoints() {
  std::vector<Eigen::Vector3d> p;
  for (int i = 0; i < 24; ++i) {
    const double a = 2 * std::numbers::pi * i / 24;
    p.emplace_back(0.3 * std::cos(a), 0.3 * std::sin(a), 0.0);
    p.emplace_back(0.3 * std::cos(a), 0.3 * std::sin(a), 0.5);
    p.emplace_back(0.1 * std::cos(a), 0.1 * std::sin(a), 0.25);
  }
  return p;
}

bool SameBits(const SolidMesh& a, const SolidMesh& b) {
  return a.vertices == b.vertices && a.triangles == b.triangles;
}

TEST(ConvexHull, FacetsAreTriangulatedTheSameWhateverTheInputOrderAndHeap) {
  const std::vector<Eigen::Vector3d> points = CylinderPoints();
  const SolidMesh first = ConvexHullOf(points);
  ASSERT_EQ(first.vertices.size(), 48u);  // the inner points are not extreme
  // a fan per cap (22 triangles each) and 2 per side quad
  EXPECT_EQ(first.triangles.size(), 2u * 22 + 2 * 24);
  const double expected = 0.5 * 0.5 * 24 * 0.3 * 0.3 * std::sin(2 * std::numbers::pi / 24);
  EXPECT_NEAR(MeshVolume(first), expected, 1e-12);
  Rng rng(7);
  std::vector<std::unique_ptr<std::vector<double>>> noise;
  for (int trial = 0; trial < 20; ++trial) {
    std::vector<Eigen::Vector3d> shuffled = points;
    for (size_t i = shuffled.size(); i > 1; --i)
      std::swap(shuffled[i - 1], shuffled[rng.NextU64() % i]);
    // other allocations in between: the library's nodes land elsewhere
    noise.push_back(std::make_unique<std::vector<double>>(1 + rng.NextU64() % 5000));
    EXPECT_TRUE(SameBits(ConvexHullOf(shuffled), first)) << "trial " << trial;
  }
}

TEST(ConvexHull, TheTorusDecomposesToTheSameBitsAfterOtherWork) {
  const SolidMesh torus = MakeTorus();
  DecompositionOptions options;
  options.concavity_threshold = 0.05;
  options.mcts_iterations = 6;
  options.search_samples = 120;
  const Decomposition a = DecomposeMesh(torus, options, "torus");
  // other work first: the bowl decomposed, the heap in another state
  DecompositionOptions bowl_options = options;
  bowl_options.max_parts = 64;
  const Decomposition bowl = DecomposeMesh(MakeBowl(), bowl_options, "bowl");
  ASSERT_GT(bowl.parts.size(), 1u);
  const Decomposition b = DecomposeMesh(torus, options, "torus");
  ASSERT_EQ(a.parts.size(), b.parts.size());
  EXPECT_EQ(a.cuts, b.cuts);
  for (size_t i = 0; i < a.parts.size(); ++i) {
    EXPECT_TRUE(SameBits(a.parts[i].hull, b.parts[i].hull)) << "part " << i;
    EXPECT_EQ(a.parts[i].concavity, b.parts[i].concavity) << "part " << i;
  }
}

}  // namespace
}  // namespace penumbra

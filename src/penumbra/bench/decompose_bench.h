#pragma once
// `penumbra bench decompose`: CoACD vs the plain convex hull vs CGAL's exact decomposition on
// the test shapes (decompose/test_shapes.h): parts, max concavity, how far the hulls stick out,
// hull volume over mesh volume, time (docs/collision.md). a benchmark, never a pass/fail test.

#include <string>
#include <vector>

#include "penumbra/decompose/decomposition.h"

namespace penumbra {

/// options of `penumbra bench decompose`.
struct BenchDecomposeOptions {
  std::vector<std::string> shapes = {"l", "u", "torus", "bowl"};
  bool exact = true;  ///< include CGAL's exact decomposition (slow)
  DecompositionOptions decomposition;
  int seed = 0;  ///< the search seed
};

/// runs the comparison and prints its table to stdout; returns 0.
/// @throws ConfigError for an unknown shape.
int BenchDecompose(const BenchDecomposeOptions& options);

}  // namespace penumbra

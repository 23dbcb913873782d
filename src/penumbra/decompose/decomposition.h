#pragma once
// convex decomposition of a closed triangle mesh into convex parts for collision (one MJCF
// convex mesh geom per part). three methods:
//   - coacd: approximate convex decomposition after Wei, Liu, Ling, Su, "Approximate Convex
//     Decomposition for 3D Meshes with Collision-Aware Concavity and Tree Search", SIGGRAPH
//     2022 (decompose/coacd.h): the mesh is cut by planes chosen by a Monte Carlo tree search
//     until every piece's collision-aware concavity (decompose/concavity.h) is under the
//     threshold, then neighbouring parts are merged while the merged part stays under it;
//   - hull: the convex hull of the whole mesh (one part);
//   - exact: CGAL's exact convex decomposition of a Nef polyhedron (decompose/
//     exact_decomposition.h; many parts, slow; for comparison).
// every result is a pure function of the mesh and the options: the search is seeded, nothing
// reads the clock, so the same input gives bit-identical parts.

#include <cstdint>
#include <string>
#include <vector>

#include "penumbra/decompose/concavity.h"
#include "penumbra/decompose/solid_mesh.h"

namespace penumbra {

/// how a mesh becomes collision geometry.
enum class DecompositionMethod { kCoacd, kHull, kExact };

/// "coacd", "hull", "exact".
const char* DecompositionMethodName(DecompositionMethod method);
/// parses a method name. @throws ConfigError("", 0, key, ...) listing the names.
DecompositionMethod ParseDecompositionMethod(const std::string& name, const std::string& key);

/// parameters of the decomposition (CoACD's names where it has them).
struct DecompositionOptions {
  DecompositionMethod method = DecompositionMethod::kCoacd;
  /// largest allowed concavity of a part, as a fraction of the largest extent of the mesh's
  /// bounding box (CoACD's -t 0.05 on its [-1, 1] normalisation is 0.025 here).
  double concavity_threshold = 0.025;
  /// most parts after merging (parts are merged beyond the threshold to get there).
  int max_parts = 32;
  /// upper bound on the number of cuts, so a pathological mesh ends (its remaining pieces are
  /// kept as they are and the result says so).
  int max_cuts = 128;
  int mcts_iterations = 60;    ///< tree search iterations per cut
  int mcts_depth = 3;          ///< cuts looked ahead per search path
  int planes_per_axis = 12;    ///< candidate planes per axis and node (3 axes)
  int rollout_planes = 3;      ///< planes tried per greedy rollout step
  int search_samples = 600;    ///< surface samples of the concavity inside the search
  bool merge = true;           ///< merge parts after cutting
  uint64_t seed = 0;           ///< seed of the search
  ConcavityOptions concavity;  ///< the measure of the final parts
  /// @throws ConfigError("", 0, "<field>", ...) for a value out of range.
  void ValidateOrThrow() const;
};

/// one convex part.
struct ConvexPart {
  SolidMesh hull;        ///< the part's convex hull (m), outward triangles
  double volume = 0;     ///< volume of the mesh material the part covers (m^3)
  double concavity = 0;  ///< concavity of that material against the hull (m)
};

/// a decomposition and what it measured.
struct Decomposition {
  DecompositionMethod method = DecompositionMethod::kCoacd;
  std::vector<ConvexPart> parts;
  double mesh_volume = 0;       ///< volume of the input (m^3)
  double extent = 0;            ///< largest bounding-box extent of the input (m)
  double max_concavity = 0;     ///< largest part concavity (m)
  int cuts = 0;                 ///< cuts made (coacd)
  bool hit_cut_limit = false;   ///< max_cuts ended the cutting before every piece was convex enough
  bool hit_part_limit = false;  ///< max_parts forced merges over the threshold
  /// max_concavity / extent: comparable with concavity_threshold.
  double relative_max_concavity() const { return extent > 0 ? max_concavity / extent : 0; }
  /// sum of the parts' hull volumes (m^3): an upper bound of the volume of their union.
  double HullVolumeSum() const;
};

/// a decomposition of `mesh` by `method` before any part: method, mesh_volume and extent set.
Decomposition StartDecomposition(DecompositionMethod method, const SolidMesh& mesh);

/// decomposes `mesh` (closed, outward oriented; see ValidateClosedMesh) with options.method.
/// @throws Error from ValidateClosedMesh (named `name`), ConfigError from ValidateOrThrow.
Decomposition DecomposeMesh(const SolidMesh& mesh, const DecompositionOptions& options,
                            const std::string& name = "mesh");

/// one part: the convex hull of the mesh, with its concavity.
Decomposition DecomposeHull(const SolidMesh& mesh, const DecompositionOptions& options);

}  // namespace penumbra

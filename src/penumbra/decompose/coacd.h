#pragma once
// CoACD: approximate convex decomposition after Wei, Liu, Ling, Su, "Approximate Convex
// Decomposition for 3D Meshes with Collision-Aware Concavity and Tree Search", ACM TOG 41(4)
// (SIGGRAPH 2022). the implementation (coacd.cc) follows the paper's three steps:
//   1. concavity: the collision-aware concavity of section 4 (decompose/concavity.h): the
//      larger of the sampled two-sided Hausdorff distance between a piece's surface and its
//      hull's surface, and the volume term R_v = k r(vol(H) - vol(S)), k = 0.3;
//   2. cutting (section 5): a piece over the threshold is cut by a plane into closed pieces
//      (decompose/mesh_clipper.h; the mesh is cut directly, no voxels). the plane is chosen by
//      a Monte Carlo tree search (UCB1, exploration constant 0.5): a node is a set of pieces, an
//      action cuts the node's most concave piece by one of its candidate planes, a path looks
//      `mcts_depth` cuts ahead, the simulation is a greedy rollout, the reward the drop of the
//      highest concavity (1 - cost / root cost). the best first plane is then refined by a
//      local search along its axis (3 halving steps);
//   3. merging (section 6): parts are merged pairwise, cheapest first, while the merged part's
//      concavity stays under the threshold, then further (over it) down to `max_parts`.
//
// where this differs from the paper (and from its reference implementation):
//   - candidate planes are `planes_per_axis` evenly spaced axis-aligned planes per axis across
//     the piece's bounds (the paper also cuts along the axes; it samples the offsets the
//     same way but has no PCA-aligned option here);
//   - the rollout tries `rollout_planes` random candidates per step and keeps the best (the
//     paper's rollout is greedy over all candidates: this is cheaper and seeded);
//   - inside the search (and to rank merge candidates) the concavity uses `search_samples`
//     surface samples; every part that is kept, and every merge that is accepted, is measured
//     with the full `concavity.samples`;
//   - merge candidates are pairs whose hull bounding boxes lie within the threshold of each
//     other (the paper merges parts that share a cut face);
//   - no manifold preprocessing: the input must already be a closed, outward 2-manifold
//     (ValidateClosedMesh), no hull simplification of the output.
// deterministic: candidate order and rollouts draw from Rng(HashKeys(seed, ...)), ties break by
// index, nothing runs concurrently, so the same mesh and options give bit-identical parts.

#include "penumbra/decompose/decomposition.h"
#include "penumbra/decompose/solid_mesh.h"

namespace penumbra {

/// the CoACD decomposition of `mesh` (closed, outward oriented, m) with `options` (the
/// threshold is a fraction of the mesh's largest bounding-box extent). the result's
/// hit_cut_limit / hit_part_limit say when max_cuts or max_parts ended the search early.
/// callers normally use DecomposeMesh, which validates the mesh and options first.
Decomposition DecomposeCoacd(const SolidMesh& mesh, const DecompositionOptions& options);

}  // namespace penumbra

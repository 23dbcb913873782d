#pragma once
// binned surface-area-heuristic BVH construction on the CPU (Wald, "On fast construction of
// SAH-based bounding volume hierarchies", IEEE Symposium on Interactive Ray Tracing 2007): 16
// bins per axis over the primitives' centroids, leaves of at most 4 primitives.

#include <cstdint>
#include <vector>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/bvh/bvh_types.h"

namespace penumbra::cuda {

/// BuildBvh builds over its pool from this many primitives on (fewer: on the calling thread).
constexpr int kParallelBuildMinPrims = 16384;

/// an axis-aligned box of one primitive.
struct PrimBox {
  float lo[3], hi[3];
};

/// builds a BVH over `boxes`: appends its nodes to *nodes (root first, children of an inner
/// node adjacent; node indices relative to the first appended node) and the primitive order to
/// *prim_index (leaf ranges index *prim_index from `prim_base`'s first appended element; each
/// element is `prim_base` + a box index). an empty `boxes` gives one empty leaf with an empty
/// box. `pool` (may be null): with at least kParallelBuildMinPrims boxes and two threads, the
/// splits near the root are made on the calling thread and the subtrees below them are built
/// over the pool, then laid out as the one-thread build lays them out: the same nodes and
/// order, bit for bit, with any pool (no unordered containers, no shared counters).
void BuildBvh(const std::vector<PrimBox>& boxes, int32_t prim_base, std::vector<BvhNode>* nodes,
              std::vector<int32_t>* prim_index, ThreadPool* pool = nullptr);

/// the traversal's form of one BVH that BuildBvh wrote (`nodes`: its nodes alone, root first):
/// its inner nodes appended to *wide in their order in `nodes` (the root first, if inner),
/// each with its children's boxes and references (BvhWideNode), and *blas's root box and
/// reference; blas->node_offset is wide's size before the call, blas->num_nodes the count
/// appended. the traversal over it visits the same nodes in the same order as over `nodes`.
void WidenBvh(const std::vector<BvhNode>& nodes, std::vector<BvhWideNode>* wide, Blas* blas);

}  // namespace penumbra::cuda

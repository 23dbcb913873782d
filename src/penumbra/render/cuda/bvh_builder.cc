#include "penumbra/render/cuda/bvh_builder.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace penumbra::cuda {
namespace {

constexpr int kBins = 16;
constexpr int kMaxLeaf = 4;
constexpr int kMaxDepth = 48;  // below the traversal's stack (kMaxBvhDepth)

struct Box {
  float lo[3] = {std::numeric_limits<float>::infinity(), std::numeric_limits<float>::infinity(),
                 std::numeric_limits<float>::infinity()};
  float hi[3] = {-std::numeric_limits<float>::infinity(), -std::numeric_limits<float>::infinity(),
                 -std::numeric_limits<float>::infinity()};
  void Grow(const float l[3], const float h[3]) {
    for (int a = 0; a < 3; ++a) lo[a] = std::min(lo[a], l[a]), hi[a] = std::max(hi[a], h[a]);
  }
  float Area() const {
    if (!(hi[0] >= lo[0])) return 0;
    const float x = hi[0] - lo[0], y = hi[1] - lo[1], z = hi[2] - lo[2];
    return x * y + y * z + z * x;
  }
};

struct Builder {
  const std::vector<PrimBox>& boxes;
  std::vector<BvhNode>& nodes;  // this BVH's nodes only
  std::vector<int32_t>& order;  // box indices

  float Centroid(int i, int a) const { return 0.5f * (boxes[i].lo[a] + boxes[i].hi[a]); }

  void Build(int node, int begin, int end, int depth) {
    Box box, cbox;
    for (int k = begin; k < end; ++k) {
      const PrimBox& b = boxes[order[k]];
      box.Grow(b.lo, b.hi);
      float c[3] = {Centroid(order[k], 0), Centroid(order[k], 1), Centroid(order[k], 2)};
      cbox.Grow(c, c);
    }
    BvhNode& n = nodes[node];
    for (int a = 0; a < 3; ++a) n.lo[a] = box.lo[a], n.hi[a] = box.hi[a];
    const int count = end - begin;
    auto make_leaf = [&] {
      nodes[node].first = begin;
      nodes[node].count = count;
    };
    if (count <= kMaxLeaf || depth >= kMaxDepth) return make_leaf();
    // best binned split over the three axes
    int best_axis = -1, best_bin = 0;
    float best_cost = std::numeric_limits<float>::infinity();
    for (int a = 0; a < 3; ++a) {
      const float extent = cbox.hi[a] - cbox.lo[a];
      if (!(extent > 0)) continue;
      Box bins[kBins];
      int counts[kBins] = {};
      const float scale = kBins / extent;
      for (int k = begin; k < end; ++k) {
        const int b =
            std::min(kBins - 1, static_cast<int>((Centroid(order[k], a) - cbox.lo[a]) * scale));
        bins[b].Grow(boxes[order[k]].lo, boxes[order[k]].hi);
        ++counts[b];
      }
      float right_area[kBins];
      int right_count[kBins];
      Box acc;
      int cnt = 0;
      for (int b = kBins - 1; b > 0; --b) {
        acc.Grow(bins[b].lo, bins[b].hi);
        cnt += counts[b];
        right_area[b] = acc.Area();
        right_count[b] = cnt;
      }
      Box left;
      int lcnt = 0;
      for (int b = 0; b < kBins - 1; ++b) {
        left.Grow(bins[b].lo, bins[b].hi);
        lcnt += counts[b];
        if (lcnt == 0 || right_count[b + 1] == 0) continue;
        const float cost = lcnt * left.Area() + right_count[b + 1] * right_area[b + 1];
        if (cost < best_cost) best_cost = cost, best_axis = a, best_bin = b;
      }
    }
    int mid;
    if (best_axis < 0) {
      // every centroid in one point: split in the middle of the list
      mid = begin + count / 2;
    } else {
      const float leaf_cost = count * box.Area();
      if (count <= 2 * kMaxLeaf && !(best_cost < leaf_cost)) return make_leaf();
      const float scale = kBins / (cbox.hi[best_axis] - cbox.lo[best_axis]);
      const float lo = cbox.lo[best_axis];
      auto* first = order.data() + begin;
      auto* last = order.data() + end;
      auto* m = std::stable_partition(first, last, [&](int32_t i) {
        return std::min(kBins - 1, static_cast<int>((Centroid(i, best_axis) - lo) * scale)) <=
               best_bin;
      });
      mid = static_cast<int>(m - order.data());
      if (mid == begin || mid == end) mid = begin + count / 2;
    }
    const int left = static_cast<int>(nodes.size());
    nodes.emplace_back();
    nodes.emplace_back();
    nodes[node].first = left;
    nodes[node].count = 0;
    Build(left, begin, mid, depth + 1);
    Build(left + 1, mid, end, depth + 1);
  }
};

}  // namespace

void BuildBvh(const std::vector<PrimBox>& boxes, int32_t prim_base, std::vector<BvhNode>* nodes,
              std::vector<int32_t>* prim_index) {
  std::vector<BvhNode> local(1);
  std::vector<int32_t> order(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) order[i] = static_cast<int32_t>(i);
  if (boxes.empty()) {
    for (int a = 0; a < 3; ++a) local[0].lo[a] = 1, local[0].hi[a] = -1;
    local[0].first = 0;
    local[0].count = 0;
  } else {
    Builder b{boxes, local, order};
    b.Build(0, 0, static_cast<int>(boxes.size()), 0);
  }
  // leaves index prim_index from its current end
  const int32_t leaf_base = static_cast<int32_t>(prim_index->size());
  for (BvhNode& n : local)
    if (n.count > 0) n.first += leaf_base;
  for (int32_t i : order) prim_index->push_back(prim_base + i);
  nodes->insert(nodes->end(), local.begin(), local.end());
}

void WidenBvh(const std::vector<BvhNode>& nodes, std::vector<BvhWideNode>* wide, Blas* blas) {
  // inner nodes: count 0 and children after themselves (an empty BVH's root leaf has first 0)
  auto inner = [&](size_t i) { return nodes[i].count == 0 && nodes[i].first > 0; };
  std::vector<int32_t> wide_index(nodes.size(), -1);
  int32_t next = 0;
  for (size_t i = 0; i < nodes.size(); ++i)
    if (inner(i)) wide_index[i] = next++;
  blas->node_offset = static_cast<int32_t>(wide->size());
  blas->num_nodes = next;
  if (nodes.empty()) {
    blas->root_first = 0, blas->root_count = 0;
    return;
  }
  for (int a = 0; a < 3; ++a) blas->lo[a] = nodes[0].lo[a], blas->hi[a] = nodes[0].hi[a];
  blas->root_first = inner(0) ? 0 : nodes[0].first;
  blas->root_count = inner(0) ? -1 : nodes[0].count;
  for (size_t i = 0; i < nodes.size(); ++i) {
    if (!inner(i)) continue;
    BvhWideNode w;
    for (int c = 0; c < 2; ++c) {
      const size_t k = static_cast<size_t>(nodes[i].first) + c;
      const BvhNode& child = nodes[k];
      for (int a = 0; a < 3; ++a) w.box[c][a] = child.lo[a], w.box[c][3 + a] = child.hi[a];
      w.first[c] = inner(k) ? wide_index[k] : child.first;
      w.count[c] = inner(k) ? -1 : child.count;
    }
    wide->push_back(w);
  }
}

}  // namespace penumbra::cuda

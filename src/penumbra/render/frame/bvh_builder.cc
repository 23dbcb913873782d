#include "penumbra/render/frame/bvh_builder.h"

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

  // the box of [begin, end) (*box) and where it splits: the best binned SAH split with
  // order[begin, end) partitioned at the returned index, or -1 for a leaf.
  int Split(int begin, int end, int depth, Box* box_out) {
    Box box, cbox;
    for (int k = begin; k < end; ++k) {
      const PrimBox& b = boxes[order[k]];
      box.Grow(b.lo, b.hi);
      float c[3] = {Centroid(order[k], 0), Centroid(order[k], 1), Centroid(order[k], 2)};
      cbox.Grow(c, c);
    }
    *box_out = box;
    const int count = end - begin;
    if (count <= kMaxLeaf || depth >= kMaxDepth) return -1;
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
    // every centroid in one point: split in the middle of the list
    if (best_axis < 0) return begin + count / 2;
    const float leaf_cost = count * box.Area();
    if (count <= 2 * kMaxLeaf && !(best_cost < leaf_cost)) return -1;
    const float scale = kBins / (cbox.hi[best_axis] - cbox.lo[best_axis]);
    const float lo = cbox.lo[best_axis];
    auto* first = order.data() + begin;
    auto* last = order.data() + end;
    auto* m = std::stable_partition(first, last, [&](int32_t i) {
      return std::min(kBins - 1, static_cast<int>((Centroid(i, best_axis) - lo) * scale)) <=
             best_bin;
    });
    const int mid = static_cast<int>(m - order.data());
    return mid == begin || mid == end ? begin + count / 2 : mid;
  }

  // nodes[node] over [begin, end) and its subtree: each inner node's two children appended
  // together, then the left child's subtree, then the right one's.
  void Build(int node, int begin, int end, int depth) {
    Box box;
    const int mid = Split(begin, end, depth, &box);
    BvhNode& n = nodes[node];
    for (int a = 0; a < 3; ++a) n.lo[a] = box.lo[a], n.hi[a] = box.hi[a];
    if (mid < 0) {
      n.first = begin;
      n.count = end - begin;
      return;
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

// the parallel build: the splits above subtrees of at most `task_prims` primitives made on the
// calling thread (Plan), those subtrees built over the pool into nodes of their own, then every
// node written where the serial Builder::Build puts it (Emit), so the BVH is the same bits.
struct ParallelBuild {
  Builder serial;
  int task_prims;
  struct Top {
    Box box;
    int begin = 0, end = 0, depth = 0, mid = -1;
    int left = -1, right = -1;  // tops of an inner node's children
    int task = -1;              // subtree built by a task
  };
  std::vector<Top> tops;
  struct Task {
    int begin, end, depth;
    std::vector<BvhNode> nodes;
  };
  std::vector<Task> tasks;

  int Plan(int begin, int end, int depth) {
    const int t = static_cast<int>(tops.size());
    tops.emplace_back();
    tops[t].begin = begin, tops[t].end = end, tops[t].depth = depth;
    if (end - begin <= task_prims) {
      tops[t].task = static_cast<int>(tasks.size());
      tasks.push_back(Task{begin, end, depth, {}});
      return t;
    }
    Box box;
    const int mid = serial.Split(begin, end, depth, &box);
    tops[t].box = box;
    tops[t].mid = mid;
    if (mid < 0) return t;
    const int left = Plan(begin, mid, depth + 1);
    const int right = Plan(mid, end, depth + 1);
    tops[t].left = left, tops[t].right = right;
    return t;
  }

  void Emit(int t, int node) {
    const Top& top = tops[t];
    if (top.task >= 0) {
      // the task's nodes after its root, its inner nodes' children moved by where they land
      const std::vector<BvhNode>& local = tasks[top.task].nodes;
      const int32_t shift = static_cast<int32_t>(serial.nodes.size()) - 1;
      auto moved = [&](BvhNode n) {
        if (n.count == 0 && n.first > 0) n.first += shift;
        return n;
      };
      serial.nodes[node] = moved(local[0]);
      for (size_t k = 1; k < local.size(); ++k) serial.nodes.push_back(moved(local[k]));
      return;
    }
    BvhNode& n = serial.nodes[node];
    for (int a = 0; a < 3; ++a) n.lo[a] = top.box.lo[a], n.hi[a] = top.box.hi[a];
    if (top.mid < 0) {
      n.first = top.begin;
      n.count = top.end - top.begin;
      return;
    }
    const int left = static_cast<int>(serial.nodes.size());
    serial.nodes.emplace_back();
    serial.nodes.emplace_back();
    serial.nodes[node].first = left;
    serial.nodes[node].count = 0;
    Emit(top.left, left);
    Emit(top.right, left + 1);
  }
};

}  // namespace

void BuildBvh(const std::vector<PrimBox>& boxes, int32_t prim_base, std::vector<BvhNode>* nodes,
              std::vector<int32_t>* prim_index, ThreadPool* pool) {
  std::vector<BvhNode> local(1);
  std::vector<int32_t> order(boxes.size());
  for (size_t i = 0; i < boxes.size(); ++i) order[i] = static_cast<int32_t>(i);
  const int num = static_cast<int>(boxes.size());
  if (boxes.empty()) {
    for (int a = 0; a < 3; ++a) local[0].lo[a] = 1, local[0].hi[a] = -1;
    local[0].first = 0;
    local[0].count = 0;
  } else if (pool == nullptr || pool->num_threads() < 2 || num < kParallelBuildMinPrims) {
    Builder b{boxes, local, order};
    b.Build(0, 0, num, 0);
  } else {
    // about four subtrees a thread, so that uneven ones even out
    ParallelBuild p{Builder{boxes, local, order},
                    std::max(kParallelBuildMinPrims / 4, num / (4 * pool->num_threads())),
                    {},
                    {}};
    p.Plan(0, num, 0);
    pool->ParallelFor(static_cast<int64_t>(p.tasks.size()), [&](int64_t k) {
      ParallelBuild::Task& t = p.tasks[k];
      t.nodes.resize(1);
      Builder b{boxes, t.nodes, order};
      b.Build(0, t.begin, t.end, t.depth);
    });
    p.Emit(0, 0);
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

// CoACD (Wei, Liu, Ling, Su, SIGGRAPH 2022), as described in the paper:
//   1. every piece whose collision-aware concavity is over the threshold is cut by a plane;
//   2. the plane is chosen by a Monte Carlo tree search over axis-aligned candidate planes:
//      a node is a set of pieces, an action cuts the node's most concave piece, a path looks
//      mcts_depth cuts ahead (expansion, then a greedy rollout), and its reward is the drop of
//      the highest concavity; UCB1 balances exploring and exploiting;
//   3. the best first plane is refined by a local search along its axis;
//   4. the parts are merged pairwise, cheapest first, while the merged part stays under the
//      threshold (and further while there are more than max_parts).
// deterministic: candidate order and rollouts draw from Rng(HashKeys(seed, ...)), ties break
// by index, and nothing runs concurrently.
#include "penumbra/decompose/coacd.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <limits>
#include <map>
#include <memory>
#include <tuple>
#include <utility>

#include "penumbra/core/rng.h"
#include "penumbra/decompose/convex_hull.h"
#include "penumbra/decompose/decomposition.h"
#include "penumbra/decompose/mesh_clipper.h"

namespace penumbra {
namespace {

struct Piece {
  SolidMesh mesh;
  SolidMesh hull;
  double volume = 0;
  double concavity = 0;  // m
};
using PiecePtr = std::shared_ptr<const Piece>;

class Coacd {
 public:
  Coacd(const DecompositionOptions& options, double extent)
      : options_(options),
        extent_(extent),
        threshold_(options.concavity_threshold * extent),
        snap_(1e-9 * extent) {
    search_concavity_ = options.concavity;
    search_concavity_.samples = options.search_samples;
  }

  Decomposition Run(const SolidMesh& mesh);

 private:
  struct Node {
    std::vector<PiecePtr> pieces;
    double cost = 0;  // highest concavity of the pieces (m)
    int depth = 0;
    Node* parent = nullptr;
    CutPlane plane;  // the cut that made this node from its parent
    std::vector<CutPlane> untried;
    std::vector<std::unique_ptr<Node>> children;
    int visits = 0;
    double reward = 0;  // sum of rewards
  };

  PiecePtr MakePiece(SolidMesh mesh, const ConcavityOptions& measure) const {
    auto piece = std::make_shared<Piece>();
    piece->hull = CanonicalMesh(ConvexHullOf(mesh.vertices));
    piece->volume = MeshVolume(mesh);
    piece->mesh = std::move(mesh);
    piece->concavity = Concavity(piece->mesh, piece->volume, piece->hull, measure).value();
    return piece;
  }
  // pieces with no volume (slivers from a cut along a face) are dropped
  bool Solid(const SolidMesh& mesh) const {
    return mesh.triangles.size() >= 4 && MeshVolume(mesh) > 1e-12 * extent_ * extent_ * extent_;
  }
  // cuts `piece` by `plane`; the pieces of both sides, measured with `measure`
  std::vector<PiecePtr> Cut(const Piece& piece, const CutPlane& plane,
                            const ConcavityOptions& measure, double* offset_used = nullptr) const {
    ClipResult clip = ClipMesh(piece.mesh, plane, snap_);
    if (offset_used) *offset_used = clip.offset_used;
    std::vector<PiecePtr> out;
    for (SolidMesh* side : {&clip.below, &clip.above}) {
      for (SolidMesh& component : ConnectedComponents(*side))
        if (Solid(component)) out.push_back(MakePiece(std::move(component), measure));
    }
    return out;
  }
  static size_t Worst(const std::vector<PiecePtr>& pieces) {
    size_t worst = 0;
    for (size_t i = 1; i < pieces.size(); ++i)
      if (pieces[i]->concavity > pieces[worst]->concavity) worst = i;
    return worst;
  }
  static double Cost(const std::vector<PiecePtr>& pieces) {
    double cost = 0;
    for (const PiecePtr& p : pieces) cost = std::max(cost, p->concavity);
    return cost;
  }
  // the candidate planes of a piece: planes_per_axis evenly spaced planes across its bounds
  // on each axis
  std::vector<CutPlane> Candidates(const Piece& piece) const {
    const auto bounds = MeshBounds(piece.mesh);
    std::vector<CutPlane> planes;
    const int m = options_.planes_per_axis;
    for (int axis = 0; axis < 3; ++axis) {
      const double lo = bounds[0][axis], hi = bounds[1][axis];
      if (!(hi - lo > 4 * snap_)) continue;
      for (int i = 0; i < m; ++i) {
        CutPlane plane;
        plane.normal = Eigen::Vector3d::Unit(axis);
        plane.offset = lo + (hi - lo) * (i + 1.0) / (m + 1.0);
        planes.push_back(plane);
      }
    }
    return planes;
  }
  // a cut with the search measure, memoised for the current search: the tree and its
  // rollouts cut the same piece by the same candidate plane many times. the key holds the
  // piece itself (not only its address) so that a freed piece's address is never reused.
  const std::vector<PiecePtr>& SearchCut(const PiecePtr& piece, const CutPlane& plane) const {
    const MemoKey key{piece.get(), plane.normal.x(), plane.normal.y(), plane.normal.z(),
                      plane.offset};
    auto it = memo_.find(key);
    if (it == memo_.end())
      it = memo_.emplace(key, std::make_pair(piece, Cut(*piece, plane, search_concavity_))).first;
    return it->second.second;
  }
  // state after cutting the most concave piece of `pieces` by `plane` (search measure)
  std::vector<PiecePtr> Apply(const std::vector<PiecePtr>& pieces, const CutPlane& plane) const {
    const size_t w = Worst(pieces);
    std::vector<PiecePtr> next;
    for (size_t i = 0; i < pieces.size(); ++i)
      if (i != w) next.push_back(pieces[i]);
    for (const PiecePtr& p : SearchCut(pieces[w], plane)) next.push_back(p);
    return next;
  }
  std::unique_ptr<Node> MakeNode(std::vector<PiecePtr> pieces, int depth, Node* parent,
                                 const CutPlane& plane, Rng& rng) const {
    auto node = std::make_unique<Node>();
    node->pieces = std::move(pieces);
    node->cost = Cost(node->pieces);
    node->depth = depth;
    node->parent = parent;
    node->plane = plane;
    if (depth < options_.mcts_depth && node->cost > threshold_ && !node->pieces.empty()) {
      node->untried = Candidates(*node->pieces[Worst(node->pieces)]);
      // seeded shuffle: the order in which untried planes are expanded
      for (size_t i = node->untried.size(); i > 1; --i)
        std::swap(node->untried[i - 1], node->untried[rng.NextU64() % i]);
    }
    return node;
  }
  // greedy rollout from `pieces` at `depth` to mcts_depth: the lowest cost reached
  double Rollout(std::vector<PiecePtr> pieces, int depth, Rng& rng) const {
    double cost = Cost(pieces);
    while (depth < options_.mcts_depth && cost > threshold_ && !pieces.empty()) {
      const std::vector<CutPlane> planes = Candidates(*pieces[Worst(pieces)]);
      if (planes.empty()) break;
      std::vector<PiecePtr> best;
      double best_cost = std::numeric_limits<double>::infinity();
      for (int k = 0; k < options_.rollout_planes; ++k) {
        const CutPlane& plane = planes[rng.NextU64() % planes.size()];
        std::vector<PiecePtr> next = Apply(pieces, plane);
        const double c = Cost(next);
        if (c < best_cost) {
          best_cost = c;
          best = std::move(next);
        }
      }
      pieces = std::move(best);
      cost = std::min(cost, best_cost);
      ++depth;
    }
    return cost;
  }
  CutPlane Search(const PiecePtr& piece, uint64_t cut_index) const;
  CutPlane Refine(const PiecePtr& piece, const CutPlane& plane) const;
  std::vector<ConvexPart> Merge(std::vector<PiecePtr> parts, Decomposition* out) const;

  using MemoKey = std::tuple<const Piece*, double, double, double, double>;
  mutable std::map<MemoKey, std::pair<PiecePtr, std::vector<PiecePtr>>> memo_;
  const DecompositionOptions& options_;
  double extent_;
  double threshold_;
  double snap_;
  ConcavityOptions search_concavity_;
};

CutPlane Coacd::Search(const PiecePtr& piece, uint64_t cut_index) const {
  memo_.clear();
  Rng rng(HashKeys(options_.seed, 0x436f414344ULL, cut_index));
  std::unique_ptr<Node> root = MakeNode({piece}, 0, nullptr, CutPlane{}, rng);
  const double root_cost = std::max(root->cost, 1e-300);
  constexpr double kExplore = 0.5;
  for (int it = 0; it < options_.mcts_iterations; ++it) {
    // selection: descend by UCB1 through fully expanded nodes
    Node* node = root.get();
    while (node->untried.empty() && !node->children.empty()) {
      Node* best = nullptr;
      double best_score = -std::numeric_limits<double>::infinity();
      for (const auto& child : node->children) {
        const double score = child->reward / child->visits +
                             kExplore * std::sqrt(std::log(node->visits) / child->visits);
        if (score > best_score) {
          best_score = score;
          best = child.get();
        }
      }
      node = best;
    }
    // expansion
    if (!node->untried.empty()) {
      const CutPlane plane = node->untried.back();
      node->untried.pop_back();
      node->children.push_back(
          MakeNode(Apply(node->pieces, plane), node->depth + 1, node, plane, rng));
      node = node->children.back().get();
    }
    // simulation and backpropagation
    const double cost = Rollout(node->pieces, node->depth, rng);
    const double reward = 1.0 - cost / root_cost;
    for (Node* n = node; n; n = n->parent) {
      ++n->visits;
      n->reward += reward;
    }
    if (root->untried.empty() && root->children.empty()) break;  // nothing to cut
  }
  // the first cut of the best path: the root child with the best mean reward
  const Node* best = nullptr;
  for (const auto& child : root->children)
    if (!best || child->reward / child->visits > best->reward / best->visits) best = child.get();
  if (!best) {
    // no candidate (a piece thinner than the snap distance on every axis): halve it
    const auto bounds = MeshBounds(piece->mesh);
    int axis = 0;
    (bounds[1] - bounds[0]).maxCoeff(&axis);
    CutPlane plane;
    plane.normal = Eigen::Vector3d::Unit(axis);
    plane.offset = 0.5 * (bounds[0][axis] + bounds[1][axis]);
    return plane;
  }
  return Refine(piece, best->plane);
}

// local search along the plane's axis: halving steps around the chosen offset, keeping a move
// when it lowers the cost of the one cut
CutPlane Coacd::Refine(const PiecePtr& piece, const CutPlane& plane) const {
  const auto bounds = MeshBounds(piece->mesh);
  int axis = 0;
  plane.normal.cwiseAbs().maxCoeff(&axis);
  const double lo = bounds[0][axis], hi = bounds[1][axis];
  double step = (hi - lo) / (options_.planes_per_axis + 1.0) / 2.0;
  CutPlane best = plane;
  double best_cost = Cost(SearchCut(piece, plane));
  for (int round = 0; round < 3; ++round) {
    for (double sign : {-1.0, 1.0}) {
      CutPlane trial = best;
      trial.offset = best.offset + sign * step;
      if (!(trial.offset > lo + 2 * snap_ && trial.offset < hi - 2 * snap_)) continue;
      const double c = Cost(SearchCut(piece, trial));
      if (c < best_cost) {
        best_cost = c;
        best = trial;
        break;
      }
    }
    step /= 2;
  }
  return best;
}

std::vector<ConvexPart> Coacd::Merge(std::vector<PiecePtr> parts, Decomposition* out) const {
  struct Part {
    SolidMesh mesh;  // the pieces' meshes concatenated
    SolidMesh hull;
    double volume = 0;
    double concavity = 0;
    std::array<Eigen::Vector3d, 2> bounds;
  };
  std::vector<Part> current;
  for (const PiecePtr& p : parts)
    current.push_back({p->mesh, p->hull, p->volume, p->concavity, MeshBounds(p->hull)});
  const double touch = threshold_;
  auto adjacent = [&](const Part& a, const Part& b) {
    for (int k = 0; k < 3; ++k)
      if (a.bounds[0][k] > b.bounds[1][k] + touch || b.bounds[0][k] > a.bounds[1][k] + touch)
        return false;
    return true;
  };
  auto merged_of = [&](const Part& a, const Part& b, const ConcavityOptions& measure) {
    Part m;
    m.mesh = ConcatenateMeshes({&a.mesh, &b.mesh});
    std::vector<Eigen::Vector3d> points = a.hull.vertices;
    points.insert(points.end(), b.hull.vertices.begin(), b.hull.vertices.end());
    m.hull = CanonicalMesh(ConvexHullOf(points));
    m.volume = a.volume + b.volume;
    m.concavity = Concavity(m.mesh, m.volume, m.hull, measure).value();
    m.bounds = MeshBounds(m.hull);
    return m;
  };
  // ids stay stable while parts merge, so costs computed once are reused
  std::vector<int> ids(current.size());
  for (size_t i = 0; i < ids.size(); ++i) ids[i] = static_cast<int>(i);
  int next_id = static_cast<int>(current.size());
  std::map<std::pair<int, int>, double> cost_cache;
  auto pair_cost = [&](size_t i, size_t j) {
    const std::pair<int, int> key{ids[i], ids[j]};
    auto it = cost_cache.find(key);
    if (it != cost_cache.end()) return it->second;
    // ranked with the search measure (fewer samples); a merge is accepted on the full one
    const double c = merged_of(current[i], current[j], search_concavity_).concavity;
    cost_cache.emplace(key, c);
    return c;
  };
  auto merge_pass = [&](bool over_threshold) {
    while (current.size() > 1) {
      if (over_threshold && static_cast<int>(current.size()) <= options_.max_parts) return;
      size_t bi = 0, bj = 0;
      double best = std::numeric_limits<double>::infinity();
      for (size_t i = 0; i < current.size(); ++i)
        for (size_t j = i + 1; j < current.size(); ++j) {
          if (!over_threshold && !adjacent(current[i], current[j])) continue;
          const double c = pair_cost(i, j);
          if (c < best) {
            best = c;
            bi = i;
            bj = j;
          }
        }
      if (!(best < std::numeric_limits<double>::infinity())) return;
      if (!over_threshold && best > threshold_) return;
      Part m = merged_of(current[bi], current[bj], options_.concavity);
      if (!over_threshold && m.concavity > threshold_) {
        // the full measure rejects what the search measure accepted: never try this pair again
        cost_cache[{ids[bi], ids[bj]}] = std::numeric_limits<double>::infinity();
        continue;
      }
      if (over_threshold && m.concavity > threshold_) out->hit_part_limit = true;
      current.erase(current.begin() + bj);
      ids.erase(ids.begin() + bj);
      current[bi] = std::move(m);
      ids[bi] = next_id++;
    }
  };
  if (options_.merge) merge_pass(false);
  merge_pass(true);
  std::vector<ConvexPart> result;
  for (Part& p : current) result.push_back({std::move(p.hull), p.volume, p.concavity});
  return result;
}

Decomposition Coacd::Run(const SolidMesh& mesh) {
  Decomposition out = StartDecomposition(DecompositionMethod::kCoacd, mesh);
  std::deque<PiecePtr> queue;
  for (SolidMesh& component : ConnectedComponents(mesh))
    queue.push_back(MakePiece(std::move(component), options_.concavity));
  std::vector<PiecePtr> done;
  while (!queue.empty()) {
    PiecePtr piece = std::move(queue.front());
    queue.pop_front();
    if (piece->concavity <= threshold_) {
      done.push_back(std::move(piece));
      continue;
    }
    if (out.cuts >= options_.max_cuts) {
      out.hit_cut_limit = true;
      done.push_back(std::move(piece));
      continue;
    }
    const CutPlane plane = Search(piece, static_cast<uint64_t>(out.cuts));
    std::vector<PiecePtr> pieces = Cut(*piece, plane, options_.concavity);
    ++out.cuts;
    if (pieces.size() <= 1) {
      // the cut removed nothing (or only a sliver): keep the piece as it is
      out.hit_cut_limit = true;
      done.push_back(std::move(piece));
      continue;
    }
    for (PiecePtr& p : pieces) queue.push_back(std::move(p));
  }
  out.parts = Merge(std::move(done), &out);
  for (const ConvexPart& part : out.parts)
    out.max_concavity = std::max(out.max_concavity, part.concavity);
  return out;
}

}  // namespace

Decomposition DecomposeCoacd(const SolidMesh& mesh, const DecompositionOptions& options) {
  const auto bounds = MeshBounds(mesh);
  const double extent = (bounds[1] - bounds[0]).maxCoeff();
  Coacd coacd(options, extent);
  return coacd.Run(mesh);
}

}  // namespace penumbra

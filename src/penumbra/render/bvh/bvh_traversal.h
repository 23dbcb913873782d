#pragma once
// closest-hit and occlusion traversal of the two-level BVH of bvh_types.h, written once as
// PB_HOST_DEVICE functions: BvhRayQuery runs them on the CPU (and the tests check them there
// against Embree), the CUDA kernels (cuda_kernels.cu) on the GPU.
//
// top level: a BVH over the instances' world boxes (SceneView::tlas), walked by closest hits
// nearer child first (the hit of the flat index-order loop, the lower instance winning a tie:
// TraceClosest) and by occlusion rays in any order, down to the instances whose boxes they
// enter; without it (or with the switches off) every instance in index order. the ray is taken
// to the instance frame in float (as Embree's instancing). bottom level: a stack traversal over
// nodes that hold their children's boxes (BvhWideNode: one 64-byte load a visit), the nearer child
// first (occlusion: any order), slab tests of Williams et al., "An efficient and robust ray-box
// intersection algorithm" (JGT 2005). triangles: Moller and Trumbore, "Fast, minimum storage
// ray/triangle intersection" (JGT 1997), in float; analytic shapes: IntersectAnalyticArrays
// (render/geometry/analytic_shapes.h) in double in the geom frame, as RayScene.

#include <cmath>

#include "penumbra/core/host_device.h"
#include "penumbra/render/bvh/bvh_types.h"
#include "penumbra/render/geometry/analytic_shape_math.h"

namespace penumbra::cuda {

/// deepest BLAS the traversal's stack holds (the builder keeps trees shallower).
constexpr int kMaxBvhDepth = 64;

/// a child TraverseWideBvh has still to visit: its reference (BvhWideNode::first and count) and
/// its box's entry distance t. 16 bytes, so one vector store a push and one vector load a pop on
/// the GPU.
struct alignas(16) BvhPending {
  int first, count;
  float t;
  int unused;
};

/// a traversal stack of kEntries entries in the thread's own array (local memory on the GPU).
/// a stack policy is default-constructible (one per traversal, empty), names kCapacity and has
/// Put(i, e) and Get(i) for entry i in [0, kCapacity) (TraverseWideBvh drops a child it cannot
/// push: the builders keep trees shallower); the traversal pushes and pops through it, so a
/// policy that keeps the entries elsewhere visits the same nodes in the same order and gives the
/// same hits, bit for bit (the tests count the stack's depth through one). a top of 8 entries in
/// shared memory was slower on an H100 (docs/journal/2026-11-26-gpu-speed.md,
/// "The traversal's local memory").
template <int kEntries>
struct ArrayBvhStack {
  static constexpr int kCapacity = kEntries;
  BvhPending entries[kEntries];
  PB_HOST_DEVICE void Put(int i, const BvhPending& e) { entries[i] = e; }
  PB_HOST_DEVICE BvhPending Get(int i) const { return entries[i]; }
};

/// TraverseWideBvh's stack for a BLAS: kMaxBvhDepth entries.
using LocalBvhStack = ArrayBvhStack<kMaxBvhDepth>;

/// deepest top level (SceneView::tlas) the top-level traversal's stack holds: BvhScene leaves a
/// deeper one out (TraceClosest and TraceOccluded then test every instance in turn).
constexpr int kMaxTlasDepth = 16;

/// the top level's stack (TraceClosest, TraceOccluded): kMaxTlasDepth entries.
using TlasStack = ArrayBvhStack<kMaxTlasDepth>;

/// p transformed by the row-major 3x4 matrix m (rotation and translation).
PB_HOST_DEVICE inline F3 TransformPoint(const float m[12], F3 p) {
  return {m[0] * p.x + m[1] * p.y + m[2] * p.z + m[3], m[4] * p.x + m[5] * p.y + m[6] * p.z + m[7],
          m[8] * p.x + m[9] * p.y + m[10] * p.z + m[11]};
}

/// v rotated by the rotation part of the row-major 3x4 matrix m.
PB_HOST_DEVICE inline F3 TransformVector(const float m[12], F3 v) {
  return {m[0] * v.x + m[1] * v.y + m[2] * v.z, m[4] * v.x + m[5] * v.y + m[6] * v.z,
          m[8] * v.x + m[9] * v.y + m[10] * v.z};
}

/// fminf(a, b) and fmaxf(a, b), the same bits on either processor: the device's own instruction;
/// on the host glibc's rule written inline (x86-64 libm: minss / maxss, so a < b ? a : b and
/// a > b ? a : b, and a quiet NaN operand gives the other one), where the out-of-line libm call
/// cost the host traversal (BvhRayQuery, RenderRealtimeOnHost) about a third of its time.
PB_HOST_DEVICE inline float SlabMin(float a, float b) {
#if defined(__CUDA_ARCH__)
  return fminf(a, b);
#else
  return a < b ? a : (b != b ? a : b);
#endif
}

PB_HOST_DEVICE inline float SlabMax(float a, float b) {
#if defined(__CUDA_ARCH__)
  return fmaxf(a, b);
#else
  return a > b ? a : (b != b ? a : b);
#endif
}

/// entry distance of o + t d (inv_d = 1 / d per axis) into box [lo, hi] within [tmin, tmax],
/// or +infinity if the ray misses it.
PB_HOST_DEVICE inline float SlabEntry(const float lo[3], const float hi[3], F3 o, F3 inv_d,
                                      float tmin, float tmax) {
  const float tx0 = (lo[0] - o.x) * inv_d.x, tx1 = (hi[0] - o.x) * inv_d.x;
  const float ty0 = (lo[1] - o.y) * inv_d.y, ty1 = (hi[1] - o.y) * inv_d.y;
  const float tz0 = (lo[2] - o.z) * inv_d.z, tz1 = (hi[2] - o.z) * inv_d.z;
  const float t0 =
      SlabMax(SlabMax(SlabMin(tx0, tx1), SlabMin(ty0, ty1)), SlabMax(SlabMin(tz0, tz1), tmin));
  const float t1 =
      SlabMin(SlabMin(SlabMax(tx0, tx1), SlabMax(ty0, ty1)), SlabMin(SlabMax(tz0, tz1), tmax));
  return t0 <= t1 ? t0 : INFINITY;
}

/// Moller-Trumbore: t in (tmin, tmax) and barycentrics (u, v) of the hit of o + t d with tri.
PB_HOST_DEVICE inline bool IntersectTriangle(const Triangle& tri, F3 o, F3 d, float tmin,
                                             float tmax, float* t, float* u, float* v) {
  const F3 p{d.y * tri.e2.z - d.z * tri.e2.y, d.z * tri.e2.x - d.x * tri.e2.z,
             d.x * tri.e2.y - d.y * tri.e2.x};
  const float det = tri.e1.x * p.x + tri.e1.y * p.y + tri.e1.z * p.z;
  if (det == 0.0f) return false;
  const float inv = 1.0f / det;
  const F3 s{o.x - tri.v0.x, o.y - tri.v0.y, o.z - tri.v0.z};
  const float uu = (s.x * p.x + s.y * p.y + s.z * p.z) * inv;
  if (!(uu >= 0.0f && uu <= 1.0f)) return false;
  const F3 q{s.y * tri.e1.z - s.z * tri.e1.y, s.z * tri.e1.x - s.x * tri.e1.z,
             s.x * tri.e1.y - s.y * tri.e1.x};
  const float vv = (d.x * q.x + d.y * q.y + d.z * q.z) * inv;
  if (!(vv >= 0.0f && uu + vv <= 1.0f)) return false;
  const float tt = (tri.e2.x * q.x + tri.e2.y * q.y + tri.e2.z * q.z) * inv;
  if (!(tt > tmin && tt < tmax)) return false;
  *t = tt, *u = uu, *v = vv;
  return true;
}

/// the hit of o + t d (group frame) with analytic prim a, t in (tmin, tmax), in double.
PB_HOST_DEVICE inline bool IntersectAnalyticPrim(const AnalyticPrim& a, F3 o, F3 d, float tmin,
                                                 float tmax, float* t, int* part) {
  const double* R = a.R_GI;
  const double oi[3] = {o.x, o.y, o.z}, di[3] = {d.x, d.y, d.z};
  double og[3], dg[3];
  for (int r = 0; r < 3; ++r) {
    og[r] = R[3 * r] * oi[0] + R[3 * r + 1] * oi[1] + R[3 * r + 2] * oi[2] + a.p_GI[r];
    dg[r] = R[3 * r] * di[0] + R[3 * r + 1] * di[1] + R[3 * r + 2] * di[2];
  }
  double td;
  if (!IntersectAnalyticArrays(a.kind, a.size, og, dg, tmin, tmax, &td, part)) return false;
  const float tf = static_cast<float>(td);
  if (!(tf < tmax)) return false;
  *t = tf;
  return true;
}

/// inner node *p (BvhWideNode): on the GPU in four 16-byte read-only loads of its 64-byte line.
PB_HOST_DEVICE inline BvhWideNode LoadWideNode(const BvhWideNode* p) {
#if defined(__CUDA_ARCH__)
  const float4* q = reinterpret_cast<const float4*>(p);
  const float4 a = __ldg(q), b = __ldg(q + 1), c = __ldg(q + 2);
  const int4 e = __ldg(reinterpret_cast<const int4*>(p) + 3);
  BvhWideNode n;
  n.box[0][0] = a.x, n.box[0][1] = a.y, n.box[0][2] = a.z, n.box[0][3] = a.w;
  n.box[0][4] = b.x, n.box[0][5] = b.y, n.box[1][0] = b.z, n.box[1][1] = b.w;
  n.box[1][2] = c.x, n.box[1][3] = c.y, n.box[1][4] = c.z, n.box[1][5] = c.w;
  n.first[0] = e.x, n.first[1] = e.y, n.count[0] = e.z, n.count[1] = e.w;
  return n;
#else
  return *p;
#endif
}

/// triangle *p: on the GPU in three 16-byte read-only loads.
PB_HOST_DEVICE inline Triangle LoadTriangle(const Triangle* p) {
#if defined(__CUDA_ARCH__)
  const float4* q = reinterpret_cast<const float4*>(p);
  const float4 a = __ldg(q), b = __ldg(q + 1), c = __ldg(q + 2);
  Triangle t;
  t.v0 = {a.x, a.y, a.z}, t.e1 = {a.w, b.x, b.y}, t.e2 = {b.z, b.w, c.x};
  return t;
#else
  return *p;
#endif
}

/// the kind and shape index of primitive *p (PrimRef): on the GPU in one 8-byte read-only load.
PB_HOST_DEVICE inline void LoadPrimShape(const PrimRef* p, int* kind, int* index) {
#if defined(__CUDA_ARCH__)
  const int2 k = __ldg(reinterpret_cast<const int2*>(p));
  *kind = k.x, *index = k.y;
#else
  *kind = p->kind, *index = p->index;
#endif
}

/// an instance's world box and BLAS (Instance::lo, hi, blas), as the top level tests it.
struct InstanceBox {
  float lo[3], hi[3];
  int32_t blas;
};

/// the box and BLAS of instance *p: on the GPU in two 16-byte read-only loads (Instance's first
/// two words), where the fields one by one were six scalar loads a box test.
PB_HOST_DEVICE inline InstanceBox LoadInstanceBox(const Instance* p) {
  InstanceBox b;
#if defined(__CUDA_ARCH__)
  const float4* q = reinterpret_cast<const float4*>(p);
  const float4 x = __ldg(q), y = __ldg(q + 1);
  b.lo[0] = x.x, b.lo[1] = x.y, b.lo[2] = x.z, b.hi[0] = x.w;
  b.hi[1] = y.x, b.hi[2] = y.y, b.blas = __float_as_int(y.z);
#else
  for (int a = 0; a < 3; ++a) b.lo[a] = p->lo[a], b.hi[a] = p->hi[a];
  b.blas = p->blas;
#endif
  return b;
}

/// the instance index *p of a top-level leaf (SceneView::tlas_instances): on the GPU a read-only
/// load.
PB_HOST_DEVICE inline int LoadTlasInstance(const int32_t* p) {
#if defined(__CUDA_ARCH__)
  return __ldg(p);
#else
  return *p;
#endif
}

/// a row-major 3x4 transform (Instance::X_IW) in registers.
struct InstanceTransform {
  float m[12];
};

/// the world-to-instance transform X_IW of instance *p: on the GPU in three 16-byte read-only
/// loads.
PB_HOST_DEVICE inline InstanceTransform LoadInstanceInverse(const Instance* p) {
  InstanceTransform t;
#if defined(__CUDA_ARCH__)
  const float4* q = reinterpret_cast<const float4*>(p->X_IW);
  const float4 a = __ldg(q), b = __ldg(q + 1), c = __ldg(q + 2);
  t.m[0] = a.x, t.m[1] = a.y, t.m[2] = a.z, t.m[3] = a.w;
  t.m[4] = b.x, t.m[5] = b.y, t.m[6] = b.z, t.m[7] = b.w;
  t.m[8] = c.x, t.m[9] = c.y, t.m[10] = c.z, t.m[11] = c.w;
#else
  for (int k = 0; k < 12; ++k) t.m[k] = p->X_IW[k];
#endif
  return t;
}

/// the stack traversal of one BVH in the traversal's form (WidenBvh: `nodes` its inner nodes,
/// `blas` its root's box and reference) along o + t d for t in [tmin, *t_max]: leaf(pi) is
/// called for every primitive index pi of every leaf the ray reaches and returns whether it
/// hit (it then shrinks *t_max to the hit's t); any_hit: stop at the first hit (occlusion).
/// returns whether any primitive hit. a visit of an inner node tests its two children's boxes
/// (stored in it, BvhWideNode), goes on with the nearer and keeps the farther. Stack: where the
/// farther children wait (LocalBvhStack, or a test's). kAnyOrder (only with any_hit): go on with
/// the first child whose box the ray enters and keep the second, and visit every popped child
/// without comparing its entry with *t_max; the verdict is the ordered traversal's (below).
template <class Stack = LocalBvhStack, bool kAnyOrder = false, typename Leaf>
PB_HOST_DEVICE inline bool TraverseWideBvh(const BvhWideNode* nodes, const Blas& blas, F3 o, F3 d,
                                           float tmin, const float* t_max, bool any_hit,
                                           Leaf& leaf) {
  const F3 inv{1.0f / d.x, 1.0f / d.y, 1.0f / d.z};
  // the farther children still to visit (their references), with their boxes' entry distances:
  // a popped child is visited if its entry is not beyond the closest hit found since (the entry
  // does not depend on the ray's far end, so this is the slab test against the shorter ray,
  // without reloading the box).
  // one 16-byte entry a child (BvhPending)
  Stack stack;
  int top = 0;
  bool found = false;
  // the node in hand: a leaf (count >= 0) or inner node `first` (count -1)
  int first = blas.root_first, count = blas.root_count;
  if (SlabEntry(blas.lo, blas.hi, o, inv, tmin, *t_max) == INFINITY) return false;
  while (true) {
    if (count >= 0) {
      for (int k = 0; k < count; ++k) {
        if (!leaf(first + k)) continue;
        found = true;
        if (any_hit) return true;
      }
    } else {
      const BvhWideNode n = LoadWideNode(nodes + first);
      const float ta = SlabEntry(n.box[0], n.box[0] + 3, o, inv, tmin, *t_max);
      const float tb = SlabEntry(n.box[1], n.box[1] + 3, o, inv, tmin, *t_max);
      const bool ha = ta != INFINITY, hb = tb != INFINITY;
      if (ha && hb) {
        // any order: the same verdict. before its first hit an any_hit traversal never shrinks
        // *t_max (it returns at that hit), so every box test and primitive test sees the ray's
        // own tmax whatever the order; the set of leaves reached (the children whose boxes pass
        // their tests, down from the root) and each primitive's verdict are the ordered
        // traversal's, and the ray is occluded iff one of them hits. a popped entry's t was
        // SlabEntry's t0 <= t1 <= *t_max, so its test would always pass.
        const bool a_first = kAnyOrder || ta <= tb;
        if (top < Stack::kCapacity)
          stack.Put(top++, BvhPending{a_first ? n.first[1] : n.first[0],
                                      a_first ? n.count[1] : n.count[0], a_first ? tb : ta, 0});
        first = a_first ? n.first[0] : n.first[1];
        count = a_first ? n.count[0] : n.count[1];
        continue;
      }
      if (ha || hb) {
        first = ha ? n.first[0] : n.first[1];
        count = ha ? n.count[0] : n.count[1];
        continue;
      }
    }
    // pop, skipping children now farther than the closest hit
    bool next = false;
    while (top > 0) {
      const BvhPending e = stack.Get(--top);
      if (kAnyOrder || e.t <= *t_max) {
        first = e.first;
        count = e.count;
        next = true;
        break;
      }
    }
    if (!next) break;
  }
  return found;
}

/// traverses one BLAS with the ray in its frame (TraverseWideBvh over its triangles and
/// analytic shapes); any_hit: stop at the first hit (occlusion). updates *hit (t shrinks) and
/// returns whether it hit. Stack and kAnyOrder (only with any_hit): TraverseWideBvh's.
template <class Stack = LocalBvhStack, bool kAnyOrder = false>
PB_HOST_DEVICE inline bool TraverseBlas(const SceneView& s, const Blas& blas, int instance, F3 o,
                                        F3 d, float tmin, bool any_hit, TraceHit* hit) {
  auto leaf = [&](int pi) {
    int kind, index;
    LoadPrimShape(s.prims + pi, &kind, &index);
    float t, u = 0, v = 0;
    int part = 0;
    const bool h =
        kind == 0
            ? IntersectTriangle(LoadTriangle(s.triangles + index), o, d, tmin, hit->t, &t, &u, &v)
            : IntersectAnalyticPrim(s.analytics[index], o, d, tmin, hit->t, &t, &part);
    if (!h) return false;
    hit->t = t, hit->u = u, hit->v = v, hit->part = part;
    hit->prim = pi, hit->instance = instance;
    return true;
  };
  return TraverseWideBvh<Stack, kAnyOrder>(s.nodes + blas.node_offset, blas, o, d, tmin, &hit->t,
                                           any_hit, leaf);
}

/// the root TraceClosest and TraceOccluded walk the instances from: the top level s.tlas where
/// `tree` (a view with one, its switch on), else one leaf of every instance in index order under
/// a box of all space (the flat loop, through the same traversal).
PB_HOST_DEVICE inline Blas TopLevelRoot(const SceneView& s, bool tree) {
  Blas top = s.tlas;
  if (!tree) {
    top.root_first = 0;
    top.root_count = s.num_instances;
    for (int a = 0; a < 3; ++a) top.lo[a] = -3.4e38f, top.hi[a] = 3.4e38f;
  }
  return top;
}

/// how TraceClosest bounds an instance below the best hit's (its tie rule): the shipped
/// kMargin, and two variants that the tests show differ from the flat loop (kNextUp: a bound
/// one float above the best t; kNone: no tie rule, the best t itself).
enum class ClosestTies { kMargin, kNextUp, kNone };

/// TraceClosest's relative margin (kMargin): an instance below the best hit's searches up to
/// t (1 + 2^-12), about 2,000 floats beyond t, where the BLAS's unpadded triangle boxes and
/// Moller-Trumbore's t of the same point differ by a few floats.
constexpr float kClosestTieMargin = 1.0f / 4096.0f;

/// the bound TraceClosest gives an instance below the best hit's (best t `t`, the ray's tmax):
/// above t (so an equal t of that instance is found), at most tmax.
template <ClosestTies kTies>
PB_HOST_DEVICE inline float ClosestTieBound(float t, float tmax) {
  if constexpr (kTies == ClosestTies::kNone) {
    return t;
  } else {
    float b = nextafterf(t, INFINITY);
    if constexpr (kTies == ClosestTies::kMargin) b = SlabMax(b, t + fabsf(t) * kClosestTieMargin);
    return b < tmax ? b : tmax;
  }
}

/// closest hit of ray r in [tmin, tmax] over every instance; hit->instance == -1 if none: the
/// flat loop's hit bit for bit (t, u, v, part, prim, instance), the loop that tests every
/// instance in index order (its world box against the best t so far, then its BLAS with that
/// t as the bound, a hit kept if strictly nearer), so the lower instance wins a tie and within
/// a BLAS the first primitive in its traversal's order. with a top level (s.tlas,
/// s.tlas_instances) it walks the top level nearer child first (TraverseWideBvh; a popped entry is
/// skipped when beyond the bound below) and tests each instance of a leaf as the loop does; its
/// without a top level it is that loop (TopLevelRoot). Stack: TraverseWideBvh's, for
/// each BLAS; kTies: ClosestTies (the tests' variants).
///
/// why the loop's hit. the instances come in another order, so an instance i is tested
/// against the best hit (t*, j) of those visited before it, not of those below it. i > j:
/// bound t* (a hit of i kept if t < t*, as the loop's order would keep it). i < j: bound
/// ClosestTieBound(t*) > t*, and a hit kept if t <= t* (the loop would have found i's equal-t
/// hit before j's), else dropped (t* unchanged). so the hit kept is the least (t, instance) over
/// the instances' own hits, the loop's hit, provided an instance's hit (t, u, v, part, prim)
/// does not depend on the bound it is searched with as long as the bound exceeds its t:
/// - the primitive tests: IntersectTriangle's t does not depend on tmin / tmax and is kept if
///   tmin < t < bound; IntersectAnalyticPrim takes the least root in (tmin, bound) in double
///   (analytic_detail::Closest: strict, the first part offered among equal roots) and keeps it
///   if its float is < bound, and float(x) < bound implies x < bound, so with any bound above
///   the float of the least root it gives that root and part, else nothing;
/// - TraverseWideBvh's choices: SlabEntry's entry t0 = max(slab entries, tmin) does not depend
///   on the bound, which only decides `t0 <= min(t1, bound)` (a box is entered or culled); the
///   nearer child first compares the two t0 (ta <= tb: the first child on a tie), so the order
///   of the boxes entered does not depend on the bound, and a pop visits an entry if
///   t0 <= the best t. a box whose t0 <= the hit's t is entered and popped with every bound
///   above it (the best t never drops below the hit's), so the hit's leaf and every leaf with
///   an equal-t primitive are reached in the same order, and the first such primitive is kept
///   (IntersectTriangle and Closest accept only a strictly nearer t);
/// - the instance's world box (BvhScene pads it by 1e-5 relative), tested as the loop tests it
///   against its own bound.
/// so the argument holds where every box on the way to a hit has t0 <= the hit's t; the BLASes'
/// triangle boxes are the vertices' float min / max, unpadded, and where a triangle lies in its
/// box's face (walls, a box's sides) SlabEntry's t0 of the face and Moller-Trumbore's t of the
/// same point may differ by a few floats either way: hence the margin (kMargin), so an equal-t
/// instance below the best one finds its hit when its box's t0 is beyond t* by up to 2^-12 of
/// t* (kNextUp, one float, and kNone miss such ties: tests/render/cuda/bvh_traversal_test.cc,
/// ClosestThroughTheTopLevelKeepsTheLowerInstanceOnATie and
/// ClosestThroughTheTopLevelGivesTheFlatLoopsHits). the loop itself culls with t0 in the same
/// way; a hit of instance i hidden behind a box t0 beyond the best t by more than the margin is
/// missed by both when searched with a bound below that t0, and by one of them only where the
/// two search i with bounds on either side of it (not seen in the tests).
///
/// the top level: its boxes are the float min / max of the instances' boxes below them
/// (BuildBvh), so a ray that enters an instance's box within a bound enters every box above it
/// within that bound (the slab test is monotonic in the box's planes: a larger box, a t0 no
/// larger and a t1 no smaller); the top level is walked with the bound `below`
/// (ClosestTieBound of the best t, or tmax before a hit), no less than any instance's bound,
/// so every instance whose own box test would pass is reached.
template <class Stack = LocalBvhStack, ClosestTies kTies = ClosestTies::kMargin>
PB_HOST_DEVICE inline void TraceClosest(const SceneView& s, const TraceRay& r, TraceHit* hit) {
  hit->t = r.tmax;
  hit->instance = -1;
  hit->prim = -1;
  const F3 inv{1.0f / r.d.x, 1.0f / r.d.y, 1.0f / r.d.z};
  const bool tree = s.tlas_instances != nullptr;
  const Blas top = TopLevelRoot(s, tree);
  // the bound of an instance below the best hit's and of the top level's boxes
  float below = r.tmax;
  auto leaf = [&](int k) {
    const int i = tree ? LoadTlasInstance(s.tlas_instances + k) : k;
    const float best = hit->t;
    const float bound = i < hit->instance ? below : best;
    const InstanceBox box = LoadInstanceBox(s.instances + i);
    if (SlabEntry(box.lo, box.hi, r.o, inv, r.tmin, bound) == INFINITY) return false;
    const InstanceTransform X_IW = LoadInstanceInverse(s.instances + i);
    const F3 o = TransformPoint(X_IW.m, r.o), d = TransformVector(X_IW.m, r.d);
    TraceHit h;
    h.t = bound;
    if (!TraverseBlas<Stack>(s, s.blases[box.blas], i, o, d, r.tmin, false, &h)) return false;
    // below the best instance: its hits in (t*, bound) are farther than the best
    if (h.t > best) return false;
    *hit = h;
    below = ClosestTieBound<kTies>(h.t, r.tmax);
    return true;
  };
  TraverseWideBvh<TlasStack>(s.tlas_nodes, top, r.o, r.d, r.tmin, &below, false, leaf);
}

/// true if anything blocks ray r in (tmin, tmax). Stack: TraverseWideBvh's, for each BLAS.
/// kAnyOrder (the default): the top level and each BLAS in their children's stored order, no
/// entry test on a pop (TraverseWideBvh; the same verdict as false, the nearer child first,
/// which the tests compare). the top level (s.tlas, with tlas_instances)
/// is walked as a BLAS whose leaves hold instances: each instance of a leaf the ray reaches is
/// tested as the flat list tests it (its own box, then its BLAS). the same verdict as the flat
/// list: an any-hit traversal's verdict does not depend on its order (TraverseWideBvh), and a
/// node's box holds its instances' boxes (BuildBvh: float min / max of them), so a ray that
/// enters an instance's box enters every box above it (the slab test is monotonic in the box's
/// planes). without a top level: one leaf of every instance in index order under a box of all
/// space.
template <class Stack = LocalBvhStack, bool kAnyOrder = true>
PB_HOST_DEVICE inline bool TraceOccluded(const SceneView& s, const TraceRay& r) {
  TraceHit hit;
  hit.t = r.tmax;
  const F3 inv{1.0f / r.d.x, 1.0f / r.d.y, 1.0f / r.d.z};
  const bool tree = s.tlas_instances != nullptr;
  const Blas top = TopLevelRoot(s, tree);
  auto leaf = [&](int k) {
    const int i = tree ? LoadTlasInstance(s.tlas_instances + k) : k;
    const InstanceBox box = LoadInstanceBox(s.instances + i);
    if (SlabEntry(box.lo, box.hi, r.o, inv, r.tmin, hit.t) == INFINITY) return false;
    const InstanceTransform X_IW = LoadInstanceInverse(s.instances + i);
    const F3 o = TransformPoint(X_IW.m, r.o), d = TransformVector(X_IW.m, r.d);
    return TraverseBlas<Stack, kAnyOrder>(s, s.blases[box.blas], i, o, d, r.tmin, true, &hit);
  };
  const float tmax = r.tmax;
  return TraverseWideBvh<TlasStack, kAnyOrder>(s.tlas_nodes, top, r.o, r.d, r.tmin, &tmax, true,
                                               leaf);
}

/// the ray tracer of the transport's chains (render/transport: a Tracer, their template
/// parameter, has these two calls) over the BVH of `scene`: the GPU's, and the host's.
struct BvhTracer {
  const SceneView& scene;
  /// the closest hit of r in [tmin, tmax] (TraceClosest); hit->instance -1 where none.
  PB_HOST_DEVICE void Closest(const TraceRay& r, TraceHit* hit) const {
    TraceClosest(scene, r, hit);
  }
  /// whether anything blocks r in (tmin, tmax) (TraceOccluded).
  PB_HOST_DEVICE bool Occluded(const TraceRay& r) const { return TraceOccluded(scene, r); }
};

}  // namespace penumbra::cuda

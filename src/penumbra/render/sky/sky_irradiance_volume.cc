#include "penumbra/render/sky/sky_irradiance_volume.h"

#include <algorithm>
#include <bit>
#include <bitset>
#include <cmath>
#include <cstring>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <utility>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"

#if defined(__SSE2__)
#include <emmintrin.h>
#endif

#include "penumbra/render/geometry/static_geometry.h"

namespace penumbra {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr int kNumSh = kSkyNumSh;
constexpr int kShFloats = kNumSh * 3;
// a probe's irradiance SH padded to 28 floats (7 4-lane packets): coefficient k (RGB) at floats
// 3 SkyShSlot(k) .. 3 SkyShSlot(k) + 2 (render/sky/sky_eval_math.h). the order puts together the
// coefficients that do not vanish for an axis-aligned normal (the basis at +-x is non-zero for
// k = 0, 3, 6, 8 only, at +-z for 0, 2, 6, at +-y for 0, 1, 6, 8), so that a lookup on an
// axis-aligned face (most of them indoors) accumulates 3 to 5 packets instead of 7.
constexpr int kShStride = kSkyShStride;

// clamped-cosine convolution weight of band l (Ramamoorthi and Hanrahan 2001, eq. 8-9).
constexpr double kBandWeight[kNumSh] = {kPi,     2 * kPi / 3, 2 * kPi / 3, 2 * kPi / 3, kPi / 4,
                                        kPi / 4, kPi / 4,     kPi / 4,     kPi / 4};

// octahedral map: (u, v) in [-1, 1]^2 to a direction of L1 norm 1 (not unit): the upper
// hemisphere is the diamond |u| + |v| <= 1, the lower one folded into the corners.
inline Eigen::Vector3d OctDecode(double u, double v) {
  double x = u, y = v;
  const double z = 1 - std::abs(u) - std::abs(v);
  if (z < 0) {
    x = (1 - std::abs(v)) * std::copysign(1.0, u);
    y = (1 - std::abs(u)) * std::copysign(1.0, v);
  }
  return {x, y, z};
}

// the fixed ray directions shared by every probe (unit): the first pass (one per texel, with
// the texel of each) and the refinement rays (one per sub-cell of each texel).
struct ProbeDirections {
  std::vector<Eigen::Vector3f> dir;
  std::vector<int> texel;
  std::vector<Eigen::Vector3f> sub;  // [texel * kSubRays + sub-cell]
};

const ProbeDirections& Directions() {
  static const ProbeDirections dirs = [] {
    constexpr int K = SkyIrradianceVolume::kOctSide;
    constexpr int S = SkyIrradianceVolume::kSubSide;
    ProbeDirections d;
    // texels in 4 x 4 blocks, so that consecutive rays are coherent.
    for (int b = 0; b < K * K; ++b) {
      const int block = b / 16, in = b % 16;
      const int ix = (block % (K / 4)) * 4 + in % 4, iy = (block / (K / 4)) * 4 + in / 4;
      const int t = ix + K * iy;
      Rng rng(HashKeys(SkyIrradianceVolume::kDirectionSeed, static_cast<uint64_t>(t), 0));
      const double ju = rng.UniformD(), jv = rng.UniformD();
      const double u = -1 + 2 * (ix + ju) / K, v = -1 + 2 * (iy + jv) / K;
      d.dir.push_back(OctDecode(u, v).normalized().cast<float>());
      d.texel.push_back(t);
    }
    d.sub.resize(static_cast<size_t>(K * K) * S * S);
    for (int t = 0; t < K * K; ++t)
      for (int c = 0; c < S * S; ++c) {
        Rng rng(HashKeys(SkyIrradianceVolume::kDirectionSeed, static_cast<uint64_t>(t),
                         static_cast<uint64_t>(1 + c)));
        const double ju = rng.UniformD(), jv = rng.UniformD();
        const double u = -1 + 2 * ((t % K) * S + c % S + ju) / (K * S);
        const double v = -1 + 2 * ((t / K) * S + c / S + jv) / (K * S);
        d.sub[static_cast<size_t>(t) * S * S + c] = OctDecode(u, v).normalized().cast<float>();
      }
    return d;
  }();
  return dirs;
}

// the texel next to texel (ix, iy) by (dx, dy) in [-1, 1]^2 on the sphere: across an edge of
// the octahedral map the neighbour is mirrored (the map folds there: u = -1 - e is u = -1 + e
// with v negated), across a corner it is the opposite corner.
int NeighbourTexel(int ix, int iy, int dx, int dy) {
  constexpr int K = SkyIrradianceVolume::kOctSide;
  int x = ix + dx, y = iy + dy;
  if (x < 0 || x >= K) x = x < 0 ? 0 : K - 1, y = K - 1 - y;
  if (y < 0 || y >= K) y = y < 0 ? 0 : K - 1, x = K - 1 - x;
  return x + K * y;
}

// one bit per texel.
using TexelBits = std::bitset<SkyIrradianceVolume::kNumTexels>;

// a batch of rays with its hits, traced through a RayQuery; its arrays grow and are reused. its
// rays are Ray's defaults but for what the caller writes (o and d: the volume sets only those).
struct RayBatch {
  std::vector<Ray> rays;
  std::vector<SurfaceHit> hits;
  std::unique_ptr<bool[]> did_hit;
  size_t capacity = 0;
  void Resize(size_t n) {
    rays.resize(n);
    hits.resize(n);
    if (n > capacity) {
      did_hit.reset(new bool[n]);
      capacity = n;
    }
  }
  void Trace(const RayQuery& query) {
    query.Intersect(rays, hits, std::span<bool>(did_hit.get(), rays.size()));
  }
};

// the texels whose 3 x 3 neighbourhood on the sphere (NeighbourTexel) holds an open texel
// (*near_open) and a closed one (*near_closed), of one probe's first pass.
void NearOpenClosed(const uint16_t* open, TexelBits* near_open, TexelBits* near_closed) {
  constexpr int K = SkyIrradianceVolume::kOctSide;
  near_open->reset();
  near_closed->reset();
  for (int t = 0; t < K * K; ++t)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
        (open[NeighbourTexel(t % K, t / K, dx, dy)] != 0 ? *near_open : *near_closed).set(t);
}

// 4-lane math for the lookup's 8 corners (two halves), with GCC/Clang vector extensions: SSE2
// registers in the portable build, VEX-encoded ones in the native build. every operation is
// the IEEE one of the scalar code (no approximations), lane by lane.
typedef float F4 __attribute__((vector_size(16)));
typedef int32_t I4 __attribute__((vector_size(16)));

inline F4 Splat4(float a) { return F4{a, a, a, a}; }
inline F4 Load4(const float* p) {
  F4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline I4 Load4(const int32_t* p) {
  I4 v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
inline void Store4(float* p, F4 v) { std::memcpy(p, &v, sizeof v); }
inline void Store4(int32_t* p, I4 v) { std::memcpy(p, &v, sizeof v); }
// bit k set where lane k of the comparison result m is true.
inline unsigned MoveMask4(I4 m) {
#if defined(__SSE2__)
  return static_cast<unsigned>(_mm_movemask_ps(reinterpret_cast<__m128>(m)));
#else
  return (m[0] & 1u) | (m[1] & 2u) | (m[2] & 4u) | (m[3] & 8u);
#endif
}
inline F4 Sqrt4(F4 a) {
#if defined(__SSE2__)
  return reinterpret_cast<F4>(_mm_sqrt_ps(reinterpret_cast<__m128>(a)));
#else
  return F4{std::sqrt(a[0]), std::sqrt(a[1]), std::sqrt(a[2]), std::sqrt(a[3])};
#endif
}
inline I4 Bits4(F4 a) { return reinterpret_cast<I4>(a); }
inline F4 Float4(I4 a) { return reinterpret_cast<F4>(a); }
// m ? a : b per lane (m all-ones or all-zeros, from a comparison).
inline F4 Select4(I4 m, F4 a, F4 b) { return Float4((Bits4(a) & m) | (Bits4(b) & ~m)); }
inline F4 Abs4(F4 a) { return Float4(Bits4(a) & 0x7fffffff); }
// std::copysign(mag, sgn) per lane.
inline F4 CopySign4(F4 mag, F4 sgn) {
  return Float4((Bits4(mag) & 0x7fffffff) | (Bits4(sgn) & static_cast<int32_t>(0x80000000u)));
}
// a < b ? a : b and a > b ? a : b per lane (MINPS / MAXPS: b where either is NaN).
inline F4 Min4(F4 a, F4 b) {
#if defined(__SSE2__)
  return reinterpret_cast<F4>(_mm_min_ps(reinterpret_cast<__m128>(a), reinterpret_cast<__m128>(b)));
#else
  return Select4(a < b, a, b);
#endif
}
inline F4 Max4(F4 a, F4 b) {
#if defined(__SSE2__)
  return reinterpret_cast<F4>(_mm_max_ps(reinterpret_cast<__m128>(a), reinterpret_cast<__m128>(b)));
#else
  return Select4(a > b, a, b);
#endif
}
// the lane type of the CPU's lookup (4 corners at a time) for the per-lane functions of
// render/sky_eval_math.h.
struct F4Lanes {
  using F = F4;
  using I = I4;
  using M = I4;
  static constexpr int kWidth = 4;
  static F Splat(float a) { return Splat4(a); }
  static F Load(const float* p) { return Load4(p); }
  static F Abs(F a) { return Abs4(a); }
  static F CopySign(F mag, F sgn) { return CopySign4(mag, sgn); }
  static F Select(M m, F a, F b) { return Select4(m, a, b); }
  static F Min(F a, F b) { return Min4(a, b); }
  static F Max(F a, F b) { return Max4(a, b); }
  static F Sqrt(F a) { return Sqrt4(a); }
  static I ToInt(F a) { return __builtin_convertvector(a, I4); }
  static F ToFloat(I a) { return __builtin_convertvector(a, F4); }
};

// the lookup's weighted mean of the probes' irradiance SH at the basis values y, for the
// active corners (bits of `active`, in increasing order, weight w[c], probe base + corner[c])
// and, of the 7 packets of a probe's SH, only packets kLo .. kHi - 1, which must hold every
// coefficient k with y[k] != 0; kK... are those k in increasing order. the terms with y[k] = 0
// that this leaves out would add an exact 0 to each channel, so the sum is bit for bit the
// full one.
template <int kLo, int kHi, int... kK>
__attribute__((always_inline)) inline Eigen::Vector3f WeightedSh(const float* sh_base,
                                                                 const int32_t* corner,
                                                                 const float* w, unsigned active,
                                                                 const float* y) {
  F4 acc[kHi - kLo];
  const float wsum = SkyAccumulateSh<F4Lanes, kLo, kHi>(sh_base, corner, w, active, acc);
  // packets kLo .. kHi - 1 of the sum at their place, zeros around them.
  alignas(16) float a[kShStride + 4] = {};
  for (int i = 0; i < kHi - kLo; ++i) Store4(a + 4 * (kLo + i), acc[i]);
  Eigen::Vector3f e;
  SkyShSumOver<kK...>(a, y, wsum, e.data());
  return e;
}

// octahedral texel of a non-zero direction (SkyIrradianceVolume::TexelOf), inlined into lookups.
inline int OctTexel(const Eigen::Vector3f& w) {
  constexpr int kOctSide = kSkyOctSide;
  const float inv_l1 = 1.0f / (std::abs(w.x()) + std::abs(w.y()) + std::abs(w.z()));
  float u = w.x() * inv_l1, v = w.y() * inv_l1;
  if (w.z() < 0) {
    const float au = std::abs(u), av = std::abs(v);
    u = std::copysign(1.0f - av, w.x());
    v = std::copysign(1.0f - au, w.y());
  }
  const int ix = std::clamp(static_cast<int>((u + 1.0f) * (0.5f * kOctSide)), 0, kOctSide - 1);
  const int iy = std::clamp(static_cast<int>((v + 1.0f) * (0.5f * kOctSide)), 0, kOctSide - 1);
  return ix + kOctSide * iy;
}

}  // namespace

int SkyIrradianceVolume::TexelOf(const Eigen::Vector3f& w) { return OctTexel(w); }

Eigen::Vector3f SkyIrradianceVolume::ProbePosition(int probe) const {
  const int i = probe % dims_[0], j = (probe / dims_[0]) % dims_[1],
            k = probe / (dims_[0] * dims_[1]);
  return origin_ + spacing_ * Eigen::Vector3f(static_cast<float>(i), static_cast<float>(j),
                                              static_cast<float>(k));
}

int SkyIrradianceVolume::num_valid_probes() const {
  return static_cast<int>(std::count(valid_.begin(), valid_.end(), uint8_t{1}));
}

SkyIrradianceVolume::SkyIrradianceVolume(RayQueryFactory make_query)
    : make_query_(std::move(make_query)) {
  if (!make_query_) throw Error("SkyIrradianceVolume: no RayQueryFactory");
}

void SkyIrradianceVolume::Build(const SceneDescription& scene, const std::vector<Pose>& X_WB,
                                ThreadPool* pool, int max_probes) {
  if (X_WB.size() != scene.bodies.size())
    throw Error("SkyIrradianceVolume::Build: " + std::to_string(X_WB.size()) +
                " body poses, scene has " + std::to_string(scene.bodies.size()) + " bodies");
  max_probes = std::clamp(max_probes, 8, 65536);
  built_ = true;
  ++generation_;
  built_static_poses_ = X_WB;
  lit_sky_ = nullptr;
  dims_ = {0, 0, 0};
  valid_.clear();
  links_.clear();
  position_.clear();
  open_.clear();
  num_refined_ = 0;
  depth_.clear();
  depth_q_.clear();
  sh_.clear();
  cell_pos_.clear();

  // the static geoms and the bounds of the finite ones, world frame.
  Eigen::Vector3d lo, hi;
  SceneDescription statics = StaticGeoms(scene, X_WB, &lo, &hi);
  if (!(lo.array() <= hi.array()).all()) return;  // no finite static geometry

  // the grid: smallest spacing >= kMinSpacingM (in steps of 5%) with <= max_probes probes,
  // padded by half a spacing and centred on the bounds.
  double s = kMinSpacingM;
  std::array<int, 3> n{};
  for (;;) {
    int64_t count = 1;
    for (int a = 0; a < 3; ++a) {
      n[a] = std::max(2, static_cast<int>(std::ceil((hi[a] - lo[a] + 1.4 * s) / s - 1e-9)) + 1);
      count *= n[a];
    }
    if (count <= max_probes) break;
    s *= 1.05;
  }
  dims_ = n;
  spacing_ = static_cast<float>(s);
  inv_spacing_ = static_cast<float>(1.0 / s);
  const Eigen::Vector3d centre = 0.5 * (lo + hi);
  // shifted by a fixed fraction of a spacing, so that probes rarely lie exactly on the faces of
  // axis-aligned geometry that is symmetric about the centre of the bounds.
  constexpr double kShift[3] = {0.113, 0.137, 0.171};
  for (int a = 0; a < 3; ++a)
    origin_[a] = static_cast<float>(centre[a] - 0.5 * s * (n[a] - 1) + kShift[a] * s);

  // trace the probes against the static geoms only.
  const std::unique_ptr<RayQuery> rays = make_query_(statics);
  WorldSnapshot snap;
  snap.X_WB = X_WB;
  rays->Update(snap);
  const ProbeDirections& dirs = Directions();
  const int num = num_probes();
  valid_.assign(num, 0);
  open_.assign(static_cast<size_t>(num) * kNumTexels, 0);
  depth_.assign(static_cast<size_t>(num) * kNumTexels, 0.0f);
  position_.resize(num);
  const float far = 2.0f * spacing_;
  // the rays of a chunk of probes go to the query as one batch (a GPU query pays a launch and a
  // round trip a batch); a ray's hit does not depend on its batch (RayQuery's contract), so the
  // volume is the same whatever the batching. a probe's rays lie next to each other, neighbouring
  // texels next to each other (Embree: packets of 16, 4 x 4 neighbouring texels share one).
  // probe x's first-pass rays into ray[0 .. kRaysPerProbe).
  auto probe_rays = [&](const Eigen::Vector3f& x, Ray* ray) {
    for (int r = 0; r < kRaysPerProbe; ++r) {
      ray[r].o = x;
      ray[r].d = dirs.dir[r];
    }
  };
  // a probe's texels from its first-pass rays' hits; returns the number of back-face hits and
  // writes the closest back-face hit (distance, direction).
  auto take_probe = [&](const RayBatch& b, size_t at, float* m, uint16_t* open, float* t_back,
                        Eigen::Vector3f* d_back) {
    std::fill_n(m, kNumTexels, far);
    std::fill_n(open, kNumTexels, uint16_t{0});
    *t_back = std::numeric_limits<float>::infinity();
    int backfaces = 0;
    for (int r = 0; r < kRaysPerProbe; ++r) {
      const size_t i = at + static_cast<size_t>(r);
      float t = far;
      if (b.did_hit[i]) {
        if (!b.hits[i].front_face) {
          ++backfaces;
          if (b.hits[i].t < *t_back) *t_back = b.hits[i].t, *d_back = b.rays[i].d;
        }
        t = std::min(b.hits[i].t, far);
      } else {
        open[dirs.texel[r]] = kAllOpen;
      }
      m[dirs.texel[r]] = std::min(m[dirs.texel[r]], t);
    }
    return backfaces;
  };
  // a probe under the scene's floor: most of its upward rays hit geometry (the floor's underside)
  // and most of its downward rays escape (no ground below the floor: the scene stands over the
  // sky's lower half). no camera looks there; its light, the sky seen from below, leaked up
  // through the floor into the foot of every wall and cabinet standing on it (a floor slab is
  // thinner than the visibility tolerance, and a texel's ray can pass under a wall), so such a
  // probe is invalid. outdoors a ground plane blocks the downward rays and keeps its probes.
  auto under_floor = [&](const uint16_t* open) {
    int up = 0, up_blocked = 0, down = 0, down_open = 0;
    for (int r = 0; r < kRaysPerProbe; ++r) {
      const float z = dirs.dir[r].z();
      const bool escaped = open[dirs.texel[r]] != 0;
      if (z > 0.2f) {
        ++up;
        up_blocked += escaped ? 0 : 1;
      } else if (z < -0.2f) {
        ++down;
        down_open += escaped ? 1 : 0;
      }
    }
    return 2 * up_blocked > up && 2 * down_open > down;
  };
  constexpr int kChunk = 16;
  const int max_back = static_cast<int>(kMaxBackfaceFraction * kRaysPerProbe);
  auto trace = [&](int64_t chunk) {
    const int p0 = static_cast<int>(chunk) * kChunk, p1 = std::min(num, p0 + kChunk);
    thread_local RayBatch b;
    thread_local std::vector<int> moved;
    thread_local std::vector<Eigen::Vector3f> moved_to;
    b.Resize(static_cast<size_t>(p1 - p0) * kRaysPerProbe);
    for (int p = p0; p < p1; ++p) {
      position_[p] = ProbePosition(p);
      probe_rays(position_[p], &b.rays[static_cast<size_t>(p - p0) * kRaysPerProbe]);
    }
    b.Trace(*rays);
    moved.clear();
    moved_to.clear();
    for (int p = p0; p < p1; ++p) {
      float* m = &depth_[static_cast<size_t>(p) * kNumTexels];
      uint16_t* open = &open_[static_cast<size_t>(p) * kNumTexels];
      float t_back;
      Eigen::Vector3f d_back = Eigen::Vector3f::Zero();
      if (take_probe(b, static_cast<size_t>(p - p0) * kRaysPerProbe, m, open, &t_back, &d_back) <=
          max_back) {
        valid_[p] = under_floor(open) ? 0 : 1;
        continue;
      }
      // inside geometry: relocate just past the closest back face when that is within half a
      // spacing (Majercik et al. 2021, "Scaling probe-based real-time dynamic global
      // illumination for production", sec. 5), and keep the probe if it is outside there
      // (traced again below, the chunk's moved probes in one batch).
      if (!(t_back < 0.5f * spacing_)) continue;
      moved.push_back(p);
      moved_to.push_back(position_[p] + (t_back + kRelocateMargin * spacing_) * d_back);
    }
    if (moved.empty()) return;
    b.Resize(moved.size() * kRaysPerProbe);
    for (size_t k = 0; k < moved.size(); ++k) probe_rays(moved_to[k], &b.rays[k * kRaysPerProbe]);
    b.Trace(*rays);
    for (size_t k = 0; k < moved.size(); ++k) {
      const int p = moved[k];
      float* m = &depth_[static_cast<size_t>(p) * kNumTexels];
      uint16_t* open = &open_[static_cast<size_t>(p) * kNumTexels];
      float t2;
      Eigen::Vector3f d2;
      if (take_probe(b, k * kRaysPerProbe, m, open, &t2, &d2) <= max_back && !under_floor(open)) {
        valid_[p] = 1;
        position_[p] = moved_to[k];
      }
    }
  };
  const int64_t chunks = (num + kChunk - 1) / kChunk;
  ParallelForOrSerial(pool, chunks, trace);

  // refinement: a texel is refined when, in the first pass of the probe or of a valid probe
  // next to it (the 3 x 3 x 3 grid neighbourhood), its 3 x 3 texel neighbourhood holds both
  // open sky and geometry. the neighbours matter: a window a few metres away is missed by every
  // first-pass ray of some probes while the probes next to them see it.
  std::vector<TexelBits> near_open(num), near_closed(num);
  auto dilate = [&](int64_t p) {
    if (valid_[p])
      NearOpenClosed(&open_[static_cast<size_t>(p) * kNumTexels], &near_open[p], &near_closed[p]);
  };
  ParallelForOrSerial(pool, num, dilate);
  std::vector<int> refined(num, 0);
  // a chunk's refined texels (see the file comment): one ray per sub-cell, a texel's kSubRays
  // rays next to each other (one packet), the chunk's rays in one batch
  auto refine = [&](int64_t chunk) {
    const int p0 = static_cast<int>(chunk) * kChunk, p1 = std::min(num, p0 + kChunk);
    thread_local RayBatch b;
    thread_local std::vector<std::pair<int, int>> texels;  // (probe, texel)
    texels.clear();
    for (int p = p0; p < p1; ++p) {
      if (!valid_[p]) continue;
      const int c[3] = {p % n[0], (p / n[0]) % n[1], p / (n[0] * n[1])};
      TexelBits any_open, any_closed;
      for (int dz = -1; dz <= 1; ++dz)
        for (int dy = -1; dy <= 1; ++dy)
          for (int dx = -1; dx <= 1; ++dx) {
            const int i = c[0] + dx, j = c[1] + dy, k = c[2] + dz;
            if (i < 0 || j < 0 || k < 0 || i >= n[0] || j >= n[1] || k >= n[2]) continue;
            const int q = ProbeIndex(i, j, k);
            if (!valid_[q]) continue;
            any_open |= near_open[q];
            any_closed |= near_closed[q];
          }
      const TexelBits refine = any_open & any_closed;
      for (int t = 0; t < kNumTexels; ++t)
        if (refine[t]) texels.push_back({p, t});
    }
    if (texels.empty()) return;
    b.Resize(texels.size() * kSubRays);
    for (size_t i = 0; i < texels.size(); ++i)
      for (int c = 0; c < kSubRays; ++c) {
        Ray& r = b.rays[i * kSubRays + c];
        r.o = position_[texels[i].first];
        r.d = dirs.sub[static_cast<size_t>(texels[i].second) * kSubRays + c];
      }
    b.Trace(*rays);
    for (size_t i = 0; i < texels.size(); ++i) {
      uint16_t mask = 0;
      for (int c = 0; c < kSubRays; ++c)
        if (!b.did_hit[i * kSubRays + c]) mask |= static_cast<uint16_t>(1u << c);
      const auto [p, t] = texels[i];
      open_[static_cast<size_t>(p) * kNumTexels + t] = mask;
      ++refined[p];
    }
  };
  ParallelForOrSerial(pool, chunks, refine);
  for (int r : refined) num_refined_ += r;

  // links between valid neighbours along the grid axes that see each other (each one's ray
  // towards the other goes at least as far as the other probe), for the smoothing in Relight.
  links_.assign(num, 0);
  for (int p = 0; p < num; ++p) {
    if (!valid_[p]) continue;
    const int c[3] = {p % n[0], (p / n[0]) % n[1], p / (n[0] * n[1])};
    const int stride[3] = {1, n[0], n[0] * n[1]};
    for (int a = 0; a < 3; ++a) {
      if (c[a] + 1 >= n[a]) continue;
      const int q = p + stride[a];
      if (!valid_[q]) continue;
      const Eigen::Vector3f d = position_[q] - position_[p];
      const float dist = d.norm();
      if (depth_[static_cast<size_t>(p) * kNumTexels + TexelOf(d)] < dist ||
          depth_[static_cast<size_t>(q) * kNumTexels + TexelOf(-d)] < dist)
        continue;
      links_[p] |= static_cast<uint8_t>(1u << (2 * a));      // p -> +a neighbour
      links_[q] |= static_cast<uint8_t>(1u << (2 * a + 1));  // q -> -a neighbour
    }
  }

  // the lookups read the depths as bytes: 1 byte a texel keeps the table of the default
  // world (3740 probes) at under 1 MB, so lookups hit the cache (4 MB of floats did not).
  // rounding down makes a depth shorter by < far / 255 = 0.008 spacing, far below the
  // visibility tolerance: a probe is dropped at most that much sooner.
  depth_q_.resize(depth_.size());
  const float to_q = 255.0f / far;
  for (size_t i = 0; i < depth_.size(); ++i)
    depth_q_[i] = static_cast<uint8_t>(std::clamp(depth_[i] * to_q, 0.0f, 255.0f));
  depth_scale_ = far / 255.0f;
  depth_.clear();
  depth_.shrink_to_fit();

  // the lookup's per-cell corner positions (see cell_pos_), NaN for invalid probes.
  for (int c = 0; c < 8; ++c)
    corner_offset_[c] = (c & 1) + n[0] * (((c >> 1) & 1) + n[1] * (c >> 2));
  cell_pos_.assign(static_cast<size_t>(num) * 24, std::numeric_limits<float>::quiet_NaN());
  for (int p = 0; p < num; ++p) {
    const int i = p % n[0], j = (p / n[0]) % n[1], k = p / (n[0] * n[1]);
    if (i + 1 >= n[0] || j + 1 >= n[1] || k + 1 >= n[2]) continue;
    float* cell = &cell_pos_[static_cast<size_t>(p) * 24];
    for (int c = 0; c < 8; ++c) {
      const int idx = p + corner_offset_[c];
      if (!valid_[idx]) continue;
      for (int a = 0; a < 3; ++a) cell[8 * a + c] = position_[idx][a];
    }
  }
}

void SkyIrradianceVolume::Relight(const SkyModel& sky, ThreadPool* pool) {
  lit_sky_ = &sky;
  ++generation_;
  if (empty()) return;
  // per sub-cell of each texel: the integral of sky radiance x y_lm over its solid angle (one
  // sample at its centre), times the band's convolution weight, so that a probe's irradiance SH
  // is a sum over its open sub-cells; and per texel the sum over its sub-cells.
  constexpr int K = kOctSide, S = kSubSide;
  std::vector<double> sub_sh(static_cast<size_t>(kNumTexels) * kSubRays * kShFloats, 0.0);
  std::vector<double> texel_sh(static_cast<size_t>(kNumTexels) * kShFloats, 0.0);
  const double du = 2.0 / (K * S);
  for (int t = 0; t < kNumTexels; ++t) {
    const int ix = t % K, iy = t / K;
    double* acc = &texel_sh[static_cast<size_t>(t) * kShFloats];
    for (int c = 0; c < kSubRays; ++c) {
      const int a = c % S, b = c / S;
      const double u = -1 + (ix * S + a + 0.5) * du, v = -1 + (iy * S + b + 0.5) * du;
      const Eigen::Vector3d x = OctDecode(u, v);
      const double len = x.norm();
      const double dw = du * du / (len * len * len);  // solid angle of the sub-cell
      const Eigen::Vector3d w = x / len;
      const Eigen::Vector3d L = sky.Radiance(w.cast<float>()).cast<double>();
      double y[kNumSh];
      SkyShBasis(w.x(), w.y(), w.z(), y);
      double* sub = &sub_sh[(static_cast<size_t>(t) * kSubRays + c) * kShFloats];
      for (int k = 0; k < kNumSh; ++k)
        for (int ch = 0; ch < 3; ++ch) sub[k * 3 + ch] = L[ch] * y[k] * dw * kBandWeight[k];
      for (int i = 0; i < kShFloats; ++i) acc[i] += sub[i];
    }
  }
  const int num = num_probes();
  sh_.assign(static_cast<size_t>(num) * kShStride, 0.0f);
  constexpr int kChunk = 64;
  auto light = [&](int64_t chunk) {
    const int p0 = static_cast<int>(chunk) * kChunk, p1 = std::min(num, p0 + kChunk);
    for (int p = p0; p < p1; ++p) {
      double acc[kShFloats] = {};
      const uint16_t* open = &open_[static_cast<size_t>(p) * kNumTexels];
      for (int t = 0; t < kNumTexels; ++t) {
        if (open[t] == 0) continue;
        if (open[t] == kAllOpen) {
          const double* ts = &texel_sh[static_cast<size_t>(t) * kShFloats];
          for (int i = 0; i < kShFloats; ++i) acc[i] += ts[i];
          continue;
        }
        for (unsigned bits = open[t]; bits != 0; bits &= bits - 1) {
          const double* ss =
              &sub_sh[(static_cast<size_t>(t) * kSubRays + std::countr_zero(bits)) * kShFloats];
          for (int i = 0; i < kShFloats; ++i) acc[i] += ss[i];
        }
      }
      float* out = &sh_[static_cast<size_t>(p) * kShStride];
      for (int k = 0; k < kNumSh; ++k)
        for (int c = 0; c < 3; ++c) out[3 * SkyShSlot(k) + c] = static_cast<float>(acc[3 * k + c]);
    }
  };
  const int64_t chunks = (num + kChunk - 1) / kChunk;
  ParallelForOrSerial(pool, chunks, light);
  // smoothing: a [1 2 1] filter along x, then y, then z over linked neighbours (renormalised),
  // which spreads the quantisation of small sky openings (a window seen by a few texels) over
  // the neighbourhood without mixing probes on the two sides of a wall.
  std::vector<float> prev;
  const int stride[3] = {1, dims_[0], dims_[0] * dims_[1]};
  for (int a = 0; a < 3; ++a) {
    prev = sh_;
    for (int p = 0; p < num; ++p) {
      if (!valid_[p]) continue;
      float* out = &sh_[static_cast<size_t>(p) * kShStride];
      float w = 2;
      for (int i = 0; i < kShFloats; ++i) out[i] *= 2;
      for (int side = 0; side < 2; ++side) {
        if (!(links_[p] & (1u << (2 * a + side)))) continue;
        const int q = side == 0 ? p + stride[a] : p - stride[a];
        const float* in = &prev[static_cast<size_t>(q) * kShStride];
        for (int i = 0; i < kShFloats; ++i) out[i] += in[i];
        w += 1;
      }
      for (int i = 0; i < kShFloats; ++i) out[i] /= w;
    }
  }
}

void SkyIrradianceVolume::Update(const SceneDescription& scene, const WorldSnapshot& snapshot,
                                 const SkyModel& sky, ThreadPool* pool) {
  bool rebuild = !built_ || snapshot.X_WB.size() != built_static_poses_.size();
  for (size_t b = 0; !rebuild && b < snapshot.X_WB.size(); ++b)
    rebuild = IsStaticBody(scene, static_cast<int>(b)) &&
              snapshot.X_WB[b].matrix() != built_static_poses_[b].matrix();
  if (rebuild) Build(scene, snapshot.X_WB, pool);
  if (rebuild || lit_sky_ != &sky) Relight(sky, pool);
}

Eigen::Vector3f SkyIrradianceVolume::ProbeIrradiance(int probe, const Eigen::Vector3f& n_W) const {
  Eigen::Vector3f e;
  SkyProbeIrradiance(pod(), probe, n_W.x(), n_W.y(), n_W.z(), e.data());
  return e;
}

SkyVolumePod SkyIrradianceVolume::pod() const {
  SkyVolumePod v;
  for (int a = 0; a < 3; ++a) {
    v.dims[a] = dims_[a];
    v.origin[a] = origin_[a];
  }
  v.spacing = spacing_;
  v.inv_spacing = inv_spacing_;
  v.depth_scale = depth_scale_;
  for (int c = 0; c < 8; ++c) v.corner_offset[c] = corner_offset_[c];
  v.sh = sh_.data();
  v.cell_pos = cell_pos_.data();
  v.depth_q = depth_q_.data();
  return v;
}

bool SkyIrradianceVolume::LookupWeights(const Eigen::Vector3f& p_W, const Eigen::Vector3f& n_W,
                                        ProbeWeights* out) const {
  const Eigen::Vector3f q = p_W + (kNormalBias * spacing_) * n_W;
  const Eigen::Vector3f g = (q - origin_) * inv_spacing_;
  const int nx = dims_[0], ny = dims_[1], nz = dims_[2];
  if (!(g.x() >= 0 && g.y() >= 0 && g.z() >= 0 && g.x() <= nx - 1 && g.y() <= ny - 1 &&
        g.z() <= nz - 1))
    return false;
  const int i0 = std::min(static_cast<int>(g.x()), nx - 2);
  const int j0 = std::min(static_cast<int>(g.y()), ny - 2);
  const int k0 = std::min(static_cast<int>(g.z()), nz - 2);
  const float fx = g.x() - i0, fy = g.y() - j0, fz = g.z() - k0;
  const float bias = kNormalBias * spacing_;
  const float tol = kVisibilityTolerance * spacing_;
  const float inv_tol = 1.0f / tol;
  const int base = ProbeIndex(i0, j0, k0);
  out->base = base;
  // probe index of corner c = dx + 2 dy + 4 dz: base + corner[c].
  const int32_t* corner = corner_offset_.data();

  // the 8 corners as two 4-lane halves (dz = 0, 1), every lane computing every branch; the
  // same operations in the same order as the one-probe-at-a-time form in the file comment,
  // so the result is bit for bit that of evaluating the corners one by one.
  const float* cell = &cell_pos_[static_cast<size_t>(base) * 24];
  const F4 qx = Splat4(q.x()), qy = Splat4(q.y()), qz = Splat4(q.z());
  const F4 wx_tri = {1 - fx, fx, 1 - fx, fx}, wy_tri = {1 - fy, 1 - fy, fy, fy};
  const F4 wxy_tri = wx_tri * wy_tri;
  float* w = out->w;
  alignas(16) int32_t texel[8];
  F4 r[2], d_n_r[2], tri[2];
  unsigned& front = out->front;
  front = 0;
  for (int h = 0; h < 2; ++h) {
    const F4 dx = Load4(cell + 4 * h) - qx, dy = Load4(cell + 8 + 4 * h) - qy,
             dz = Load4(cell + 16 + 4 * h) - qz;
    // probes behind the surface's tangent plane at p never light it (invalid probes sit at
    // NaN, which fails the test too); the octahedral texel of -d.
    I4 in_front, tex;
    SkyCornerGeometry<F4Lanes>(dx, dy, dz, n_W.x(), n_W.y(), n_W.z(), bias, &in_front, &r[h],
                               &d_n_r[h], &tex);
    front |= MoveMask4(in_front) << (4 * h);
    tri[h] = wxy_tri * (h ? fz : 1 - fz);
    // offset of the texel in depth_q_ from the cell's first probe.
    Store4(texel + 4 * h, tex + kNumTexels * Load4(corner + 4 * h));
  }
  out->active = 0;
  if (front == 0) return true;
  // the depth of each probe's ray towards q.
  const uint8_t* dq = &depth_q_[static_cast<size_t>(base) * kNumTexels];
  alignas(16) int32_t depth_q[8];
  for (int c = 0; c < 8; c += 2) {
    // the offsets (>= 0) two at a time: one load instead of two lane extractions.
    uint64_t pair;
    std::memcpy(&pair, texel + c, sizeof pair);
    depth_q[c] = dq[static_cast<uint32_t>(pair)];
    depth_q[c + 1] = dq[pair >> 32];
  }
  unsigned& active = out->active;
  for (int h = 0; h < 2; ++h) {
    // the probe sees q if its ray towards q (nearest texel) goes at least r far; the weight
    // ramps down to 0 over tol beyond that. r <= 1e-6: q on the probe, trilinear weight only.
    const F4 wh = SkyCornerWeight<F4Lanes>(r[h], d_n_r[h], tri[h], Load4(depth_q + 4 * h),
                                           depth_scale_, tol, inv_tol);
    Store4(w + 4 * h, wh);
    active |= MoveMask4(wh > 0.0f) << (4 * h);
  }
  active &= front;
  return true;
}

Eigen::Vector3f SkyIrradianceVolume::Irradiance(const Eigen::Vector3f& p_W,
                                                const Eigen::Vector3f& n_W,
                                                const SkyModel& sky) const {
  if (empty()) return sky.Irradiance(n_W);
  ProbeWeights pw;
  if (!LookupWeights(p_W, n_W, &pw)) return sky.Irradiance(n_W);
  if (pw.front == 0) return Eigen::Vector3f::Zero();
  const int base = pw.base;
  const int32_t* corner = corner_offset_.data();
  const float* w = pw.w;
  const unsigned active = pw.active;
  Eigen::Vector3f e = Eigen::Vector3f::Zero();
  float y[kNumSh];
  SkyShBasis(n_W.x(), n_W.y(), n_W.z(), y);
  if (active != 0) {
    // the weighted sum of the probes' irradiance SH, evaluated once at the end. on a face
    // whose normal is an axis (exact zeros in n), y[k] = 0 exactly for every k but 0, 3, 6, 8
    // (x), 0, 2, 6 (z) or 0, 1, 6, 8 (y).
    const float* sh_base = &sh_[static_cast<size_t>(base) * kShStride];
    if (n_W.y() == 0 && n_W.z() == 0)
      e = WeightedSh<0, 3, 0, 3, 6, 8>(sh_base, corner, w, active, y);
    else if (n_W.x() == 0 && n_W.y() == 0)
      e = WeightedSh<1, 4, 0, 2, 6>(sh_base, corner, w, active, y);
    else if (n_W.x() == 0 && n_W.z() == 0)
      e = WeightedSh<0, 5, 0, 1, 6, 8>(sh_base, corner, w, active, y);
    else
      e = WeightedSh<0, kShStride / 4, 0, 1, 2, 3, 4, 5, 6, 7, 8>(sh_base, corner, w, active, y);
  } else if (const int dark = DarkestFrontCorner(pw, n_W); dark >= 0) {
    // no probe sees q: the darkest valid probe in front of the surface.
    e = ProbeIrradiance(base + corner[dark], n_W);
  }
  return e.cwiseMax(0.0f);
}

int SkyIrradianceVolume::DarkestFrontCorner(const ProbeWeights& pw,
                                            const Eigen::Vector3f& n_W) const {
  return SkyDarkestFrontCorner(pod(), pw.base, pw.front, n_W.x(), n_W.y(), n_W.z());
}

void SkyIrradianceVolume::Blend(const Eigen::Vector3f& p_W, const Eigen::Vector3f& ng_W,
                                ShBlend* out) const {
  std::fill_n(out->c, 32, 0.0f);
  out->open_sky = false;
  ProbeWeights pw;
  if (empty() || !LookupWeights(p_W, ng_W, &pw)) {
    out->open_sky = true;
    return;
  }
  if (pw.front == 0) return;
  const int32_t* corner = corner_offset_.data();
  const float* sh_base = &sh_[static_cast<size_t>(pw.base) * kShStride];
  if (pw.active != 0) {
    // the weighted mean of the probes' SH, all 7 packets.
    F4 acc[kShStride / 4];
    const float wsum =
        SkyAccumulateSh<F4Lanes, 0, kShStride / 4>(sh_base, corner, pw.w, pw.active, acc);
    const F4 inv = Splat4(1.0f / wsum);
    for (int i = 0; i < kShStride / 4; ++i) Store4(out->c + 4 * i, acc[i] * inv);
    return;
  }
  // no probe sees the point: the darkest valid probe in front of the surface (at ng_W).
  if (const int dark = DarkestFrontCorner(pw, ng_W); dark >= 0)
    std::copy_n(sh_base + corner[dark] * kShStride, kShStride, out->c);
}

Eigen::Vector3f SkyIrradianceVolume::IrradianceAt(const ShBlend& blend, const Eigen::Vector3f& n_W,
                                                  const SkyModel& sky) const {
  Eigen::Vector3f e;
  SkyVolumeIrradianceAt(sky.pod(), blend.c, blend.open_sky, n_W.data(), e.data());
  return e;
}

Eigen::Vector3f SkyIrradianceVolume::ProbeAmbient(int probe) const {
  // the irradiance SH's l = 0 coefficient is A0 L00 = pi L00; the mean radiance over the
  // sphere is L00 Y00.
  const float* c = &sh_[static_cast<size_t>(probe) * kShStride + 3 * SkyShSlot(0)];
  constexpr float kY00OverPi = static_cast<float>(0.282094791773878 / kPi);
  return Eigen::Vector3f(c[0], c[1], c[2]) * kY00OverPi;
}

Eigen::Vector3f SkyIrradianceVolume::AmbientRadiance(const Eigen::Vector3f& p_W,
                                                     const Eigen::Vector3f& open_sky) const {
  Eigen::Vector3f out;
  SkyVolumeAmbientRadiance(pod(), p_W.data(), open_sky.data(), out.data());
  return out;
}

}  // namespace penumbra

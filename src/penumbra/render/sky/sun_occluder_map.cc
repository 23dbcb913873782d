#include "penumbra/render/sky/sun_occluder_map.h"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/geometry/static_geometry.h"
#include "penumbra/render/sky/occluder_math.h"

#if defined(__AVX512F__)
#include <immintrin.h>
#endif

namespace penumbra {

void SunOccluderMap::Build(const SceneDescription& scene, const std::vector<Pose>& X_WB,
                           int light_index, const Eigen::Vector3f& to_sun_W,
                           float cos_angular_radius, ThreadPool* pool) {
  if (X_WB.size() != scene.bodies.size())
    throw Error("SunOccluderMap::Build: " + std::to_string(X_WB.size()) +
                " body poses, scene has " + std::to_string(scene.bodies.size()) + " bodies");
  built_ = true;
  built_static_poses_ = X_WB;
  built_to_sun_ = to_sun_W;
  built_cos_radius_ = cos_angular_radius;
  light_index_ = light_index;
  boxes_.clear();
  cells_.clear();
  full_.clear();
  nx_ = ny_ = nz_ = 0;
  // the occluders: static visible boxes, shrunk.
  for (const Geom& g : scene.geoms) {
    if (g.shape != GeomShape::kBox || !IsStaticVisible(scene, g)) continue;
    const Eigen::Vector3d half = g.size - Eigen::Vector3d::Constant(kShrinkM);
    if (!(half.minCoeff() > 0) || !half.allFinite()) continue;
    const Pose X_WG = X_WB[g.body] * g.X_BG;
    Box b;
    b.R_GW = X_WG.linear().transpose().cast<float>();
    b.p_W = X_WG.translation().cast<float>();
    b.half = half.cast<float>();
    if (!b.R_GW.allFinite() || !b.p_W.allFinite()) continue;
    boxes_.push_back(b);
  }
  Eigen::Vector3d lo, hi;
  StaticGeoms(scene, X_WB, &lo, &hi);
  if (boxes_.empty() || !(lo.array() <= hi.array()).all()) return;
  // cells: kCellM, enlarged until the grid holds <= kMaxCells.
  double cell = kCellM;
  int nx = 0, ny = 0, nz = 0;
  for (;;) {
    nx = std::max(1, static_cast<int>(std::ceil((hi.x() - lo.x()) / cell)));
    ny = std::max(1, static_cast<int>(std::ceil((hi.y() - lo.y()) / cell)));
    nz = std::max(1, static_cast<int>(std::ceil((hi.z() - lo.z()) / cell)));
    if (static_cast<int64_t>(nx) * ny * nz <= kMaxCells) break;
    cell *= 1.25;
  }
  nx_ = nx, ny_ = ny, nz_ = nz;
  cell_m_ = static_cast<float>(cell);
  inv_cell_ = static_cast<float>(1.0 / cell);
  origin_ = lo.cast<float>();
  cells_.assign(static_cast<size_t>(nx) * ny * nz * kCandidates, -1);
  full_.assign(static_cast<size_t>(nx) * ny * nz, 0);
  // the directions of the sun's disc for the whole-cell test: 8 directions on a cone that
  // the octagon they span circumscribes the disc's cone widened by kDiscMarginRad (its
  // half-angle over cos(pi / 8)); rays within the disc widened by half that margin are the
  // ones a full cell skips (disc_sin2_), which leaves room for float rounding.
  const float half = std::acos(std::clamp(cos_angular_radius, -1.0f, 1.0f));
  const float wide =
      std::atan(std::tan(half + kDiscMarginRad) / std::cos(static_cast<float>(M_PI) / 8));
  const float inner = half + 0.5f * kDiscMarginRad;
  disc_sin2_ = std::sin(inner) * std::sin(inner);
  std::vector<Eigen::Vector3f> disc;
  {
    const Eigen::Vector3f a =
        std::abs(to_sun_W.x()) < 0.9f ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitY();
    const Eigen::Vector3f t = to_sun_W.cross(a).normalized(), b = to_sun_W.cross(t);
    for (int k = 0; k < 8; ++k) {
      const float phi = static_cast<float>(k) * static_cast<float>(M_PI) / 4;
      disc.push_back(
          (std::cos(wide) * to_sun_W + std::sin(wide) * (std::cos(phi) * t + std::sin(phi) * b))
              .normalized());
    }
  }
  const int num_boxes = static_cast<int>(boxes_.size());
  std::vector<float> radius(num_boxes);
  for (int bi = 0; bi < num_boxes; ++bi) radius[bi] = boxes_[bi].half.norm() + kShrinkM;
  const float cell_radius = 0.8661f * cell_m_;  // half the cell's diagonal, rounded up
  // one z-y row of cells per task: per cell, every box scored by how many of the 9 rays
  // (centre, corners) towards the sun it blocks; the best kCandidates with a score > 0.
  auto row = [&](int64_t r) {
    const int iy = static_cast<int>(r % ny), iz = static_cast<int>(r / ny);
    std::vector<std::pair<int, int>> scored;  // (-score, box)
    for (int ix = 0; ix < nx; ++ix) {
      const Eigen::Vector3f c0 =
          origin_ + cell_m_ * Eigen::Vector3f(static_cast<float>(ix), static_cast<float>(iy),
                                              static_cast<float>(iz));
      std::array<Eigen::Vector3f, 9> pts;
      pts[0] = c0 + Eigen::Vector3f::Constant(0.5f * cell_m_);
      for (int k = 0; k < 8; ++k)
        pts[k + 1] = c0 + cell_m_ * Eigen::Vector3f(static_cast<float>(k & 1),
                                                    static_cast<float>((k >> 1) & 1),
                                                    static_cast<float>((k >> 2) & 1));
      scored.clear();
      for (int bi = 0; bi < num_boxes; ++bi) {
        // a box whose bounding sphere stays clear of the cell's rays blocks none of them.
        const Eigen::Vector3f rel = boxes_[bi].p_W - pts[0];
        const float along = rel.dot(to_sun_W);
        const float reach = radius[bi] + cell_radius;
        if (along < -reach || (rel - along * to_sun_W).squaredNorm() > reach * reach) continue;
        int score = 0;
        for (const Eigen::Vector3f& p : pts) score += HitsBox(boxes_[bi], p, to_sun_W) ? 1 : 0;
        if (score > 0) scored.emplace_back(-score, bi);
      }
      const int keep = std::min<int>(kCandidates, static_cast<int>(scored.size()));
      std::partial_sort(scored.begin(), scored.begin() + keep, scored.end());
      const size_t cell_index = (static_cast<size_t>(iz) * ny + iy) * nx + ix;
      for (int c = 0; c < keep; ++c) cells_[cell_index * kCandidates + c] = scored[c].second;
      // the whole cell: one candidate that blocks the rays from all 8 corners in every
      // direction of `disc` blocks every ray from the cell towards the sun's disc (file
      // comment).
      for (int c = 0; c < keep && scored[c].first == -9 && !full_[cell_index]; ++c) {
        bool all = true;
        for (int k = 1; k < 9 && all; ++k)
          for (const Eigen::Vector3f& d : disc)
            if (!CrossesBoxAhead(boxes_[scored[c].second], pts[k], d)) {
              all = false;
              break;
            }
        full_[cell_index] = all ? 1 : 0;
      }
    }
  };
  ParallelForOrSerial(pool, static_cast<int64_t>(ny) * nz, row);
}

void SunOccluderMap::Update(const SceneDescription& scene, const WorldSnapshot& snapshot,
                            const LightSampler& lights, ThreadPool* pool) {
  int sun = -1;
  for (int j = 0; j < lights.size() && sun < 0; ++j)
    if (lights.lights()[j].type == Light::Type::kDirectional && lights.lights()[j].cast_shadow)
      sun = j;
  if (sun < 0) {
    boxes_.clear();
    cells_.clear();
    full_.clear();
    built_ = false;
    return;
  }
  const Eigen::Vector3f to_sun = -lights.lights()[sun].direction_W.normalized();
  const float cos_radius = lights.lights()[sun].cos_angular_radius;
  bool rebuild =
      !built_ || sun != light_index_ || cos_radius != built_cos_radius_ ||
      snapshot.X_WB.size() != built_static_poses_.size() ||
      !(to_sun.dot(built_to_sun_) >= static_cast<float>(std::cos(kRebuildDeg * M_PI / 180.0)));
  for (size_t b = 0; !rebuild && b < snapshot.X_WB.size(); ++b)
    rebuild = IsStaticBody(scene, static_cast<int>(b)) &&
              snapshot.X_WB[b].matrix() != built_static_poses_[b].matrix();
  if (rebuild) Build(scene, snapshot.X_WB, sun, to_sun, cos_radius, pool);
}

bool SunOccluderMap::HitsBox(const Box& b, const Eigen::Vector3f& o_W,
                             const Eigen::Vector3f& d_W) const {
  const Eigen::Vector3f o = b.R_GW * (o_W - b.p_W);
  const Eigen::Vector3f d = b.R_GW * d_W;
  return BoxChordAhead(o.data(), d.data(), b.half.data(), d_W.norm(), kMinChordM, true);
}

bool SunOccluderMap::CrossesBoxAhead(const Box& b, const Eigen::Vector3f& o_W,
                                     const Eigen::Vector3f& d_W) const {
  const Eigen::Vector3f o = b.R_GW * (o_W - b.p_W);
  const Eigen::Vector3f d = b.R_GW * d_W;
  return BoxChordAhead(o.data(), d.data(), b.half.data(), d_W.norm(), kMinChordM, false);
}

int SunOccluderMap::CellOf(const Eigen::Vector3f& p_W) const {
  const Eigen::Vector3f f = (p_W - origin_) * inv_cell_;
  if (!(f.x() >= 0 && f.y() >= 0 && f.z() >= 0 && f.x() < nx_ && f.y() < ny_ && f.z() < nz_))
    return -1;
  return (static_cast<int>(f.z()) * ny_ + static_cast<int>(f.y())) * nx_ + static_cast<int>(f.x());
}

bool SunOccluderMap::Blocks(const Eigen::Vector3f& o_W, const Eigen::Vector3f& d_W) const {
  if (empty() || !o_W.allFinite() || !d_W.allFinite() || !(d_W.squaredNorm() > 0)) return false;
  const int cell = CellOf(o_W);
  if (cell < 0) return false;
  if (full_[cell]) {
    const Eigen::Vector3f d = d_W.normalized();
    if (d.dot(built_to_sun_) > 0 && d.cross(built_to_sun_).squaredNorm() <= disc_sin2_) return true;
  }
  for (int c = 0; c < kCandidates; ++c) {
    const int32_t bi = cells_[static_cast<size_t>(cell) * kCandidates + c];
    if (bi < 0) break;
    if (HitsBox(boxes_[bi], o_W, d_W)) return true;
  }
  return false;
}

#if defined(__AVX512F__)
namespace {

// one Lanes as an AVX-512 register and back.
inline __m512 Load(const Lanes& a) { return _mm512_loadu_ps(a.data()); }

// the lanes of x that are finite (x - x == 0 is false for inf and NaN).
inline __mmask16 FiniteLanes(__m512 x) {
  return _mm512_cmp_ps_mask(_mm512_sub_ps(x, x), _mm512_setzero_ps(), _CMP_EQ_OQ);
}

// a0 b0 + (a1 b1 + a2 b2): the order in which Eigen sums a 3-vector's dot product,
// squaredNorm and each row of a fixed-size 3x3 product (measured with this build's flags; also
// render/light/shadow_window_math.h).
inline __m512 Dot3(__m512 a0, __m512 a1, __m512 a2, __m512 b0, __m512 b1, __m512 b2) {
  return _mm512_add_ps(_mm512_mul_ps(a0, b0),
                       _mm512_add_ps(_mm512_mul_ps(a1, b1), _mm512_mul_ps(a2, b2)));
}

// row i of R times (x, y, z), as Eigen's R * v in HitsBox.
inline __m512 RowTimes(const Eigen::Matrix3f& R, int i, __m512 x, __m512 y, __m512 z) {
  return Dot3(_mm512_set1_ps(R(i, 0)), _mm512_set1_ps(R(i, 1)), _mm512_set1_ps(R(i, 2)), x, y, z);
}

}  // namespace
#endif

LaneMask SunOccluderMap::BlocksLanes(const Vec3Lanes& o_W, const Vec3Lanes& d_W,
                                     const LaneMask& active) const {
  LaneMask blocked;
  if (empty() || !active.any()) return blocked;
#if defined(__AVX512F__)
  // Blocks for 16 lanes at once, bit for bit: the same float operations per lane in the same
  // order (tests/render/sky/sun_occluder_map_test.cc compares every lane with Blocks). lanes that
  // share a cell (most of a tile row) test its candidates together.
  static_assert(kLanes == 16, "one AVX-512 register of lanes");
  const __m512 ox = Load(o_W.x), oy = Load(o_W.y), oz = Load(o_W.z);
  const __m512 dx = Load(d_W.x), dy = Load(d_W.y), dz = Load(d_W.z);
  const __m512 zero = _mm512_setzero_ps();
  // finite rays with a direction (Blocks' first test); d2 = |d|^2 as Eigen's squaredNorm.
  const __m512 d2 = Dot3(dx, dy, dz, dx, dy, dz);
  __mmask16 todo = static_cast<__mmask16>(active.bits()) & FiniteLanes(ox) & FiniteLanes(oy) &
                   FiniteLanes(oz) & FiniteLanes(dx) & FiniteLanes(dy) & FiniteLanes(dz) &
                   _mm512_cmp_ps_mask(d2, zero, _CMP_GT_OQ);
  if (todo == 0) return blocked;
  // CellOf: f = (o - origin) inv_cell inside [0, n) per axis, cell = (z ny + y) nx + x.
  const __m512 inv = _mm512_set1_ps(inv_cell_);
  const __m512 fx = _mm512_mul_ps(_mm512_sub_ps(ox, _mm512_set1_ps(origin_.x())), inv);
  const __m512 fy = _mm512_mul_ps(_mm512_sub_ps(oy, _mm512_set1_ps(origin_.y())), inv);
  const __m512 fz = _mm512_mul_ps(_mm512_sub_ps(oz, _mm512_set1_ps(origin_.z())), inv);
  auto inside = [&](__m512 f, int n) {
    return _mm512_cmp_ps_mask(f, zero, _CMP_GE_OQ) &
           _mm512_cmp_ps_mask(f, _mm512_set1_ps(static_cast<float>(n)), _CMP_LT_OQ);
  };
  todo &= inside(fx, nx_) & inside(fy, ny_) & inside(fz, nz_);
  if (todo == 0) return blocked;
  const __m512i nx = _mm512_set1_epi32(nx_), ny = _mm512_set1_epi32(ny_);
  const __m512i cell = _mm512_add_epi32(
      _mm512_mullo_epi32(_mm512_add_epi32(_mm512_mullo_epi32(_mm512_cvttps_epi32(fz), ny),
                                          _mm512_cvttps_epi32(fy)),
                         nx),
      _mm512_cvttps_epi32(fx));
  alignas(64) int32_t cells[kLanes];
  _mm512_store_si512(cells, cell);
  // |d| (HitsBox's d_len) and, for whole cells, the unit direction d / |d| (Eigen's
  // normalized divides by the square root).
  const __m512 d_len = _mm512_sqrt_ps(d2);
  const __m512 kInf = _mm512_set1_ps(std::numeric_limits<float>::infinity());
  const __m512 min_chord = _mm512_set1_ps(kMinChordM);
  __mmask16 hit = 0;
  while (todo != 0) {
    const int c = cells[std::countr_zero(static_cast<unsigned>(todo))];
    const __mmask16 group = _mm512_mask_cmpeq_epi32_mask(todo, cell, _mm512_set1_epi32(c));
    todo &= static_cast<__mmask16>(~group);
    __mmask16 open = group;
    if (full_[c]) {
      const __m512 ux = _mm512_div_ps(dx, d_len), uy = _mm512_div_ps(dy, d_len),
                   uz = _mm512_div_ps(dz, d_len);
      const float sx = built_to_sun_.x(), sy = built_to_sun_.y(), sz = built_to_sun_.z();
      const __m512 dot =
          Dot3(ux, uy, uz, _mm512_set1_ps(sx), _mm512_set1_ps(sy), _mm512_set1_ps(sz));
      const __m512 cx = _mm512_sub_ps(_mm512_mul_ps(uy, _mm512_set1_ps(sz)),
                                      _mm512_mul_ps(uz, _mm512_set1_ps(sy)));
      const __m512 cy = _mm512_sub_ps(_mm512_mul_ps(uz, _mm512_set1_ps(sx)),
                                      _mm512_mul_ps(ux, _mm512_set1_ps(sz)));
      const __m512 cz = _mm512_sub_ps(_mm512_mul_ps(ux, _mm512_set1_ps(sy)),
                                      _mm512_mul_ps(uy, _mm512_set1_ps(sx)));
      const __m512 c2 = Dot3(cx, cy, cz, cx, cy, cz);
      const __mmask16 on_disc = _mm512_mask_cmp_ps_mask(open, dot, zero, _CMP_GT_OQ) &
                                _mm512_cmp_ps_mask(c2, _mm512_set1_ps(disc_sin2_), _CMP_LE_OQ);
      hit |= on_disc;
      open &= static_cast<__mmask16>(~on_disc);
    }
    for (int k = 0; k < kCandidates && open != 0; ++k) {
      const int32_t bi = cells_[static_cast<size_t>(c) * kCandidates + k];
      if (bi < 0) break;
      const Box& b = boxes_[bi];
      // HitsBox: the ray in the box frame, then BoxChordAhead (entry ahead) per lane.
      const __m512 px = _mm512_sub_ps(ox, _mm512_set1_ps(b.p_W.x()));
      const __m512 py = _mm512_sub_ps(oy, _mm512_set1_ps(b.p_W.y()));
      const __m512 pz = _mm512_sub_ps(oz, _mm512_set1_ps(b.p_W.z()));
      const __m512 o[3] = {RowTimes(b.R_GW, 0, px, py, pz), RowTimes(b.R_GW, 1, px, py, pz),
                           RowTimes(b.R_GW, 2, px, py, pz)};
      const __m512 d[3] = {RowTimes(b.R_GW, 0, dx, dy, dz), RowTimes(b.R_GW, 1, dx, dy, dz),
                           RowTimes(b.R_GW, 2, dx, dy, dz)};
      __m512 t_near = zero, t_far = kInf;
      __mmask16 ok = open;
      for (int a = 0; a < 3; ++a) {
        const __m512 h = _mm512_set1_ps(b.half[a]);
        const __m512 nh = _mm512_set1_ps(-b.half[a]);
        // d_a == 0: inside the slab or no hit; else the slab's entry and exit.
        const __mmask16 flat = _mm512_cmp_ps_mask(d[a], zero, _CMP_EQ_OQ);
        const __mmask16 in_slab =
            _mm512_cmp_ps_mask(o[a], h, _CMP_LT_OQ) & _mm512_cmp_ps_mask(o[a], nh, _CMP_GT_OQ);
        ok &= static_cast<__mmask16>(~flat | in_slab);
        const __m512 inv_d = _mm512_div_ps(_mm512_set1_ps(1.0f), d[a]);
        __m512 t0 = _mm512_mul_ps(_mm512_sub_ps(nh, o[a]), inv_d);
        __m512 t1 = _mm512_mul_ps(_mm512_sub_ps(h, o[a]), inv_d);
        const __mmask16 swap = _mm512_cmp_ps_mask(t0, t1, _CMP_GT_OQ);
        const __m512 lo = _mm512_mask_blend_ps(swap, t0, t1);
        const __m512 hi = _mm512_mask_blend_ps(swap, t1, t0);
        // t_near = lo > t_near ? lo : t_near; t_far = hi < t_far ? hi : t_far (flat axes skip).
        const __mmask16 slab = static_cast<__mmask16>(~flat);
        t_near =
            _mm512_mask_blend_ps(slab & _mm512_cmp_ps_mask(lo, t_near, _CMP_GT_OQ), t_near, lo);
        t_far = _mm512_mask_blend_ps(slab & _mm512_cmp_ps_mask(hi, t_far, _CMP_LT_OQ), t_far, hi);
      }
      const __mmask16 through =
          ok & _mm512_cmp_ps_mask(t_far, kInf, _CMP_LT_OQ) &
          _mm512_cmp_ps_mask(t_near, zero, _CMP_GT_OQ) &
          _mm512_cmp_ps_mask(_mm512_mul_ps(_mm512_sub_ps(t_far, t_near), d_len), min_chord,
                             _CMP_GT_OQ);
      hit |= through;
      open &= static_cast<__mmask16>(~through);
    }
  }
  return LaneMask(hit);
#else
  for (int k = 0; k < kLanes; ++k)
    if (active[k]) blocked[k] = Blocks(o_W.Lane(k), d_W.Lane(k));
  return blocked;
#endif
}

}  // namespace penumbra

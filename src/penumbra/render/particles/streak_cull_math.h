#pragma once
// the per-drop decision of ParticleStreaks::Build (render/particles/particle_streaks.h) written
// once for the CPU and the CUDA backend's device culling (render/cuda/cuda_streak_cull.h): a drop
// is nothing (no radius, sheltered, behind the near plane, outside the camera's view pyramid), a
// rain streak culled as invisible (kRainCullContrast over the homogeneous media's transmittance) or
// a streak (its far end, widened radius and coverage). plain data only (Float3, the pods below): no
// Eigen. every product and sum is rounded on its own (MulRn, AddRn, SubRn) and dot products and
// squared norms are summed as Eigen sums a Vector3f's (EigenDotRn: x + (y + z)), so that the device
// decides every drop as the CPU does, to the bit; division and square root are IEEE on both
// processors (no fast math), and the exponentials (the rain culling in media) are ExpRn
// (core/exp_rn.h), whose bits are the same on both (expf's may differ by an ulp between glibc and
// CUDA).

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/core/exp_rn.h"
#include "penumbra/core/host_device.h"
#include "penumbra/render/media/media_scene_math.h"
#include "penumbra/render/particles/particle_math.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

/// rain streaks whose coverage times media transmittance from the camera is below this are
/// not drawn in the realtime tier (one 8-bit step of display-linear contrast; see
/// particle_streaks.h).
constexpr float kRainCullContrast = 1.0f / 255.0f;

/// the error ParticleStreaks::Build and the device culling report for the first drop with a
/// non-finite position, velocity or radius: drop `index` of particle set `set` (host only).
inline ConfigError NonFiniteParticleError(size_t set, size_t index) {
  return ConfigError("", 0, "effects.particles[" + std::to_string(set) + "]",
                     "particle " + std::to_string(index) + " has a non-finite value");
}

/// a ShelterMap as the shared test reads it (ShelterMap::pod): roof heights per plan cell.
struct ShelterPod {
  const float* roof = nullptr;  ///< [ix + nx iy] roof z (world, m), -inf where nothing; null: none
  int32_t nx = 0, ny = 0;       ///< cells along x and y
  float origin_x = 0, origin_y = 0;  ///< plan position of cell 0's low corner, m
  float inv_cell = 0;                ///< 1 / cell size, 1/m
  float margin = 0;                  ///< sheltered below the roof by more than this, m
  uint64_t version = 0;              ///< the map's build count: a new roof has a new version
};

/// roof height (world z, m) of the cell of `s` holding (x, y); -inf outside the grid
/// (ShelterMap::RoofHeight).
PB_HOST_DEVICE inline float ShelterRoofHeight(const ShelterPod& s, float x, float y) {
  const float fx = MulRn(x - s.origin_x, s.inv_cell), fy = MulRn(y - s.origin_y, s.inv_cell);
  if (!(fx >= 0 && fy >= 0 && fx < static_cast<float>(s.nx) && fy < static_cast<float>(s.ny)))
    return -INFINITY;
  return s.roof[static_cast<size_t>(fy) * static_cast<size_t>(s.nx) + static_cast<size_t>(fx)];
}

/// true when `s` has a roof above p (world, m) by more than its margin (ShelterMap::Sheltered);
/// false for an empty map, outside the grid and for non-finite points.
PB_HOST_DEVICE inline bool ShelterSheltered(const ShelterPod& s, const Float3& p) {
  if (s.roof == nullptr) return false;
  return p.z < ShelterRoofHeight(s, p.x, p.y) - s.margin;
}

/// per frame, per homogeneous medium: what the rain culling needs of it that does not depend on
/// the streak.
struct StreakCullMedium {
  int32_t bounded = 0;      ///< has a box
  int32_t cam_in = 0;       ///< the camera is in its box (or it is unbounded)
  float sigma_t_min = 0;    ///< smallest channel of sigma_t, 1/m
  float cam_density = 0;    ///< relative density at the camera's height
  float falloff = 0;        ///< height falloff, 1/m (MediumHeightDensity)
  float base = 0;           ///< height below which the density is 1, m
  Float3 box_min, box_max;  ///< its box (world, m), when bounded
};

/// per particle set: how the decision treats its drops.
struct StreakCullSet {
  int32_t rain = 0;       ///< ParticleKind::kRain (culled as invisible in the realtime tier)
  int32_t sheltered = 0;  ///< ShelterApplies: the shelter map leaves its sheltered drops out
};

/// per frame: the camera, exposure and culling inputs of the decision (StreakCullSetupOf,
/// particle_streaks.h, fills it).
struct StreakCullFrame {
  Float3 cam_o;        ///< the camera's origin X_WO (world, m)
  float T = 0;         ///< exposure time, s (>= 0)
  float fx_px = 1;     ///< focal length, px
  float four_fx2 = 4;  ///< 4 fx_px^2
  /// the realtime tier's pixel-centre rays: the near-plane test and the rain culling apply.
  int32_t pixel_hits = 0;
  /// row 2 of R_OW (world to optical frame) and p_OW.z: a point's optical-frame depth.
  Float3 depth_row;
  float depth_offset = 0;
  /// the camera's rays through a lens without distortion: the frustum test applies.
  int32_t frustum = 0;
  /// the camera moves during the exposure: the planes' margins turn and shift apply.
  int32_t moving = 0;
  Float3 side_W[4];           ///< outward unit normals (world) of the view pyramid's side planes
  float turn = 0, shift = 0;  ///< StreakMotion's bounds of the planes' motion
  /// the homogeneous media (RainInvisible; null when num_media is 0) and the shelter.
  const StreakCullMedium* media = nullptr;
  int32_t num_media = 0;
  ShelterPod shelter;
};

/// what StreakCullDrop decided of a drop.
enum StreakCullVerdict : int32_t {
  kStreakNone = 0,    ///< no streak: no radius, sheltered, or never drawn (near plane, frustum)
  kStreakCulled = 1,  ///< a rain streak culled as invisible (counted)
  kStreakDrawn = 2,   ///< a streak: StreakCullOut holds its fields
};

/// a drawn drop's streak: the capsule around [p, q] (world, m) of radius r_wide (m, widened to
/// half a pixel at its nearest distance) and coverage alpha in (0, 1].
struct StreakCullOut {
  Float3 q;
  float r_wide = 0;
  float alpha = 0;
};

/// the optical-frame depth (m) of x (world, m): (R_OW x + p_OW).z as Eigen rounds it.
PB_HOST_DEVICE inline float StreakCullDepth(const StreakCullFrame& f, const Float3& x) {
  return AddRn(EigenDotRn(f.depth_row, x), f.depth_offset);
}

/// true when the capsule around [p, q] of radius r widened to r_wide = max(r, 0.5 dist / fx)
/// (dist <= the larger distance D of p and q from the camera) lies wholly beyond one side
/// plane of the view pyramid: both ends farther than r and 0.5 D / fx from it (0.1 % to spare
/// for rounding) and, for a moving camera, than the planes' motion. then no pixel ray meets it.
PB_HOST_DEVICE inline bool StreakCullOutside(const StreakCullFrame& f, const Float3& p,
                                             const Float3& q, float r) {
  const Float3 dp = p - f.cam_o, dq = q - f.cam_o;
  const float D2 = pbm::Max(EigenDotRn(dp, dp), EigenDotRn(dq, dq));
  if (f.moving == 0) {
    for (int i = 0; i < 4; ++i) {
      const float s = pbm::Min(EigenDotRn(f.side_W[i], dp), EigenDotRn(f.side_W[i], dq));
      if (s > MulRn(1.001f, r) && MulRn(MulRn(f.four_fx2, s), s) > MulRn(1.002f, D2)) return true;
    }
    return false;
  }
  const float D = sqrtf(D2);
  const float R = MulRn(1.001f, pbm::Max(r, MulRn(0.5f, D) / f.fx_px));
  const float margin = AddRn(AddRn(R, MulRn(f.turn, AddRn(D, R))), f.shift);
  for (int i = 0; i < 4; ++i)
    if (pbm::Min(EigenDotRn(f.side_W[i], dp), EigenDotRn(f.side_W[i], dq)) > margin) return true;
  return false;
}

/// true when a rain streak of coverage alpha whose nearest point to the camera is p_W cannot
/// change a displayed pixel by kRainCullContrast: alpha times an upper bound of the homogeneous
/// media's transmittance between the camera and p_W (per medium that holds the whole segment:
/// unbounded, or both ends in its box, which is convex; its smallest channel of sigma_t times
/// the length times the smaller density of the two ends; see particle_streaks.h).
PB_HOST_DEVICE inline bool StreakRainInvisible(const StreakCullFrame& f, float alpha,
                                               const Float3& p_W) {
  if (alpha < kRainCullContrast) return true;
  if (f.num_media == 0) return false;
  const Float3 d = p_W - f.cam_o;
  const float dist = sqrtf(EigenDotRn(d, d));
  float tau = 0;
  for (int i = 0; i < f.num_media; ++i) {
    const StreakCullMedium& m = f.media[i];
    if (m.bounded != 0 &&
        !(m.cam_in != 0 && p_W.x >= m.box_min.x && p_W.y >= m.box_min.y && p_W.z >= m.box_min.z &&
          p_W.x <= m.box_max.x && p_W.y <= m.box_max.y && p_W.z <= m.box_max.z))
      continue;
    const float h = pbm::Min(m.cam_density, MediumHeightDensity<true>(m.falloff, m.base, p_W.z));
    tau = AddRn(tau, MulRn(MulRn(m.sigma_t_min, dist), h));
  }
  return MulRn(alpha, ExpRn(-tau)) < kRainCullContrast;
}

/// the decision of one drop at p (world, m) moving at v (m/s) of radius r (m; finite values) of
/// a set `set` for frame `f`: kStreakNone (r <= 0; sheltered; the realtime tier: wholly behind
/// the near plane kStreakNear; outside the view pyramid), kStreakCulled (the realtime tier: rain
/// invisible, StreakRainInvisible) or kStreakDrawn with its streak in *out (the capsule around
/// [p, q = p + T v] widened to half a pixel at its nearest distance to the camera, coverage
/// 2r / (|v| T + 2r) times r / r_wide; a still drop: q = p + (1e-3 r, 0, 0)).
PB_HOST_DEVICE inline int32_t StreakCullDrop(const StreakCullFrame& f, const StreakCullSet& set,
                                             const Float3& p, const Float3& v, float r,
                                             StreakCullOut* out) {
  if (!(r > 0)) return kStreakNone;
  if (set.sheltered != 0 && ShelterSheltered(f.shelter, p)) return kStreakNone;
  Float3 q{AddRn(p.x, MulRn(f.T, v.x)), AddRn(p.y, MulRn(f.T, v.y)), AddRn(p.z, MulRn(f.T, v.z))};
  // a still particle: a capsule of negligible length (Embree needs two distinct ends).
  const Float3 qp = q - p;
  const float r_still = MulRn(1e-3f, r);
  if (!(sqrtf(EigenDotRn(qp, qp)) > r_still))
    q = Float3{AddRn(p.x, r_still), AddRn(p.y, 0.0f), AddRn(p.z, 0.0f)};
  if (f.pixel_hits != 0 && StreakCullDepth(f, p) < kStreakNear &&
      StreakCullDepth(f, q) < kStreakNear)
    return kStreakNone;
  if (f.frustum != 0 && StreakCullOutside(f, p, q, r)) return kStreakNone;
  const float len = MulRn(f.T, sqrtf(EigenDotRn(v, v)));  // the motion, not the widened capsule
  // widen to half a pixel at the streak's nearest distance to the camera.
  const Float3 seg = q - p;
  const float l2 = EigenDotRn(seg, seg);
  const float w = l2 > 0 ? pbm::Clamp(EigenDotRn(f.cam_o - p, seg) / l2, 0.0f, 1.0f) : 0.0f;
  const Float3 near{AddRn(p.x, MulRn(w, seg.x)), AddRn(p.y, MulRn(w, seg.y)),
                    AddRn(p.z, MulRn(w, seg.z))};
  const Float3 to_near = near - f.cam_o;
  const float dist = sqrtf(EigenDotRn(to_near, to_near));
  const float r_wide = pbm::Max(r, MulRn(0.5f, dist) / f.fx_px);
  const float two_r = MulRn(2.0f, r);
  const float alpha = MulRn(pbm::Min(1.0f, two_r / AddRn(len, two_r)), r / r_wide);
  if (f.pixel_hits != 0 && set.rain != 0 && StreakRainInvisible(f, alpha, near))
    return kStreakCulled;
  out->q = q;
  out->r_wide = r_wide;
  out->alpha = alpha;
  return kStreakDrawn;
}

}  // namespace penumbra

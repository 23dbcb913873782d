#pragma once
// the realtime tier's per-pixel media formulas (render/media/media_realtime.h) as PB_HOST_DEVICE
// functions (docs/gpu.md, "One shading code"): the CPU's RealtimeMedia calls them for its
// images, and a device path can call the same definitions over the frame's volumes.
//  - the homogeneous media's closed forms (interval, density integrals, phase function, optical
//    depth) are render/media/media_analytic_math.h's; HomogeneousViewDepths sums the optical depths
//    of a ray through every homogeneous medium (to its end and to a grid's entry),
//    MediaViewClosedForm turns them into the ray's transmittance and sky in-scatter
//    (IntegrateView's homogeneous part);
//  - MediaTrilinear: the cell-centred trilinear lookup of the light volumes
//    (LightTransmittance, the grids' light volumes); CellLightsLookup: the world light volume's
//    lookup of every light at once in its [cell][light] layout (the CPU keeps an SSE
//    restatement, RealtimeMedia::CellLightsLookup, tested bit for bit against it);
//  - MediaAxisAt / MediaColumnsFrom / MediaColumnsAt: the four froxel columns around an image
//    position and their bilinear weights; FogSlice, FogFroxelLookup: the light in-scatter
//    froxels' lookup at a distance; FogQuadPrepare / FogQuadValue: the 2x2 quads' shared fog
//    lookups;
//  - GridFroxelLookup, GridQuadPrepare / GridQuadValue: the grid froxels' lookup at a distance
//    and the 2x2 quads' shared one (with slopes in distance); GridToFrame, GridRotate and
//    GridLightTransmittance: a grid's light volume at a shadow ray's entry into its box;
//  - RealtimeMediaView, MediaViewSegment, MediaLightTransmittance: a frame's media (homogeneous
//    and grids) as plain data (RealtimeMedia::HostView; device copies for a GPU path) and,
//    composed of the functions above, a pixel's view segment (IntegrateView, per pixel or with a
//    quad's shared lookups) and a surface point's transmittance to a light (the CPU realtime
//    surface loop's); RealtimeMedia's member functions call these.
// operation order: the CPU's, bit for bit (the rule of shading_math.h;
// docs/journal/2026-11-26-gpu-effects.md,
// "Homogeneous media").
//
// record types: the froxel lookups are templates over their record type R, an rgb value with a
// 4th lane that is 0 (Eigen::Array4f on the CPU, whose SSE lanes round as the scalar
// operations; Rgb4 here for scalar and device code), needing R + R, R - R, float * R, R += R.

#include <math.h>

#include "penumbra/core/host_device.h"
#include "penumbra/render/media/media_analytic_math.h"
#include "penumbra/render/shading_math.h"
#include "penumbra/render/sky/sky_eval_math.h"

namespace penumbra {

/// pixels per side of the square pixel block of one grid froxel column.
constexpr int kFroxelBlock = 12;
/// depth slices of a grid froxel column.
constexpr int kFroxelSlices = 24;
/// pixels per side of the block of one light in-scatter column of the homogeneous media.
constexpr int kFogFroxelBlock = 24;
/// slices of a light in-scatter column of the homogeneous media.
constexpr int kFogFroxelSlices = 40;
/// distance (m) of the first exponentially spaced slice boundary.
constexpr float kFogFroxelNear = 0.25f;
/// lights with light volumes; further lights are unshadowed in media and unattenuated by grids.
constexpr int kMaxVolumeLights = 16;

/// an rgb value and a 4th lane (0) for scalar and device code: the froxel records' type there.
struct Rgb4 {
  float x = 0, y = 0, z = 0, w = 0;
};
PB_HOST_DEVICE inline Rgb4 operator+(const Rgb4& a, const Rgb4& b) {
  return {a.x + b.x, a.y + b.y, a.z + b.z, a.w + b.w};
}
PB_HOST_DEVICE inline Rgb4 operator-(const Rgb4& a, const Rgb4& b) {
  return {a.x - b.x, a.y - b.y, a.z - b.z, a.w - b.w};
}
PB_HOST_DEVICE inline Rgb4 operator*(float s, const Rgb4& a) {
  return {s * a.x, s * a.y, s * a.z, s * a.w};
}
PB_HOST_DEVICE inline Rgb4& operator+=(Rgb4& a, const Rgb4& b) {
  a = a + b;
  return a;
}

/// the optical depths of the view ray o + t d (d unit, o at height o[2]), t in [0, t_end],
/// through the n homogeneous media: tau_t and tau_s (sigma_t and sigma_s times the density
/// integral, summed in media order), and with to_grid the extinction depth tau_a to first_a,
/// where the ray enters a grid. h_cam_oz: the camera's height (the media's h_cam hold there).
PB_HOST_DEVICE inline void HomogeneousViewDepths(const MediumPod* media, int n, const float* o,
                                                 const float* d, float t_end, bool to_grid,
                                                 float first_a, float h_cam_oz, Float3* tau_t,
                                                 Float3* tau_s, Float3* tau_a) {
  for (int i = 0; i < n; ++i) {
    const MediumPod& m = media[i];
    float a, b;
    if (!MediumInterval(m, o, d, 0.0f, t_end, &a, &b)) continue;
    const float h_0 = o[2] == h_cam_oz ? m.h_cam : NAN;
    const float I = pbm::Min(DensityIntegralF(m.falloff, m.base, o[2], d[2], a, b, h_0), 1e30f);
    tau_t->x = tau_t->x + m.sigma_t[0] * I;
    tau_t->y = tau_t->y + m.sigma_t[1] * I;
    tau_t->z = tau_t->z + m.sigma_t[2] * I;
    tau_s->x = tau_s->x + m.sigma_s[0] * I;
    tau_s->y = tau_s->y + m.sigma_s[1] * I;
    tau_s->z = tau_s->z + m.sigma_s[2] * I;
    if (to_grid && a < first_a) {
      const float Ia = pbm::Min(
          DensityIntegralF(m.falloff, m.base, o[2], d[2], a, pbm::Min(b, first_a), h_0), 1e30f);
      tau_a->x = tau_a->x + m.sigma_t[0] * Ia;
      tau_a->y = tau_a->y + m.sigma_t[1] * Ia;
      tau_a->z = tau_a->z + m.sigma_t[2] * Ia;
    }
  }
}

/// the channel mean (x + y + z) / 3 of an rgb triple (Mean3 of media_common.h).
PB_HOST_DEVICE inline float MediaMean3(const float* v) {
  return (v[0] + v[1] + v[2]) * (1.0f / 3.0f);
}

/// where SkyAlongRay samples the sky that lights the media along the view ray o + t d (d unit),
/// t in [0, t_end]: in the medium of the largest optical depth along the ray, the distance
/// t_med where half of its in-scatter weight 1 - T has accrued, T(t_med) = (1 + T(t_end)) / 2
/// (channel-mean sigma_t). false where no medium has optical depth > 0 there (or t_med is not
/// finite): then the open sky's ambient radiance lights the media.
PB_HOST_DEVICE inline bool SkyMedianDistance(const MediumPod* media, int n, const float* o,
                                             const float* d, float t_end, float* t_med) {
  int best = -1;
  float best_tau = 0, best_a = 0, best_b = 0;
  for (int i = 0; i < n; ++i) {
    const MediumPod& m = media[i];
    float a, b;
    if (!MediumInterval(m, o, d, 0.0f, t_end, &a, &b)) continue;
    const float sigma = MediaMean3(m.sigma_t);
    const float tau =
        sigma * pbm::Min(DensityIntegralF(m.falloff, m.base, o[2], d[2], a, b, NAN), 1e30f);
    if (best < 0 || tau > best_tau) best = i, best_tau = tau, best_a = a, best_b = b;
  }
  if (best < 0 || !(best_tau > 0)) return false;
  const MediumPod& m = media[best];
  const float tau_med = -log1pf(expf(-best_tau)) + logf(2.0f);  // -ln((1 + T) / 2)
  const double t = MediaInvertDensityIntegral(m.falloff, m.base, o[2], d[2], best_a, best_b,
                                              tau_med / MediaMean3(m.sigma_t));
  const bool finite = t == t && !MediaIsInf(t);  // std::isfinite(t)
  const float tm = finite ? static_cast<float>(t) : 0.5f * (best_a + best_b);
  if (!pbm::IsFinite(tm)) return false;
  *t_med = tm;
  return true;
}

/// e^-tau per channel; one exponential when the channels are equal or the media are `grey`
/// (every sigma_t grey: equal channels, the same operations on equal values).
PB_HOST_DEVICE inline Float3 MediaExpNeg(const Float3& tau, bool grey) {
  if (grey || (tau.x == tau.y && tau.y == tau.z)) {
    const float e = expf(-tau.x);
    return {e, e, e};
  }
  return {expf(-tau.x), expf(-tau.y), expf(-tau.z)};
}

/// the homogeneous media's part of a view segment (IntegrateView): from the optical depths of
/// HomogeneousViewDepths, the grids' transmittance Tg over the segment (1 without grids) and
/// the sky radiance lighting the media `sky` (SkyAlongRay): *T = e^-tau_t Tg and *L_add +=
/// albedo w sky, the sky in-scatter in closed form (albedo = tau_s / tau_t, w = 1 - e^-tau_t,
/// or with to_grid (1 - e^-tau_a) + (e^-tau_a - e^-tau_t) Tg: behind a grid's entry its
/// transmittance attenuates it). the light in-scatter (FogFroxelLookup) is added apart.
PB_HOST_DEVICE inline void MediaViewClosedForm(const Float3& tau_t, const Float3& tau_s,
                                               const Float3& tau_a, bool to_grid, bool grey,
                                               const Float3& Tg, const Float3& sky, Float3* T,
                                               Float3* L_add) {
  const Float3 Th_end = MediaExpNeg(tau_t, grey);
  const Float3 albedo = {tau_t.x > 0.0f ? tau_s.x / tau_t.x : 0.0f,
                         tau_t.y > 0.0f ? tau_s.y / tau_t.y : 0.0f,
                         tau_t.z > 0.0f ? tau_s.z / tau_t.z : 0.0f};
  Float3 sky_w = {1.0f - Th_end.x, 1.0f - Th_end.y, 1.0f - Th_end.z};
  if (to_grid) {
    const Float3 Th_a = MediaExpNeg(tau_a, grey);
    sky_w = {(1.0f - Th_a.x) + (Th_a.x - Th_end.x) * Tg.x,
             (1.0f - Th_a.y) + (Th_a.y - Th_end.y) * Tg.y,
             (1.0f - Th_a.z) + (Th_a.z - Th_end.z) * Tg.z};
  }
  L_add->x = L_add->x + albedo.x * sky_w.x * sky.x;
  L_add->y = L_add->y + albedo.y * sky_w.y * sky.y;
  L_add->z = L_add->z + albedo.z * sky_w.z * sky.z;
  *T = {Th_end.x * Tg.x, Th_end.y * Tg.y, Th_end.z * Tg.z};
}

/// trilinear lookup in a cell-centred (r[0] x r[1] x r[2]) array `a` (x fastest) at continuous
/// index (f0, f1, f2) (cell centre i at f = i), clamped to the outermost centres. T: float, or
/// any value type with T * float and T + T (the CPU's rgb sources).
template <typename T>
PB_HOST_DEVICE inline T MediaTrilinear(const T* a, const int r[3], float f0, float f1, float f2) {
  const float f[3] = {f0, f1, f2};
  int i0[3], i1[3];
  float w[3];
  for (int k = 0; k < 3; ++k) {
    const float c = pbm::Clamp(f[k], 0.0f, static_cast<float>(r[k] - 1));
    i0[k] = MediaMinI(static_cast<int>(c), MediaMaxI(r[k] - 2, 0));
    i1[k] = MediaMinI(i0[k] + 1, r[k] - 1);
    w[k] = c - static_cast<float>(i0[k]);
  }
  const size_t nx = static_cast<size_t>(r[0]), ny = static_cast<size_t>(r[1]);
  const T* z0 = a + static_cast<size_t>(i0[2]) * ny * nx;
  const T* z1 = a + static_cast<size_t>(i1[2]) * ny * nx;
  const size_t y0 = static_cast<size_t>(i0[1]) * nx, y1 = static_cast<size_t>(i1[1]) * nx;
  const T c00 = z0[y0 + i0[0]] * (1 - w[0]) + z0[y0 + i1[0]] * w[0];
  const T c10 = z0[y1 + i0[0]] * (1 - w[0]) + z0[y1 + i1[0]] * w[0];
  const T c01 = z1[y0 + i0[0]] * (1 - w[0]) + z1[y0 + i1[0]] * w[0];
  const T c11 = z1[y1 + i0[0]] * (1 - w[0]) + z1[y1 + i1[0]] * w[0];
  const T c0 = c00 * (1 - w[1]) + c10 * w[1];
  const T c1 = c01 * (1 - w[1]) + c11 * w[1];
  return c0 * (1 - w[2]) + c1 * w[2];
}

/// the world light volume's layout for CellLightsLookup: the box [lo, hi] (m, world frame),
/// cells per m and cells per axis r, and `stride` lights per cell (a multiple of 4).
struct CellLightsPod {
  float lo[3] = {0, 0, 0}, hi[3] = {0, 0, 0}, cells_per_m[3] = {1, 1, 1};
  int r[3] = {1, 1, 1};
  int stride = 0;
};

/// the eight trilinear weights of the fractions w (x, y, z in [0, 1]) of a cell's corners, corner
/// k at +1 along x, y, z for bits 0, 1, 2 of k: the products (1 - w) or w, x first.
PB_HOST_DEVICE inline void TrilinearCornerWeights(const float w[3], float out[8]) {
  const float ux = 1 - w[0], uy = 1 - w[1], uz = 1 - w[2];
  out[0] = ux * uy * uz;
  out[1] = w[0] * uy * uz;
  out[2] = ux * w[1] * uz;
  out[3] = w[0] * w[1] * uz;
  out[4] = ux * uy * w[2];
  out[5] = w[0] * uy * w[2];
  out[6] = ux * w[1] * w[2];
  out[7] = w[0] * w[1] * w[2];
}

/// a cell's eight corners in a [cell][light] array of layout `v` (r, stride): the first
/// corner's record c0 (cell `base`) and the offsets in floats of the +x, +y and +z corners
/// (`step` 0 or 1 per axis: 0 where the upper corner is clamped onto the lower one); corner k
/// (+1 along x, y, z for bits 0, 1, 2 of k) starts at c0 + bit0 ox + bit1 oy + bit2 oz.
struct CellCorners {
  const float* c0 = nullptr;
  size_t ox = 0, oy = 0, oz = 0;
};
PB_HOST_DEVICE inline CellCorners CellLightsCorners(const CellLightsPod& v, const float* cl,
                                                    const int base[3], const int step[3]) {
  const size_t S = static_cast<size_t>(v.stride);
  const size_t nx = static_cast<size_t>(v.r[0]), nxy = nx * static_cast<size_t>(v.r[1]);
  CellCorners k;
  k.c0 = cl + (base[2] * nxy + base[1] * nx + base[0]) * S;
  k.ox = step[0] * S;
  k.oy = step[1] * nx * S;
  k.oz = step[2] * nxy * S;
  return k;
}

/// trilinear lookup at p (world, m) of every light's value in a [cell][light] array `cl` of
/// the world light volume into out[0 .. stride); false outside the box (out untouched). per
/// axis c = clamp((p - lo) cells_per_m - 0.5, 0, r - 1), i0 = min(trunc(c), max(r - 2, 0)),
/// the upper corner i0 + 1 where that is <= r - 1 (else i0), w = c - i0; the eight corners
/// (+1 along x, y, z for bits 0, 1, 2 of the corner index) weighted by the products of their
/// axis weights and summed in corner order.
PB_HOST_DEVICE inline bool CellLightsLookup(const CellLightsPod& v, const float* cl, const float* p,
                                            float* out) {
  for (int k = 0; k < 3; ++k)
    if (!(p[k] >= v.lo[k] && p[k] <= v.hi[k])) return false;
  int base[3], step[3];
  float w[3];
  for (int k = 0; k < 3; ++k) {
    const float rmax = static_cast<float>(v.r[k] - 1);
    float c = (p[k] - v.lo[k]) * v.cells_per_m[k] - 0.5f;
    c = c > 0.0f ? c : 0.0f;  // _mm_max_ps(c, 0): c is never NaN here
    c = c < rmax ? c : rmax;
    const float imax = static_cast<float>(MediaMaxI(v.r[k] - 2, 0));
    float i0 = static_cast<float>(static_cast<int>(c));
    i0 = i0 < imax ? i0 : imax;
    w[k] = c - i0;
    base[k] = static_cast<int>(i0);
    step[k] = i0 + 1.0f <= rmax ? 1 : 0;
  }
  const size_t S = static_cast<size_t>(v.stride);
  const CellCorners k = CellLightsCorners(v, cl, base, step);
  const size_t ox = k.ox, oy = k.oy, oz = k.oz;
  float wc[8];
  TrilinearCornerWeights(w, wc);
  for (size_t j = 0; j < S; ++j) {
    const float* c = k.c0 + j;
    float sum = wc[0] * c[0];
    sum += wc[1] * c[ox];
    sum += wc[2] * c[oy];
    sum += wc[3] * c[ox + oy];
    sum += wc[4] * c[oz];
    sum += wc[5] * c[ox + oz];
    sum += wc[6] * c[oy + oz];
    sum += wc[7] * c[ox + oy + oz];
    out[j] = sum;
  }
  return true;
}

/// one axis of the bilinear interpolation between froxel columns at an image position:
/// columns i0 and i1 along the axis and the weight w of i1.
struct MediaAxis {
  int i0 = 0, i1 = 0;
  float w = 0;
};

/// the four froxel columns around an image position (indices into an nx-wide column grid)
/// and their bilinear weights.
struct MediaColumns {
  int cols[4];
  float w[4];
};

/// the centre pixel (*uc, *vc) of froxel column c of a w x h image cut into nx columns of
/// block x block pixels per row (the pixel a column's ray passes through; clamped into the
/// image for the last, partial blocks).
PB_HOST_DEVICE inline void MediaColumnCentre(int c, int nx, int block, int w, int h, int* uc,
                                             int* vc) {
  *uc = MediaMinI((c % nx) * block + block / 2, w - 1);
  *vc = MediaMinI((c / nx) * block + block / 2, h - 1);
}

/// the axis part of the columns at position x (pixels) of columns centred on blocks of
/// `block` pixels, `columns` of them along the axis: f = clamp((x - block / 2) / block, 0,
/// columns - 1), i0 = trunc(f), i1 = min(i0 + 1, columns - 1), w = f - i0.
PB_HOST_DEVICE inline MediaAxis MediaAxisAt(float x, int block, int columns) {
  const float f = pbm::Clamp((x - block / 2) / static_cast<float>(block), 0.0f,
                             static_cast<float>(columns - 1));
  const int i0 = static_cast<int>(f);
  return MediaAxis{i0, MediaMinI(i0 + 1, columns - 1), f - i0};
}

/// the columns and weights from the axis parts x and y (nx columns per row).
PB_HOST_DEVICE inline MediaColumns MediaColumnsFrom(const MediaAxis& x, const MediaAxis& y,
                                                    int nx) {
  const float wx = x.w, wy = y.w;
  return {{y.i0 * nx + x.i0, y.i0 * nx + x.i1, y.i1 * nx + x.i0, y.i1 * nx + x.i1},
          {(1 - wx) * (1 - wy), wx * (1 - wy), (1 - wx) * wy, wx * wy}};
}

/// the four columns around image position (x, y) of an nx x ny column grid of blocks of
/// `block` pixels.
PB_HOST_DEVICE inline MediaColumns MediaColumnsAt(float x, float y, int block, int nx, int ny) {
  return MediaColumnsFrom(MediaAxisAt(x, block, nx), MediaAxisAt(y, block, ny), nx);
}

/// slice coordinate in [0, Z] of distance t for the exponentially spaced boundaries 0, near,
/// ..., t_far of a light in-scatter column (boundary k >= 1 at near (t_far / near)^((k - 1) /
/// (Z - 1))); log_t = log(t / near) (shared by the columns of a lookup), inv_log_far =
/// 1 / log(t_far / near).
PB_HOST_DEVICE inline float FogSlice(float t, float log_t, float inv_log_far) {
  constexpr int Z = kFogFroxelSlices;
  if (!(t > 0)) return 0.0f;
  if (t < kFogFroxelNear) return t / kFogFroxelNear;
  const float s = 1.0f + (Z - 1) * log_t * inv_log_far;
  return pbm::Min(s, static_cast<float>(Z));
}

/// the light in-scatter of the homogeneous media from the camera to distance t (m) at the
/// columns `cb`: per column linear between its slice boundaries, bilinear between the columns
/// (columns of weight 0 skipped). S: [column][boundary 0..kFogFroxelSlices] records,
/// inv_log_far: [column]; `zero` is R's 0.
template <typename R>
PB_HOST_DEVICE inline R FogFroxelLookup(const MediaColumns& cb, const R* S,
                                        const float* inv_log_far, float t, const R& zero) {
  constexpr int Z = kFogFroxelSlices;
  R out = zero;
  const float log_t = t > kFogFroxelNear ? logf(t / kFogFroxelNear) : 0.0f;
  for (int q = 0; q < 4; ++q) {
    if (!(cb.w[q] > 0)) continue;
    const int c = cb.cols[q];
    const float s = FogSlice(t, log_t, inv_log_far[c]);
    const int k = MediaMinI(static_cast<int>(s), Z - 1);
    const float f = s - k;
    const R* rec = S + static_cast<size_t>(c) * (Z + 1) + k;
    const float w0 = cb.w[q] * (1 - f), w1 = cb.w[q] * f;
    out += w0 * rec[0] + w1 * rec[1];
  }
  return out;
}

/// a 2x2 quad's shared light in-scatter lookup (FogQuadPrepare), read by its pixels with
/// FogQuadValue.
template <typename R>
struct FogQuad {
  float log_c = 0;       ///< log(t_c / kFogFroxelNear)
  float lo = 1, hi = 0;  ///< log distances where fS holds (empty: none)
  R fS, fS_dlog;         ///< in-scatter at t_c and its change per unit of log distance
};

/// the fog lookups of a 2x2 quad at its centre's columns `cb` and reference distance t_c (m,
/// > kFogFroxelNear): the value at t_c and its slope in log distance within the range of log
/// distances where every column stays in one slice (beyond the last boundary: constant). q's
/// fS and fS_dlog must hold R's 0 on entry.
template <typename R>
PB_HOST_DEVICE inline void FogQuadPrepare(const MediaColumns& cb, const R* S,
                                          const float* inv_log_far, float t_c, FogQuad<R>* q) {
  constexpr int Z = kFogFroxelSlices;
  const float log_t = logf(t_c / kFogFroxelNear);
  q->log_c = log_t;
  float lo = 0.0f, hi = INFINITY;
  for (int k = 0; k < 4; ++k) {
    if (!(cb.w[k] > 0)) continue;
    const int c = cb.cols[k];
    const float ilf = inv_log_far[c];
    const float s = 1.0f + (Z - 1) * log_t * ilf;
    const R* rec = S + static_cast<size_t>(c) * (Z + 1);
    if (!(s < Z)) {  // beyond the last boundary: record Z
      lo = pbm::Max(lo, 1.0f / ilf);
      q->fS += cb.w[k] * rec[Z];
      continue;
    }
    const int i = MediaMinI(static_cast<int>(s), Z - 1);
    const float f = s - i;
    const float per_slice = 1.0f / ((Z - 1) * ilf);  // log distance per slice
    lo = pbm::Max(lo, (i - 1) * per_slice);
    hi = pbm::Min(hi, i * per_slice);
    q->fS += cb.w[k] * ((1 - f) * rec[i] + f * rec[i + 1]);
    q->fS_dlog += (cb.w[k] * (Z - 1) * ilf) * (rec[i + 1] - rec[i]);
  }
  q->lo = lo;
  q->hi = hi;
}

/// the quad's fog in-scatter at a pixel's distance t (m): true with *out where q holds t,
/// false where the pixel must look it up itself (FogFroxelLookup).
template <typename R>
PB_HOST_DEVICE inline bool FogQuadValue(const FogQuad<R>& q, float t, R* out) {
  if (!(t > kFogFroxelNear)) return false;
  const float log_t = logf(t / kFogFroxelNear);
  if (!(log_t >= q.lo && log_t <= q.hi)) return false;
  const float dl = log_t == q.log_c ? 0.0f : log_t - q.log_c;
  *out = q.fS + dl * q.fS_dlog;
  return true;
}

/// a grid froxel column's record at a slice boundary: the grids' in-scatter S and
/// transmittance T (rgb, 4th lane 0) from the camera to it (RealtimeMedia's grid froxels).
template <typename R>
struct GridFroxelRecord {
  R S, T;
};

/// the grid froxel volume's lookup at distance t (m) at the columns `cb` (RealtimeMedia::
/// LookupFroxels): per column linear between its slice boundaries (kFroxelSlices slices over the
/// column's overlap [t0, t1] with the grid boxes, slices_per_m of them per m), bilinear between
/// the columns (columns of weight 0 skipped; a column that meets no grid adds weight w to T).
/// *S and *T get the in-scatter and transmittance (`zero` and `unit`: R's 0 and (1, 1, 1, 0));
/// returns the smallest entry distance of the four columns (+inf if none meets a grid; then S =
/// 0, T = unit). records: [column][boundary 0..kFroxelSlices].
template <typename R>
PB_HOST_DEVICE inline float GridFroxelLookup(const MediaColumns& cb, const float* t0,
                                             const float* t1, const float* slices_per_m,
                                             const GridFroxelRecord<R>* records, float t,
                                             const R& zero, const R& unit, R* S, R* T) {
  constexpr int Z = kFroxelSlices;
  const int* cols = cb.cols;
  // nothing before the nearest column entry (every record 0 there is {0, 1}): no grid.
  float t_enter = INFINITY;
  for (int q = 0; q < 4; ++q)
    if (t0[cols[q]] < t1[cols[q]]) t_enter = pbm::Min(t_enter, t0[cols[q]]);
  *S = zero;
  if (!(t > t_enter)) {
    *T = unit;
    return t_enter;
  }
  *T = zero;
  const float* w = cb.w;
  for (int q = 0; q < 4; ++q) {
    if (!(w[q] > 0)) continue;
    const int c = cols[q];
    const float a = t0[c], b = t1[c];
    if (!(a < b)) {
      *T += w[q] * unit;
      continue;
    }
    const float s = pbm::Clamp((t - a) * slices_per_m[c], 0.0f, static_cast<float>(Z));
    const int k = MediaMinI(static_cast<int>(s), Z - 1);
    const float f = s - k;
    const GridFroxelRecord<R>* rec = records + static_cast<size_t>(c) * (Z + 1) + k;
    const float w0 = w[q] * (1 - f), w1 = w[q] * f;
    *S += w0 * rec[0].S + w1 * rec[1].S;
    *T += w0 * rec[0].T + w1 * rec[1].T;
  }
  return t_enter;
}

/// a 2x2 quad's shared grid froxel lookup (GridQuadPrepare), read by its pixels with
/// GridQuadValue: the values at the reference distance t_c and their slopes in distance, within
/// [g_lo, g_hi] where every column stays in one slice.
template <typename R>
struct GridQuad {
  float t_c = 0;             ///< reference distance of the values (m)
  float g_enter = 0;         ///< smallest entry distance of the columns (m)
  float g_lo = 1, g_hi = 0;  ///< distances (m) where gS, gT hold (empty: none)
  R gS, gT, gS_dt, gT_dt;    ///< at t_c, and per m
};

/// the grid froxel lookups of a 2x2 quad at its centre's columns `cb` and reference distance
/// t_c (m, +inf for sky quads; RealtimeMedia::PrepareQuad's grid part): per column the slice
/// that holds t_c and the distances where that stays so (constant before the column's entry and
/// after its exit). q's gS, gT, gS_dt and gT_dt must hold R's 0 on entry; `unit` is R's (1, 1, 1,
/// 0).
template <typename R>
PB_HOST_DEVICE inline void GridQuadPrepare(const MediaColumns& cb, const float* t0, const float* t1,
                                           const float* slices_per_m,
                                           const GridFroxelRecord<R>* records, float t_c,
                                           const R& unit, GridQuad<R>* q) {
  constexpr int Z = kFroxelSlices;
  const float t = pbm::Min(t_c, 1e30f);
  q->t_c = t;
  const int* cols = cb.cols;
  float t_enter = INFINITY;
  for (int k = 0; k < 4; ++k)
    if (t0[cols[k]] < t1[cols[k]]) t_enter = pbm::Min(t_enter, t0[cols[k]]);
  q->g_enter = t_enter;
  if (!(t > t_enter)) return;
  const float* w = cb.w;
  float lo = t_enter, hi = INFINITY;
  for (int k = 0; k < 4; ++k) {
    if (!(w[k] > 0)) continue;
    const int c = cols[k];
    const float a = t0[c], b = t1[c];
    if (!(a < b)) {
      q->gT += w[k] * unit;
      continue;
    }
    const GridFroxelRecord<R>* rec = records + static_cast<size_t>(c) * (Z + 1);
    const float spm = slices_per_m[c];
    const float s = (t - a) * spm;
    if (!(s > 0)) {  // before the column's entry: record 0
      hi = pbm::Min(hi, a);
      q->gS += w[k] * rec[0].S;
      q->gT += w[k] * rec[0].T;
    } else if (!(s < Z)) {  // after its exit: record Z
      lo = pbm::Max(lo, b);
      q->gS += w[k] * rec[Z].S;
      q->gT += w[k] * rec[Z].T;
    } else {
      const int i = MediaMinI(static_cast<int>(s), Z - 1);
      const float f = s - i;
      lo = pbm::Max(lo, a + i / spm);
      hi = pbm::Min(hi, a + (i + 1) / spm);
      q->gS += w[k] * ((1 - f) * rec[i].S + f * rec[i + 1].S);
      q->gT += w[k] * ((1 - f) * rec[i].T + f * rec[i + 1].T);
      q->gS_dt += (w[k] * spm) * (rec[i + 1].S - rec[i].S);
      q->gT_dt += (w[k] * spm) * (rec[i + 1].T - rec[i].T);
    }
  }
  q->g_lo = lo;
  q->g_hi = hi;
}

/// the quad's grid values at a pixel's distance t (m; RealtimeMedia::QuadFroxels): 1 with *S,
/// *T (no grid before the columns' entry: S = zero, T = unit) where q holds t, 0 where the pixel
/// must look them up itself (GridFroxelLookup); *t_enter: the columns' entry distance.
template <typename R>
PB_HOST_DEVICE inline int GridQuadValue(const GridQuad<R>& q, float t, const R& zero, const R& unit,
                                        R* S, R* T, float* t_enter) {
  *t_enter = q.g_enter;
  if (!(t > q.g_enter)) {
    *S = zero;
    *T = unit;
    return 1;
  }
  if (!(t >= q.g_lo && t <= q.g_hi)) return 0;
  const float dt = t == q.t_c ? 0.0f : t - q.t_c;
  *S = q.gS + dt * q.gS_dt;
  *T = q.gT + dt * q.gT_dt;
  return 1;
}

/// a grid medium's box and coarse light volume as LightTransmittance reads them (RealtimeMedia's
/// grid light volumes): the world-to-grid transform x_G = R_GW x_W + p_GW (R_GW row-major), the
/// box half extents, the light volume's r[0] x r[1] x r[2] cells (x fastest) and cells per m,
/// and where its [light][cell] transmittances start in RealtimeMediaView::grid_light_T.
struct GridLightPod {
  float R_GW[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  float p_GW[3] = {0, 0, 0};
  float half[3] = {0.5f, 0.5f, 0.5f};
  float cells_per_m[3] = {1, 1, 1};
  int r[3] = {1, 1, 1};
  size_t offset = 0;  ///< index of light 0's cell 0 in grid_light_T
};

/// x_G = R_GW x + p_GW (GridVolume::ToGrid; the operation order of Eigen's 3x3 product:
/// r0 x0 + (r1 x1 + r2 x2) per row, tested bit for bit against it).
PB_HOST_DEVICE inline void GridToFrame(const GridLightPod& g, const float* x, float* out) {
  for (int i = 0; i < 3; ++i)
    out[i] =
        g.R_GW[3 * i] * x[0] + (g.R_GW[3 * i + 1] * x[1] + g.R_GW[3 * i + 2] * x[2]) + g.p_GW[i];
}

/// R_GW d (a direction into the grid frame, as GridVolume::Interval rotates it).
PB_HOST_DEVICE inline void GridRotate(const GridLightPod& g, const float* d, float* out) {
  for (int i = 0; i < 3; ++i)
    out[i] = g.R_GW[3 * i] * d[0] + (g.R_GW[3 * i + 1] * d[1] + g.R_GW[3 * i + 2] * d[2]);
}

/// a grid's transmittance from p (world, m) towards light j (unit direction wi, distance dist,
/// +inf for directional lights) through its light volume `T` ([light][cell], this grid's;
/// RealtimeMedia::GridLightT): 1 for lights without volumes (j >= num_lights) and for shadow
/// rays that miss the box, else the volume's trilinear value at the ray's entry into the box.
PB_HOST_DEVICE inline float GridLightTransmittance(const GridLightPod& g, const float* T,
                                                   int num_lights, int j, const float* p,
                                                   const float* wi, float dist) {
  if (j >= num_lights) return 1.0f;
  float o_G[3], d_G[3];
  GridToFrame(g, p, o_G);
  GridRotate(g, wi, d_G);
  const float lo[3] = {-g.half[0], -g.half[1], -g.half[2]};
  float a, b;
  if (!MediaSlabInterval(o_G, d_G, lo, g.half, 0.0f, dist, &a, &b)) return 1.0f;
  const float x[3] = {p[0] + a * wi[0], p[1] + a * wi[1], p[2] + a * wi[2]};
  float x_G[3];
  GridToFrame(g, x, x_G);
  float f[3];
  for (int k = 0; k < 3; ++k) f[k] = (x_G[k] + g.half[k]) * g.cells_per_m[k] - 0.5f;
  const size_t cells = static_cast<size_t>(g.r[0]) * g.r[1] * g.r[2];
  return MediaTrilinear(T + static_cast<size_t>(j) * cells, g.r, f[0], f[1], f[2]);
}

/// a frame's media (homogeneous and grids) as the per-pixel view functions read them:
/// RealtimeMedia's arrays (RealtimeMedia::HostView), on the host or copied to a device.
struct RealtimeMediaView {
  const MediumPod* media = nullptr;  ///< the homogeneous media (h_cam set for the camera)
  int num_media = 0;
  float camera_height = 0;  ///< world z of the camera's rays (MediumPod::h_cam holds there)
  int grey = 0;             ///< every sigma_t grey (MediaViewClosedForm's `grey`)
  float sky_ambient[3] = {0, 0, 0};  ///< the open sky's sphere-average radiance (cd/m^2)
  /// the sky volume that occludes it (SkyAlongRay), or null (then sky_ambient lights the media)
  const SkyVolumePod* sky_volume = nullptr;
  /// the image the froxel volumes' per-pixel axis tables cover (MediaAxisAt at every pixel
  /// centre, and at u + 0.5 for the 2x2 quads' centres)
  int width = 0, height = 0;
  /// the light in-scatter froxels: fog_nx x fog_ny columns of kFogFroxelSlices + 1 records,
  /// 1 / log(t_far / near) per column, and their axis tables; fog_S null: none (no lights or no
  /// homogeneous media)
  int fog_nx = 0, fog_ny = 0;
  const Rgb4* fog_S = nullptr;
  const float* fog_inv_log_far = nullptr;
  const MediaAxis* fog_ax = nullptr;       ///< [width]
  const MediaAxis* fog_ay = nullptr;       ///< [height]
  const MediaAxis* fog_ax_half = nullptr;  ///< [width]: at u + 0.5, the 2x2 quads' centres
  const MediaAxis* fog_ay_half = nullptr;  ///< [height]
  /// the world light volume (stride 0: none): Th per light in [cell][light] layout, for the
  /// first num_volume_lights lights
  CellLightsPod light_volume;
  const float* light_trans = nullptr;
  int num_volume_lights = 0;
  /// the grid froxels (grid_records null: no grids): grid_nx x grid_ny columns, per column the
  /// overlap [t0, t1] of its ray with the grid boxes and kFroxelSlices / (t1 - t0) (0 without
  /// overlap), kFroxelSlices + 1 records, and their axis tables
  int grid_nx = 0, grid_ny = 0;
  const float* grid_t0 = nullptr;
  const float* grid_t1 = nullptr;
  const float* grid_slices_per_m = nullptr;
  const GridFroxelRecord<Rgb4>* grid_records = nullptr;
  const MediaAxis* grid_ax = nullptr;       ///< [width]
  const MediaAxis* grid_ay = nullptr;       ///< [height]
  const MediaAxis* grid_ax_half = nullptr;  ///< [width]
  const MediaAxis* grid_ay_half = nullptr;  ///< [height]
  /// the grids' boxes and light volumes (LightTransmittance's grid factor outside the world
  /// light volume), their [light][cell] transmittances end to end (GridLightPod::offset), for
  /// the first num_grid_lights lights (RealtimeMedia::num_volume_lights)
  int num_grids = 0;
  const GridLightPod* grids = nullptr;
  const float* grid_light_T = nullptr;
  int num_grid_lights = 0;
};

/// the four fog froxel columns of pixel (u, v) (RealtimeMedia's PixelColumns: the axis tables
/// inside the image, MediaColumnsAt outside).
PB_HOST_DEVICE inline MediaColumns MediaPixelColumns(const RealtimeMediaView& m, int u, int v) {
  if (u >= 0 && v >= 0 && u < m.width && v < m.height)
    return MediaColumnsFrom(m.fog_ax[u], m.fog_ay[v], m.fog_nx);
  return MediaColumnsAt(static_cast<float>(u), static_cast<float>(v), kFogFroxelBlock, m.fog_nx,
                        m.fog_ny);
}

/// a 2x2 pixel quad's shared lookups (RealtimeMedia::PrepareQuad; MediaPrepareQuad): the grid
/// and fog froxels' at the quad's centre and reference distance, and the sky lighting the media
/// along the quad's mean direction.
struct MediaQuadShared {
  GridQuad<Rgb4> grid;
  FogQuad<Rgb4> fog;
  int has_sky = 0;  ///< sky holds the quad's SkyAlongRay
  float sky[3] = {0, 0, 0};
};

/// the sky radiance lighting the media along o + t d, t in [0, t_end] (RealtimeMedia::
/// SkyAlongRay): the sky volume's at the in-scatter median point, else the open sky's.
PB_HOST_DEVICE inline void MediaSkyAlongRay(const RealtimeMediaView& m, const float* o,
                                            const float* d, float t_end, float* sky) {
  for (int k = 0; k < 3; ++k) sky[k] = m.sky_ambient[k];
  float t_med;
  if (m.sky_volume != nullptr && SkyMedianDistance(m.media, m.num_media, o, d, t_end, &t_med)) {
    const float p[3] = {o[0] + t_med * d[0], o[1] + t_med * d[1], o[2] + t_med * d[2]};
    SkyVolumeAmbientRadiance(*m.sky_volume, p, m.sky_ambient, sky);
  }
}

/// the four grid froxel columns of pixel (u, v), as MediaPixelColumns.
PB_HOST_DEVICE inline MediaColumns MediaGridPixelColumns(const RealtimeMediaView& m, int u, int v) {
  if (u >= 0 && v >= 0 && u < m.width && v < m.height)
    return MediaColumnsFrom(m.grid_ax[u], m.grid_ay[v], m.grid_nx);
  return MediaColumnsAt(static_cast<float>(u), static_cast<float>(v), kFroxelBlock, m.grid_nx,
                        m.grid_ny);
}

/// the shared lookups of the 2x2 quad of pixels (u0, v0) .. (u0 + 1, v0 + 1) at its reference
/// distance t_c (m, the mean of its pixels' distances; +inf for sky pixels) and the sky along
/// the ray from the camera centre o in the quad's mean direction d_c (unit) (RealtimeMedia::
/// PrepareQuad).
PB_HOST_DEVICE inline void MediaPrepareQuad(const RealtimeMediaView& m, int u0, int v0, float t_c,
                                            const float* o, const float* d_c, MediaQuadShared* q) {
  *q = MediaQuadShared();
  if (m.sky_volume != nullptr && m.num_media > 0) {
    MediaSkyAlongRay(m, o, d_c, t_c, q->sky);
    q->has_sky = 1;
  }
  const bool in = u0 >= 0 && v0 >= 0 && u0 < m.width && v0 < m.height;
  if (m.grid_records != nullptr) {
    const MediaColumns cb =
        in ? MediaColumnsFrom(m.grid_ax_half[u0], m.grid_ay_half[v0], m.grid_nx)
           : MediaColumnsAt(u0 + 0.5f, v0 + 0.5f, kFroxelBlock, m.grid_nx, m.grid_ny);
    GridQuadPrepare(cb, m.grid_t0, m.grid_t1, m.grid_slices_per_m, m.grid_records, t_c,
                    Rgb4{1, 1, 1, 0}, &q->grid);
  }
  if (m.fog_S != nullptr && t_c > kFogFroxelNear) {
    const MediaColumns cb =
        in ? MediaColumnsFrom(m.fog_ax_half[u0], m.fog_ay_half[v0], m.fog_nx)
           : MediaColumnsAt(u0 + 0.5f, v0 + 0.5f, kFogFroxelBlock, m.fog_nx, m.fog_ny);
    FogQuadPrepare(cb, m.fog_S, m.fog_inv_log_far, t_c, &q->fog);
  }
}

/// what the media do to the radiance L behind the view segment o + t d (o the camera centre, d
/// unit), t in [0, t_end], of pixel (u, v): *T L + *L_add (RealtimeMedia::IntegrateView): the
/// grid froxels' in-scatter and transmittance at t_end; the homogeneous media's closed-form
/// transmittance and sky in-scatter (the sky at the ray's in-scatter median point through the
/// sky volume; behind a grid's entry attenuated by the grids' transmittance) and the light
/// in-scatter of the fog froxels. with `quad` (MediaPrepareQuad of the 2x2 quad holding the
/// pixel; may be null) the quad's sky, and its froxel lookups where they hold t_end, as
/// IntegrateView with a MediaQuad; else each pixel its own lookups.
PB_HOST_DEVICE inline void MediaViewSegment(const RealtimeMediaView& m, int u, int v,
                                            const float* o, const float* d, float t_end, Float3* T,
                                            Float3* L_add, const MediaQuadShared* quad = nullptr) {
  // grids: the froxel volume at the pixel's distance.
  Rgb4 gS{0, 0, 0, 0}, gT{1, 1, 1, 0};
  float first_a = INFINITY;
  if (m.grid_records != nullptr) {
    const float t = pbm::Min(t_end, 1e30f);
    const Rgb4 zero{0, 0, 0, 0}, unit{1, 1, 1, 0};
    if (quad == nullptr || GridQuadValue(quad->grid, t, zero, unit, &gS, &gT, &first_a) == 0)
      first_a = GridFroxelLookup(MediaGridPixelColumns(m, u, v), m.grid_t0, m.grid_t1,
                                 m.grid_slices_per_m, m.grid_records, t, zero, unit, &gS, &gT);
  }
  if (m.num_media == 0) {
    *T = Float3{gT.x, gT.y, gT.z};
    *L_add = Float3{gS.x, gS.y, gS.z};
    return;
  }
  // homogeneous media: closed-form transmittance and sky in-scatter, to the end and, when the
  // ray enters a grid before it, to the grid's entry.
  const bool to_grid = first_a < t_end;
  Float3 tau_t, tau_s, tau_a;
  HomogeneousViewDepths(m.media, m.num_media, o, d, t_end, to_grid, first_a, m.camera_height,
                        &tau_t, &tau_s, &tau_a);
  float sky[3];
  if (m.sky_volume != nullptr && quad != nullptr && quad->has_sky) {
    for (int k = 0; k < 3; ++k) sky[k] = quad->sky[k];
  } else {
    MediaSkyAlongRay(m, o, d, t_end, sky);
  }
  Float3 L{gS.x, gS.y, gS.z};
  MediaViewClosedForm(tau_t, tau_s, tau_a, to_grid, m.grey != 0, Float3{gT.x, gT.y, gT.z},
                      Float3{sky[0], sky[1], sky[2]}, T, &L);
  if (m.fog_S != nullptr) {
    Rgb4 f;
    if (quad == nullptr || !FogQuadValue(quad->fog, t_end, &f))
      f = FogFroxelLookup(MediaPixelColumns(m, u, v), m.fog_S, m.fog_inv_log_far, t_end, Rgb4{});
    L = {L.x + f.x, L.y + f.y, L.z + f.z};
  }
  *L_add = L;
}

/// the media's transmittance from surface point p towards light j (unit direction wi, distance
/// dist, +inf for directional lights), as the CPU's realtime surface loop takes it: inside the
/// world light volume, for the lights it holds, the volume's channel-mean value
/// (CellLightsLookup); elsewhere the closed form e^-tau of AnalyticOpticalDepthOf times each
/// grid's GridLightTransmittance (RealtimeMedia::LightTransmittance).
PB_HOST_DEVICE inline Float3 MediaLightTransmittance(const RealtimeMediaView& m, int j,
                                                     const float* p, const float* wi, float dist) {
  if (m.light_trans != nullptr && j < m.num_volume_lights) {
    float T[kMaxVolumeLights];
    if (CellLightsLookup(m.light_volume, m.light_trans, p, T)) return {T[j], T[j], T[j]};
  }
  Float3 T{1, 1, 1};
  if (m.num_media > 0)
    T = MediaExpNeg(AnalyticOpticalDepthOf(m.media, m.num_media, p, wi, 0.0f, dist), false);
  for (int g = 0; g < m.num_grids; ++g) {
    const float Tg = GridLightTransmittance(m.grids[g], m.grid_light_T + m.grids[g].offset,
                                            m.num_grid_lights, j, p, wi, dist);
    T = {T.x * Tg, T.y * Tg, T.z * Tg};
  }
  return T;
}

}  // namespace penumbra

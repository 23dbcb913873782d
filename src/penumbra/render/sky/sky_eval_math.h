#pragma once
// the sky terms of a surface point or an escaping ray over plain data, shared by the CPU
// backend (SkyModel, SkyIrradianceVolume) and the CUDA backend's realtime kernels
// (core/host_device.h): SkyModel's radiance (the Preetham, Shirley and Smits daylight model,
// render/sky/sky_model.h), its tabulated irradiance and MJCF skybox background, and
// SkyIrradianceVolume's lookup (probe weights, SH blends and their evaluation,
// render/sky/sky_irradiance_volume.h, where the formulas are documented). the CPU's 4-lane lookup
// and the GPU's scalar one run the same per-lane functions (SkyCornerGeometry,
// SkyCornerWeight, SkyAccumulateSh) instantiated for a lane type: SkyScalarLanes here (float),
// the CPU's 4-float vectors in sky_irradiance_volume.cc; every operation is the IEEE one lane by
// lane, so on the CPU both give the same bits. the pods point at arrays owned by the SkyModel /
// SkyIrradianceVolume (host) or by their device copies (cuda_realtime.h).

#include <cmath>
#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/sky/sky_math.h"

#if defined(__CUDACC__)
#define PB_SKY_INLINE __forceinline__
#else
#define PB_SKY_INLINE __attribute__((always_inline)) inline
#endif

namespace penumbra {

/// irradiance nodes per side of SkyModel's octahedral irradiance table (odd: the axes are nodes).
inline constexpr int kSkyIrrSide = 49;
/// octahedral texels per side of a probe's direction map (SkyIrradianceVolume::kOctSide).
inline constexpr int kSkyOctSide = 16;
inline constexpr int kSkyNumTexels = kSkyOctSide * kSkyOctSide;
/// a probe's irradiance SH: 9 (l, m) x 3 channels padded to 28 floats; coefficient k (rgb) at
/// floats 3 kSkyShSlot[k] .. 3 kSkyShSlot[k] + 2 (the order is explained in
/// sky_irradiance_volume.cc).
inline constexpr int kSkyNumSh = 9;
inline constexpr int kSkyShStride = 28;
/// lookup offset along the normal and visibility tolerance, in probe spacings.
inline constexpr float kSkyNormalBias = 0.25f;
inline constexpr float kSkyVisibilityTolerance = 0.1f;

PB_HOST_DEVICE inline int SkyShSlot(int k) {
  // storage order 3 8 0 6 2 1 4 5 7
  constexpr int kSlot[9] = {2, 5, 4, 0, 6, 7, 3, 8, 1};
  return kSlot[k];
}

/// the Perez et al. 1993 sky luminance distribution with the five coefficients of one quantity:
/// F(theta, gamma), theta from the zenith, gamma from the sun.
struct SkyPerez {
  double a = 0, b = 0, c = 0, d = 0, e = 0;
  PB_HOST_DEVICE double operator()(double cos_theta, double gamma, double cos_gamma) const {
    const double ct = cos_theta < 1e-4 ? 1e-4 : cos_theta;
    return (1 + a * exp(b / ct)) * (1 + c * exp(d * gamma) + e * cos_gamma * cos_gamma);
  }
};

/// a SkyModel as plain data (SkyModel::pod()).
struct SkyModelPod {
  int32_t daylight = 0;  ///< 0: uniform radiance `uniform`; 1: the daylight model
  double uniform[3] = {0, 0, 0};
  double sun[3] = {0, 0, 1};  ///< unit, at or above the horizon
  SkyPerez perez_y, perez_x, perez_yc;
  double y_scale = 0, x_scale = 0, yc_scale = 0;  ///< zenith value / F(0, theta_sun)
  double ground[3] = {0, 0, 0};                   ///< radiance below the horizon
  /// kSkyIrrSide x kSkyIrrSide octahedral irradiance nodes, rgb (lux), row-major.
  const float* irradiance = nullptr;
  /// the MJCF skybox's level 0: six square faces of skybox_width^2 sRGB rgb texels; null: none.
  const uint8_t* skybox = nullptr;
  int32_t skybox_width = 0;
  const float* srgb_decode = nullptr;  ///< 256 entries (SrgbDecodeTable)
  double skybox_white = 0;             ///< radiance of a white skybox texel
};

PB_HOST_DEVICE inline double SkyClampD(double v, double lo, double hi) {
  return v < lo ? lo : (hi < v ? hi : v);
}
PB_HOST_DEVICE inline float SkyClampF(float v, float lo, float hi) {
  return v < lo ? lo : (hi < v ? hi : v);
}
PB_HOST_DEVICE inline int SkyClampI(int v, int lo, int hi) {
  return v < lo ? lo : (hi < v ? hi : v);
}

/// daylight radiance (cd/m^2, linear rgb) of unit direction d in the upper hemisphere: Y, x, y
/// each follow the Perez function normalised at the zenith; xyY -> CIE XYZ -> linear sRGB
/// (Rec. 709 primaries, D65 white, IEC 61966-2-1); negative channels clamp to 0.
PB_HOST_DEVICE inline void SkyUpperRadiance(const SkyModelPod& m, const double d[3],
                                            double out[3]) {
  const double cos_theta = SkyClampD(d[2], 0.0, 1.0);
  const double cos_gamma =
      SkyClampD(d[0] * m.sun[0] + d[1] * m.sun[1] + d[2] * m.sun[2], -1.0, 1.0);
  const double gamma = acos(cos_gamma);
  const double lum = m.y_scale * m.perez_y(cos_theta, gamma, cos_gamma);
  const double x = m.x_scale * m.perez_x(cos_theta, gamma, cos_gamma);
  const double y = m.yc_scale * m.perez_yc(cos_theta, gamma, cos_gamma);
  if (!(y > 1e-6) || !(lum > 0)) {
    out[0] = out[1] = out[2] = 0;
    return;
  }
  const double cx = x / y * lum;
  const double cz = (1 - x - y) / y * lum;
  const double rgb[3] = {3.2404542 * cx - 1.5371385 * lum - 0.4985314 * cz,
                         -0.9692660 * cx + 1.8760108 * lum + 0.0415560 * cz,
                         0.0556434 * cx - 0.2040259 * lum + 1.0572252 * cz};
  for (int k = 0; k < 3; ++k) out[k] = rgb[k] < 0.0 ? 0.0 : rgb[k];
}

/// SkyModel::Radiance in double: the uniform radiance, the ground below the horizon of a
/// daylight sky, else SkyUpperRadiance.
PB_HOST_DEVICE inline void SkyRadianceD(const SkyModelPod& m, const double d[3], double out[3]) {
  if (m.daylight == 0) {
    for (int k = 0; k < 3; ++k) out[k] = m.uniform[k];
  } else if (d[2] < 0) {
    for (int k = 0; k < 3; ++k) out[k] = m.ground[k];
  } else {
    SkyUpperRadiance(m, d, out);
  }
}

/// SkyModel::Radiance: linear rgb radiance arriving from unit direction (x, y, z).
PB_HOST_DEVICE inline void SkyRadiance(const SkyModelPod& m, float x, float y, float z,
                                       float out[3]) {
  const double d[3] = {x, y, z};
  double r[3];
  SkyRadianceD(m, d, r);
  for (int k = 0; k < 3; ++k) out[k] = static_cast<float>(r[k]);
}

/// SkyModel::Irradiance: the table's bilinear value at the octahedral coordinates of unit
/// normal (x, y, z) (no trigonometry).
PB_HOST_DEVICE inline void SkyIrradiance(const SkyModelPod& m, float x, float y, float z,
                                         float out[3]) {
  constexpr int side = kSkyIrrSide;
  const float inv = 1.0f / (fabsf(x) + fabsf(y) + fabsf(z));
  float ox = x * inv, oy = y * inv;
  if (z < 0) {
    const float fx = (1 - fabsf(oy)) * (ox >= 0 ? 1.0f : -1.0f);
    const float fy = (1 - fabsf(ox)) * (oy >= 0 ? 1.0f : -1.0f);
    ox = fx, oy = fy;
  }
  const float s = ox * 0.5f + 0.5f, t = oy * 0.5f + 0.5f;
  const float fs = s * (side - 1), ft = t * (side - 1);
  const int c0 = SkyClampI(static_cast<int>(fs), 0, side - 2);
  const int r0 = SkyClampI(static_cast<int>(ft), 0, side - 2);
  const float a = SkyClampF(ft - r0, 0.0f, 1.0f), b = SkyClampF(fs - c0, 0.0f, 1.0f);
  const float* row0 = m.irradiance + 3 * (static_cast<int64_t>(r0) * side + c0);
  const float* row1 = row0 + 3 * side;
  for (int k = 0; k < 3; ++k)
    out[k] =
        (1 - a) * ((1 - b) * row0[k] + b * row0[3 + k]) + a * ((1 - b) * row1[k] + b * row1[3 + k]);
}

/// SkyModel::Background: the MJCF skybox seen along unit direction (x, y, z) (the cube-map
/// lookup of render/sky/sky_math.h; texel colour bilinear between the texel centres of level 0,
/// clamped to the face, decoded from sRGB, times skybox_white); without a skybox, SkyRadiance.
PB_HOST_DEVICE inline void SkyBackground(const SkyModelPod& m, float x, float y, float z,
                                         float out[3]) {
  if (m.skybox == nullptr) {
    SkyRadiance(m, x, y, z, out);
    return;
  }
  float qx, qy, qz, s, t;
  int face = 0;
  SkyboxLookupDirection(x, y, z, &qx, &qy, &qz);
  if (!CubeFaceCoords(qx, qy, qz, &face, &s, &t)) {
    out[0] = out[1] = out[2] = 0;
    return;
  }
  const int w = m.skybox_width;
  const float fx = SkyClampF(s * w - 0.5f, 0.0f, static_cast<float>(w - 1));
  const float fy = SkyClampF(t * w - 0.5f, 0.0f, static_cast<float>(w - 1));
  const int x0 = static_cast<int>(fx), y0 = static_cast<int>(fy);
  const int x1 = x0 + 1 < w - 1 ? x0 + 1 : w - 1, y1 = y0 + 1 < w - 1 ? y0 + 1 : w - 1;
  const float ax = fx - x0, ay = fy - y0;
  const uint8_t* p00 = m.skybox + 3 * ((static_cast<int64_t>(face) * w + y0) * w + x0);
  const uint8_t* p10 = m.skybox + 3 * ((static_cast<int64_t>(face) * w + y0) * w + x1);
  const uint8_t* p01 = m.skybox + 3 * ((static_cast<int64_t>(face) * w + y1) * w + x0);
  const uint8_t* p11 = m.skybox + 3 * ((static_cast<int64_t>(face) * w + y1) * w + x1);
  const float* decode = m.srgb_decode;
  const float white = static_cast<float>(m.skybox_white);
  for (int k = 0; k < 3; ++k) {
    const float c = (1 - ay) * ((1 - ax) * decode[p00[k]] + ax * decode[p10[k]]) +
                    ay * ((1 - ax) * decode[p01[k]] + ax * decode[p11[k]]);
    out[k] = c * white;
  }
}

/// real spherical harmonics y_lm of a unit vector, l <= 2, in the order (0,0), (1,-1), (1,0),
/// (1,1), (2,-2), (2,-1), (2,0), (2,1), (2,2) (Ramamoorthi and Hanrahan 2001, eq. 3).
template <typename T>
PB_HOST_DEVICE inline void SkyShBasis(T x, T y, T z, T* out) {
  out[0] = T(0.282094791773878);
  out[1] = T(0.488602511902920) * y;
  out[2] = T(0.488602511902920) * z;
  out[3] = T(0.488602511902920) * x;
  out[4] = T(1.092548430592079) * x * y;
  out[5] = T(1.092548430592079) * y * z;
  out[6] = T(0.315391565252520) * (T(3) * z * z - T(1));
  out[7] = T(1.092548430592079) * x * z;
  out[8] = T(0.546274215296040) * (x * x - y * y);
}

/// a SkyIrradianceVolume as plain data (SkyIrradianceVolume::pod()); empty when a dimension is 0.
struct SkyVolumePod {
  int32_t dims[3] = {0, 0, 0};  ///< probes along x, y, z
  float spacing = 0, inv_spacing = 0;
  float origin[3] = {0, 0, 0};  ///< world position of probe (0, 0, 0)
  float depth_scale = 0;        ///< m per step of depth_q
  /// probe index of a cell's corner c (dx + 2 dy + 4 dz) minus that of its corner 0.
  int32_t corner_offset[8] = {};
  const float* sh = nullptr;         ///< per probe kSkyShStride floats (irradiance SH)
  const float* cell_pos = nullptr;   ///< per cell 24 floats: x, y, z rows of its 8 corners
  const uint8_t* depth_q = nullptr;  ///< per probe and texel, quantised hit distance
  PB_HOST_DEVICE bool empty() const { return dims[0] * dims[1] * dims[2] == 0; }
};

/// the lane type of the GPU's lookup (one corner at a time) for the per-lane functions below.
struct SkyScalarLanes {
  using F = float;
  using I = int32_t;
  using M = bool;
  static constexpr int kWidth = 1;
  PB_HOST_DEVICE static F Splat(float a) { return a; }
  PB_HOST_DEVICE static F Load(const float* p) { return *p; }
  PB_HOST_DEVICE static F Abs(F a) { return fabsf(a); }
  PB_HOST_DEVICE static F CopySign(F mag, F sgn) { return copysignf(mag, sgn); }
  PB_HOST_DEVICE static F Select(M m, F a, F b) { return m ? a : b; }
  // MINPS / MAXPS: b where either is NaN.
  PB_HOST_DEVICE static F Min(F a, F b) { return a < b ? a : b; }
  PB_HOST_DEVICE static F Max(F a, F b) { return a > b ? a : b; }
  PB_HOST_DEVICE static F Sqrt(F a) { return sqrtf(a); }
  PB_HOST_DEVICE static I ToInt(F a) { return static_cast<int32_t>(a); }
  PB_HOST_DEVICE static F ToFloat(I a) { return static_cast<float>(a); }
};

/// per lane (a probe corner): from the offset (dx, dy, dz) = probe - q of the lookup point q,
/// unit normal n and normal bias `bias` (m): whether the probe is in front of the surface
/// (*front; NaN offsets of invalid probes fail), its distance *r, (d . n) / r, and the
/// octahedral texel of -d (NaN lanes land in texel 0).
template <class L>
PB_HOST_DEVICE PB_SKY_INLINE void SkyCornerGeometry(typename L::F dx, typename L::F dy,
                                                    typename L::F dz, float nx, float ny, float nz,
                                                    float bias, typename L::M* front,
                                                    typename L::F* r, typename L::F* d_n_r,
                                                    typename L::I* texel) {
  using F = typename L::F;
  using M = typename L::M;
  const F d_n = dx * nx + (dy * ny + dz * nz);
  *front = d_n + bias > 0.0f;
  *r = L::Sqrt(dx * dx + (dy * dy + dz * dz));
  *d_n_r = d_n / *r;
  const F ux = -dx, uy = -dy, uz = -dz;
  const F inv_l1 = 1.0f / (L::Abs(ux) + L::Abs(uy) + L::Abs(uz));
  F u = ux * inv_l1, v = uy * inv_l1;
  const M lower = uz < 0.0f;
  const F u_fold = L::CopySign(1.0f - L::Abs(v), ux), v_fold = L::CopySign(1.0f - L::Abs(u), uy);
  u = L::Select(lower, u_fold, u);
  v = L::Select(lower, v_fold, v);
  // std::clamp(static_cast<int>(t), 0, kSkyOctSide - 1) (clamping first in float gives the
  // same integers; NaN lanes give 0).
  constexpr float kMax = kSkyOctSide - 1;
  const F tu = (u + 1.0f) * (0.5f * kSkyOctSide), tv = (v + 1.0f) * (0.5f * kSkyOctSide);
  const typename L::I ix = L::ToInt(L::Min(L::Max(tu, L::Splat(0.0f)), L::Splat(kMax)));
  const typename L::I iy = L::ToInt(L::Min(L::Max(tv, L::Splat(0.0f)), L::Splat(kMax)));
  *texel = ix + kSkyOctSide * iy;
}

/// per lane: the probe's weight, trilinear weight `tri` x ((1 + n . d) / 2)^2 x the visibility
/// ramp clamp((depth + tol - r) / tol, 0, 1), depth = depth_scale depth_q; `tri` alone where
/// r <= 1e-6 (q on the probe).
template <class L>
PB_HOST_DEVICE PB_SKY_INLINE typename L::F SkyCornerWeight(typename L::F r, typename L::F d_n_r,
                                                           typename L::F tri, typename L::I depth_q,
                                                           float depth_scale, float tol,
                                                           float inv_tol) {
  using F = typename L::F;
  const F back = 0.5f * (1.0f + d_n_r);
  const F depth = depth_scale * L::ToFloat(depth_q);
  // std::clamp(x, 0, 1) = Min(1, Max(0, x)), lane by lane (x for x = -0 or NaN too).
  const F vis = L::Min(L::Splat(1.0f), L::Max(L::Splat(0.0f), ((depth + tol) - r) * inv_tol));
  return L::Select(r > 1e-6f, tri * (back * back * vis), tri);
}

/// index of the lowest set bit of a non-zero mask.
PB_HOST_DEVICE inline int SkyLowestBit(unsigned bits) {
#if defined(__CUDA_ARCH__)
  return __ffs(static_cast<int>(bits)) - 1;
#else
  return __builtin_ctz(bits);
#endif
}

/// the weighted sum of packets kLo .. kHi - 1 (of L::kWidth floats) of the active corners' SH
/// (bits of `active`, in increasing order, weight w[c], probe `corner[c]` from sh_base) into
/// acc[0 .. kHi - kLo); returns the sum of the weights.
template <class L, int kLo, int kHi>
PB_HOST_DEVICE PB_SKY_INLINE float SkyAccumulateSh(const float* sh_base, const int32_t* corner,
                                                   const float* w, unsigned active,
                                                   typename L::F* acc) {
  for (int i = 0; i < kHi - kLo; ++i) acc[i] = L::Splat(0.0f);
  float wsum = 0;
  for (unsigned bits = active; bits != 0; bits &= bits - 1) {
    const int c = SkyLowestBit(bits);
    const float* sh = sh_base + corner[c] * kSkyShStride;
    const typename L::F wc = L::Splat(w[c]);
    for (int i = 0; i < kHi - kLo; ++i) acc[i] += wc * L::Load(sh + L::kWidth * (kLo + i));
    wsum += w[c];
  }
  return wsum;
}

/// sum over the listed coefficients kK (increasing) of (y[k] / wsum) times coefficient k of the
/// SH `a` (kSkyShStride floats), per channel from 0.
template <int... kK>
PB_HOST_DEVICE PB_SKY_INLINE void SkyShSumOver(const float* a, const float* y, float wsum,
                                               float out[3]) {
  for (int ch = 0; ch < 3; ++ch) {
    float sum = 0.0f;
    ((sum += (y[kK] / wsum) * a[3 * SkyShSlot(kK) + ch]), ...);
    out[ch] = sum;
  }
}

/// the SH c (kSkyShStride floats) evaluated at the basis values y, per channel from 0.
PB_HOST_DEVICE inline void SkyEvalSh(const float* c, const float* y, float out[3]) {
  for (int ch = 0; ch < 3; ++ch) {
    float sum = 0.0f;
    for (int k = 0; k < kSkyNumSh; ++k) sum += y[k] * c[3 * SkyShSlot(k) + ch];
    out[ch] = sum;
  }
}

/// irradiance SH of one probe evaluated at unit normal n (no clamping).
PB_HOST_DEVICE inline void SkyProbeIrradiance(const SkyVolumePod& v, int probe, float nx, float ny,
                                              float nz, float out[3]) {
  float y[kSkyNumSh];
  SkyShBasis(nx, ny, nz, y);
  SkyEvalSh(v.sh + static_cast<int64_t>(probe) * kSkyShStride, y, out);
}

/// the corner of the darkest probe in front of the surface (bits of `front`), by its
/// irradiance luminance at n: the lookup's fallback when no probe sees the point; -1 if none.
PB_HOST_DEVICE inline int SkyDarkestFrontCorner(const SkyVolumePod& v, int base, unsigned front,
                                                float nx, float ny, float nz) {
  float dark_lum = INFINITY;
  int dark = -1;
  for (unsigned bits = front; bits != 0; bits &= bits - 1) {
    const int c = SkyLowestBit(bits);
    float e[3];
    SkyProbeIrradiance(v, base + v.corner_offset[c], nx, ny, nz, e);
    const float lum = 0.2126f * e[0] + 0.7152f * e[1] + 0.0722f * e[2];
    if (lum < dark_lum) dark_lum = lum, dark = c;
  }
  return dark;
}

/// the probe weights of a lookup at p with unit normal n (SkyIrradianceVolume's file comment),
/// one corner at a time: the cell's first probe, the corners in front of the surface and those
/// with weight > 0 (bits c = dx + 2 dy + 4 dz), and the weights (w[c] set for every corner
/// when front != 0). false outside the grid.
struct SkyProbeWeights {
  int base = 0;
  unsigned front = 0, active = 0;
  float w[8];
};
PB_HOST_DEVICE inline bool SkyLookupWeights(const SkyVolumePod& v, const float p[3],
                                            const float n[3], SkyProbeWeights* out) {
  using L = SkyScalarLanes;
  const float bias = kSkyNormalBias * v.spacing;
  float q[3], g[3];
  for (int k = 0; k < 3; ++k) q[k] = p[k] + bias * n[k];
  for (int k = 0; k < 3; ++k) g[k] = (q[k] - v.origin[k]) * v.inv_spacing;
  const int nx = v.dims[0], ny = v.dims[1], nz = v.dims[2];
  if (!(g[0] >= 0 && g[1] >= 0 && g[2] >= 0 && g[0] <= nx - 1 && g[1] <= ny - 1 && g[2] <= nz - 1))
    return false;
  const int i0 = static_cast<int>(g[0]) < nx - 2 ? static_cast<int>(g[0]) : nx - 2;
  const int j0 = static_cast<int>(g[1]) < ny - 2 ? static_cast<int>(g[1]) : ny - 2;
  const int k0 = static_cast<int>(g[2]) < nz - 2 ? static_cast<int>(g[2]) : nz - 2;
  const float fx = g[0] - i0, fy = g[1] - j0, fz = g[2] - k0;
  const float tol = kSkyVisibilityTolerance * v.spacing;
  const float inv_tol = 1.0f / tol;
  const int base = i0 + nx * (j0 + ny * k0);
  out->base = base;
  const float* cell = v.cell_pos + static_cast<int64_t>(base) * 24;
  float r[8], d_n_r[8], tri[8];
  int32_t texel[8];
  unsigned front = 0;
  for (int c = 0; c < 8; ++c) {
    bool f;
    SkyCornerGeometry<L>(cell[c] - q[0], cell[8 + c] - q[1], cell[16 + c] - q[2], n[0], n[1], n[2],
                         bias, &f, &r[c], &d_n_r[c], &texel[c]);
    front |= (f ? 1u : 0u) << c;
    const float wx = (c & 1) ? fx : 1 - fx, wy = (c & 2) ? fy : 1 - fy;
    tri[c] = (wx * wy) * ((c & 4) ? fz : 1 - fz);
    texel[c] += kSkyNumTexels * v.corner_offset[c];
  }
  out->front = front;
  out->active = 0;
  if (front == 0) return true;
  const uint8_t* dq = v.depth_q + static_cast<int64_t>(base) * kSkyNumTexels;
  unsigned active = 0;
  for (int c = 0; c < 8; ++c) {
    out->w[c] =
        SkyCornerWeight<L>(r[c], d_n_r[c], tri[c], dq[texel[c]], v.depth_scale, tol, inv_tol);
    active |= (out->w[c] > 0.0f ? 1u : 0u) << c;
  }
  out->active = active & front;
  return true;
}

/// SkyIrradianceVolume::Blend: the weighted mean of the probes' SH at point p on a surface of
/// unit geometric normal ng into c[kSkyShStride] (zero when no probe lights the point);
/// *open_sky where p is outside the grid or the volume is empty.
PB_HOST_DEVICE inline void SkyVolumeBlend(const SkyVolumePod& v, const float p[3],
                                          const float ng[3], float* c, bool* open_sky) {
  for (int i = 0; i < kSkyShStride; ++i) c[i] = 0.0f;
  *open_sky = false;
  SkyProbeWeights pw;
  if (v.empty() || !SkyLookupWeights(v, p, ng, &pw)) {
    *open_sky = true;
    return;
  }
  if (pw.front == 0) return;
  const float* sh_base = v.sh + static_cast<int64_t>(pw.base) * kSkyShStride;
  if (pw.active != 0) {
    float acc[kSkyShStride];
    const float wsum = SkyAccumulateSh<SkyScalarLanes, 0, kSkyShStride>(sh_base, v.corner_offset,
                                                                        pw.w, pw.active, acc);
    const float inv = 1.0f / wsum;
    for (int i = 0; i < kSkyShStride; ++i) c[i] = acc[i] * inv;
    return;
  }
  const int dark = SkyDarkestFrontCorner(v, pw.base, pw.front, ng[0], ng[1], ng[2]);
  if (dark >= 0)
    for (int i = 0; i < kSkyShStride; ++i) c[i] = sh_base[v.corner_offset[dark] * kSkyShStride + i];
}

/// SkyIrradianceVolume::IrradianceAt: the blend's SH at unit shading normal n, clamped to >= 0;
/// the sky's SkyIrradiance where the blend is open_sky.
PB_HOST_DEVICE inline void SkyVolumeIrradianceAt(const SkyModelPod& sky, const float* c,
                                                 bool open_sky, const float n[3], float out[3]) {
  if (open_sky) {
    SkyIrradiance(sky, n[0], n[1], n[2], out);
    return;
  }
  float y[kSkyNumSh];
  SkyShBasis(n[0], n[1], n[2], y);
  SkyEvalSh(c, y, out);
  for (int k = 0; k < 3; ++k) out[k] = out[k] < 0.0f ? 0.0f : out[k];
}

/// SkyIrradianceVolume::Irradiance: the occluded sky irradiance at point p with unit normal n
/// (weights at n itself, no shared blend); SkyIrradiance outside the grid or when empty.
PB_HOST_DEVICE inline void SkyVolumeIrradiance(const SkyVolumePod& v, const SkyModelPod& sky,
                                               const float p[3], const float n[3], float out[3]) {
  SkyProbeWeights pw;
  if (v.empty() || !SkyLookupWeights(v, p, n, &pw)) {
    SkyIrradiance(sky, n[0], n[1], n[2], out);
    return;
  }
  out[0] = out[1] = out[2] = 0;
  if (pw.front == 0) return;
  float y[kSkyNumSh];
  SkyShBasis(n[0], n[1], n[2], y);
  if (pw.active != 0) {
    float acc[kSkyShStride];
    const float wsum = SkyAccumulateSh<SkyScalarLanes, 0, kSkyShStride>(
        v.sh + static_cast<int64_t>(pw.base) * kSkyShStride, v.corner_offset, pw.w, pw.active, acc);
    SkyShSumOver<0, 1, 2, 3, 4, 5, 6, 7, 8>(acc, y, wsum, out);
  } else {
    const int dark = SkyDarkestFrontCorner(v, pw.base, pw.front, n[0], n[1], n[2]);
    if (dark >= 0) SkyProbeIrradiance(v, pw.base + v.corner_offset[dark], n[0], n[1], n[2], out);
  }
  for (int k = 0; k < 3; ++k) out[k] = out[k] < 0.0f ? 0.0f : out[k];
}

/// the octahedral texel of a non-zero direction w (SkyIrradianceVolume::TexelOf): w over its
/// L1 norm, the lower hemisphere folded, then clamp(trunc((u + 1) kSkyOctSide / 2), 0,
/// kSkyOctSide - 1) per axis.
PB_HOST_DEVICE inline int SkyOctTexel(float wx, float wy, float wz) {
  const float inv_l1 = 1.0f / (fabsf(wx) + fabsf(wy) + fabsf(wz));
  float u = wx * inv_l1, v = wy * inv_l1;
  if (wz < 0) {
    const float au = fabsf(u), av = fabsf(v);
    u = copysignf(1.0f - av, wx);
    v = copysignf(1.0f - au, wy);
  }
  const int tu = static_cast<int>((u + 1.0f) * (0.5f * kSkyOctSide));
  const int tv = static_cast<int>((v + 1.0f) * (0.5f * kSkyOctSide));
  const int ix = tu < 0 ? 0 : (kSkyOctSide - 1 < tu ? kSkyOctSide - 1 : tu);
  const int iy = tv < 0 ? 0 : (kSkyOctSide - 1 < tv ? kSkyOctSide - 1 : tv);
  return ix + kSkyOctSide * iy;
}

/// SkyIrradianceVolume::AmbientRadiance: the occluded sphere-average sky radiance at p (world,
/// m) into out[3]: the trilinear blend over the valid probes of p's cell (those whose
/// cell_pos corner is not NaN) of their mean radiance (the irradiance SH's l = 0 term over pi,
/// times Y00), each weighted by its trilinear weight times the visibility ramp clamp((depth +
/// tol - r) / tol, 0, 1) of p seen from the probe (r its distance, depth the probe's depth
/// map in p's direction; 1 where r <= 1e-6), clamped to >= 0; where no probe has a positive
/// weight the darkest valid probe's (0 if none is valid); `open_sky` outside the grid or when
/// the volume is empty.
PB_HOST_DEVICE inline void SkyVolumeAmbientRadiance(const SkyVolumePod& v, const float* p,
                                                    const float* open_sky, float* out) {
  if (v.empty()) {
    for (int k = 0; k < 3; ++k) out[k] = open_sky[k];
    return;
  }
  float g[3];
  for (int k = 0; k < 3; ++k) g[k] = (p[k] - v.origin[k]) * v.inv_spacing;
  const int nx = v.dims[0], ny = v.dims[1], nz = v.dims[2];
  if (!(g[0] >= 0 && g[1] >= 0 && g[2] >= 0 && g[0] <= nx - 1 && g[1] <= ny - 1 &&
        g[2] <= nz - 1)) {
    for (int k = 0; k < 3; ++k) out[k] = open_sky[k];
    return;
  }
  // std::max(0, std::min(trunc(g), n - 2)) per axis (n >= 2: the cell's corners exist)
  int i[3];
  for (int k = 0; k < 3; ++k) {
    const int t = static_cast<int>(g[k]), hi = v.dims[k] - 2;
    const int m = hi < t ? hi : t;
    i[k] = m < 0 ? 0 : m;
  }
  const float f[3] = {g[0] - i[0], g[1] - i[1], g[2] - i[2]};
  const float tol = kSkyVisibilityTolerance * v.spacing;
  const int base = i[0] + nx * (i[1] + ny * i[2]);
  const float* cell = v.cell_pos + static_cast<int64_t>(base) * 24;
  float sum[3] = {0, 0, 0}, dark[3] = {0, 0, 0};
  float wsum = 0, dark_lum = INFINITY;
  constexpr float kY00OverPi = static_cast<float>(0.282094791773878 / 3.14159265358979323846);
  for (int c = 0; c < 8; ++c) {
    const int dx = c & 1, dy = (c >> 1) & 1, dz = (c >> 2) & 1;
    if (!(cell[c] == cell[c])) continue;  // an invalid probe (NaN position)
    const int probe = base + v.corner_offset[c];
    const float* sh = v.sh + static_cast<int64_t>(probe) * kSkyShStride + 3 * SkyShSlot(0);
    const float a[3] = {sh[0] * kY00OverPi, sh[1] * kY00OverPi, sh[2] * kY00OverPi};
    const float lum = 0.2126f * a[0] + 0.7152f * a[1] + 0.0722f * a[2];
    if (lum < dark_lum) {
      dark_lum = lum;
      for (int k = 0; k < 3; ++k) dark[k] = a[k];
    }
    const float tri = (dx ? f[0] : 1 - f[0]) * (dy ? f[1] : 1 - f[1]) * (dz ? f[2] : 1 - f[2]);
    const float to_p[3] = {p[0] - cell[c], p[1] - cell[8 + c], p[2] - cell[16 + c]};
    // Eigen's norm of a 3-vector: sqrt(x^2 + (y^2 + z^2))
    const float r = sqrtf(to_p[0] * to_p[0] + (to_p[1] * to_p[1] + to_p[2] * to_p[2]));
    float vis = 1;
    if (r > 1e-6f) {
      const int texel = SkyOctTexel(to_p[0] / r, to_p[1] / r, to_p[2] / r);
      const float depth =
          v.depth_scale * v.depth_q[static_cast<int64_t>(probe) * kSkyNumTexels + texel];
      const float x = (depth + tol - r) / tol;
      vis = x < 0.0f ? 0.0f : (1.0f < x ? 1.0f : x);
    }
    const float w = tri * vis;
    if (!(w > 0)) continue;
    for (int k = 0; k < 3; ++k) sum[k] = sum[k] + w * a[k];
    wsum += w;
  }
  for (int k = 0; k < 3; ++k) {
    const float x = wsum > 0 ? sum[k] / wsum : dark[k];
    out[k] = x < 0.0f ? 0.0f : x;  // cwiseMax(0)
  }
}

}  // namespace penumbra

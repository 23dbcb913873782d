#pragma once
// texture filtering formulas of render/material/material_eval.h (wrapped bilinear lookups,
// trilinear mixing of mip levels, ray-cone level of detail, anisotropic taps, cube-map faces),
// shared by MaterialEvaluator on the CPU and the CUDA kernels. a level is read through a plain view
// of its 8-bit sRGB texels; texels are decoded to linear through a 256-entry table
// (SrgbDecodeTable).

#include <cmath>
#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/shading_math.h"

namespace penumbra {

/// one mip level of a texture: width x height (x faces) texels of 3 sRGB-encoded bytes,
/// row-major (cube textures: the six faces stacked, each width x width).
struct TextureLevelView {
  const uint8_t* rgb = nullptr;
  int32_t width = 0;
  int32_t height = 0;
};

/// the smallest |cos| of incidence the level of detail divides by (grazing rays).
constexpr float kMinCosIncidence = 1e-4f;

/// the four texels around wrapped coordinates (s, t) (in images, 1 = one image) of a w x h
/// level, and the bilinear fractions between them.
struct WrappedTexels {
  int x0, y0, x1, y1;
  float fx, fy;
};

/// the texels of a wrapped bilinear lookup at (s, t): texel centres at (i + 0.5) / w.
PB_HOST_DEVICE inline WrappedTexels WrapTexels(float s, float t, int w, int h) {
  // wrap the integer part away first to keep precision.
  const float x = (s - floorf(s)) * static_cast<float>(w) - 0.5f;
  const float y = (t - floorf(t)) * static_cast<float>(h) - 0.5f;
  const float x0f = floorf(x), y0f = floorf(y);
  WrappedTexels q;
  q.fx = x - x0f;
  q.fy = y - y0f;
  // x0f in [-1, w - 1] and y0f in [-1, h - 1] (texel centres), so one step wraps them.
  q.x0 = static_cast<int>(x0f);
  q.y0 = static_cast<int>(y0f);
  q.x1 = q.x0 + 1;
  q.y1 = q.y0 + 1;
  q.x0 = q.x0 < 0 ? q.x0 + w : q.x0;
  q.y0 = q.y0 < 0 ? q.y0 + h : q.y0;
  q.x1 = q.x1 >= w ? q.x1 - w : q.x1;
  q.y1 = q.y1 >= h ? q.y1 - h : q.y1;
  return q;
}

/// the decoded linear rgb of texel (xi, yi) of a row-major level `w` texels wide.
PB_HOST_DEVICE inline Float3 DecodeTexel(const uint8_t* p, int w, const float* decode, int xi,
                                         int yi) {
  const uint8_t* q = p + (static_cast<int64_t>(yi) * w + xi) * 3;
  return Float3{decode[q[0]], decode[q[1]], decode[q[2]]};
}

/// bilinear mix of four texels by the fractions fx, fy.
PB_HOST_DEVICE inline Float3 BilinearMix(const Float3& a00, const Float3& a10, const Float3& a01,
                                         const Float3& a11, float fx, float fy) {
  return (1 - fy) * ((1 - fx) * a00 + fx * a10) + fy * ((1 - fx) * a01 + fx * a11);
}

/// bilinear lookup in one level, wrapped; (s, t) in images (1 = one image).
PB_HOST_DEVICE inline Float3 BilinearWrap(const TextureLevelView& L, const float* decode, float s,
                                          float t) {
  const WrappedTexels q = WrapTexels(s, t, L.width, L.height);
  const int w = L.width;
  return BilinearMix(DecodeTexel(L.rgb, w, decode, q.x0, q.y0),
                     DecodeTexel(L.rgb, w, decode, q.x1, q.y0),
                     DecodeTexel(L.rgb, w, decode, q.x0, q.y1),
                     DecodeTexel(L.rgb, w, decode, q.x1, q.y1), q.fx, q.fy);
}

/// bilinear lookup in face `face` of one level of a cube texture, clamped to the face; (s, t)
/// in [0, 1].
PB_HOST_DEVICE inline Float3 BilinearFace(const TextureLevelView& L, const float* decode, int face,
                                          float s, float t) {
  const int w = L.width;
  const float x = pbm::Clamp(s * w - 0.5f, 0.0f, static_cast<float>(w - 1));
  const float y = pbm::Clamp(t * w - 0.5f, 0.0f, static_cast<float>(w - 1));
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = x0 + 1 < w - 1 ? x0 + 1 : w - 1, y1 = y0 + 1 < w - 1 ? y0 + 1 : w - 1;
  const float fx = x - x0, fy = y - y0;
  const uint8_t* p = L.rgb + static_cast<int64_t>(face) * w * w * 3;
  return BilinearMix(DecodeTexel(p, w, decode, x0, y0), DecodeTexel(p, w, decode, x1, y0),
                     DecodeTexel(p, w, decode, x0, y1), DecodeTexel(p, w, decode, x1, y1), fx, fy);
}

/// the mip level of a footprint `width_m` wide met at |cos| `cos_incidence` on a mapping of
/// rho texels per metre (ray cones, Akenine-Moller et al., JCGT 10(1), 2021):
/// log2(W rho / |n . v|); 0 when the footprint or rho is 0.
PB_HOST_DEVICE inline float TextureLod(float width_m, float cos_incidence, float rho) {
  if (!(width_m > 0) || !(rho > 0)) return 0;
  return log2f(width_m * rho / pbm::Max(cos_incidence, kMinCosIncidence));
}

/// the levels a trilinear lookup at `lod` reads in a chain of `num_levels` levels and their
/// weights: one (weight 1: level 0 for lod <= 0, the last level beyond it, or an integer lod)
/// or two (floor(lod) with 1 - f, the next with f, f = the fraction of lod). returns the count.
PB_HOST_DEVICE inline int TrilinearLevels(int num_levels, float lod, int level[2],
                                          float weight[2]) {
  level[0] = 0;
  weight[0] = 1.0f;
  if (!(lod > 0)) return 1;
  const int last = num_levels - 1;
  if (!(lod < static_cast<float>(last))) return level[0] = last, 1;
  const int l = static_cast<int>(lod);
  const float f = lod - static_cast<float>(l);
  level[0] = l;
  if (!(f > 0)) return 1;
  weight[0] = 1 - f;
  level[1] = l + 1;
  weight[1] = f;
  return 2;
}

/// the taps of an anisotropic lookup (material_eval.h, "anisotropic filtering").
struct AnisoTaps {
  int n = 1;
  float lod = 0;
};

/// the taps for squared axis lengths (in level-0 texels^2) l2_major, l2_minor: N = the axis
/// ratio rounded to the nearest integer (below 1.5: one tap), capped at max_anisotropy. one tap
/// keeps the trilinear lookup at lambda = log2 of the longer axis; several taps share the mip
/// level nearest to lambda = log2(max(L_min, L_maj / N)), an integer: round(lambda) =
/// floor(ilogb(2 l^2) / 2).
PB_HOST_DEVICE inline AnisoTaps TapsFor(float l2_major, float l2_minor, int max_anisotropy) {
  if (l2_minor > l2_major) {
    const float t = l2_major;
    l2_major = l2_minor;
    l2_minor = t;
  }
  AnisoTaps taps;
  const float cap = static_cast<float>(max_anisotropy);
  const float ratio = l2_minor > 0 ? pbm::Min(cap, sqrtf(l2_major / l2_minor)) : cap;
  const int n = static_cast<int>(ratio + 0.5f);
  taps.n = n > 1 ? n : 1;
  if (taps.n == 1) {
    taps.lod = l2_major > 0 ? 0.5f * log2f(l2_major) : 0.0f;
    return taps;
  }
  const float nf = static_cast<float>(taps.n);
  const float l2 = pbm::Max(l2_minor, l2_major / (nf * nf));
  // l2 >= 1/2 gives a level >= 0 (smaller footprints: level 0).
  taps.lod = l2 >= 0.5f ? static_cast<float>(ilogbf(2 * l2) / 2) : 0.0f;
  return taps;
}

/// the level index an integer lod (TapsFor, N > 1) selects, clamped to `num_levels` levels.
PB_HOST_DEVICE inline int TapLevel(int num_levels, float lod) {
  const int l = static_cast<int>(lod);
  return l < num_levels - 1 ? l : num_levels - 1;
}

/// offset of tap k of n along the major axis, in units of the axis: ((k + 1/2) / n - 1/2).
PB_HOST_DEVICE inline float TapOffset(int k, int n) {
  return (static_cast<float>(k) + 0.5f) / static_cast<float>(n) - 0.5f;
}

/// mean of n bilinear lookups in one level (wrapped) at (s, t) + o_k (ds, dt), o_k the tap
/// offsets (footprint assembly along the major axis).
PB_HOST_DEVICE inline Float3 BilinearWrapTaps(const TextureLevelView& L, const float* decode,
                                              float s, float t, float ds, float dt, int n) {
  const int w = L.width, h = L.height;
  const uint8_t* p = L.rgb;
  const float step = 1.0f / static_cast<float>(n);
  const float o0 = 0.5f * step - 0.5f;
  float r = 0, g = 0, b = 0;
  for (int k = 0; k < n; ++k) {
    const float o = o0 + static_cast<float>(k) * step;
    const float u = s + o * ds, v = t + o * dt;
    const WrappedTexels q = WrapTexels(u, v, w, h);
    const uint8_t* r0 = p + static_cast<int64_t>(q.y0) * w * 3;
    const uint8_t* r1 = p + static_cast<int64_t>(q.y1) * w * 3;
    const uint8_t* a = r0 + q.x0 * 3;
    const uint8_t* bq = r0 + q.x1 * 3;
    const uint8_t* c = r1 + q.x0 * 3;
    const uint8_t* d = r1 + q.x1 * 3;
    const float w00 = (1 - q.fx) * (1 - q.fy), w10 = q.fx * (1 - q.fy);
    const float w01 = (1 - q.fx) * q.fy, w11 = q.fx * q.fy;
    r += w00 * decode[a[0]] + w10 * decode[bq[0]] + w01 * decode[c[0]] + w11 * decode[d[0]];
    g += w00 * decode[a[1]] + w10 * decode[bq[1]] + w01 * decode[c[1]] + w11 * decode[d[1]];
    b += w00 * decode[a[2]] + w10 * decode[bq[2]] + w01 * decode[c[2]] + w11 * decode[d[2]];
  }
  return Float3{r, g, b} * step;
}

/// the cube face and face coordinates (s, t) in [0, 1] of direction q (any length > 0), with
/// the face orientation of OpenGL cube maps (OpenGL 4.6 core spec, table 8.19) and MuJoCo's face
/// order (+x, -x, +y, -y, +z, -z). false when q is 0.
PB_HOST_DEVICE inline bool CubeFaceCoords(const Float3& q, int* face, float* s, float* t) {
  const float ax = fabsf(q.x), ay = fabsf(q.y), az = fabsf(q.z);
  float sc, tc, ma;
  if (ax >= ay && ax >= az) {
    ma = ax;
    *face = q.x >= 0 ? 0 : 1;
    sc = q.x >= 0 ? -q.z : q.z;
    tc = -q.y;
  } else if (ay >= az) {
    ma = ay;
    *face = q.y >= 0 ? 2 : 3;
    sc = q.x;
    tc = q.y >= 0 ? q.z : -q.z;
  } else {
    ma = az;
    *face = q.z >= 0 ? 4 : 5;
    sc = q.z >= 0 ? q.x : -q.x;
    tc = -q.y;
  }
  if (!(ma > 0)) return false;
  *s = 0.5f * (sc / ma + 1.0f);
  *t = 0.5f * (tc / ma + 1.0f);
  return true;
}

/// the direction a geom's cube texture is looked up by at geom-frame point p_G
/// (render/material/material_eval.h, "cube texture"): q = p_G / h per axis, h the half extents of
/// the geom's local bounding box, and along a flat axis (h = 0) the outward geom-frame normal n_G's
/// component.
PB_HOST_DEVICE inline Float3 CubeLookupDirection(const Float3& p_G, const Float3& n_G,
                                                 const Float3& h) {
  return Float3{h.x > 0 ? p_G.x / h.x : n_G.x, h.y > 0 ? p_G.y / h.y : n_G.y,
                h.z > 0 ? p_G.z / h.z : n_G.z};
}

/// texels per metre of a cube texture w texels wide on a geom whose largest half extent is
/// h_max: w / (2 h_max) (each face spans the geom); 0 when h_max is not positive.
PB_HOST_DEVICE inline float CubeRho(float w, float h_max) {
  return h_max > 0 ? w / (2 * h_max) : 0.0f;
}

/// a planar texture mapping at a point (render/material/material_eval.h, "texture mapping"):
/// texture coordinates (s, t) in images, their derivatives ds / dp_a0 and dt / dp_a1 along the face
/// axes a0, a1 (the only non-zero entries of the mapping's gradient), and its texels per metre.
/// the mapping is MuJoCo's for 2d textures (render_gl3.c, settexture: 0.5 texrepeat per unit
/// of the geom's unit-size object coordinates), pinned down against MuJoCo 4.0.0's own renders
/// of a quadrant texture on boxes and planes: on a face of half sizes (h0, h1) the coordinates
/// run from its corner (-h0, +h1), s = 0.5 rx (p_a0 / h0 + 1), t = 0.5 ry (1 - p_a1 / h1); with
/// texuniform the same without the division, s = 0.5 rx (p_a0 + h0), t = 0.5 ry (h1 - p_a1)
/// (texrepeat / 2 images per metre); an infinite plane (no half sizes) has
/// s = 0.5 rx p_a0 - 0.5, t = -0.5 ry p_a1 - 0.5. Menagerie's floor (an infinite plane,
/// texrepeat 5, a 2 x 2 checker): 0.4 m per image, 0.2 m checks, edge marks at 0.2 m + k 0.4 m.
struct PlanarMap {
  float s = 0, t = 0;
  float j0 = 0, j1 = 0;
  bool uniform = true;   ///< texuniform (or an infinite plane), else per face
  float rx = 1, ry = 1;  ///< texrepeat
  float h0 = 1, h1 = 1;  ///< per face: half sizes of the face

  /// texels per metre of surface for a w x th image (the isotropic lookup's rho).
  PB_HOST_DEVICE float rho(float w, float th) const {
    if (uniform) return sqrtf(0.5f * fabsf(rx) * w * 0.5f * fabsf(ry) * th);
    return sqrtf(fabsf(rx) * w / (2 * h0) * fabsf(ry) * th / (2 * h1));
  }
};

/// texuniform mapping: texrepeat (rx, ry) images per 2 m of the face coordinates p_a0, p_a1,
/// counted from the face's corner (-h0, +h1) when it has half sizes h0, h1 > 0, else (an
/// infinite plane, h0 or h1 <= 0) from MuJoCo's offset of half an image; image rows along -a1.
PB_HOST_DEVICE inline PlanarMap PlanarMapUniform(float p_a0, float p_a1, float h0, float h1,
                                                 float rx, float ry) {
  PlanarMap m;
  m.uniform = true;
  m.rx = rx, m.ry = ry;
  if (h0 > 0 && h1 > 0) {
    m.s = 0.5f * rx * (p_a0 + h0);
    m.t = 0.5f * ry * (h1 - p_a1);
  } else {
    m.s = 0.5f * rx * p_a0 - 0.5f;
    m.t = -0.5f * ry * p_a1 - 0.5f;
  }
  m.j0 = 0.5f * rx;
  m.j1 = -0.5f * ry;
  return m;
}

/// per-face mapping: texrepeat times across the face of half sizes h0, h1 (> 0), from its
/// corner (-h0, +h1).
PB_HOST_DEVICE inline PlanarMap PlanarMapPerFace(float p_a0, float p_a1, float h0, float h1,
                                                 float rx, float ry) {
  PlanarMap m;
  m.uniform = false;
  m.rx = rx, m.ry = ry;
  m.h0 = h0, m.h1 = h1;
  m.s = (0.5f * p_a0 / h0 + 0.5f) * rx;
  m.t = (0.5f - 0.5f * p_a1 / h1) * ry;
  m.j0 = 0.5f * rx / h0;
  m.j1 = -0.5f * ry / h1;
  return m;
}

/// how an anisotropic footprint is filtered: n > 1 taps along (ds, dt) in the level round(lod),
/// else a trilinear lookup at lod; ok false when the major axis has no length (then the
/// isotropic level of detail applies).
struct PlanarFilterPlan {
  bool ok = false;
  float lod = 0;
  int n = 1;
  float ds = 0, dt = 0;
};

/// the anisotropic filter plan of a footprint whose major and minor axes are (major_s,
/// major_t) and (minor_s, minor_t) in texture units (images), for a w x th image: their squared
/// lengths in level-0 texels, the taps (TapsFor) spread along the longer one.
PB_HOST_DEVICE inline PlanarFilterPlan PlanAnisotropic(float major_s, float major_t, float minor_s,
                                                       float minor_t, float w, float th,
                                                       int max_anisotropy) {
  PlanarFilterPlan plan;
  const float ms = major_s * w, mt = major_t * th, ns = minor_s * w, nt = minor_t * th;
  const float l2_major = ms * ms + mt * mt;
  const float l2_minor = ns * ns + nt * nt;
  if (!(l2_major > 0)) return plan;
  plan.ok = true;
  // the axis the taps spread along: the longer one in texels.
  const bool swap = l2_minor > l2_major;
  const AnisoTaps taps = TapsFor(l2_major, l2_minor, max_anisotropy);
  plan.lod = taps.lod;
  if (taps.n > 1) {
    plan.n = taps.n;
    plan.ds = swap ? minor_s : major_s;
    plan.dt = swap ? minor_t : major_t;
  }
  return plan;
}

/// PlanAnisotropic for a planar map and a footprint's geom-frame axes along the face axes
/// (major_a0, major_a1, minor_a0, minor_a1).
PB_HOST_DEVICE inline PlanarFilterPlan PlanPlanarFilter(const PlanarMap& map, float major_a0,
                                                        float major_a1, float minor_a0,
                                                        float minor_a1, float w, float th,
                                                        int max_anisotropy) {
  return PlanAnisotropic(map.j0 * major_a0, map.j1 * major_a1, map.j0 * minor_a0, map.j1 * minor_a1,
                         w, th, max_anisotropy);
}

/// texels per metre of surface of a mesh's texcoords on a w x th image (the isotropic lookup's
/// rho, render/material/material_eval.h "filtering"): uv_per_m sqrt(w th), uv_per_m the hit
/// triangle's SurfaceHit::uv_per_m.
PB_HOST_DEVICE inline float TexcoordRho(float uv_per_m, float w, float th) {
  return uv_per_m * sqrtf(w * th);
}

/// a geom-frame vector a (a footprint axis) in texture units: (s, t) = J a, J the 2 x 3
/// texcoord gradient given by its rows j_s, j_t (SurfaceHit::duv_dp_G; for a planar mapping
/// the rows with j0, j1 at the face axes and zeros elsewhere).
PB_HOST_DEVICE inline void TexcoordAxis(const float j_s[3], const float j_t[3], const float a[3],
                                        float* s, float* t) {
  // summed as Eigen's 2 x 3 by 3 product sums them (x0 + (x1 + x2)): the CPU's bits
  *s = j_s[0] * a[0] + (j_s[1] * a[1] + j_s[2] * a[2]);
  *t = j_t[0] * a[0] + (j_t[1] * a[1] + j_t[2] * a[2]);
}

/// the tangent t_G (increasing s) and bitangent b_G (towards the image's top row: decreasing
/// t) of a mesh's texcoord mapping, geom frame: the columns of the pseudo-inverse
/// P = J^T (J J^T)^-1 of its gradient J (rows j_s, j_t), t_G = P e_s, b_G = -P e_t (normal
/// mapping, MaterialEvaluator::ApplyNormalMap). false where J J^T is singular
/// (|det| <= 1e-20).
PB_HOST_DEVICE inline bool TexcoordTangents(const float j_s[3], const float j_t[3], float t_G[3],
                                            float b_G[3]) {
  const float a = j_s[0] * j_s[0] + j_s[1] * j_s[1] + j_s[2] * j_s[2];
  const float b = j_s[0] * j_t[0] + j_s[1] * j_t[1] + j_s[2] * j_t[2];
  const float d = j_t[0] * j_t[0] + j_t[1] * j_t[1] + j_t[2] * j_t[2];
  const float det = a * d - b * b;
  if (!(fabsf(det) > 1e-20f)) return false;
  const float inv = 1.0f / det;
  // (J J^T)^-1 = [d -b; -b a] / det
  const float i00 = d * inv, i01 = -b * inv, i11 = a * inv;
  for (int k = 0; k < 3; ++k) {
    t_G[k] = j_s[k] * i00 + j_t[k] * i01;
    b_G[k] = -(j_s[k] * i01 + j_t[k] * i11);
  }
  return true;
}

/// normal mapping (render/material/material_eval.h, MaterialEvaluator::ApplyNormalMap; the CPU
/// keeps its Eigen form of these lines, whose vectorised products round differently: docs/gpu.md):
/// the unit world shading normal that texel c of a tangent-space normal map ((x, y, z) = 2 c - 1)
/// gives at a surface of unit shading normal ns (as the hit has it: flipped towards the ray on back
/// faces, front_face false), with the mapping's tangent t_W (increasing s) and bitangent b_W
/// (towards the image's top row), world frame, not yet orthogonal: t is made orthogonal to the
/// outward normal n (Gram-Schmidt), b is +-(n x t) on the side of b_W, and the mapped normal
/// normalize(x t + y b + max(z, 0) n) is flipped back with the hit. false (no change) where the
/// frame degenerates.
PB_HOST_DEVICE inline bool BendNormal(const Float3& ns, bool front_face, Float3 t_W,
                                      const Float3& b_W, const Float3& c, Float3* out) {
  const Float3 tn{2 * c.x - 1, 2 * c.y - 1, 2 * c.z - 1};
  const Float3 n = front_face ? ns : -ns;
  const float t_n = t_W.x * n.x + t_W.y * n.y + t_W.z * n.z;
  t_W = t_W - t_n * n;
  const float lt = sqrtf(t_W.x * t_W.x + t_W.y * t_W.y + t_W.z * t_W.z);
  if (!(lt > 0)) return false;
  const Float3 t{t_W.x / lt, t_W.y / lt, t_W.z / lt};
  // b minus its components along n and t, normalised, is +-(n x t) (n, t orthonormal).
  const Float3 n_x_t{n.y * t.z - n.z * t.y, n.z * t.x - n.x * t.z, n.x * t.y - n.y * t.x};
  const float b_along = b_W.x * n_x_t.x + b_W.y * n_x_t.y + b_W.z * n_x_t.z;
  if (!(b_along != 0)) return false;
  const Float3 b = b_along > 0 ? n_x_t : -n_x_t;
  const float zn = pbm::Max(tn.z, 0.0f);
  const Float3 mapped{tn.x * t.x + tn.y * b.x + zn * n.x, tn.x * t.y + tn.y * b.y + zn * n.y,
                      tn.x * t.z + tn.y * b.z + zn * n.z};
  const float len = sqrtf(mapped.x * mapped.x + mapped.y * mapped.y + mapped.z * mapped.z);
  if (!(len > 0) || !pbm::IsFinite(mapped.x) || !pbm::IsFinite(mapped.y) ||
      !pbm::IsFinite(mapped.z))
    return false;
  const Float3 m{mapped.x / len, mapped.y / len, mapped.z / len};
  *out = front_face ? m : -m;
  return true;
}

}  // namespace penumbra

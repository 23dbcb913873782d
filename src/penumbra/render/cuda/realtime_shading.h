#pragma once
// the CUDA backend's realtime tier, per pixel, as PB_HOST_DEVICE functions over plain data: the
// kernels of realtime_kernels.cu run them on the GPU and RealtimeHostRenderer
// (realtime_frame.h) runs the same functions on the CPU (tests, and machines without a GPU).
// the formulas are the shared ones of render/ (brdf_math.h, light_math.h, texture_math.h,
// film_math.h) that the CPU backend's RealtimeIntegrator and Film call; this file only chains
// them as render/cpu/realtime_integrator.cc does:
//
//   L = Le + E_sky / pi (c_diff (1 - S) + S) + sum over lights f(wo, wi) |n . wi| E_i V_i
//
// with the same lattice points per pixel (render/lamp_math.h: LightStratum, no random numbers),
// lamps and the sun's disc in the same closed form (ExtendedLightShading) and their visibility
// V_i shared between neighbouring pixels as the CPU shares it (render/shadow_window_math.h:
// the ratio estimator of Heitz et al. 2018 over each pixel's 5x5 same-surface window, cut at
// the 16x16 tiles' edges; SharedVisibilityRays / Fraction / Resolve after ShadeRealtimePixel),
// the same negligible-light rule (no shadow ray below kNegligibleLight of the unshadowed total)
// and shadow rays from OffsetRayOrigin. E_sky (occluded sky irradiance on the surface normal,
// one probe blend per flat 2x2 quad as the CPU) and the sky radiance of rays that escape come
// per pixel from QuadSkyTerms, the shared lookups of render/sky_eval_math.h that SkyModel and
// SkyIrradianceVolume call on the CPU (a kernel of their own, or the host's
// RealtimeFrameData::SkyTerms). the mirror layer (SurfaceMaterial::mirror, weight r: L becomes
// (1 - r) L + r L_m) as render/cpu/mirror_layer.cc: the mirrored view ray traced on the layer's
// grid (render/mirror_math.h; TraceMirrorRay), its hit shaded with one random sample of every
// light and a shadow ray and the occluded sky irradiance at the hit (MirrorSkyTerm, beside the
// primary sky terms; ShadeMirrorHit), the other
// layer pixels interpolated from the grid and blended (ApplyMirrorLayer). the lighting effects
// reach it as the CPU's: the lights (scaled, extra) and the sky (moved sun, scaled) through
// the frame's data, the surface wetness in EvaluateSurface (render/wetness_math.h). meshes and
// height fields shade with their vertex normals mixed at the hit and map their textures by their
// texcoords (HitShadingNormal, HitTexcoords: primary_pixel.h), escaping rays see the MJCF
// skybox (SkyBackground), and cube textures wrap geoms (FilterCube), as the CPU.

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/brdf_math.h"
#include "penumbra/render/cuda/bvh_traversal.h"
#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/cuda/path_streaks.h"
#include "penumbra/render/cuda/primary_pixel.h"
#include "penumbra/render/film_math.h"
#include "penumbra/render/lamp_math.h"
#include "penumbra/render/light_math.h"
#include "penumbra/render/media_build_math.h"
#include "penumbra/render/media_realtime_math.h"
#include "penumbra/render/mirror_math.h"
#include "penumbra/render/particle_math.h"
#include "penumbra/render/shading_math.h"
#include "penumbra/render/shadow_window_math.h"
#include "penumbra/render/sky_eval_math.h"
#include "penumbra/render/texture_math.h"
#include "penumbra/render/wetness_math.h"

namespace penumbra::cuda {

/// lights below this fraction of a pixel's unshadowed radiance get no shadow ray (as
/// RealtimeIntegrator's kNegligibleLight).
constexpr float kGpuNegligibleLight = 1e-3f;
/// render/ray.h's kRayOffsetScale (shadow-ray origins pushed off the surface).
constexpr float kGpuRayOffsetScale = 5e-5f;
/// the most mip levels a texture has (a 65536-texel side).
constexpr int kMaxTextureLevels = 17;

/// a material as the GPU evaluates it (Material's factors and its 2d base texture).
struct MaterialPod {
  Float3 base_color{0.8f, 0.8f, 0.8f};
  float roughness = 0.5f, metallic = 0, specular = 0.5f;
  Float3 emission;
  int32_t texture = -1;  ///< into the frame's textures: a 2d texture, planar-mapped; -1 none
  float texrepeat[2] = {1, 1};
  int32_t texuniform = 0;
  /// the PBR maps (render/material_eval.h, "PBR maps"), into the frame's textures; -1 none.
  int32_t normal_map = -1, metallic_roughness_map = -1, occlusion_map = -1, emissive_map = -1;
  /// the mirror layer's weight on a plane or a box's top face: min(reflectance, 1), 0 none
  /// (MaterialEvaluator::Untextured's SurfaceMaterial::mirror).
  float mirror = 0;
  PB_HOST_DEVICE bool any_map() const {
    return texture >= 0 || normal_map >= 0 || metallic_roughness_map >= 0 || occlusion_map >= 0 ||
           emissive_map >= 0;
  }
};

/// a 2d texture, or a cube texture (cube 1: each level holds the six faces of width[l]^2
/// texels, face after face, as TextureLevel): its mip levels' texels at texels[level_offset[l]]
/// (bytes).
struct TexturePod {
  int32_t num_levels = 0;
  int32_t cube = 0;
  int32_t width[kMaxTextureLevels] = {};
  int32_t height[kMaxTextureLevels] = {};
  int64_t level_offset[kMaxTextureLevels] = {};
};

/// a geom as the GPU maps textures on it, posed for the frame.
struct GeomPod {
  float X_GW[12] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0};  ///< row-major [R | p], world to geom
  Float3 half_extent;          ///< local bounding-box half extents (MaterialEvaluator's)
  int32_t infinite_plane = 0;  ///< a plane without finite size in the face's axes
  int32_t plane = 0;           ///< GeomShape::kPlane
  int32_t box = 0;             ///< GeomShape::kBox (its top face, n_G.z > 0.5, takes a mirror)
};

/// what a pixel's primary ray (or its mirrored ray, TraceMirrorRay) hits, for the host's sky
/// pass: p_W, the unit geometric normal facing the ray and the unit shading normal (normal map
/// applied, UsableShadingNormal) where it hits; the unit ray direction where it does not.
struct PixelGeometry {
  Float3 p_or_d;
  Float3 ng;
  Float3 ns;
  /// 1 hit, 0 miss; -1 (mirrored rays only): the pixel traced no mirrored ray.
  int32_t hit = 0;
  int32_t geom = -1;  ///< the hit's SceneDescription geom index (-1: none or not a geom)
  float mirror = 0;   ///< the hit surface's mirror weight r (ShadingPoint::mirror), 0 none
};

/// a pixel's nearest particle streak (EffectsFrame::particles), shaded: drawn over the pixel's
/// radiance where it lies in front of the primary hit (ApplyStreak). made by the device's splat
/// (StreakSplatView: SplatStreakRow, ShadeSplatPixel) or, with the host splat
/// (RealtimeFrameData::set_device_streaks(false)), found and shaded on the host by the CPU
/// backend's functions (ParticleStreaks::PixelHit and Shade, render/particle_streaks.h).
struct StreakPixel {
  int64_t pixel = 0;  ///< row-major pixel index
  float t = 0;        ///< ray parameter of the streak (the primary ray's units: as the depth)
  float alpha = 0;    ///< coverage in (0, 1]
  Float3 L;           ///< radiance of the streak, cd/m^2 (before the media in front of it)
};

/// the realtime tier's particle streaks splatted per pixel by the frame itself (branch gpu18;
/// render/particle_math.h's ProjectStreak, StreakRowColumns and IntersectCapsuleRay, which the
/// CPU backend's ParticleStreaks::BuildPixelHits calls too): every streak's pixel box is
/// scanned, each pixel-centre ray (PrimaryRay) met by the capsule keeps the smallest StreakKey
/// (nearest t, then lower index: the host splat's rule) in `nearest`, and each pixel with a key
/// is shaded into `pixels` (ShadeSplatPixel).
struct StreakSplatView {
  /// the frame's streaks in ParticleStreaks' index order (StreakPod::prim = the index; no BVH:
  /// nodes null), their particle sets and the open sky's sphere-average radiance (sky_ambient);
  /// rain radiance is shaded per pixel (rain null). num 0: no splat.
  PathStreaks streaks;
  /// the streaks' count where streaks.num is only a bound of it (the device culling's streaks
  /// read in place, RealtimeFrameData::DeviceStreakList, branch gpu30), in the memory the
  /// reader runs in, as the streaks (SplatStreakCount); null: streaks.num is their count.
  const int32_t* count = nullptr;
  /// the projection of the frame's camera (Camera::X_WO and its intrinsics, as BuildPixelHits):
  /// world to optical frame, R_OW row-major, and the pinhole intrinsics (px).
  float R_OW[9] = {1, 0, 0, 0, 1, 0, 0, 0, 1};
  Float3 p_OW{0, 0, 0};
  double fx = 1, fy = 1, cx = 0, cy = 0;
  /// a moving camera without lens distortion: per row v (height of them, 12 doubles each) the
  /// pose the CPU's rays take (Camera::PoseAtRow(v)): the rotation R_WO row-major, then the
  /// origin (m); the splat's rays are then Camera::GenerateRay's to the bit (SplatRay). null:
  /// the frame's camera rays (PrimaryRay<true>; a moving camera with lens distortion takes its
  /// float tables, whose rays may differ from the CPU's in their last bits).
  const double* rows = nullptr;
  /// a moving camera (lens distortion or not): its rows' motion (StreakMotionOf), which widens
  /// every streak's box (SplatProjection: WidenStreakForMotion), and per row v (height of them,
  /// 12 doubles each, as `rows`) its pose, in which the row's columns are taken
  /// (SplatStreakRow: StreakRowColumnsAtPose), as ParticleStreaks::BuildPixelHits takes them.
  /// null poses: a still camera (motion zero).
  StreakMotion motion;
  const double* poses = nullptr;
  /// per pixel (row-major, width x height): the nearest streak's StreakKey (kNoStreakKey: none;
  /// all kNoStreakKey before the splat) and, where it has one, the shaded streak
  /// (ShadeSplatPixel). arrays of the memory the reader runs in (device, or host for
  /// RenderRealtimeOnHost); null when num is 0.
  unsigned long long* nearest = nullptr;
  StreakPixel* pixels = nullptr;
};

/// everything a realtime frame reads, as device (or host) pointers.
struct RealtimeFrameView {
  SceneView scene;
  PinholeCamera camera;
  float spread_rad = 0;                    ///< Camera::pixel_spread_rad
  const MaterialPod* materials = nullptr;  ///< by SceneDescription material index
  MaterialPod default_material;            ///< for material -1
  const GeomPod* geoms = nullptr;          ///< by SceneDescription geom index
  const TexturePod* textures = nullptr;
  const uint8_t* texels = nullptr;
  const float* srgb_decode = nullptr;  ///< 256 entries (SrgbDecodeTable)
  const LightPod* lights = nullptr;
  int32_t num_lights = 0;
  int32_t max_anisotropy = 1;
  /// EffectsFrame::surface_wetness of the frame in [0, 1] (0: dry; EvaluateSurface).
  float wetness = 0;
  uint64_t frame_key = 0;  ///< FrameContext::FrameKey()
  /// per pixel: E_sky on the surface the pixel's ray hits, or the sky radiance where it
  /// escapes (QuadSkyTerms).
  const Float3* sky_term = nullptr;
  /// the sky and the occluded sky volume (render/sky_eval_math.h) whose lookups make the sky
  /// terms (QuadSkyTerms, MirrorSkyTerm): device copies in the kernels, host arrays on the host.
  SkyModelPod sky;
  SkyVolumePod volume;
  /// the shared visibility of lights with an extent (render/shadow_window_math.h), per pixel i
  /// of the n = width x height image: its primary geometry (PrimaryGeometry) and its 5x5
  /// window's same-surface mask (SharedVisibilityRays), the luminance of its radiance with
  /// every light unshadowed (ShadeRealtimePixel; decides the penumbra ray budget,
  /// PenumbraLatticePoints); per light j and pixel i at [j n + i]:
  /// the unshadowed contribution and the pixel's own shadow ray's verdict (1 visible,
  /// 0 occluded, -1 none traced; ShadeRealtimePixel), the visible and traced rays after the
  /// penumbra rays, whether the pixel keeps its own fraction (a tile's outer ring), and the
  /// window's fraction (SharedVisibilityFraction). device or host arrays the caller owns.
  const PixelGeometry* geometry = nullptr;
  uint32_t* window = nullptr;
  float* total = nullptr;
  Float3* area_c = nullptr;
  int8_t* area_vis = nullptr;
  float* area_visible = nullptr;
  float* area_rays = nullptr;
  uint8_t* area_own = nullptr;
  float* area_fraction = nullptr;
  /// the mirror layer (any_mirror: some material has one), per pixel: the mirrored ray's
  /// geometry (hit -1 where the pixel traces none; TraceMirrorRay) and closest hit, its sky
  /// term (MirrorSkyTerm: E_sky at the hit, or the sky's Background where it escapes) and the
  /// reflected radiance L_m (ShadeMirrorHit).
  int32_t any_mirror = 0;
  PixelGeometry* mirror_geometry = nullptr;
  TraceHit* mirror_hits = nullptr;
  const Float3* mirror_sky = nullptr;
  Float3* mirror_radiance = nullptr;
  /// the frame's particle streaks found and shaded on the host (the host splat,
  /// RealtimeFrameData::set_device_streaks(false)), num_streaks of them in pixel order (none:
  /// no particles, or the device splat's `splat`).
  const StreakPixel* streaks = nullptr;
  int64_t num_streaks = 0;
  /// the frame's particle streaks for the splat the frame makes itself (streaks.num 0: none).
  StreakSplatView splat;
  /// the frame's homogeneous media (fog, haze, dust; has_media 1), their arrays as device or
  /// host pointers (render/media_realtime_math.h, RealtimeMedia::HostView): the light
  /// transmittances of the surface loop (ShadeRealtimePoint) and the view pass (MediaViewQuad).
  int32_t has_media = 0;
  RealtimeMediaView media;
  /// the media volumes this frame builds itself before its first kernel reads them
  /// (MediaLightVolumeCell, MediaFogColumn; RealtimeMedia::Build's device_volumes): their
  /// layouts are in `media`, their arrays (light_trans, fog_S, fog_inv_log_far) filled then.
  MediaVolumesToBuild media_build;
};

/// a surface point as the realtime tier shades it: the textured material and the frame.
struct ShadingPoint {
  Float3 p, ng, n, wo;  ///< point, geometric normal (facing the ray), shading normal, to viewer
  Float3 base, emission;
  float roughness = 0.5f, metallic = 0, specular = 0.5f, occlusion = 1;
  float mirror = 0;  ///< the mirror layer's weight r (MaterialPod::mirror where it applies)
};

/// the material terms of a ShadingPoint that PixelGeometry does not hold (40 bytes): the
/// geometry kernel keeps them so that the shading kernel need not evaluate the surface again
/// (ShadeRealtimeStored).
struct SurfaceTerms {
  Float3 base, emission;
  float roughness = 0.5f, metallic = 0, specular = 0.5f, occlusion = 1;
};

PB_HOST_DEVICE inline Float3 ToFloat3(const F3& v) { return Float3{v.x, v.y, v.z}; }
PB_HOST_DEVICE inline F3 ToF3(const Float3& v) { return F3{v.x, v.y, v.z}; }

/// streak s is not beyond the pixel's primary hit at depth `depth` (m, 0: the ray escapes).
PB_HOST_DEVICE inline bool StreakInFront(const StreakPixel& s, float depth) {
  return !(depth > 0 && !(s.t <= depth));
}

/// the radiance of a pixel with streak s over its radiance L (after the surface, the shared
/// visibility and the mirror layer), as RealtimeIntegrator's view effects: s drawn over L
/// (StreakOver) where it lies in front of the primary hit (StreakInFront), else L.
PB_HOST_DEVICE inline Float3 ApplyStreak(const StreakPixel& s, float depth, const Float3& L) {
  if (!StreakInFront(s, depth)) return L;
  return Float3{StreakOver(s.alpha, s.L.x, L.x), StreakOver(s.alpha, s.L.y, L.y),
                StreakOver(s.alpha, s.L.z, L.z)};
}

/// the origin of rays leaving point p on the side of unit normal n: p pushed off the surface by
/// kGpuRayOffsetScale (1 + |p|_inf) along n (render/ray.h's OffsetRayOrigin).
PB_HOST_DEVICE inline F3 OffsetOrigin(const Float3& p, const Float3& n) {
  const float amax = pbm::Max(pbm::Max(fabsf(p.x), fabsf(p.y)), fabsf(p.z));
  const float off = kGpuRayOffsetScale * (1.0f + amax);
  return F3{p.x + off * n.x, p.y + off * n.y, p.z + off * n.z};
}

/// the pixel-centre ray of pixel (u, v) of camera c: primary_pixel.h's PinholePixelRay, or with
/// c's tables (lens distortion, a moving camera; camera_rays.h) the pixel's undistorted
/// coordinates and its row's pose, as Camera::GenerateRay. kRn: the direction's products and
/// sums rounded on their own (NormalizedPixelRay<true>: the realtime splat's rays).
template <bool kRn = false>
PB_HOST_DEVICE inline TraceRay PrimaryRay(const PinholeCamera& c, int u, int v) {
  if (!c.xy && !c.rows)
    return PinholePixelRay<kRn>(c.o, c.ex, c.ey, c.ez, c.cx, c.cy, c.inv_fx, c.inv_fy, c.near, u,
                                v);
  float x = (static_cast<float>(u) - c.cx) * c.inv_fx;
  float y = (static_cast<float>(v) - c.cy) * c.inv_fy;
  if (c.xy) {
    const float* p = c.xy + 2 * (static_cast<int64_t>(v) * c.width + u);
    x = p[0];
    y = p[1];
  }
  if (!c.rows) return NormalizedPixelRay<kRn>(c.o, c.ex, c.ey, c.ez, x, y, c.near);
  const float* r = c.rows + 12 * static_cast<int64_t>(v);
  return NormalizedPixelRay<kRn>(F3{r[0], r[1], r[2]}, F3{r[3], r[4], r[5]}, F3{r[6], r[7], r[8]},
                                 F3{r[9], r[10], r[11]}, x, y, c.near);
}

/// where a pixel's ray cone meets a surface, for planar texture lookups (MaterialEvaluator's
/// planar mapping along the dominant axis a0, a1 of the geom-frame normal n_G; the footprint's
/// anisotropic axes, FootprintAxes, when max_anisotropy > 1).
struct PlanarFootprint {
  PlanarMap map;
  int a0 = 0, a1 = 1;
  bool axes = false;
  float major[3] = {0, 0, 0}, minor[3] = {0, 0, 0};
  float width_m = 0, cos_incidence = 1;
  /// a mesh triangle's texcoords (HitTexcoords) instead of the planar mapping: map.s, map.t
  /// are the hit's (u, v), rho is TexcoordRho of its uv_per_m and the axes are mapped by its
  /// duv_dp_G (MaterialEvaluator's kTexcoords mapping); null: planar.
  const TriangleShading* texcoords = nullptr;
};

/// the footprint of material m on geom g at geom-frame point p_G, normal n_G and ray direction
/// d_G, for a cone width_m wide met at |cos| cos_incidence.
PB_HOST_DEVICE inline PlanarFootprint PlanarFootprintAt(const MaterialPod& m, const GeomPod& g,
                                                        const Float3& p_G, const Float3& n_G,
                                                        const Float3& d_G, float width_m,
                                                        float cos_incidence, int max_anisotropy) {
  PlanarFootprint fp;
  fp.width_m = width_m;
  fp.cos_incidence = cos_incidence;
  const float an[3] = {fabsf(n_G.x), fabsf(n_G.y), fabsf(n_G.z)};
  const int axis = (an[0] >= an[1] && an[0] >= an[2]) ? 0 : (an[1] >= an[2] ? 1 : 2);
  fp.a0 = (axis + 1) % 3;
  fp.a1 = (axis + 2) % 3;
  const float p[3] = {p_G.x, p_G.y, p_G.z};
  const float h[3] = {g.half_extent.x, g.half_extent.y, g.half_extent.z};
  const float rx = m.texrepeat[0], ry = m.texrepeat[1];
  const int a0 = fp.a0, a1 = fp.a1;
  const bool infinite = g.plane != 0 && !(h[a0] > 0 && h[a1] > 0);
  if (m.texuniform != 0 || infinite)
    fp.map = PlanarMapUniform(p[a0], p[a1], infinite ? 0.0f : h[a0], infinite ? 0.0f : h[a1], rx,
                              ry);
  else
    fp.map =
        PlanarMapPerFace(p[a0], p[a1], h[a0] > 0 ? h[a0] : 1.0f, h[a1] > 0 ? h[a1] : 1.0f, rx, ry);
  if (max_anisotropy > 1 && width_m > 0) {
    const float dn = d_G.x * n_G.x + d_G.y * n_G.y + d_G.z * n_G.z;
    const Float3 t{d_G.x - dn * n_G.x, d_G.y - dn * n_G.y, d_G.z - dn * n_G.z};
    const float len = sqrtf(t.x * t.x + t.y * t.y + t.z * t.z);
    if (len > 1e-4f) {
      const Float3 tu{t.x / len, t.y / len, t.z / len};
      const float major_len = width_m / pbm::Max(cos_incidence, kMinCosIncidence);
      const Float3 b{n_G.y * tu.z - n_G.z * tu.y, n_G.z * tu.x - n_G.x * tu.z,
                     n_G.x * tu.y - n_G.y * tu.x};
      fp.major[0] = tu.x * major_len, fp.major[1] = tu.y * major_len,
      fp.major[2] = tu.z * major_len;
      fp.minor[0] = b.x * width_m, fp.minor[1] = b.y * width_m, fp.minor[2] = b.z * width_m;
      fp.axes = true;
    }
  }
  return fp;
}

/// mip level l of texture `tex` in the frame's texels.
PB_HOST_DEVICE inline TextureLevelView LevelView(const RealtimeFrameView& f, const TexturePod& tex,
                                                 int l) {
  return TextureLevelView{f.texels + tex.level_offset[l], tex.width[l], tex.height[l]};
}

/// the trilinear filter of `tex` at `lod`: tap(level) (a level's bilinear value) of the one or
/// two levels TrilinearLevels picks, weighted and summed in level order (MaterialEvaluator's
/// trilinear lookups, planar and cube).
template <class Tap>
PB_HOST_DEVICE inline Float3 TrilinearMix(const RealtimeFrameView& f, const TexturePod& tex,
                                          float lod, const Tap& tap) {
  int level[2];
  float weight[2];
  const int count = TrilinearLevels(tex.num_levels, lod, level, weight);
  Float3 c{0, 0, 0};
  for (int i = 0; i < count; ++i) c = c + weight[i] * tap(LevelView(f, tex, level[i]));
  return c;
}

/// the linear rgb of texture `slot` over footprint fp (material_eval.h's filtering: anisotropic
/// taps in one level, else trilinear over the isotropic level of detail).
PB_HOST_DEVICE inline Float3 FilterPlanar(const RealtimeFrameView& f, int slot,
                                          const PlanarFootprint& fp) {
  const TexturePod& tex = f.textures[slot];
  const float w = static_cast<float>(tex.width[0]), th = static_cast<float>(tex.height[0]);
  float lod = 0, ds = 0, dt = 0;
  int n = 1;
  bool planned = false;
  const TriangleShading* tc = fp.texcoords;
  if (fp.axes) {
    PlanarFilterPlan plan;
    if (tc) {
      float ms, mt, ns, nt;
      TexcoordAxis(tc->duv_dp_G, tc->duv_dp_G + 3, fp.major, &ms, &mt);
      TexcoordAxis(tc->duv_dp_G, tc->duv_dp_G + 3, fp.minor, &ns, &nt);
      plan = PlanAnisotropic(ms, mt, ns, nt, w, th, f.max_anisotropy);
    } else {
      plan = PlanPlanarFilter(fp.map, fp.major[fp.a0], fp.major[fp.a1], fp.minor[fp.a0],
                              fp.minor[fp.a1], w, th, f.max_anisotropy);
    }
    if (plan.ok) {
      lod = plan.lod, n = plan.n, ds = plan.ds, dt = plan.dt;
      planned = true;
    }
  }
  if (!planned)
    lod = TextureLod(fp.width_m, fp.cos_incidence,
                     tc ? TexcoordRho(tc->uv_per_m, w, th) : fp.map.rho(w, th));
  if (n > 1)
    return BilinearWrapTaps(LevelView(f, tex, TapLevel(tex.num_levels, lod)), f.srgb_decode,
                            fp.map.s, fp.map.t, ds, dt, n);
  return TrilinearMix(f, tex, lod, [&](const TextureLevelView& L) {
    return BilinearWrap(L, f.srgb_decode, fp.map.s, fp.map.t);
  });
}

/// the linear rgb of cube texture `slot` in direction q (any length > 0), trilinear at `lod`,
/// clamped to the face (MaterialEvaluator::SampleCube); white where q is 0.
PB_HOST_DEVICE inline Float3 SampleCubeTexture(const RealtimeFrameView& f, int slot,
                                               const Float3& q, float lod) {
  int face;
  float s, t;
  if (!CubeFaceCoords(q, &face, &s, &t)) return Float3{1, 1, 1};
  return TrilinearMix(f, f.textures[slot], lod, [&](const TextureLevelView& L) {
    return BilinearFace(L, f.srgb_decode, face, s, t);
  });
}

/// the linear rgb of cube texture `slot` on geom g at geom-frame point p_G of outward
/// geom-frame normal n_G over footprint fp (MaterialEvaluator::Evaluate's cube branch: the
/// lookup direction CubeLookupDirection, rho CubeRho; anisotropic taps along the footprint's
/// major axis, each a cube lookup of the displaced point, where fp has axes).
PB_HOST_DEVICE inline Float3 FilterCube(const RealtimeFrameView& f, int slot, const GeomPod& g,
                                        const Float3& p_G, const Float3& n_G,
                                        const PlanarFootprint& fp) {
  const Float3& h = g.half_extent;
  const float rho =
      CubeRho(static_cast<float>(f.textures[slot].width[0]), pbm::Max(pbm::Max(h.x, h.y), h.z));
  if (fp.axes && rho > 0) {
    const float rho2 = rho * rho;
    const float* a = fp.major;
    const float* b = fp.minor;
    const AnisoTaps taps =
        TapsFor((a[0] * a[0] + a[1] * a[1] + a[2] * a[2]) * rho2,
                (b[0] * b[0] + b[1] * b[1] + b[2] * b[2]) * rho2, f.max_anisotropy);
    Float3 c{0, 0, 0};
    for (int k = 0; k < taps.n; ++k) {
      const float o = TapOffset(k, taps.n);
      const Float3 p{p_G.x + o * a[0], p_G.y + o * a[1], p_G.z + o * a[2]};
      c = c + SampleCubeTexture(f, slot, CubeLookupDirection(p, n_G, h), taps.lod);
    }
    const float n = static_cast<float>(taps.n);
    return Float3{c.x / n, c.y / n, c.z / n};
  }
  return SampleCubeTexture(f, slot, CubeLookupDirection(p_G, n_G, h),
                           TextureLod(fp.width_m, fp.cos_incidence, rho));
}

/// whether light l has an extent: a sphere lamp (radius > 0) or the sun's disc (as the CPU
/// realtime integrator's IsExtendedLight).
PB_HOST_DEVICE inline bool IsExtendedLightPod(const LightPod& l) {
  return HasLightExtent(l.kind == LightKind::kDirectional, l.cos_angular_radius, l.radius_m);
}

/// the two uniform numbers of lattice point r (0 <= r < kLightPenumbraRays) of pixel (u, v):
/// point kLightPenumbraRays LightStratum(u, v) + r of the kLightStrata kLightPenumbraRays
/// lattice (render/lamp_math.h), as RealtimeIntegrator takes them.
PB_HOST_DEVICE inline void PixelLatticeUniforms(int u, int v, int r, float* u1, float* u2) {
  LightStratumUniforms(kLightPenumbraRays * LightStratum(u, v) + r,
                       kLightStrata * kLightPenumbraRays, u1, u2);
}

/// the unshadowed contribution f(wo, wi) |n . wi| E of light j at p for pixel (u, v), as the
/// CPU realtime integrator computes it (0 where the light sends nothing): a light without an
/// extent sampled at the pixel's lattice point; a lamp or sun disc in closed form
/// (ExtendedLightShading: the BRDF towards the light's centre, tilted above the horizon where
/// the light straddles it). *wi, *dist: the shadow ray of the pixel's first lattice point (the
/// shading direction where that point lies below the geometric surface).
PB_HOST_DEVICE inline Float3 LightContribution(const RealtimeFrameView& f, int j, int u, int v,
                                               const Float3& p, const Float3& n, const Float3& ng,
                                               const Float3& wo, float n_v, const Float3& c_diff,
                                               const Float3& f0, float a2, Float3* wi,
                                               float* dist) {
  float u1, u2;
  PixelLatticeUniforms(u, v, 0, &u1, &u2);
  Float3 E;
  bool valid;
  const LightPod& l = f.lights[j];
  SampleLight<float, Float3, bool>(l, p, u1, u2, wi, dist, &E, &valid);
  if (!valid) return Float3{0, 0, 0};
  if (!IsExtendedLightPod(l)) {
    const Float3 fr = BrdfEvalWorld<float, Float3>(n, ng, wo, n_v, c_diff, f0, a2, *wi);
    return Float3{fr.x * E.x, fr.y * E.y, fr.z * E.z};
  }
  // the axis, sin^2 sigma and near distance.
  float w[3], sin2, dist_near;
  if (l.kind == LightKind::kDirectional) {
    w[0] = -l.direction_W.x, w[1] = -l.direction_W.y, w[2] = -l.direction_W.z;
    sin2 = 1.0f - l.cos_angular_radius * l.cos_angular_radius;
    dist_near = INFINITY;
  } else {
    const float c[3] = {l.position_W.x, l.position_W.y, l.position_W.z};
    const float pp[3] = {p.x, p.y, p.z};
    SphereLightAxis(c, l.radius_m, pp, w, &sin2, &dist_near);
  }
  const float nn[3] = {n.x, n.y, n.z};
  const float cos_t = nn[0] * w[0] + nn[1] * w[1] + nn[2] * w[2];
  const float sin_sigma = sqrtf(pbm::Max(sin2, 0.0f));
  float rep[3] = {w[0], w[1], w[2]};
  float scale = cos_t > 1e-6f ? 1.0f : 0.0f;
  if (LightStraddlesHorizon(cos_t, sin2, sin_sigma)) scale = ExtendedLightShading(w, sin2, nn, rep);
  const Float3 wi_rep{rep[0], rep[1], rep[2]};
  if (!(pbm::Dot<float>(ng, *wi) > 0)) *wi = wi_rep, *dist = dist_near;
  const Float3 fr = BrdfEvalWorld<float, Float3>(n, ng, wo, n_v, c_diff, f0, a2, wi_rep);
  return Float3{fr.x * E.x * scale, fr.y * E.y * scale, fr.z * E.z * scale};
}

/// the shading point of hit h of ray r (d_len = |r.d|): the material with its textures and
/// PBR maps filtered over the pixel's ray cone (MaterialEvaluator's order: base colour,
/// metallic-roughness, occlusion, emissive, normal map), its mirror weight (a plane, or a
/// box's face whose outward geom-frame normal has z > 0.5, as MaterialEvaluator::Untextured),
/// and the shading normal the viewer sees (UsableShadingNormal). path_m: the cone's length
/// before r's origin (a mirrored ray: the camera-to-mirror distance; 0 for a primary ray).
PB_HOST_DEVICE inline ShadingPoint EvaluateSurface(const RealtimeFrameView& f, const TraceRay& r,
                                                   const TraceHit& h, float d_len,
                                                   float path_m = 0) {
  const SceneView& s = f.scene;
  ShadingPoint sp;
  const Float3 d{r.d.x / d_len, r.d.y / d_len, r.d.z / d_len};
  sp.wo = -d;
  sp.p = Float3{r.o.x + h.t * r.d.x, r.o.y + h.t * r.d.y, r.o.z + h.t * r.d.z};
  bool front_face = true;
  sp.ng = ToFloat3(HitNormal(s, r, h, &front_face));
  const Float3& p = sp.p;
  const Float3& ng = sp.ng;
  const Record& rec = s.records[s.prims[h.prim].record];
  const MaterialPod& m = rec.material >= 0 ? f.materials[rec.material] : f.default_material;
  sp.base = m.base_color;
  sp.roughness = m.roughness;
  sp.metallic = m.metallic;
  sp.specular = m.specular;
  sp.emission = m.emission;
  if (m.mirror > 0 && rec.geom >= 0) {
    const GeomPod& g = f.geoms[rec.geom];
    // the outward normal's geom-frame z: row 2 of R_GW times the normal facing the ray.
    const float* R = g.X_GW;
    const float nz = R[8] * ng.x + R[9] * ng.y + R[10] * ng.z;
    if (g.plane != 0 || (g.box != 0 && (front_face ? nz : -nz) > 0.5f)) sp.mirror = m.mirror;
  }
  // smooth shading: a mesh's (or height field's) vertex normals mixed at the hit
  Float3 ns = ng;
  HitShadingNormal(s, h, front_face, &ns);
  if (m.any_map() && rec.geom >= 0) {
    const GeomPod& g = f.geoms[rec.geom];
    const Float3 p_G = ToFloat3(TransformPoint(g.X_GW, ToF3(p)));
    const Float3 n_G = ToFloat3(TransformVector(g.X_GW, ToF3(ng)));
    const Float3 d_G = ToFloat3(TransformVector(g.X_GW, ToF3(d)));
    const float cos_inc = pbm::Min(1.0f, fabsf(ng.x * d.x + ng.y * d.y + ng.z * d.z));
    const float width_m =
        path_m > 0 ? f.spread_rad * (path_m + h.t * d_len) : f.spread_rad * h.t * d_len;
    PlanarFootprint fp = PlanarFootprintAt(m, g, p_G, n_G, d_G, width_m, cos_inc, f.max_anisotropy);
    // a mesh's texcoords replace the planar mapping (MaterialEvaluator::MapAt)
    fp.texcoords = HitTexcoords(s, h, &fp.map.s, &fp.map.t);
    if (m.texture >= 0) {
      // a cube texture by the geom's box (the outward normal along flat axes), else 2d
      const Float3 c = f.textures[m.texture].cube != 0
                           ? FilterCube(f, m.texture, g, p_G, front_face ? n_G : -n_G, fp)
                           : FilterPlanar(f, m.texture, fp);
      sp.base = Float3{sp.base.x * c.x, sp.base.y * c.y, sp.base.z * c.z};
    }
    if (m.metallic_roughness_map >= 0) {
      const Float3 c = FilterPlanar(f, m.metallic_roughness_map, fp);
      sp.roughness *= c.y;
      sp.metallic *= c.z;
    }
    if (m.occlusion_map >= 0)
      sp.occlusion = pbm::Clamp(FilterPlanar(f, m.occlusion_map, fp).x, 0.0f, 1.0f);
    if (m.emissive_map >= 0) {
      const Float3 c = FilterPlanar(f, m.emissive_map, fp);
      sp.emission = Float3{sp.emission.x * c.x, sp.emission.y * c.y, sp.emission.z * c.z};
    }
    if (m.normal_map >= 0) {
      const float* R = g.X_GW;
      Float3 t_W, b_W;
      bool frame = true;
      if (fp.texcoords) {
        // the texcoords' tangent frame (TexcoordTangents) rotated to the world by R_GW^T.
        float t_G[3], b_G[3];
        frame = TexcoordTangents(fp.texcoords->duv_dp_G, fp.texcoords->duv_dp_G + 3, t_G, b_G);
        t_W = Float3{R[0] * t_G[0] + R[4] * t_G[1] + R[8] * t_G[2],
                     R[1] * t_G[0] + R[5] * t_G[1] + R[9] * t_G[2],
                     R[2] * t_G[0] + R[6] * t_G[1] + R[10] * t_G[2]};
        b_W = Float3{R[0] * b_G[0] + R[4] * b_G[1] + R[8] * b_G[2],
                     R[1] * b_G[0] + R[5] * b_G[1] + R[9] * b_G[2],
                     R[2] * b_G[0] + R[6] * b_G[1] + R[10] * b_G[2]};
      } else {
        // the planar mapping's tangent (+-a0) and bitangent (-+a1) in the world: rows of R_GW.
        const float st = fp.map.j0 >= 0 ? 1.0f : -1.0f, sb = fp.map.j1 >= 0 ? -1.0f : 1.0f;
        t_W = Float3{st * R[4 * fp.a0], st * R[4 * fp.a0 + 1], st * R[4 * fp.a0 + 2]};
        b_W = Float3{sb * R[4 * fp.a1], sb * R[4 * fp.a1 + 1], sb * R[4 * fp.a1 + 2]};
      }
      Float3 bent;
      if (frame && BendNormal(ns, front_face, t_W, b_W, FilterPlanar(f, m.normal_map, fp), &bent))
        ns = bent;
    }
  }
  // rain wetness (render/wetness_math.h) at the (bent) shading normal, after the PBR maps: the
  // CPU's ApplySurfaceWetness at SurfaceHit::ns_W, in its primary shading and mirror layer.
  float wet_scale, wet_roughness;
  if (f.wetness > 0 &&
      SurfaceWetnessTerms(f.wetness, ns.z, sp.metallic, sp.roughness, &wet_scale, &wet_roughness)) {
    sp.base = sp.base * wet_scale;
    sp.roughness = wet_roughness;
  }
  sp.n = pbm::Dot<float>(ns, sp.wo) > 0 ? ns : ng;
  return sp;
}

/// the sky term of one pixel from its primary geometry g: SkyBackground (the MJCF skybox, else
/// SkyRadiance) where the ray escapes; where it hits, the occluded sky irradiance (the volume's
/// blend at the point and geometric normal, evaluated at the shading normal; SkyIrradiance of the
/// shading normal outside the grid or with an empty volume).
PB_HOST_DEVICE inline Float3 PixelSkyTerm(const SkyModelPod& sky, const SkyVolumePod& volume,
                                          const PixelGeometry& g) {
  float e[3];
  if (g.hit == 0) {
    // the MJCF skybox where there is one (SkyRadiance without), as the CPU's Background
    SkyBackground(sky, g.p_or_d.x, g.p_or_d.y, g.p_or_d.z, e);
  } else {
    const float ns[3] = {g.ns.x, g.ns.y, g.ns.z};
    if (!volume.empty()) {
      const float p[3] = {g.p_or_d.x, g.p_or_d.y, g.p_or_d.z}, ng[3] = {g.ng.x, g.ng.y, g.ng.z};
      float c[kSkyShStride];
      bool open_sky;
      SkyVolumeBlend(volume, p, ng, c, &open_sky);
      SkyVolumeIrradianceAt(sky, c, open_sky, ns, e);
    } else {
      SkyIrradiance(sky, ns[0], ns[1], ns[2], e);
    }
  }
  return Float3{e[0], e[1], e[2]};
}

/// the sky terms (RealtimeFrameView::sky_term) of the 2x2 quad at even (u0, v0) of a
/// width-pixel image (pixels at or below row1 and right of the image left out), as
/// RealtimeIntegrator's TileSkyIrradiance: with a sky volume, a quad whose pixels see one flat
/// face (one geom, bitwise equal geometric normals, points on one plane within 1 mm and within
/// a quarter probe spacing of each other) shares one blend at the quad's mean point; other
/// pixels take PixelSkyTerm.
PB_HOST_DEVICE inline void QuadSkyTerms(const SkyModelPod& sky, const SkyVolumePod& volume,
                                        const PixelGeometry* geometry, int width, int row1, int u0,
                                        int v0, Float3* out) {
  const int64_t i00 = static_cast<int64_t>(v0) * width + u0;
  const int64_t quad[4] = {i00, i00 + 1, i00 + width, i00 + width + 1};
  const bool occluded = !volume.empty();
  bool shared = occluded && u0 + 1 < width && v0 + 1 < row1;
  if (shared) {
    const PixelGeometry& g0 = geometry[quad[0]];
    for (int c = 0; c < 4 && shared; ++c) {
      const PixelGeometry& g = geometry[quad[c]];
      shared = g.hit != 0 && g.geom == g0.geom && g.ng.x == g0.ng.x && g.ng.y == g0.ng.y &&
               g.ng.z == g0.ng.z;
    }
    const float max_extent = 0.25f * volume.spacing;
    constexpr float kPlaneTolM = 1e-3f;
    float mean[3] = {0, 0, 0};
    for (int c = 0; c < 4 && shared; ++c) {
      const PixelGeometry& g = geometry[quad[c]];
      const float dp[3] = {g.p_or_d.x - g0.p_or_d.x, g.p_or_d.y - g0.p_or_d.y,
                           g.p_or_d.z - g0.p_or_d.z};
      const float n_dp = g0.ng.x * dp[0] + (g0.ng.y * dp[1] + g0.ng.z * dp[2]);
      shared = fabsf(n_dp) <= kPlaneTolM && fabsf(dp[0]) <= max_extent &&
               fabsf(dp[1]) <= max_extent && fabsf(dp[2]) <= max_extent;
      mean[0] += 0.25f * g.p_or_d.x;
      mean[1] += 0.25f * g.p_or_d.y;
      mean[2] += 0.25f * g.p_or_d.z;
    }
    if (shared) {
      const float n0[3] = {g0.ng.x, g0.ng.y, g0.ng.z};
      float c[kSkyShStride];
      bool open_sky;
      SkyVolumeBlend(volume, mean, n0, c, &open_sky);
      for (int k = 0; k < 4; ++k) {
        const PixelGeometry& g = geometry[quad[k]];
        const float ns[3] = {g.ns.x, g.ns.y, g.ns.z};
        float e[3];
        SkyVolumeIrradianceAt(sky, c, open_sky, ns, e);
        out[quad[k]] = Float3{e[0], e[1], e[2]};
      }
      return;
    }
  }
  for (int c = 0; c < 4; ++c)
    if (u0 + (c & 1) < width && v0 + (c >> 1) < row1)
      out[quad[c]] = PixelSkyTerm(sky, volume, geometry[quad[c]]);
}

/// the sky term of a mirrored ray (RealtimeFrameView::mirror_sky) from its geometry g
/// (TraceMirrorRay): where it hits, the occluded sky irradiance at the hit's shading normal
/// (SkyVolumeIrradiance, no shared blends: render/cpu/mirror_layer.cc's MirrorRadiance), where
/// it escapes SkyBackground; false (out unchanged) where the pixel traced none (hit -1).
PB_HOST_DEVICE inline bool MirrorSkyTerm(const SkyModelPod& sky, const SkyVolumePod& volume,
                                         const PixelGeometry& g, Float3* out) {
  if (g.hit < 0) return false;
  float e[3];
  if (g.hit == 0) {
    SkyBackground(sky, g.p_or_d.x, g.p_or_d.y, g.p_or_d.z, e);
  } else {
    const float p[3] = {g.p_or_d.x, g.p_or_d.y, g.p_or_d.z}, ns[3] = {g.ns.x, g.ns.y, g.ns.z};
    SkyVolumeIrradiance(volume, sky, p, ns, e);
  }
  *out = Float3{e[0], e[1], e[2]};
  return true;
}

/// the geometry of pixel (u, v)'s primary ray for the sky terms; *t_hit: its hit's t
/// (0 on a miss); *hit_out (if given): the closest hit; *surface_out (if given, where the ray
/// hits): the shading point's material terms (ShadeRealtimeStored).
PB_HOST_DEVICE inline PixelGeometry PrimaryGeometry(const RealtimeFrameView& f, int u, int v,
                                                    float* t_hit, TraceHit* hit_out = nullptr,
                                                    SurfaceTerms* surface_out = nullptr) {
  const TraceRay r = PrimaryRay(f.camera, u, v);
  TraceHit h;
  TraceClosest(f.scene, r, &h);
  if (hit_out) *hit_out = h;
  PixelGeometry g;
  *t_hit = 0;
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  if (h.instance < 0) {
    const float inv = 1.0f / d_len;
    g.p_or_d = Float3{r.d.x * inv, r.d.y * inv, r.d.z * inv};
    return g;
  }
  *t_hit = h.t;
  const ShadingPoint sp = EvaluateSurface(f, r, h, d_len);
  g.hit = 1;
  g.geom = f.scene.records[f.scene.prims[h.prim].record].geom;
  g.p_or_d = sp.p;
  g.ng = sp.ng;
  g.ns = sp.n;
  g.mirror = sp.mirror;
  if (surface_out) {
    surface_out->base = sp.base;
    surface_out->emission = sp.emission;
    surface_out->roughness = sp.roughness;
    surface_out->metallic = sp.metallic;
    surface_out->specular = sp.specular;
    surface_out->occlusion = sp.occlusion;
  }
  return g;
}

/// light j's contribution c at surface point p (shadow ray direction wi, distance dist:
/// LightContribution's) attenuated by the frame's homogeneous media on the way to the light, as
/// RealtimeIntegrator's surface loop: c as it is where it is 0, else c times
/// MediaLightTransmittance (the world light volume's channel-mean value where p lies in it and
/// it holds light j, else the closed form). the CPU looks every light up at once per point
/// (LightTransmittances): the same values; here one light at a time, so that nothing stays live
/// across the light loop.
PB_HOST_DEVICE inline Float3 MediaAttenuated(const RealtimeFrameView& f, int j, const Float3& p,
                                             const Float3& wi, float dist, const Float3& c) {
  if (c.x == 0 && c.y == 0 && c.z == 0) return c;
  const float pp[3] = {p.x, p.y, p.z}, ww[3] = {wi.x, wi.y, wi.z};
  const Float3 T = MediaLightTransmittance(f.media, j, pp, ww, dist);
  return Float3{c.x * T.x, c.y * T.y, c.z * T.z};
}

/// lights whose unshadowed contribution ShadeRealtimeHit keeps between its two loops (the
/// others are evaluated twice).
constexpr int kShadeCachedLights = 16;

/// where ShadeRealtimePoint keeps lights 0 .. capacity() - 1's unshadowed terms (contribution c,
/// unit direction wi towards the light, distance dist, LightContribution's) between its two
/// loops: the thread's own arrays (on the device, local memory: the shading kernel's stack).
struct LocalLightTerms {
  Float3 c[kShadeCachedLights], wi[kShadeCachedLights];
  float dist[kShadeCachedLights];
  /// the lights kept: kShadeCachedLights
  PB_HOST_DEVICE int capacity() const { return kShadeCachedLights; }
  /// keeps light j's terms (j < capacity())
  PB_HOST_DEVICE void Put(int j, const Float3& cj, const Float3& wij, float dj) {
    c[j] = cj, wi[j] = wij, dist[j] = dj;
  }
  /// light j's terms as Put kept them
  PB_HOST_DEVICE void Get(int j, Float3* cj, Float3* wij, float* dj) const {
    *cj = c[j], *wij = wi[j], *dj = dist[j];
  }
};

/// LocalLightTerms in memory the caller owns, interleaved over `stride` threads (the shading
/// kernel's shared memory, RealtimeKernelOptions::shared_light_terms): float k (0 .. 6: c, wi,
/// dist) of light j at at[(kLightTermFloats j + k) stride], `at` the block's array plus the
/// thread's index, so a warp's lanes touch consecutive words. the same values as
/// LocalLightTerms, so the same bits.
struct StridedLightTerms {
  /// floats a light's terms take
  static constexpr int kLightTermFloats = 7;
  float* at = nullptr;  ///< the thread's first float
  int stride = 0;       ///< the threads sharing the array (floats between two of a thread's)
  int lights = 0;       ///< the lights kept (at most kShadeCachedLights)
  /// the lights kept
  PB_HOST_DEVICE int capacity() const { return lights; }
  /// keeps light j's terms (j < capacity())
  PB_HOST_DEVICE void Put(int j, const Float3& cj, const Float3& wij, float dj) {
    float* q = at + kLightTermFloats * j * stride;
    q[0] = cj.x, q[stride] = cj.y, q[2 * stride] = cj.z;
    q[3 * stride] = wij.x, q[4 * stride] = wij.y, q[5 * stride] = wij.z;
    q[6 * stride] = dj;
  }
  /// light j's terms as Put kept them
  PB_HOST_DEVICE void Get(int j, Float3* cj, Float3* wij, float* dj) const {
    const float* q = at + kLightTermFloats * j * stride;
    *cj = Float3{q[0], q[stride], q[2 * stride]};
    *wij = Float3{q[3 * stride], q[4 * stride], q[5 * stride]};
    *dj = q[6 * stride];
  }
};

/// what ShadeRealtimePoint computes at a shading point before its lights: the BRDF's
/// coefficients (BrdfCoefficientsOf: c_diff, f0, a2 = alpha^2), n . wo, the ambient radiance
/// Le + E_sky / pi (c_diff (1 - S) + S) and the shadow rays' origin (OffsetOrigin off the
/// geometric normal).
struct ShadeSetup {
  Float3 c_diff, f0;
  float a2 = 0, n_v = 0;
  Float3 L;
  F3 origin;
};

/// ShadeSetup of shading point sp with sky term `sky` (E_sky where the pixel's ray hits).
PB_HOST_DEVICE inline ShadeSetup BeginShadePoint(const ShadingPoint& sp, const Float3& sky) {
  ShadeSetup s;
  const float roughness = sp.roughness;
  const Float3 emission = sp.emission;
  const float occlusion = sp.occlusion;
  // the BRDF's coefficients and the ambient term E_sky / pi (c_diff (1 - S) + S); the shading
  // normal where it faces the viewer, else the geometric one (UsableShadingNormal).
  float alpha;
  BrdfCoefficientsOf<float, Float3>(sp.base, roughness, sp.metallic, sp.specular, &s.c_diff, &s.f0,
                                    &alpha);
  s.a2 = alpha * alpha;
  s.n_v = pbm::Dot<float>(sp.n, sp.wo);
  const Float3 spec = EnvBrdfApprox<float, Float3>(s.f0, pbm::Max(s.n_v, 0.0f), roughness);
  const Float3 reflect{s.c_diff.x * (1.0f - spec.x) + spec.x, s.c_diff.y * (1.0f - spec.y) + spec.y,
                       s.c_diff.z * (1.0f - spec.z) + spec.z};
  const Float3 sky_E = occlusion * sky;
  s.L = Float3{emission.x + (sky_E.x * pbm::kInvPi) * reflect.x,
               emission.y + (sky_E.y * pbm::kInvPi) * reflect.y,
               emission.z + (sky_E.z * pbm::kInvPi) * reflect.z};
  // shadow rays start off the surface on the lit side.
  s.origin = OffsetOrigin(sp.p, sp.ng);
  return s;
}

/// light j's unshadowed contribution at shading point sp of pixel (u, v) (LightContribution,
/// attenuated by the frame's media where kMedia and f.has_media), its shadow ray's unit
/// direction *wi and distance *dist.
template <bool kMedia>
PB_HOST_DEVICE inline Float3 UnshadowedLight(const RealtimeFrameView& f, int j, int u, int v,
                                             const ShadingPoint& sp, const ShadeSetup& s,
                                             Float3* wi, float* dist) {
  Float3 c = LightContribution(f, j, u, v, sp.p, sp.n, sp.ng, sp.wo, s.n_v, s.c_diff, s.f0, s.a2,
                               wi, dist);
  if (kMedia && f.has_media != 0) c = MediaAttenuated(f, j, sp.p, *wi, *dist, c);
  return c;
}

/// ShadeRealtimePoint's first light loop: every light's unshadowed term (the first
/// terms.capacity() kept in `terms`), returns the unshadowed total's luminance (the ambient
/// term's and every light's), which decides the shadow rays worth tracing.
template <bool kMedia, class Terms>
PB_HOST_DEVICE inline float UnshadowedLights(const RealtimeFrameView& f, int u, int v,
                                             const ShadingPoint& sp, const ShadeSetup& s,
                                             Terms& terms) {
  float total = pbm::Luminance709(s.L.x, s.L.y, s.L.z);
  const int cached = terms.capacity();
  for (int j = 0; j < f.num_lights; ++j) {
    Float3 wi;
    float dist;
    const Float3 c = UnshadowedLight<kMedia>(f, j, u, v, sp, s, &wi, &dist);
    if (j < cached) terms.Put(j, c, wi, dist);
    total += pbm::Luminance709(c.x, c.y, c.z);
  }
  return total;
}

/// light j's unshadowed terms for ShadeRealtimePoint's second loop: kept in `terms`, or
/// evaluated again (UnshadowedLight) for lights from terms.capacity() on.
template <bool kMedia, class Terms>
PB_HOST_DEVICE inline Float3 KeptLight(const RealtimeFrameView& f, int j, int u, int v,
                                       const ShadingPoint& sp, const ShadeSetup& s,
                                       const Terms& terms, Float3* wi, float* dist) {
  if (j < terms.capacity()) {
    Float3 c;
    terms.Get(j, &c, wi, dist);
    return c;
  }
  return UnshadowedLight<kMedia>(f, j, u, v, sp, s, wi, dist);
}

/// a light of luminance lum (> 0) at a pixel whose unshadowed total is `total` gets a shadow
/// ray: it casts shadows and is not negligible (kGpuNegligibleLight of the total).
PB_HOST_DEVICE inline bool WantsShadowRay(const LightPod& l, float lum, float total) {
  return l.cast_shadow != 0 && lum >= kGpuNegligibleLight * total;
}

/// the shadow ray from `origin` towards a light in unit direction wi at distance dist (stops
/// just short of it; +inf stays +inf).
PB_HOST_DEVICE inline TraceRay ShadowRayOf(const F3& origin, const Float3& wi, float dist) {
  TraceRay sr;
  sr.o = origin;
  sr.d = ToF3(wi);
  sr.tmin = 0;
  sr.tmax = dist * (1.0f - 1e-4f);  // +inf stays +inf
  return sr;
}

/// ShadeRealtimePoint's second loop at light j (lit: luminance > 0) of pixel `pixel` of
/// n_pixels, once its shadow ray's verdict is known (traced false: none traced, the light is
/// added as it is): a light with an extent leaves its contribution c and the verdict to the
/// shared visibility (f.area_c, f.area_vis); another adds c to *L unless occluded.
PB_HOST_DEVICE inline void AddLitLight(const RealtimeFrameView& f, int j, int64_t pixel,
                                       int64_t n_pixels, const Float3& c, bool traced,
                                       bool occluded, Float3* L) {
  if (traced) {
    if (IsExtendedLightPod(f.lights[j])) {
      f.area_vis[j * n_pixels + pixel] = occluded ? 0 : 1;
      f.area_c[j * n_pixels + pixel] = c;
      return;
    }
    if (occluded) return;
  }
  *L = *L + c;
}

/// the part ShadeRealtimePoint and ShadeQueuedLights share, at the shading point sp of pixel
/// (u, v) with sky term `sky`: sets *ambient to the ambient term (the sum's start) and
/// f.total[pixel] to the lights' unshadowed total (UnshadowedLights into `terms`), then calls
/// lit(j, pixel, n_pixels, c, traced, origin, wi, dist) for each light j in light order whose
/// unshadowed contribution c (KeptLight) has a luminance > 0; traced: whether its shadow ray,
/// ShadowRayOf(origin, wi, dist), is worth tracing (WantsShadowRay).
template <bool kMedia, class Terms, class Lit>
PB_HOST_DEVICE inline void ForEachLitLight(const RealtimeFrameView& f, int u, int v,
                                           const ShadingPoint& sp, const Float3& sky, Terms& terms,
                                           Float3* ambient, Lit&& lit) {
  const int64_t pixel = static_cast<int64_t>(v) * f.camera.width + u;
  const int64_t n_pixels = static_cast<int64_t>(f.camera.width) * f.camera.height;
  const ShadeSetup s = BeginShadePoint(sp, sky);
  *ambient = s.L;
  // one sample per light; the unshadowed total decides which shadow rays are worth tracing.
  const float total = UnshadowedLights<kMedia>(f, u, v, sp, s, terms);
  f.total[pixel] = total;
  for (int j = 0; j < f.num_lights; ++j) {
    Float3 wi;
    float dist;
    const Float3 c = KeptLight<kMedia>(f, j, u, v, sp, s, terms, &wi, &dist);
    const float lum = pbm::Luminance709(c.x, c.y, c.z);
    if (!(lum > 0)) continue;
    lit(j, pixel, n_pixels, c, WantsShadowRay(f.lights[j], lum, total), s.origin, wi, dist);
  }
}

/// ShadeRealtimeHit from the shading point sp of pixel (u, v)'s primary hit and its sky term
/// (f.sky_term), after f.area_vis is cleared for the pixel: the ambient term, the lights and
/// their shadow rays, each light attenuated by the frame's media where f.has_media. kMedia
/// false: for frames known to have none (f.has_media must be 0): the media's code is left out,
/// so the kernels of frames without media keep their registers. terms: where the lights'
/// unshadowed terms wait between the two loops (LocalLightTerms, StridedLightTerms); lights from
/// terms.capacity() on are evaluated twice. ShadeQueuedLights and SumQueuedLights do the same
/// with the shadow rays traced apart (the same bits).
template <bool kMedia = true, class Terms>
PB_HOST_DEVICE inline Float3 ShadeRealtimePoint(const RealtimeFrameView& f, int u, int v,
                                                const ShadingPoint& sp, const Float3& sky,
                                                Terms& terms) {
  // lights in order: negligible or shadowless contributions are added as they are, the others
  // after a shadow ray; those of lights with an extent wait for their neighbours' verdicts.
  Float3 L;
  ForEachLitLight<kMedia>(f, u, v, sp, sky, terms, &L,
                          [&](int j, int64_t pixel, int64_t n_pixels, const Float3& c, bool traced,
                              const F3& origin, const Float3& wi, float dist) {
                            const bool occluded =
                                traced && TraceOccluded(f.scene, ShadowRayOf(origin, wi, dist));
                            AddLitLight(f, j, pixel, n_pixels, c, traced, occluded, &L);
                          });
  return L;
}

/// the most lights a frame may have for its shadow rays to go through a queue
/// (RealtimeKernelOptions::queue_shadow_rays: a pixel's lights are bits of 32-bit masks).
constexpr int kMaxQueuedShadowLights = 32;

/// what ShadeQueuedLights leaves of a pixel for SumQueuedLights: the lights whose unshadowed
/// contribution is lit (luminance > 0; kept in f.area_c) and, of those, the ones whose shadow
/// ray went to the queue (bit j: light j).
struct QueuedLightMasks {
  uint32_t lit = 0;
  uint32_t traced = 0;
};

/// a shadow ray in the queue: its origin, unit direction and tmax (ShadowRayOf; tmin 0), and
/// key = pixel kMaxQueuedShadowLights + light (pixel: in the whole batch, camera-major).
struct alignas(16) QueuedShadowRay {
  F3 o, d;
  float tmax = 0;
  uint32_t key = 0;
};

/// the queue entry of shadow ray r (tmin 0) of light j at pixel `pixel` (in the whole batch).
PB_HOST_DEVICE inline QueuedShadowRay QueueEntryOf(const TraceRay& r, uint32_t pixel, int j) {
  QueuedShadowRay e;
  e.o = r.o;
  e.d = r.d;
  e.tmax = r.tmax;
  e.key = pixel * kMaxQueuedShadowLights + static_cast<uint32_t>(j);
  return e;
}

/// the shadow ray of queue entry r (tmin 0).
PB_HOST_DEVICE inline TraceRay QueuedRay(const QueuedShadowRay& r) {
  TraceRay sr;
  sr.o = r.o;
  sr.d = r.d;
  sr.tmin = 0;
  sr.tmax = r.tmax;
  return sr;
}

/// ShadeRealtimePoint up to its shadow rays (f.num_lights <= kMaxQueuedShadowLights), pass 1
/// of 3 of the queued shadow rays (RealtimeKernelOptions::queue_shadow_rays): the unshadowed
/// terms and total as there, every lit light's contribution kept in f.area_c at [j n + pixel],
/// each shadow ray that ShadeRealtimePoint traces handed to queue.Push(j, ray) instead, in
/// light order; returns the ambient term (the sum's start) and sets *masks. pass 2 traces the
/// queue (TraceOccluded, any order: each verdict is the ray's own), pass 3 sums the lights
/// (SumQueuedLights).
template <bool kMedia, class Terms, class Queue>
PB_HOST_DEVICE inline Float3 ShadeQueuedLights(const RealtimeFrameView& f, int u, int v,
                                               const ShadingPoint& sp, const Float3& sky,
                                               Terms& terms, Queue& queue,
                                               QueuedLightMasks* masks) {
  QueuedLightMasks m;
  Float3 L;
  ForEachLitLight<kMedia>(f, u, v, sp, sky, terms, &L,
                          [&](int j, int64_t pixel, int64_t n_pixels, const Float3& c, bool traced,
                              const F3& origin, const Float3& wi, float dist) {
                            m.lit |= 1u << j;
                            f.area_c[j * n_pixels + pixel] = c;
                            if (!traced) return;
                            m.traced |= 1u << j;
                            queue.Push(j, ShadowRayOf(origin, wi, dist));
                          });
  *masks = m;
  return L;
}

/// pass 3 of the queued shadow rays: pixel `pixel` (of n_pixels)'s radiance from the ambient
/// term L (ShadeQueuedLights' return), its masks and the verdicts of its queued rays (bit j of
/// `occluded`: light j's ray hit something): its lit lights added in light order as
/// ShadeRealtimePoint's second loop adds them (AddLitLight: the same operations in the same
/// order, so the same bits).
PB_HOST_DEVICE inline Float3 SumQueuedLights(const RealtimeFrameView& f, int64_t pixel,
                                             int64_t n_pixels, Float3 L, const QueuedLightMasks& m,
                                             uint32_t occluded) {
  for (uint32_t b = m.lit; b != 0; b &= b - 1) {
    const int j = LowestSetBit(b);
    AddLitLight(f, j, pixel, n_pixels, f.area_c[j * n_pixels + pixel], (m.traced >> j & 1u) != 0,
                (occluded >> j & 1u) != 0, &L);
  }
  return L;
}

/// ShadeRealtimePoint with the lights' terms in the thread's own arrays (LocalLightTerms).
template <bool kMedia = true>
PB_HOST_DEVICE inline Float3 ShadeRealtimePoint(const RealtimeFrameView& f, int u, int v,
                                                const ShadingPoint& sp, const Float3& sky) {
  LocalLightTerms terms;
  return ShadeRealtimePoint<kMedia>(f, u, v, sp, sky, terms);
}

/// starts the shading of pixel (u, v): no light's shared visibility is known yet (its area_vis
/// entries set to -1), and returns the pixel's sky term.
PB_HOST_DEVICE inline Float3 BeginRealtimePixel(const RealtimeFrameView& f, int u, int v) {
  const int64_t pixel = static_cast<int64_t>(v) * f.camera.width + u;
  const int64_t n_pixels = static_cast<int64_t>(f.camera.width) * f.camera.height;
  for (int j = 0; j < f.num_lights; ++j) f.area_vis[j * n_pixels + pixel] = -1;
  return f.sky_term[pixel];
}

/// ShadeRealtimePixel of pixel (u, v) whose primary ray r (PrimaryRay) has the closest hit h
/// (TraceClosest; the CUDA kernels take it from the geometry pass instead of tracing it again).
/// every light's unshadowed contribution is evaluated once (kShadeCachedLights of them).
PB_HOST_DEVICE inline Float3 ShadeRealtimeHit(const RealtimeFrameView& f, int u, int v,
                                              const TraceRay& r, const TraceHit& h) {
  const Float3 sky = BeginRealtimePixel(f, u, v);
  if (h.instance < 0) return sky;
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  return ShadeRealtimePoint(f, u, v, EvaluateSurface(f, r, h, d_len), sky);
}

/// the shading point of pixel (u, v) from what the geometry pass kept of it: its primary
/// geometry g (a hit) and material terms t (PrimaryGeometry's surface_out; the view direction
/// from PrimaryRay as EvaluateSurface): EvaluateSurface's shading point, without evaluating the
/// surface (textures, normal map) a second time.
PB_HOST_DEVICE inline ShadingPoint StoredShadingPoint(const RealtimeFrameView& f, int u, int v,
                                                      const PixelGeometry& g,
                                                      const SurfaceTerms& t) {
  const TraceRay r = PrimaryRay(f.camera, u, v);
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  ShadingPoint sp;
  sp.wo = -Float3{r.d.x / d_len, r.d.y / d_len, r.d.z / d_len};
  sp.p = g.p_or_d;
  sp.ng = g.ng;
  sp.n = g.ns;
  sp.base = t.base;
  sp.emission = t.emission;
  sp.roughness = t.roughness;
  sp.metallic = t.metallic;
  sp.specular = t.specular;
  sp.occlusion = t.occlusion;
  sp.mirror = g.mirror;
  return sp;
}

/// ShadeRealtimeHit of pixel (u, v) from what the geometry pass kept of its shading point
/// (StoredShadingPoint of g and t): the same shading point, so the same radiance. kMedia and
/// terms: ShadeRealtimePoint's.
template <bool kMedia = true, class Terms>
PB_HOST_DEVICE inline Float3 ShadeRealtimeStored(const RealtimeFrameView& f, int u, int v,
                                                 const PixelGeometry& g, const SurfaceTerms& t,
                                                 Terms& terms) {
  const Float3 sky = BeginRealtimePixel(f, u, v);
  if (g.hit == 0) return sky;
  return ShadeRealtimePoint<kMedia>(f, u, v, StoredShadingPoint(f, u, v, g, t), sky, terms);
}

/// ShadeRealtimeStored up to its shadow rays (pass 1 of the queued shadow rays,
/// ShadeQueuedLights): the pixel's area_vis cleared, returns its sky term where its ray
/// escapes (no lights: *masks empty), else ShadeQueuedLights' ambient term.
template <bool kMedia, class Terms, class Queue>
PB_HOST_DEVICE inline Float3 ShadeQueuedStored(const RealtimeFrameView& f, int u, int v,
                                               const PixelGeometry& g, const SurfaceTerms& t,
                                               Terms& terms, Queue& queue,
                                               QueuedLightMasks* masks) {
  const Float3 sky = BeginRealtimePixel(f, u, v);
  *masks = QueuedLightMasks();
  if (g.hit == 0) return sky;
  return ShadeQueuedLights<kMedia>(f, u, v, StoredShadingPoint(f, u, v, g, t), sky, terms, queue,
                                   masks);
}

/// ShadeRealtimeStored with the lights' terms in the thread's own arrays (LocalLightTerms).
template <bool kMedia = true>
PB_HOST_DEVICE inline Float3 ShadeRealtimeStored(const RealtimeFrameView& f, int u, int v,
                                                 const PixelGeometry& g, const SurfaceTerms& t) {
  LocalLightTerms terms;
  return ShadeRealtimeStored<kMedia>(f, u, v, g, t, terms);
}

/// the linear radiance of pixel (u, v) (the file comment's L; the sky term where the ray
/// escapes) without the shadowed light of lights with an extent: their unshadowed contribution
/// and the pixel's own shadow ray's verdict go to f.area_c and f.area_vis, resolved by
/// SharedVisibilityRays, SharedVisibilityFraction and SharedVisibilityResolve once every pixel
/// has them (as the CPU's RealtimeIntegrator defers them to ResolveSharedVisibility).
PB_HOST_DEVICE inline Float3 ShadeRealtimePixel(const RealtimeFrameView& f, int u, int v) {
  const TraceRay r = PrimaryRay(f.camera, u, v);
  TraceHit h;
  TraceClosest(f.scene, r, &h);
  return ShadeRealtimeHit(f, u, v, r, h);
}

/// one light's penumbra rays at one pixel (SharedVisibilityRays): the pixel's own verdict and
/// the lattice points of its extra shadow rays r = 1 .. extra - 1.
struct PenumbraRays {
  Float3 p, ng;        ///< the pixel's hit point and unit geometric normal (PixelGeometry)
  int32_t first = 0;   ///< the pixel's first lattice point, kLightPenumbraRays LightStratum(u, v)
  int32_t points = 0;  ///< PenumbraLatticePoints of the light's share of the pixel's luminance
  int32_t extra = 0;   ///< rays r = 1 .. extra - 1 are traced (extra <= 1: none)
  int32_t own = 0;     ///< 1: a tile's outer ring (the pixel's own points, PenumbraLatticeIndex)
  int32_t active = 0;  ///< 1: the pixel traced a verdict towards a light with an extent
  float visible = 0;   ///< the pixel's own verdict (f.area_vis: 1 visible, 0 occluded)
};

/// the pixels' surfaces as the window masks read them (ShadowWindowMask): the frame's
/// PixelGeometry records at k.
struct FrameWindowSurfaces {
  const PixelGeometry* geometry = nullptr;
  /// whether the pixel at k has a hit.
  PB_HOST_DEVICE bool Hit(int64_t k) const { return geometry[k].hit != 0; }
  /// the geom of the pixel at k (which has a hit).
  PB_HOST_DEVICE int Geom(int64_t k) const { return geometry[k].geom; }
  /// the unit geometric normal and the hit point of the pixel at k (which has a hit).
  PB_HOST_DEVICE void Surface(int64_t k, float ng[3], float p[3]) const {
    const PixelGeometry& g = geometry[k];
    ng[0] = g.ng.x, ng[1] = g.ng.y, ng[2] = g.ng.z;
    p[0] = g.p_or_d.x, p[1] = g.p_or_d.y, p[2] = g.p_or_d.z;
  }
};

/// a shadow tile's copy of the surfaces FrameWindowSurfaces reads (the GPU's
/// VisibilityRaysWarpKernel with RealtimeKernelOptions::staged_window: shared memory, one
/// entry a tile pixel, structure of arrays): key the geom of a hit, kNoWindowSurface where
/// the pixel has none (a miss or outside the image); the normal and point of a hit.
struct TileWindowSurfaces {
  static constexpr int32_t kNoWindowSurface = INT32_MIN;  ///< the key of a pixel without a hit
  const int32_t* key = nullptr;                           ///< a key a tile pixel
  const float *ng_x = nullptr, *ng_y = nullptr, *ng_z = nullptr;  ///< unit normals (world)
  const float *p_x = nullptr, *p_y = nullptr, *p_z = nullptr;     ///< hit points, m (world)
  /// the key of `g` (its geom where it has a hit, else kNoWindowSurface).
  PB_HOST_DEVICE static int32_t KeyOf(const PixelGeometry& g) {
    return g.hit != 0 ? g.geom : kNoWindowSurface;
  }
  /// whether the pixel at k has a hit.
  PB_HOST_DEVICE bool Hit(int64_t k) const { return key[k] != kNoWindowSurface; }
  /// the geom of the pixel at k (which has a hit).
  PB_HOST_DEVICE int Geom(int64_t k) const { return key[k]; }
  /// the unit geometric normal and the hit point of the pixel at k (which has a hit).
  PB_HOST_DEVICE void Surface(int64_t k, float ng[3], float p[3]) const {
    ng[0] = ng_x[k], ng[1] = ng_y[k], ng[2] = ng_z[k];
    p[0] = p_x[k], p[1] = p_y[k], p[2] = p_z[k];
  }
};

/// the window mask of tile-local pixel (x, y) of `tile` (the pixels of its 5x5 window, cut at
/// the tile's edges, on its surface: SameShadowSurface, ShadowWindowBit) whose surface is at
/// `at` of `s` (FrameWindowSurfaces or TileWindowSurfaces: Hit, Geom, Surface), its neighbour
/// (dx, dy) at at + dy stride + dx. 0 where the pixel has no hit.
template <class Surfaces>
PB_HOST_DEVICE inline uint32_t ShadowWindowMask(const Surfaces& s, int64_t at, int64_t stride,
                                                int x, int y, const ShadowTile& tile) {
  if (!s.Hit(at)) return 0;
  float ng_i[3], p_i[3];
  s.Surface(at, ng_i, p_i);
  const int geom_i = s.Geom(at);
  uint32_t bits = 0;
  for (int dy = -kShadowWindowRadius; dy <= kShadowWindowRadius; ++dy) {
    if (y + dy < 0 || y + dy >= tile.height) continue;
    for (int dx = -kShadowWindowRadius; dx <= kShadowWindowRadius; ++dx) {
      if (x + dx < 0 || x + dx >= tile.width) continue;
      const int64_t kk = at + static_cast<int64_t>(dy) * stride + dx;
      if (kk != at) {
        if (!s.Hit(kk)) continue;
        float ng_g[3], p_g[3];
        s.Surface(kk, ng_g, p_g);
        if (!SameShadowSurface(geom_i, ng_i, p_i, s.Geom(kk), ng_g, p_g)) continue;
      }
      bits |= 1u << ShadowWindowBit(dx, dy);
    }
  }
  return bits;
}

/// the shared visibility, step 1 of 3, first part: pixel (u, v)'s window mask (ShadowWindowMask)
/// with its surface at `at` of `s` (a tile's copy: TileWindowSurfaces, stride
/// kShadowTileSize), written to f.window and returned.
template <class Surfaces>
PB_HOST_DEVICE inline uint32_t SharedVisibilityWindow(const RealtimeFrameView& f, int u, int v,
                                                      const Surfaces& s, int64_t at,
                                                      int64_t stride) {
  const int W = f.camera.width, H = f.camera.height;
  const ShadowTile tile = ShadowTileOf(u, v, W, H);
  const uint32_t bits = ShadowWindowMask(s, at, stride, u - tile.x0, v - tile.y0, tile);
  f.window[static_cast<int64_t>(v) * W + u] = bits;
  return bits;
}

/// SharedVisibilityWindow with the surfaces read from the frame's f.geometry.
PB_HOST_DEVICE inline uint32_t SharedVisibilityWindow(const RealtimeFrameView& f, int u, int v) {
  return SharedVisibilityWindow(f, u, v, FrameWindowSurfaces{f.geometry},
                                static_cast<int64_t>(v) * f.camera.width + u, f.camera.width);
}

/// a light's verdicts around a pixel as SharedVisibilityPenumbra reads them: the pixel's own at
/// vis[at], its window neighbour (dx, dy)'s at vis[at + dy stride + dx] (the frame's f.area_vis
/// + j n, or a tile's int8 copy).
struct StridedWindowVerdicts {
  const int8_t* vis = nullptr;  ///< 1 visible, 0 occluded, -1 none traced
  int64_t at = 0;               ///< the pixel's own entry
  int64_t stride = 0;           ///< the entries of one row (the image's width, or 16)
  /// the pixel's own verdict: 1, 0 or -1.
  PB_HOST_DEVICE int Own() const { return vis[at]; }
  /// whether the window mask `bits` holds a verdict 1 (seen[1]) and 0 (seen[0]): each set bit's
  /// verdict in turn.
  PB_HOST_DEVICE void Seen(uint32_t bits, bool seen[2]) const {
    seen[0] = seen[1] = false;
    for (uint32_t b = bits; b != 0; b &= b - 1) {
      const int bit = LowestSetBit(b);
      const int8_t w = vis[at + static_cast<int64_t>(bit / 5 - 2) * stride + (bit % 5 - 2)];
      if (w >= 0) seen[w] = true;
    }
  }
};

/// a light's verdicts of a shadow tile as bit rows (kShadowVerdictRows words,
/// render/shadow_window_math.h; the GPU's VisibilityRaysWarpKernel with
/// RealtimeKernelOptions::window_verdict_rows: shared memory) around tile pixel (x, y): the
/// same values as StridedWindowVerdicts over the tile.
struct RowWindowVerdicts {
  const uint32_t* rows = nullptr;  ///< kShadowVerdictRows words (ShadowVerdictBits)
  int x = 0, y = 0;                ///< the pixel in its tile (column, row)
  /// the pixel's own verdict: 1, 0 or -1 (ShadowRowVerdict).
  PB_HOST_DEVICE int Own() const { return ShadowRowVerdict(rows, x, y); }
  /// whether the window mask `bits` holds a verdict 1 (seen[1]) and 0 (seen[0])
  /// (ShadowWindowVerdicts: five shifted rows).
  PB_HOST_DEVICE void Seen(uint32_t bits, bool seen[2]) const {
    ShadowWindowVerdicts(rows, x, y, bits, seen);
  }
};

/// the shared visibility, step 1 of 3, second part: light j's penumbra rays at pixel (u, v)
/// whose window mask is `bits` (SharedVisibilityWindow). inactive (active 0) where the pixel
/// traced no verdict towards j or j has no extent; where the verdicts in the window disagree (a
/// penumbra), as many rays as the light's share of the pixel's unshadowed luminance asks for
/// (PenumbraLatticePoints, render/lamp_math.h, as the CPU's ResolveSharedVisibility): on a
/// tile's outer ring the pixel's own points - 1 more (f.area_own set: that pixel keeps its own
/// fraction), else max(1, points / kLightStrata) - 1 more after its first. writes f.area_own.
/// the window's verdicts of light j come from `w` (Own, Seen): StridedWindowVerdicts over the
/// frame's f.area_vis or a tile's copy, or RowWindowVerdicts over a tile's bit rows.
template <class Verdicts>
PB_HOST_DEVICE inline PenumbraRays SharedVisibilityPenumbraOf(const RealtimeFrameView& f, int u,
                                                              int v, int j, uint32_t bits,
                                                              const Verdicts& w) {
  const int W = f.camera.width, H = f.camera.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int64_t i = static_cast<int64_t>(v) * W + u;
  const int64_t k = j * n + i;
  PenumbraRays job;
  f.area_own[k] = 0;
  if (!IsExtendedLightPod(f.lights[j])) return job;
  const int vis = w.Own();
  if (vis < 0) return job;
  job.active = 1;
  job.visible = static_cast<float>(vis);
  bool seen[2];
  w.Seen(bits, seen);
  if (!(seen[0] && seen[1])) return job;
  const ShadowTile tile = ShadowTileOf(u, v, W, H);
  const bool own = OnShadowTileRing(u - tile.x0, v - tile.y0, tile);
  f.area_own[k] = own ? 1 : 0;
  const Float3 c = f.area_c[k];
  const int points = PenumbraLatticePoints(pbm::Luminance709(c.x, c.y, c.z) / f.total[i]);
  const int shared = points / kLightStrata > 1 ? points / kLightStrata : 1;
  const PixelGeometry& gi = f.geometry[i];
  job.p = gi.p_or_d;
  job.ng = gi.ng;
  job.first = kLightPenumbraRays * LightStratum(u, v);
  job.points = points;
  job.extra = own ? points : shared;
  job.own = own ? 1 : 0;
  return job;
}

/// SharedVisibilityPenumbraOf with the window's verdicts of light j read at vis_j[at + dy stride
/// + dx] (the pixel's own at vis_j[at]): f.area_vis + j n with at the pixel's index and stride
/// the image's width, or a tile's copy (StridedWindowVerdicts).
PB_HOST_DEVICE inline PenumbraRays SharedVisibilityPenumbra(const RealtimeFrameView& f, int u,
                                                            int v, int j, uint32_t bits,
                                                            const int8_t* vis_j, int64_t at,
                                                            int64_t stride) {
  return SharedVisibilityPenumbraOf(f, u, v, j, bits, StridedWindowVerdicts{vis_j, at, stride});
}

/// SharedVisibilityPenumbra with the window's verdicts read from the frame's f.area_vis.
PB_HOST_DEVICE inline PenumbraRays SharedVisibilityPenumbra(const RealtimeFrameView& f, int u,
                                                            int v, int j, uint32_t bits) {
  const int64_t n = static_cast<int64_t>(f.camera.width) * f.camera.height;
  return SharedVisibilityPenumbra(f, u, v, j, bits, f.area_vis + j * n,
                                  static_cast<int64_t>(v) * f.camera.width + u, f.camera.width);
}

/// penumbra ray r (1 <= r < job.extra) of light j (SharedVisibilityPenumbra): -1 where no ray
/// is traced (the light sends nothing to the point, or the direction lies below its geometric
/// surface), else 1 visible, 0 occluded.
PB_HOST_DEVICE inline int PenumbraRayVerdict(const RealtimeFrameView& f, int j,
                                             const PenumbraRays& job, int r) {
  constexpr int kAll = kLightStrata * kLightPenumbraRays;
  float u1, u2, d_r;
  Float3 w_r, E_r;
  bool ok;
  LightStratumUniforms(
      job.own != 0 ? PenumbraLatticeIndex(job.first, r, job.points) : job.first + r, kAll, &u1,
      &u2);
  SampleLight<float, Float3, bool>(f.lights[j], job.p, u1, u2, &w_r, &d_r, &E_r, &ok);
  if (!ok || !(pbm::Dot<float>(w_r, job.ng) > 0)) return -1;
  TraceRay sr;
  sr.o = OffsetOrigin(job.p, job.ng);
  sr.tmin = 0;
  sr.d = ToF3(w_r);
  sr.tmax = d_r * (1.0f - 1e-4f);  // +inf stays +inf
  return TraceOccluded(f.scene, sr) ? 0 : 1;
}

/// light j's penumbra rays r0 .. r1 - 1 of `job` in turn (PenumbraRayVerdict): *traced, how
/// many were traced, and *visible, how many of those reached the light.
PB_HOST_DEVICE inline void CountPenumbraRays(const RealtimeFrameView& f, int j,
                                             const PenumbraRays& job, int r0, int r1, int* traced,
                                             int* visible) {
  *traced = *visible = 0;
  for (int r = r0; r < r1; ++r) {
    const int verdict = PenumbraRayVerdict(f, j, job, r);
    if (verdict < 0) continue;
    ++*traced;
    if (verdict > 0) ++*visible;
  }
}

/// the window's verdicts of every light as SharedVisibilityRaysOf takes them: light j's at
/// vis + j light_stride around `at` (StridedWindowVerdicts).
struct StridedLightVerdicts {
  const int8_t* vis = nullptr;
  int64_t light_stride = 0, at = 0, stride = 0;
  /// light j's verdicts.
  PB_HOST_DEVICE StridedWindowVerdicts operator()(int j) const {
    return StridedWindowVerdicts{vis + j * light_stride, at, stride};
  }
};

/// every light's bit rows of a shadow tile (kShadowVerdictRows words each, light after light)
/// around tile pixel (x, y) as SharedVisibilityRaysOf takes them (RowWindowVerdicts).
struct RowLightVerdicts {
  const uint32_t* rows = nullptr;
  int x = 0, y = 0;
  /// light j's verdicts.
  PB_HOST_DEVICE RowWindowVerdicts operator()(int j) const {
    return RowWindowVerdicts{rows + j * kShadowVerdictRows, x, y};
  }
};

/// the shared visibility, step 1 of 3 (after ShadeRealtimePixel at every pixel): pixel (u,
/// v)'s window mask (SharedVisibilityWindow over the surfaces `s` at `at`, `stride`) and, per
/// light with an extent, its penumbra rays in order (SharedVisibilityPenumbraOf over light j's
/// verdicts `verdicts(j)`: StridedLightVerdicts or RowLightVerdicts; PenumbraRayVerdict);
/// f.area_visible, f.area_rays: the pixel's visible and traced rays (its own verdict
/// included). the GPU's VisibilityRaysWarpKernel spreads a warp's penumbra rays over its lanes
/// and sums the same integer counts.
template <class Surfaces, class LightVerdicts>
PB_HOST_DEVICE inline void SharedVisibilityRaysOf(const RealtimeFrameView& f, int u, int v,
                                                  const Surfaces& s, int64_t at, int64_t stride,
                                                  const LightVerdicts& verdicts) {
  const int64_t n = static_cast<int64_t>(f.camera.width) * f.camera.height;
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  const uint32_t bits = SharedVisibilityWindow(f, u, v, s, at, stride);
  for (int j = 0; j < f.num_lights; ++j) {
    const PenumbraRays job = SharedVisibilityPenumbraOf(f, u, v, j, bits, verdicts(j));
    if (job.active == 0) continue;
    int traced, visible;
    CountPenumbraRays(f, j, job, 1, job.extra, &traced, &visible);
    // integer counts: the same sums as one ray at a time in float
    f.area_visible[j * n + i] = job.visible + static_cast<float>(visible);
    f.area_rays[j * n + i] = 1.0f + static_cast<float>(traced);
  }
}

/// SharedVisibilityRaysOf with the surfaces of the frame's f.geometry and the window's verdicts
/// of light j read at vis + j light_stride (SharedVisibilityPenumbra's vis_j, at and stride):
/// the frame's f.area_vis, or a tile's copy.
PB_HOST_DEVICE inline void SharedVisibilityRays(const RealtimeFrameView& f, int u, int v,
                                                const int8_t* vis, int64_t light_stride, int64_t at,
                                                int64_t stride) {
  SharedVisibilityRaysOf(f, u, v, FrameWindowSurfaces{f.geometry},
                         static_cast<int64_t>(v) * f.camera.width + u, f.camera.width,
                         StridedLightVerdicts{vis, light_stride, at, stride});
}

/// SharedVisibilityRays with the window's verdicts read from the frame's f.area_vis.
PB_HOST_DEVICE inline void SharedVisibilityRays(const RealtimeFrameView& f, int u, int v) {
  const int W = f.camera.width;
  SharedVisibilityRays(f, u, v, f.area_vis, static_cast<int64_t>(W) * f.camera.height,
                       static_cast<int64_t>(v) * W + u, W);
}

/// one light's shared-visibility arrays as SharedWindowFraction and SharedLampFraction read
/// them: the pixel at `at` has its window neighbour (dx, dy) at at + dy stride + dx. the
/// frame's arrays (f.area_* + j n, `at` the pixel's index, stride the image's width) or a
/// shadow tile's copy (the GPU's VisibilityTileKernel: shared memory, stride kShadowTileSize).
struct VisibilityTaps {
  const int8_t* vis = nullptr;      ///< f.area_vis: 1 visible, 0 occluded, -1 none traced
  const float* visible = nullptr;   ///< f.area_visible
  const float* rays = nullptr;      ///< f.area_rays
  const float* fraction = nullptr;  ///< f.area_fraction (SharedLampFraction)
  int64_t stride = 0;
  /// the pixels' ShadowWindowCounts of vis, visible and rays, packed once (a tile's copy), or
  /// null: packed from them at each tap (WindowTapCounts)
  const uint32_t* counts = nullptr;
};

/// the ShadowWindowCounts of the pixel at kk of t: t.counts's, or packed from t's arrays.
PB_HOST_DEVICE inline uint32_t WindowTapCounts(const VisibilityTaps& t, int64_t kk) {
  if (t.counts != nullptr) return t.counts[kk];
  return ShadowWindowCounts(t.vis[kk], t.visible[kk], t.rays[kk]);
}

/// the fraction of visible rays at the pixel at `at` (which traced a verdict) with window mask
/// `window`: its own (visible / rays) where `own` (a tile's outer ring in a penumbra), else the
/// window's weighted sum of visible rays over its weighted sum of rays (ShadowWindowWeight,
/// neighbours without a verdict left out). the sums in integers over the 25 taps, each tap's
/// counts packed in one word (WindowTapCounts, ShadowWindowSumFraction: exactly the float sums
/// in the window's bit order, whatever the order of the integer adds).
PB_HOST_DEVICE inline float SharedWindowFraction(const VisibilityTaps& t, int64_t at,
                                                 uint32_t window, bool own) {
  if (own) return ShadowWindowSumFraction(WindowTapCounts(t, at));
  uint32_t sum = 0;
#if defined(__CUDA_ARCH__)
#pragma unroll
#endif
  for (int bit = 0; bit < kShadowWindowTaps; ++bit) {
    if ((window >> bit & 1u) == 0) continue;
    const int dy = bit / 5 - 2, dx = bit % 5 - 2;
    sum += ShadowWindowWeight4(dx, dy) *
           WindowTapCounts(t, at + static_cast<int64_t>(dy) * t.stride + dx);
  }
  return ShadowWindowSumFraction(sum);
}

/// the visibility V the resolve gives the pixel at `at` (which traced a verdict), tile-local
/// (x, y) of `tile`, window mask `window`: its fraction (SharedWindowFraction, t.fraction), for
/// a lamp (`lamp`: not directional, and the pixel keeps no fraction of its own) the mean of
/// the fractions of the 3x3 pixels around it in its tile that lie in its window and traced a
/// verdict (a lamp's penumbrae are tens of pixels wide; the sun's stay as they are).
PB_HOST_DEVICE inline float SharedLampFraction(const VisibilityTaps& t, int64_t at, uint32_t window,
                                               bool lamp, int x, int y, const ShadowTile& tile) {
  if (!lamp) return t.fraction[at];
  float sum = 0;
  int count = 0;
  for (int yy = y - 1 < 0 ? 0 : y - 1; yy <= (y + 1 < tile.height ? y + 1 : tile.height - 1); ++yy)
    for (int xx = x - 1 < 0 ? 0 : x - 1; xx <= (x + 1 < tile.width ? x + 1 : tile.width - 1);
         ++xx) {
      const int64_t kk = at + static_cast<int64_t>(yy - y) * t.stride + (xx - x);
      if (t.vis[kk] < 0 || (window >> ShadowWindowBit(xx - x, yy - y) & 1u) == 0) continue;
      sum += t.fraction[kk];
      ++count;
    }
  return sum / static_cast<float>(count);
}

/// radiance L plus V times a light's unshadowed contribution c where V > 0 (the resolve).
PB_HOST_DEVICE inline Float3 AddSharedVisibility(const Float3& L, float V, const Float3& c) {
  if (!(V > 0)) return L;
  return Float3{L.x + V * c.x, L.y + V * c.y, L.z + V * c.z};
}

/// frame f's shared-visibility arrays from entry k = j n + i on (light j at pixel i) as
/// VisibilityTaps: pixel i's entry at 0, its neighbours around it (stride: the image's width).
PB_HOST_DEVICE inline VisibilityTaps FrameVisibilityTaps(const RealtimeFrameView& f, int64_t k) {
  VisibilityTaps t;
  t.vis = f.area_vis + k;
  t.visible = f.area_visible + k;
  t.rays = f.area_rays + k;
  t.fraction = f.area_fraction + k;
  t.stride = f.camera.width;
  return t;
}

/// the shared visibility, step 2 of 3 (after SharedVisibilityRays at every pixel): per light
/// with an extent that pixel (u, v) traced a verdict towards, the weighted fraction of visible
/// rays over its window (ShadowWindowWeight), or its own fraction on a tile's ring in a
/// penumbra (f.area_fraction; SharedWindowFraction).
PB_HOST_DEVICE inline void SharedVisibilityFraction(const RealtimeFrameView& f, int u, int v) {
  const int W = f.camera.width;
  const int64_t n = static_cast<int64_t>(W) * f.camera.height;
  const int64_t i = static_cast<int64_t>(v) * W + u;
  for (int j = 0; j < f.num_lights; ++j) {
    const int64_t k = j * n + i;
    if (!IsExtendedLightPod(f.lights[j]) || f.area_vis[k] < 0) continue;
    f.area_fraction[k] =
        SharedWindowFraction(FrameVisibilityTaps(f, k), 0, f.window[i], f.area_own[k] != 0);
  }
}

/// the shared visibility, step 3 of 3 (after SharedVisibilityFraction at every pixel): pixel
/// (u, v)'s radiance L plus, per light with an extent, V times its unshadowed contribution, V
/// the window's fraction, for a lamp once more averaged over the 3x3 pixels of its tile on the
/// same surface (SharedLampFraction, AddSharedVisibility).
PB_HOST_DEVICE inline Float3 SharedVisibilityResolve(const RealtimeFrameView& f, int u, int v,
                                                     Float3 L) {
  const int W = f.camera.width, H = f.camera.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int64_t i = static_cast<int64_t>(v) * W + u;
  const ShadowTile tile = ShadowTileOf(u, v, W, H);
  const int x = u - tile.x0, y = v - tile.y0;
  for (int j = 0; j < f.num_lights; ++j) {
    const int64_t k = j * n + i;
    if (!IsExtendedLightPod(f.lights[j]) || f.area_vis[k] < 0) continue;
    const bool lamp = f.lights[j].kind != LightKind::kDirectional && f.area_own[k] == 0;
    const float V = SharedLampFraction(FrameVisibilityTaps(f, k), 0, f.window[i], lamp, x, y, tile);
    L = AddSharedVisibility(L, V, f.area_c[k]);
  }
  return L;
}

/// the mirrored view ray of pixel (u, v), whose primary geometry f.geometry holds a hit: the
/// unit primary direction d reflected about the geometric normal, d - 2 (d . ng) ng, from the
/// hit pushed off the surface on that side (render/ray.h's SpawnRay); *path_m: the
/// camera-to-hit distance (the texture cone's length before the ray).
PB_HOST_DEVICE inline TraceRay MirrorRay(const RealtimeFrameView& f, int u, int v, float* path_m) {
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  const PixelGeometry& g = f.geometry[i];
  const TraceRay pr = PrimaryRay(f.camera, u, v);
  const float d_len = sqrtf(pr.d.x * pr.d.x + pr.d.y * pr.d.y + pr.d.z * pr.d.z);
  const Float3 d{pr.d.x / d_len, pr.d.y / d_len, pr.d.z / d_len};
  const Float3& ng = g.ng;
  const Float3& p = g.p_or_d;
  const float k = 2.0f * pbm::Dot<float>(d, ng);
  const Float3 wi{d.x - k * ng.x, d.y - k * ng.y, d.z - k * ng.z};
  const float side = pbm::Dot<float>(wi, ng) >= 0 ? 1.0f : -1.0f;
  TraceRay r;
  r.o = OffsetOrigin(p, Float3{side * ng.x, side * ng.y, side * ng.z});
  r.d = ToF3(wi);
  r.tmin = 0;
  r.tmax = INFINITY;
  const Float3 to_cam{p.x - pr.o.x, p.y - pr.o.y, p.z - pr.o.z};
  *path_m = sqrtf(pbm::Dot<float>(to_cam, to_cam));
  return r;
}

/// the traced grid pixels whose reflected radiance pixel (u, v) of the mirror layer takes when
/// it is off its layer's grid (render/mirror_math.h, as render/cpu/mirror_layer.cc): of the up
/// to 4 grid pixels around it in its 16x16 tile (ShadowTileOf), those with a layer of the same
/// grid step on the same flat face (same geom, equal geometric normal), in the CPU's order (v,
/// then u); their pixel indices in idx and bilinear weights (MirrorGridWeight) in w. returns
/// how many (0: the pixel traces its own ray).
PB_HOST_DEVICE inline int MirrorGridNeighbours(const RealtimeFrameView& f, int u, int v,
                                               int64_t idx[4], float w[4]) {
  const int W = f.camera.width, H = f.camera.height;
  const PixelGeometry& gi = f.geometry[static_cast<int64_t>(v) * W + u];
  const int s = MirrorGridStep(gi.mirror);
  const ShadowTile tile = ShadowTileOf(u, v, W, H);
  const int x = u - tile.x0, y = v - tile.y0;
  const int gx = x - x % s, gy = y - y % s;
  const int xs[2] = {gx, gx + s}, ys[2] = {gy, gy + s};
  const float wx[2] = {MirrorGridWeight(x % s, s, 0), MirrorGridWeight(x % s, s, 1)};
  const float wy[2] = {MirrorGridWeight(y % s, s, 0), MirrorGridWeight(y % s, s, 1)};
  int count = 0;
  for (int b = 0; b < 2; ++b) {
    if (!(wy[b] > 0) || ys[b] >= tile.height) continue;
    for (int a = 0; a < 2; ++a) {
      if (!(wx[a] > 0) || xs[a] >= tile.width) continue;
      const int64_t j = static_cast<int64_t>(tile.y0 + ys[b]) * W + tile.x0 + xs[a];
      const PixelGeometry& gj = f.geometry[j];
      // a grid pixel of a layer with this step traces its own ray.
      if (!(gj.mirror > 0) || MirrorGridStep(gj.mirror) != s) continue;
      if (gj.geom != gi.geom || !(gj.ng.x == gi.ng.x && gj.ng.y == gi.ng.y && gj.ng.z == gi.ng.z))
        continue;
      idx[count] = j;
      w[count] = wx[a] * wy[b];
      ++count;
    }
  }
  return count;
}

/// whether pixel (u, v) traces its own mirrored ray: its surface has a mirror layer and the
/// pixel lies on the layer's grid, or no grid pixel around it can lend it theirs.
PB_HOST_DEVICE inline bool MirrorTraces(const RealtimeFrameView& f, int u, int v) {
  const int W = f.camera.width;
  const float r = f.geometry[static_cast<int64_t>(v) * W + u].mirror;
  if (!(r > 0)) return false;
  const int s = MirrorGridStep(r);
  if ((u % kShadowTileSize) % s == 0 && (v % kShadowTileSize) % s == 0) return true;
  int64_t idx[4];
  float w[4];
  return MirrorGridNeighbours(f, u, v, idx, w) == 0;
}

/// the mirror layer, step 1 of 3 (after PrimaryGeometry at every pixel): where pixel (u, v)
/// traces (MirrorTraces), its mirrored ray's closest hit (f.mirror_hits) and geometry for the
/// host's sky pass (f.mirror_geometry; hit -1 where it traces none).
PB_HOST_DEVICE inline void TraceMirrorRay(const RealtimeFrameView& f, int u, int v) {
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  PixelGeometry g;
  g.hit = -1;
  if (!MirrorTraces(f, u, v)) {
    f.mirror_geometry[i] = g;
    return;
  }
  float path_m;
  const TraceRay r = MirrorRay(f, u, v, &path_m);
  TraceHit h;
  TraceClosest(f.scene, r, &h);
  f.mirror_hits[i] = h;
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  if (h.instance < 0) {
    g.hit = 0;
    g.p_or_d = Float3{r.d.x / d_len, r.d.y / d_len, r.d.z / d_len};
  } else {
    const ShadingPoint sp = EvaluateSurface(f, r, h, d_len, path_m);
    g.hit = 1;
    g.geom = f.scene.records[f.scene.prims[h.prim].record].geom;
    g.p_or_d = sp.p;
    g.ng = sp.ng;
    g.ns = sp.n;
  }
  f.mirror_geometry[i] = g;
}

/// the mirror layer, step 2 of 3 (after the host's mirror sky terms): the reflected radiance
/// L_m of a pixel that traced a mirrored ray (f.mirror_radiance), as render/cpu/mirror_layer.cc's
/// MirrorRadiance: the sky's where it escapes, else the hit's emission, its ambient term
/// E_sky / pi occlusion (c_diff (1 - S) + S) and one sample of every light (random numbers:
/// draws num_lights + j of the pixel's stream 0, FrameContext::PixelStream) through the BRDF,
/// with a shadow ray where the light casts shadows. one reflection: a mirror seen in a mirror
/// shows its BRDF only.
PB_HOST_DEVICE inline void ShadeMirrorHit(const RealtimeFrameView& f, int u, int v) {
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  if (f.mirror_geometry[i].hit < 0) return;
  const Float3 sky = f.mirror_sky[i];
  const TraceHit h = f.mirror_hits[i];
  if (h.instance < 0) {
    f.mirror_radiance[i] = sky;
    return;
  }
  float path_m;
  const TraceRay r = MirrorRay(f, u, v, &path_m);
  const float d_len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  const ShadingPoint sp = EvaluateSurface(f, r, h, d_len, path_m);
  const Float3& p = sp.p;
  const Float3& ng = sp.ng;
  const Float3& n = sp.n;
  const Float3& wo = sp.wo;
  Float3 c_diff, f0;
  float alpha;
  BrdfCoefficientsOf<float, Float3>(sp.base, sp.roughness, sp.metallic, sp.specular, &c_diff, &f0,
                                    &alpha);
  const float a2 = alpha * alpha;
  const float n_v = pbm::Dot<float>(n, wo);
  const Float3 spec =
      EnvBrdfApprox<float, Float3>(f0, pbm::Max(n_v, 0.0f), pbm::Clamp(sp.roughness, 0.0f, 1.0f));
  const Float3 reflect{c_diff.x * (1.0f - spec.x) + spec.x, c_diff.y * (1.0f - spec.y) + spec.y,
                       c_diff.z * (1.0f - spec.z) + spec.z};
  const float k = pbm::kInvPi * sp.occlusion;
  Float3 L{sp.emission.x + (sky.x * k) * reflect.x, sp.emission.y + (sky.y * k) * reflect.y,
           sp.emission.z + (sky.z * k) * reflect.z};
  TraceRay sr;
  sr.o = OffsetOrigin(p, ng);
  sr.tmin = 0;
  const uint64_t pixel =
      static_cast<uint64_t>(v) * static_cast<uint64_t>(f.camera.width) + static_cast<uint64_t>(u);
  const uint64_t stream = HashKeys(HashKeys(f.frame_key, pixel), uint64_t{0});
  const uint64_t first_draw = static_cast<uint64_t>(f.num_lights);
  for (int j = 0; j < f.num_lights; ++j) {
    float u1, u2;
    Rng::Uniform2Of(Rng::DrawAt(stream, first_draw + static_cast<uint64_t>(j)), &u1, &u2);
    Float3 wi, E;
    float dist;
    bool valid;
    SampleLight<float, Float3, bool>(f.lights[j], p, u1, u2, &wi, &dist, &E, &valid);
    if (!valid) continue;
    const Float3 fr = BrdfEvalWorld<float, Float3>(n, ng, wo, n_v, c_diff, f0, a2, wi);
    const Float3 c{fr.x * E.x, fr.y * E.y, fr.z * E.z};
    if (!(pbm::Max(pbm::Max(c.x, c.y), c.z) > 0)) continue;
    if (f.lights[j].cast_shadow != 0) {
      sr.d = ToF3(wi);
      sr.tmax = dist * (1.0f - 1e-4f);  // +inf stays +inf
      if (TraceOccluded(f.scene, sr)) continue;
    }
    L = L + c;
  }
  f.mirror_radiance[i] = L;
}

/// the mirror layer, step 3 of 3 (after ShadeMirrorHit at every pixel, and after the shared
/// visibility): pixel (u, v)'s radiance L blended with its reflected radiance L_m,
/// (1 - r) L + r L_m (MirrorBlend), L_m its own or the MirrorGridNeighbours' weighted mean;
/// L unchanged where its surface has no mirror layer.
PB_HOST_DEVICE inline Float3 ApplyMirrorLayer(const RealtimeFrameView& f, int u, int v, Float3 L) {
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  const float r = f.geometry[i].mirror;
  if (!(r > 0)) return L;
  Float3 Lm;
  if (f.mirror_geometry[i].hit >= 0) {
    Lm = f.mirror_radiance[i];
  } else {
    int64_t idx[4];
    float w[4];
    const int count = MirrorGridNeighbours(f, u, v, idx, w);
    Float3 acc{0, 0, 0};
    float wsum = 0;
    for (int k = 0; k < count; ++k) {
      acc = acc + w[k] * f.mirror_radiance[idx[k]];
      wsum += w[k];
    }
    Lm = Float3{acc.x / wsum, acc.y / wsum, acc.z / wsum};
  }
  return Float3{MirrorBlend(L.x, Lm.x, r), MirrorBlend(L.y, Lm.y, r), MirrorBlend(L.z, Lm.z, r)};
}

/// the index in f.streaks (sorted by pixel) of pixel i's streak, -1 if it has none (binary
/// search).
PB_HOST_DEVICE inline int64_t FindStreak(const RealtimeFrameView& f, int64_t i) {
  int64_t lo = 0, hi = f.num_streaks;
  while (lo < hi) {
    const int64_t mid = lo + (hi - lo) / 2;
    if (f.streaks[mid].pixel < i)
      lo = mid + 1;
    else
      hi = mid;
  }
  return lo < f.num_streaks && f.streaks[lo].pixel == i ? lo : -1;
}

/// the projection of splat streak s (ProjectStreak of its ends in the frame's optical frame,
/// StreakToOptical), its box widened by a moving camera's rows (WidenStreakForMotion; nothing
/// for a still camera).
PB_HOST_DEVICE inline StreakProjection SplatProjection(const RealtimeFrameView& f,
                                                       const StreakPod& s) {
  const StreakSplatView& sp = f.splat;
  const Float3 ao = StreakToOptical(sp.R_OW, sp.p_OW, Float3{s.a[0], s.a[1], s.a[2]});
  const Float3 bo = StreakToOptical(sp.R_OW, sp.p_OW, Float3{s.b[0], s.b[1], s.b[2]});
  const int W = f.camera.width, H = f.camera.height;
  const StreakProjection p = ProjectStreak(ao, bo, s.r, sp.fx, sp.fy, sp.cx, sp.cy, W, H);
  return sp.poses != nullptr ? WidenStreakForMotion(p, sp.motion, sp.fx, sp.fy, W, H) : p;
}

/// the ray of pixel (u, v) that the splat tests and shades (origin and direction as the CPU's
/// Camera::GenerateRay, which ParticleStreaks' host splat traces): with f.splat.rows (a moving
/// camera without lens distortion) the row's double pose times the pixel's double coordinates
/// ((u - cx) / fx, (v - cy) / fy, 1), each product and sum rounded on its own (MulRnD, AddRnD:
/// Eigen's order), then rounded to float, and the row's origin; else PrimaryRay<true>.
PB_HOST_DEVICE inline TraceRay SplatRay(const RealtimeFrameView& f, int u, int v) {
  if (f.splat.rows == nullptr) return PrimaryRay<true>(f.camera, u, v);
  const StreakSplatView& sp = f.splat;
  const double* r = sp.rows + 12 * static_cast<int64_t>(v);
  const double x = (static_cast<double>(u) - sp.cx) / sp.fx;
  const double y = (static_cast<double>(v) - sp.cy) / sp.fy;
  float d[3];
  for (int i = 0; i < 3; ++i)
    d[i] = static_cast<float>(
        AddRnD(AddRnD(MulRnD(r[3 * i], x), MulRnD(r[3 * i + 1], y)), MulRnD(r[3 * i + 2], 1.0)));
  TraceRay ray;
  ray.o = F3{static_cast<float>(r[9]), static_cast<float>(r[10]), static_cast<float>(r[11])};
  ray.d = F3{d[0], d[1], d[2]};
  ray.tmin = f.camera.near;
  ray.tmax = INFINITY;
  return ray;
}

/// keeps the smaller of *slot and key: atomicMin on the device (the keys of many streaks meet
/// there; an integer minimum, so the result does not depend on their order), a plain minimum
/// on the host (RenderRealtimeOnHost splats one streak at a time).
PB_HOST_DEVICE inline void KeepNearestStreak(unsigned long long* slot, unsigned long long key) {
#if defined(__CUDA_ARCH__)
  atomicMin(slot, key);
#else
  if (key < *slot) *slot = key;
#endif
}

/// the number of streaks the splat of f.splat draws: *count where the count is in the
/// reader's memory (the device culling's streaks in place: streaks.num only a bound), else
/// streaks.num.
PB_HOST_DEVICE inline int32_t SplatStreakCount(const StreakSplatView& sp) {
  return sp.count != nullptr ? *sp.count : sp.streaks.num;
}

/// splat streak k (projection p, SplatProjection) on row v (inside p's box): every pixel of
/// StreakRowColumns (a moving camera, f.splat.poses: StreakRowColumnsAtPose, the columns in the
/// row's own pose) whose pixel-centre ray (SplatRay) meets the capsule (IntersectCapsuleRay,
/// with the row's ray origin) keeps StreakKey(t, k) in f.splat.nearest if it is smaller, as
/// ParticleStreaks::BuildPixelHits for the CPU's pixel rays: every product and sum of the rays,
/// the projection and the capsule test rounded on its own (SplatRay, MulRn, AddRn), so
/// the device finds the CPU's pixels and t to the bit.
PB_HOST_DEVICE inline void SplatStreakRow(const RealtimeFrameView& f, int k,
                                          const StreakProjection& p, int v) {
  const StreakSplatView& sp = f.splat;
  const StreakPod& s = sp.streaks.streaks[k];
  int c0, c1;
  if (sp.poses != nullptr)
    StreakRowColumnsAtPose(sp.poses + 12 * static_cast<int64_t>(v), Float3{s.a[0], s.a[1], s.a[2]},
                           Float3{s.b[0], s.b[1], s.b[2]}, s.r, sp.fx, sp.fy, sp.cx, sp.cy,
                           f.camera.width, f.camera.height, v, &c0, &c1);
  else
    StreakRowColumns(p, v, &c0, &c1);
  if (c0 > c1) return;
  const CapsuleOrigin c =
      MakeCapsuleOrigin(ToFloat3(SplatRay(f, c0, v).o), Float3{s.a[0], s.a[1], s.a[2]},
                        Float3{s.b[0], s.b[1], s.b[2]}, s.r);
  for (int u = c0; u <= c1; ++u) {
    const float t = IntersectCapsuleRay(c, ToFloat3(SplatRay(f, u, v).d));
    if (!(t > 0)) continue;
    KeepNearestStreak(&f.splat.nearest[static_cast<int64_t>(v) * f.camera.width + u],
                      static_cast<unsigned long long>(StreakKey(t, k)));
  }
}

/// pixel (u, v)'s streak after the splat, shaded into f.splat.pixels where it has one, as the
/// host splat shades it (RealtimeFrameData's host path: ParticleStreaks::PixelHit and Shade):
/// ShadeStreak of the streak's set at the pixel ray's hit o + t |d| d / |d| with the capsule's
/// normal at o + t d (CapsuleNormal), the frame's lights and its sky volume over the open sky's
/// radiance; rain at the streak's centre (ParticleStreaks::PrecomputeRain's point; its normal
/// unused). t is the primary ray's (the depth's units), alpha the streak's coverage.
PB_HOST_DEVICE inline void ShadeSplatPixel(const RealtimeFrameView& f, int u, int v) {
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  const unsigned long long key = f.splat.nearest[i];
  if (key == kNoStreakKey) return;
  const float t = StreakKeyT(key);
  const StreakPod& s = f.splat.streaks.streaks[StreakKeyIndex(key)];
  const StreakSetPod& set = f.splat.streaks.sets[s.set];
  const Float3 a{s.a[0], s.a[1], s.a[2]}, b{s.b[0], s.b[1], s.b[2]};
  const TraceRay r = SplatRay(f, u, v);
  const Float3 o = ToFloat3(r.o), d = ToFloat3(r.d);
  Float3 p, ng{0, 0, 1};
  if (set.kind == StreakKind::kRain) {
    p = Float3{0.5f * (a.x + b.x), 0.5f * (a.y + b.y), 0.5f * (a.z + b.z)};
  } else {
    // the hit point and normal rounded as the CPU rounds them (AddRn, MulRn, EigenDotRn)
    ng = CapsuleNormal(
        Float3{AddRn(o.x, MulRn(t, d.x)), AddRn(o.y, MulRn(t, d.y)), AddRn(o.z, MulRn(t, d.z))}, a,
        b, d);
    const float d_len = sqrtf(EigenDotRn(d, d));
    const float td = t * d_len;
    p = Float3{AddRn(o.x, MulRn(td, d.x / d_len)), AddRn(o.y, MulRn(td, d.y / d_len)),
               AddRn(o.z, MulRn(td, d.z / d_len))};
  }
  StreakPixel& out = f.splat.pixels[i];
  out.pixel = i;
  out.t = t;
  out.alpha = s.alpha;
  out.L = ShadeStreak(set, nullptr, p, ng, f.lights, f.num_lights, f.volume,
                      f.splat.streaks.sky_ambient);
}

/// pixel i's streak, shaded (*s), if it has one: the device splat's (f.splat) or the host
/// splat's (FindStreak in f.streaks).
PB_HOST_DEVICE inline bool PixelStreakOf(const RealtimeFrameView& f, int64_t i, StreakPixel* s) {
  if (f.splat.streaks.num > 0) {
    if (f.splat.nearest[i] == kNoStreakKey) return false;
    *s = f.splat.pixels[i];
    return true;
  }
  const int64_t k = FindStreak(f, i);
  if (k < 0) return false;
  *s = f.streaks[k];
  return true;
}

/// whether a media volume cell at p sees a light whose visibility asks `w` (LightVolumeCellLight,
/// GridLightCellLight): lit, or a shadow ray along d to tmax traced here through f.scene and
/// not occluded, as RealtimeMedia::Build's rays (a RayQuery's: the same TraceRay, tmin 0).
PB_HOST_DEVICE inline bool MediaCellSees(const RealtimeFrameView& f, uint8_t w, const float p[3],
                                         const float d[3], float tmax) {
  if (w != kMediaRayTrace) return w == kMediaRayLit;
  TraceRay r;
  r.o = F3{p[0], p[1], p[2]};
  r.d = F3{d[0], d[1], d[2]};
  r.tmin = 0.0f;
  r.tmax = tmax;
  return !TraceOccluded(f.scene, r);
}

/// cell c of the world light volume that frame f builds itself (f.media_build.light_volume;
/// layout f.media.light_volume): per light l < stride its [cell][light] transmittance
/// trans_cl[c stride + l] (LightVolumeCellLight; 0 past the volume's lights) and, where vis_cl
/// is not null (f.media_build.with_visibility), the visibility V Th Tgrid, each asked shadow ray
/// traced here through f.scene, as RealtimeMedia::Build's cells (whose rays go through a
/// RayQuery: the same TraceRay, o at the cell centre, tmin 0).
PB_HOST_DEVICE inline void MediaLightVolumeCell(const RealtimeFrameView& f, int64_t c,
                                                float* trans_cl, float* vis_cl) {
  const RealtimeMediaView& m = f.media;
  LightVolumeBuild b;
  b.layout = m.light_volume;
  b.num_lights = m.num_volume_lights;
  b.with_visibility = vis_cl != nullptr ? 1 : 0;
  b.lights = f.lights;
  b.media = m.media;
  b.num_media = m.num_media;
  b.grids = m.grids;
  b.grid_light_T = m.grid_light_T;
  b.num_grids = m.num_grids;
  float p[3];
  LightVolumeCellCentre(b.layout, c, p);
  const int S = b.layout.stride;
  for (int l = 0; l < S; ++l) {
    const int64_t at = c * S + l;
    if (l >= b.num_lights) {
      trans_cl[at] = 0.0f;
      if (vis_cl != nullptr) vis_cl[at] = 0.0f;
      continue;
    }
    float T, d[3], tmax;
    const uint8_t w = LightVolumeCellLight(b, p, l, &T, d, &tmax);
    trans_cl[at] = T;
    if (vis_cl == nullptr) continue;
    const bool seen = MediaCellSees(f, w, p, d, tmax);
    vis_cl[at] = seen ? T : 0.0f;
  }
}

/// the ray o + t d (PrimaryRay, d normalised) through the centre pixel (*uc, *vc) of froxel
/// column c of a volume of nx columns of block x block pixels in frame f (RealtimeMedia's
/// columns take Camera::GenerateRay's).
PB_HOST_DEVICE inline void MediaColumnRay(const RealtimeFrameView& f, int c, int nx, int block,
                                          int* uc, int* vc, float o[3], float d[3]) {
  const int W = f.camera.width, H = f.camera.height;
  *uc = MediaMinI((c % nx) * block + block / 2, W - 1);
  *vc = MediaMinI((c / nx) * block + block / 2, H - 1);
  const TraceRay r = PrimaryRay(f.camera, *uc, *vc);
  const float len = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
  o[0] = r.o.x, o[1] = r.o.y, o[2] = r.o.z;
  d[0] = r.d.x / len, d[1] = r.d.y / len, d[2] = r.d.z / len;
}

/// the inputs of the grids' light volumes of frame f (f.media_build.grids): the grids' arrays
/// (f.media_build.grid_media), their layouts (f.media.grids), the volume lights, the homogeneous
/// media and the sky lighting them.
PB_HOST_DEVICE inline GridLightBuild MediaGridLightBuildOf(const RealtimeFrameView& f) {
  const RealtimeMediaView& m = f.media;
  GridLightBuild b;
  b.grids = f.media_build.grid_media;
  b.layouts = m.grids;
  b.num_grids = m.num_grids;
  b.lights = f.lights;
  b.num_lights = m.num_grid_lights;
  b.media = m.media;
  b.num_media = m.num_media;
  for (int k = 0; k < 3; ++k) b.sky_ambient[k] = m.sky_ambient[k];
  b.sky_volume = m.sky_volume;
  return b;
}

/// cell c of the grids' light volumes of frame f counted end to end (grid g's cells follow those
/// of the grids before it, GridSourceOffset): per light l its transmittance grid_T[offset + l
/// cells + i] (GridLightCellLight; i the cell within its grid) and the cell's in-scatter source
/// source[c] (GridLightCellSky, then GridLightCellSource of each light seen, in light order),
/// each asked shadow ray traced here through f.scene, as RealtimeMedia::Build's cells (whose
/// rays go through a RayQuery: the same TraceRay, o at the cell centre, tmin 0).
PB_HOST_DEVICE inline void MediaGridLightCell(const RealtimeFrameView& f, int64_t c, float* grid_T,
                                              Float3* source) {
  const GridLightBuild b = MediaGridLightBuildOf(f);
  int g = 0;
  int64_t i = c;
  while (g < b.num_grids && i >= GridLightCells(b.layouts[g])) i -= GridLightCells(b.layouts[g++]);
  if (g >= b.num_grids) return;
  const GridLightPod& gl = b.layouts[g];
  const int64_t cells = GridLightCells(gl);
  float p[3];
  GridLightCellCentre(gl, i, p);
  Float3 src = GridLightCellSky(b, p);
  for (int l = 0; l < b.num_lights; ++l) {
    float Tg, d[3], tmax;
    const uint8_t w = GridLightCellLight(b, g, p, l, &Tg, d, &tmax);
    grid_T[gl.offset + l * cells + i] = Tg;
    const bool seen = MediaCellSees(f, w, p, d, tmax);
    if (seen) src = GridLightCellSource(b, p, l, Tg, src);
  }
  source[c] = src;
}

/// the inputs of grid froxel column c of frame f (f.media_build.grids; f.media.grid_nx x grid_ny
/// columns): the build over f's grids, their light volumes' sources `source` and the homogeneous
/// media, the column's centre pixel's ray o + t d (PrimaryRay, unit direction; RealtimeMedia::
/// BuildFroxels takes Camera::GenerateRay's), its slice jitter (stream 2) and its overlap
/// [t0, t1] with the grid boxes (`hit` 0: none).
struct MediaGridColumnInputs {
  GridFroxelBuild b;
  float o[3], d[3];
  float jitter;
  float t0, t1;
  int hit;
};
PB_HOST_DEVICE inline MediaGridColumnInputs MediaGridColumnOf(const RealtimeFrameView& f, int c,
                                                              const Float3* source) {
  const RealtimeMediaView& m = f.media;
  MediaGridColumnInputs in;
  int uc, vc;
  MediaColumnRay(f, c, m.grid_nx, kFroxelBlock, &uc, &vc, in.o, in.d);
  GridFroxelBuild& b = in.b;
  b.grids = f.media_build.grid_media;
  b.layouts = m.grids;
  b.source = source;
  b.num_grids = m.num_grids;
  b.media = m.media;
  b.num_media = m.num_media;
  in.jitter = FroxelColumnJitter(f.media_build.frame_key, uc, vc, f.camera.width, 2);
  in.hit = GridFroxelColumnInterval(b, in.o, in.d, &in.t0, &in.t1) ? 1 : 0;
  return in;
}

/// the grid froxel column c's overlap as RealtimeMedia::BuildFroxels keeps it: t0[c], t1[c] and
/// slices_per_m[c] = min(kFroxelSlices / (t1 - t0), 1e30) where the column meets a grid, else 0.
PB_HOST_DEVICE inline void MediaGridColumnSpan(const MediaGridColumnInputs& in, int c, float* t0,
                                               float* t1, float* slices_per_m) {
  t0[c] = in.hit != 0 ? in.t0 : 0.0f;
  t1[c] = in.hit != 0 ? in.t1 : 0.0f;
  slices_per_m[c] =
      in.hit != 0 ? pbm::Min(static_cast<float>(kFroxelSlices) / (in.t1 - in.t0), 1e30f) : 0.0f;
}

/// slice k of grid froxel column `in` (GridFroxelSlice; nothing where the column meets no grid).
PB_HOST_DEVICE inline GridFroxelStep MediaGridSlice(const MediaGridColumnInputs& in, int k) {
  if (in.hit == 0) return GridFroxelStep();
  return GridFroxelSlice(in.b, in.o, in.d, in.t0, in.t1, in.jitter, k);
}

/// grid froxel column c of frame f whole (the host path; the device runs its slices in parallel,
/// MediaGridSlice, then GridFroxelRecords: the same bits): its span (MediaGridColumnSpan) and its
/// kFroxelSlices + 1 records at records[c (kFroxelSlices + 1) ..].
PB_HOST_DEVICE inline void MediaGridFroxelColumn(const RealtimeFrameView& f, int c,
                                                 const Float3* source, float* t0, float* t1,
                                                 float* slices_per_m,
                                                 GridFroxelRecord<Rgb4>* records) {
  const MediaGridColumnInputs in = MediaGridColumnOf(f, c, source);
  MediaGridColumnSpan(in, c, t0, t1, slices_per_m);
  GridFroxelStep steps[kFroxelSlices];
  for (int k = 0; k < kFroxelSlices; ++k) steps[k] = MediaGridSlice(in, k);
  GridFroxelRecords(
      steps, reinterpret_cast<float*>(records + static_cast<int64_t>(c) * (kFroxelSlices + 1)));
}

/// the inputs of fog froxel column c of frame f (f.media_build.fog; f.media.fog_nx x fog_ny
/// columns): the build over f's media, lights, grid froxels and the visibility volume vis_cl
/// (null: none), its centre pixel's ray o + t d (PrimaryRay, unit direction; RealtimeMedia::
/// BuildFogFroxels takes Camera::GenerateRay's), its slice jitter and grid froxel columns.
struct MediaFogColumnInputs {
  FogFroxelBuild<Rgb4> b;
  float o[3], d[3];
  float jitter;
  MediaColumns grid_cols;
};
PB_HOST_DEVICE inline MediaFogColumnInputs MediaFogColumnOf(const RealtimeFrameView& f, int c,
                                                            const float* vis_cl) {
  const RealtimeMediaView& m = f.media;
  MediaFogColumnInputs in;
  int uc, vc;
  MediaColumnRay(f, c, m.fog_nx, kFogFroxelBlock, &uc, &vc, in.o, in.d);
  FogFroxelBuild<Rgb4>& b = in.b;
  b.media = m.media;
  b.num_media = m.num_media;
  b.lights = f.lights;
  b.num_lights = f.num_lights;
  b.num_volume_lights = m.num_volume_lights;
  b.vis_layout = m.light_volume;
  b.vis_cl = vis_cl;
  b.grids = m.grids;
  b.grid_light_T = m.grid_light_T;
  b.num_grids = m.num_grids;
  b.grid_t0 = m.grid_t0;
  b.grid_t1 = m.grid_t1;
  b.grid_slices_per_m = m.grid_slices_per_m;
  b.grid_records = m.grid_records;
  in.grid_cols = m.grid_records != nullptr ? MediaGridPixelColumns(m, uc, vc) : MediaColumns{};
  in.jitter = FroxelColumnJitter(f.media_build.frame_key, uc, vc, f.camera.width, 3);
  return in;
}

/// fog froxel column c of frame f (MediaFogColumnOf): FogFroxelColumn into the column's
/// kFogFroxelSlices + 1 records S[c (kFogFroxelSlices + 1) ..] and inv_log_far[c], as
/// RealtimeMedia::BuildFogFroxels (whose column ray is Camera::GenerateRay's). the device runs
/// its slices in parallel (MediaFogSlice, then FogFroxelRecords: the same bits).
PB_HOST_DEVICE inline void MediaFogColumn(const RealtimeFrameView& f, int c, const float* vis_cl,
                                          Rgb4* S, float* inv_log_far) {
  const MediaFogColumnInputs in = MediaFogColumnOf(f, c, vis_cl);
  FogFroxelColumn(in.b, in.o, in.d, in.jitter, in.grid_cols, Rgb4{0, 0, 0, 0}, Rgb4{1, 1, 1, 0},
                  inv_log_far + c,
                  reinterpret_cast<float*>(S + static_cast<int64_t>(c) * (kFogFroxelSlices + 1)));
}

/// slice k of fog froxel column c of frame f: its increment (FogFroxelSlice of
/// MediaFogColumnOf), and for k = 0 the column's inv_log_far[c].
PB_HOST_DEVICE inline Float3 MediaFogSlice(const RealtimeFrameView& f, int c, int k,
                                           const float* vis_cl, float* inv_log_far) {
  const MediaFogColumnInputs in = MediaFogColumnOf(f, c, vis_cl);
  const float t_far = FogColumnFar(in.b.media, in.b.num_media, in.o, in.d);
  if (k == 0) inv_log_far[c] = 1.0f / logf(t_far / kFogFroxelNear);
  return FogFroxelSlice(in.b, in.o, in.d, in.jitter, t_far, k, in.grid_cols, Rgb4{0, 0, 0, 0},
                        Rgb4{1, 1, 1, 0});
}

/// the media (homogeneous and grids) over the radiance of the pixels of the 2x2 quad (u0, v0) ..
/// (u0 + 1, v0 + 1) (u0, v0 even; pixels outside the image are skipped) once it is final (after
/// the shared visibility and the mirror layer), as RealtimeIntegrator's ApplyTileViewEffects: L
/// becomes T L + L_add (MediaViewSegment of f.media) along the pixel's ray (PrimaryRay, unit
/// direction) to its primary hit, t_end = depth[i] |d| (depth: the primary hits' t,
/// f.geometry[i].hit 0: the ray escapes, t_end = +inf). a quad inside the image whose four
/// pixels all hit or all escape shares the lookups of MediaPrepareQuad at the mean of their
/// t_end (+inf for escaping rays) and the normalised sum of their unit directions from the
/// first pixel's origin; the others look up per pixel. the CPU walks the quads of its 16x16
/// tiles, which start at even pixels, so its quads are these. a pixel with a particle streak in
/// front of its hit (PixelStreakOf) then gets it over L (ApplyStreak) with the streak's radiance
/// seen through the media up to it (MediaViewSegment to s.t |d|, the same quad lookups), as
/// the CPU's ApplyViewEffects; StreakKernel does not run for frames with media.
PB_HOST_DEVICE inline void MediaViewQuad(const RealtimeFrameView& f, int u0, int v0,
                                         const float* depth, Float3* radiance) {
  const int W = f.camera.width, H = f.camera.height;
  float o[4][3], d[4][3], t_end[4], d_len[4];
  int hit[4] = {0, 0, 0, 0};
  bool inside[4];
  for (int c = 0; c < 4; ++c) {
    const int u = u0 + (c & 1), v = v0 + (c >> 1);
    inside[c] = u < W && v < H;
    if (!inside[c]) continue;
    const int64_t i = static_cast<int64_t>(v) * W + u;
    const TraceRay r = PrimaryRay(f.camera, u, v);
    d_len[c] = sqrtf(r.d.x * r.d.x + r.d.y * r.d.y + r.d.z * r.d.z);
    o[c][0] = r.o.x, o[c][1] = r.o.y, o[c][2] = r.o.z;
    d[c][0] = r.d.x / d_len[c], d[c][1] = r.d.y / d_len[c], d[c][2] = r.d.z / d_len[c];
    hit[c] = f.geometry[i].hit != 0 ? 1 : 0;
    t_end[c] = hit[c] != 0 ? depth[i] * d_len[c] : INFINITY;
  }
  const bool shared =
      u0 + 1 < W && v0 + 1 < H && hit[1] == hit[0] && hit[2] == hit[0] && hit[3] == hit[0];
  MediaQuadShared q;
  if (shared) {
    float t_c = INFINITY;
    if (hit[0] != 0) {
      t_c = 0;
      for (int c = 0; c < 4; ++c) t_c += 0.25f * t_end[c];
    }
    float dc[3] = {0, 0, 0};
    for (int c = 0; c < 4; ++c)
      for (int k = 0; k < 3; ++k) dc[k] += d[c][k];
    const float dc_len = sqrtf(dc[0] * dc[0] + dc[1] * dc[1] + dc[2] * dc[2]);
    for (int k = 0; k < 3; ++k) dc[k] = dc[k] / dc_len;
    MediaPrepareQuad(f.media, u0, v0, t_c, o[0], dc, &q);
  }
  for (int c = 0; c < 4; ++c) {
    if (!inside[c]) continue;
    const int u = u0 + (c & 1), v = v0 + (c >> 1);
    const int64_t i = static_cast<int64_t>(v) * W + u;
    Float3 T, L_add;
    MediaViewSegment(f.media, u, v, o[c], d[c], t_end[c], &T, &L_add, shared ? &q : nullptr);
    const Float3 L = radiance[i];
    radiance[i] = Float3{T.x * L.x + L_add.x, T.y * L.y + L_add.y, T.z * L.z + L_add.z};
    // the pixel's streak over it, seen through the media in front of it: alpha (media to the
    // streak, then the streak) + (1 - alpha) (media to the end, then the surface)
    StreakPixel s;
    if (!PixelStreakOf(f, i, &s) || !StreakInFront(s, depth[i])) continue;
    Float3 T_f, L_f;
    MediaViewSegment(f.media, u, v, o[c], d[c], s.t * d_len[c], &T_f, &L_f, shared ? &q : nullptr);
    s.L = Float3{T_f.x * s.L.x + L_f.x, T_f.y * s.L.y + L_f.y, T_f.z * s.L.z + L_f.z};
    radiance[i] = ApplyStreak(s, depth[i], radiance[i]);
  }
}

/// the sum over row v of the log-luminance terms (film_math.h's LogLuminanceTerm), in column
/// order (the exposure's log-average; rows are summed on the host in row order).
PB_HOST_DEVICE inline double RowLogLuminance(const Float3* radiance, int width, int v,
                                             double min_luminance) {
  double sum = 0;
  for (int u = 0; u < width; ++u) {
    const Float3& c = radiance[static_cast<int64_t>(v) * width + u];
    const float rgb[3] = {c.x, c.y, c.z};
    sum += LogLuminanceTerm(rgb, min_luminance);
  }
  return sum;
}

/// the 8-bit sRGB code of every channel of one pixel (film_math.h's DevelopPixelIndices, then
/// the encoding table).
PB_HOST_DEVICE inline void DevelopPixel(const Float3& c, const float exposure[3], bool filmic,
                                        const uint8_t* lut, uint8_t out[3]) {
  const float rgb[3] = {c.x, c.y, c.z};
  int32_t index[3];
  DevelopPixelIndices(rgb, exposure, filmic, index);
  for (int k = 0; k < 3; ++k) out[k] = lut[index[k]];
}

}  // namespace penumbra::cuda

#pragma once
// the plain data the transport reads per frame (no Eigen, no standard containers: C++17, so that
// the CUDA kernels include it): materials, textures, posed geoms, the realtime frame's view
// (RealtimeFrameView) with its per-pixel work arrays, the shading point, and the pixel-centre
// ray of the frame's camera. the host builds it (render/cuda/realtime_frame.h), the GPU reads
// device copies of it.

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/film/film_math.h"
#include "penumbra/render/light/light_math.h"
#include "penumbra/render/material/texture_math.h"
#include "penumbra/render/media/media_build_math.h"
#include "penumbra/render/media/media_realtime_math.h"
#include "penumbra/render/particles/particle_math.h"
#include "penumbra/render/shading_math.h"
#include "penumbra/render/sky/sky_eval_math.h"
#include "penumbra/render/transport/path_streaks.h"
#include "penumbra/render/transport/primary_pixel.h"

namespace penumbra::cuda {

/// lights below this fraction of a pixel's unshadowed radiance get no shadow ray, on the CPU and
/// the GPU (ShadowRayWorthTracing).
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
  /// the PBR maps (render/material/material_eval.h, "PBR maps"), into the frame's textures; -1
  /// none.
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
/// radiance where it lies in front of the primary hit (ApplyStreak). made by the frame's splat
/// (StreakSplatView: SplatStreakRow, ShadeSplatPixel).
struct StreakPixel {
  int64_t pixel = 0;  ///< row-major pixel index
  float t = 0;        ///< ray parameter of the streak (the primary ray's units: as the depth)
  float alpha = 0;    ///< coverage in (0, 1]
  Float3 L;           ///< radiance of the streak, cd/m^2 (before the media in front of it)
};

/// the realtime tier's particle streaks splatted per pixel by the frame itself
/// (render/particles/particle_math.h's ProjectStreak, StreakRowColumns and IntersectCapsuleRay,
/// which the CPU backend's ParticleStreaks::BuildPixelHits calls too): every streak's pixel box is
/// scanned, each pixel-centre ray (PrimaryRay) met by the capsule keeps the smallest StreakKey
/// (nearest t, then lower index: the host splat's rule) in `nearest`, and each pixel with a key
/// is shaded into `pixels` (ShadeSplatPixel).
struct StreakSplatView {
  /// the frame's streaks in ParticleStreaks' index order (StreakPod::prim = the index; no BVH:
  /// nodes null), their particle sets and the open sky's sphere-average radiance (sky_ambient);
  /// rain radiance is shaded per pixel (rain null). num 0: no splat.
  PathStreaks streaks;
  /// the streaks' count where streaks.num is only a bound of it (the device culling's streaks
  /// read in place, RealtimeFrameData::DeviceStreakList), in the memory the
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
  /// the sky and the occluded sky volume (render/sky/sky_eval_math.h) whose lookups make the sky
  /// terms (QuadSkyTerms, MirrorSkyTerm): device copies in the kernels, host arrays on the host.
  SkyModelPod sky;
  SkyVolumePod volume;
  /// the shared visibility of lights with an extent (render/light/shadow_window_math.h), per pixel
  /// i of the n = width x height image: its primary geometry (PrimaryGeometry) and its 5x5 window's
  /// same-surface mask (SharedVisibilityRays), the luminance of its radiance with every light
  /// unshadowed (ShadeRealtimePixel; decides the penumbra ray budget, PenumbraLatticePoints); per
  /// light j and pixel i at [j n + i]: the unshadowed contribution and the pixel's own shadow ray's
  /// verdict (1 visible, 0 occluded, -1 none traced; ShadeRealtimePixel), the visible and traced
  /// rays after the penumbra rays, whether the pixel keeps its own fraction (a tile's outer ring),
  /// and the window's fraction (SharedVisibilityFraction). device or host arrays the caller owns.
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
  /// the frame's particle streaks for the splat the frame makes itself (streaks.num 0: none).
  StreakSplatView splat;
  /// the frame's homogeneous media (fog, haze, dust; has_media 1), their arrays as device or
  /// host pointers (render/media/media_realtime_math.h, RealtimeMedia::HostView): the light
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

}  // namespace penumbra::cuda

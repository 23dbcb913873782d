#pragma once
// the surface at a hit as the transport shades it: the material with its textures filtered over
// the ray's cone (planar and cube mapping, trilinear and anisotropic mip filtering: FilterPlanar,
// FilterCube), the PBR maps, the mirror layer's weight and the surface wetness (EvaluateSurface),
// as the CPU's MaterialEvaluator (render/material/material_eval.h).

#include <cstdint>

#include "penumbra/core/host_device.h"
#include "penumbra/render/light/brdf_math.h"
#include "penumbra/render/material/texture_math.h"
#include "penumbra/render/material/wetness_math.h"
#include "penumbra/render/transport/scene_view.h"

namespace penumbra::cuda {

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
    fp.map =
        PlanarMapUniform(p[a0], p[a1], infinite ? 0.0f : h[a0], infinite ? 0.0f : h[a1], rx, ry);
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
  // rain wetness (render/material/wetness_math.h) at the (bent) shading normal, after the PBR maps:
  // the CPU's ApplySurfaceWetness at SurfaceHit::ns_W, in its primary shading and mirror layer.
  float wet_scale, wet_roughness;
  if (f.wetness > 0 &&
      SurfaceWetnessTerms(f.wetness, ns.z, sp.metallic, sp.roughness, &wet_scale, &wet_roughness)) {
    sp.base = sp.base * wet_scale;
    sp.roughness = wet_roughness;
  }
  sp.n = pbm::Dot<float>(ns, sp.wo) > 0 ? ns : ng;
  return sp;
}

}  // namespace penumbra::cuda

#pragma once
// the material of a surface point: the geom's Material with its texture applied.
//
// texture mapping (chosen to match MuJoCo's OpenGL renderer where it is defined):
//  - textures are sRGB-encoded 8-bit RGB with mip levels (scene/texture_image.h); texels are
//    decoded to linear (256-entry table) before filtering, and the filtered colour multiplies
//    Material::base_color.
//  - 2d texture on a mesh with texcoords: (u, v) = texcoords (row 0 of the image at v = 0),
//    wrapped (repeat).
//  - 2d texture elsewhere: planar projection of the hit point in the geom frame onto the
//    plane of the dominant axis of the geom-frame normal (for planes and box faces: the face
//    plane), as MuJoCo draws it (texture_math.h, PlanarMap): with texuniform the texture
//    repeats texrepeat / 2 times per metre (MuJoCo's unit-size geom is 2 m across); without,
//    texrepeat times across the geom's extent along that axis (2 x half-size; an infinite
//    plane counts as uniform); counted from the face's corner (an infinite plane: from
//    MuJoCo's half-image offset), wrapped (repeat), image rows running along -y of the face.
//  - cube texture: looked up by the direction q = p_G / h (h = half extents of the geom's
//    local bounding box; for a box each face shows a whole cube face, for a sphere q is the
//    normal), with the face orientation of OpenGL cube maps (OpenGL 4.6 core spec, table 8.19)
//    and the faces stacked in MuJoCo's order (+x, -x, +y, -y, +z, -z); clamped per face.
//  - skybox textures on geoms are treated as cube textures.
//
// filtering (texture level of detail by ray cones: Akenine-Moller, Crassin, Boksansky, Belcour,
// Panteleev, Wright, "Improved Shader and Texture Level of Detail Using Ray Cones", JCGT 10(1),
// 2021): a pixel's rays form a cone of spread angle alpha (Camera::pixel_spread_rad); where it
// meets a surface at distance d it is W = alpha d wide (TextureFootprint::width_m). the mip level
//   lambda = log2(W rho / |n . v|)
// with rho the texels per metre of surface of the mapping at the hit and n . v the cosine
// between the ray and the geometric normal (the paper's isotropic level, its equation for
// lambda with Delta_0 = log2 rho). rho: planar mapping, sqrt(rho_s rho_t) with rho_s =
// texrepeat.x w / 2 (uniform) or texrepeat.x w / (2 h_a0) (per face), rho_t likewise with the
// height; mesh texcoords, SurfaceHit::uv_per_m sqrt(w h) (the triangle's texcoord-to-surface
// area ratio, the paper's t_a / p_a); cube textures, w / (2 max(h)). the colour is a trilinear
// lookup: bilinear in levels floor(lambda) and floor(lambda) + 1, mixed by the fraction
// (lambda <= 0: bilinear in level 0, beyond the last level: bilinear in the last level).
// with max_anisotropy 1 this isotropic lookup is all: at grazing angles the footprint is long
// and thin, and the level follows its long axis (textures blur there rather than alias).
//
// anisotropic filtering (max_anisotropy N_max > 1; the paper's anisotropic section and the
// footprint assembly of Schilling, Knittel, Strasser, "Texram: A Smart Memory for Texturing",
// IEEE CG&A 1996, as in EXT_texture_filter_anisotropic): the cone meets the surface in an
// ellipse with minor axis W along b = n x t and major axis W / |n . v| along t, the ray
// direction projected on the surface (n, t, b in the geom frame: SurfaceHit::n_G, d_G). both
// axes are mapped to texels by the mapping's gradient (planar mapping: its per-axis scales;
// mesh texcoords: SurfaceHit::duv_dp_G of the hit triangle, times the image size), giving
// lengths L_maj >= L_min. N = min(N_max, L_maj / L_min) rounded to the nearest integer (a
// ratio below 1.5 gives N = 1: one trilinear lookup at lambda = log2(L_maj)); N > 1 taps are
// placed at offsets ((k + 1/2) / N - 1/2) of the major axis, k = 0 .. N-1, each a bilinear
// lookup in the one mip level nearest to lambda = log2(max(L_min, L_maj / N)) (round(lambda),
// clamped to the levels; the taps already integrate along the major axis, so they skip the
// second level of a trilinear lookup: half the texel reads), averaged with equal weights. cube
// textures: the taps are the cube lookups of the displaced points, the lengths those of the
// isotropic rho. a footprint without a width, or seen head-on, takes the isotropic lookup.
// deterministic: no random numbers; the lookup depends on the hit and the cone only, so images
// do not depend on the thread count.

// PBR maps (glTF 2.0 section 3.9; docs/assets.md): a material named M gets the 2d textures
// named "M/normal", "M/metallic_roughness", "M/occlusion" and "M/emissive" as its maps, mapped
// as its base texture is (mesh texcoords, else the planar mapping with its texrepeat and
// texuniform; a material without a base texture maps them the same way). their texels hold
// data, sRGB-encoded like every texture (so that filtering and mip levels average the values):
// the decoded value v of a texel is the map's value. normal: tangent-space n = 2 v - 1, x
// along increasing u, y towards the image's top row (decreasing v), z along the surface
// normal (ApplyNormalMap). metallic_roughness: G multiplies roughness, B metallic.
// occlusion: R is the ambient occlusion (SurfaceMaterial::occlusion). emissive: multiplies
// Material::emission.
//
// packed maps (speed): a material with at least two of a 2d base texture, a normal map and a
// metallic-roughness map, all of one size of at most kMaxPackedTexels texels, gets them
// interleaved at construction, 8 linear channels of 16 bits a texel (base RGB, normal RGB,
// metallic-roughness G and B: the decoded 8-bit codes in steps of 1/65535, at most 7.7e-6
// off; 16 bytes a texel, 22 MB for 1024 x 1024 maps with their mip levels) in every level, and
// EvaluateAndMapNormal filters all of them with one mapping, one footprint and one set of taps
// (the same taps, levels and weights as filtering each map alone; results differ from the
// separate lookups by the channels' 16-bit steps and float rounding: below 2e-5 in tests).
// occlusion and emissive maps are filtered alone, and larger maps map by map.

#include <Eigen/Core>
#include <cstdint>
#include <utility>
#include <vector>

#include "penumbra/render/light/bsdf.h"
#include "penumbra/render/ray.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// the evaluated material of one surface point.
struct SurfaceMaterial {
  PbrParams pbr;                      ///< BRDF parameters, base colour textured
  Eigen::Vector3f emission{0, 0, 0};  ///< emitted radiance, cd/m^2 per channel
  /// weight r in [0, 1] of a perfect mirror layered over the BRDF: the point's radiance is
  /// (1 - r) L_brdf + r L_mirror, L_mirror the radiance arriving along the mirrored view ray.
  /// this is how MuJoCo's renderer blends its planar reflection with weight `reflectance`
  /// (MuJoCo XML reference, material/reflectance: "If the value is larger than 0, and the
  /// material is applied to a plane or a box geom, the renderer will simulate reflection ...
  /// For boxes, only the face in the direction of the local +Z axis is reflective"), so it is
  /// Material::reflectance on planes and on box faces whose geom-frame normal is +z, else 0.
  /// a constant weight (no Fresnel rise at grazing angles), as MuJoCo's.
  float mirror = 0;
  /// ambient occlusion in [0, 1] from the material's occlusion map (1 without): the realtime
  /// tier multiplies the sky light by it.
  float occlusion = 1;
};

/// darkens and smooths an upward-facing surface for rain wetness w in [0, 1] (Lagarde, "Water
/// drop 2a - Dynamic rain and its effects" and "Water drop 2b", 2013: wet porous surfaces
/// absorb more light, diffuse albedo x lerp(1, 0.3, w'), and a water film makes them glossier,
/// gloss = 1 - roughness x lerp(1, 2.5, w') capped at 1). w' = w s, with s the facing weight
/// clamp((n_z - 0.3) / 0.4, 0, 1) of the unit shading normal n_W (world z up): vertical and
/// downward-facing surfaces stay dry. metals keep their albedo (only their gloss changes).
/// whether a surface is sheltered from the rain is not tested. the formula is
/// SurfaceWetnessTerms (render/material/wetness_math.h), shared with the CUDA backend.
void ApplySurfaceWetness(float wetness, const Eigen::Vector3f& n_W, PbrParams* pbr);

/// where a ray cone meets a surface (file comment, "filtering").
struct TextureFootprint {
  /// width of the cone at the hit, m; 0 = an infinitely thin ray (bilinear in level 0).
  float width_m = 0;
  /// |cos| of the angle between the ray and the surface's geometric normal, in (0, 1].
  float cos_incidence = 1;
};

/// the footprint at `hit` of a cone of spread angle `spread_rad` around a ray of unit direction
/// `d_unit`, `distance_m` long from the cone's apex (or `distance_m` plus the width the cone had
/// at its origin, see render/transport/path_trace.h): width spread_rad x distance_m.
TextureFootprint ConeFootprint(float spread_rad, float distance_m, const Eigen::Vector3f& d_unit,
                               const SurfaceHit& hit);

/// half extents of the bounding box of geom `g` of `scene` in its own frame (zero where a shape
/// is flat; a plane's z): what the planar texture mapping and cube lookups scale by.
Eigen::Vector3f GeomHalfExtents(const SceneDescription& scene, const Geom& g);

/// the largest level-0 texel count (width x height) of packed maps (file comment).
constexpr int64_t kMaxPackedTexels = 1024 * 1024;

/// evaluates materials and textures of a scene. immutable after construction, thread-safe.
class MaterialEvaluator {
 public:
  /// precomputes per-geom texture mapping data. `scene` must outlive this object.
  /// @throws Error if a material refers to a missing texture or a texture without an image,
  /// or a cube or skybox texture whose image does not hold six square faces.
  /// `max_anisotropy` (>= 1; 1 = isotropic) caps the taps of an anisotropic lookup (file
  /// comment, "anisotropic filtering"); values below 1 count as 1.
  explicit MaterialEvaluator(const SceneDescription& scene, int max_anisotropy = 1);

  /// material at `hit` (default Material when hit.material < 0), its texture filtered over
  /// `footprint` (file comment; the default footprint gives bilinear level-0 lookups).
  SurfaceMaterial Evaluate(const SurfaceHit& hit, const TextureFootprint& footprint = {}) const;

  /// a material's PBR maps: texture indices into SceneDescription::textures, -1 none (file
  /// comment, "PBR maps").
  struct PbrMaps {
    int normal = -1, metallic_roughness = -1, occlusion = -1, emissive = -1;
    bool any() const {
      return normal >= 0 || metallic_roughness >= 0 || occlusion >= 0 || emissive >= 0;
    }
  };
  /// the PBR maps of material `material` (index into SceneDescription::materials).
  const PbrMaps& pbr_maps(int material) const { return maps_[material]; }

  /// true when some material has a normal map (file comment, "PBR maps").
  bool has_normal_maps() const { return has_normal_maps_; }

  /// the rotation R_WG of every geom (index = SceneDescription::geoms) at the frame being
  /// rendered, for normal mapping; the renderer sets it before tracing a frame (not while
  /// Evaluate / ApplyNormalMap run). without it (or for geoms beyond it) normal maps are not
  /// applied.
  void SetGeomRotations(std::vector<Eigen::Matrix3f> R_WG) { R_WG_ = std::move(R_WG); }

  /// ApplyNormalMap(hit, footprint) then Evaluate(*hit, footprint), in one pass that filters a
  /// material's packed maps together (file comment, "packed maps"); the same result up to the
  /// packed channels' 16-bit steps and float rounding.
  SurfaceMaterial EvaluateAndMapNormal(SurfaceHit* hit,
                                       const TextureFootprint& footprint = {}) const;

  /// one mip level of a material's packed maps (file comment): width x height texels of 8
  /// linear channels (base RGB, normal RGB, metallic-roughness G, B), each the decoded value
  /// of the map's 8-bit code in units of kScale, row-major.
  struct PackedLevel {
    static constexpr float kScale = 1.0f / 65535.0f;
    int width = 0;
    int height = 0;
    std::vector<uint16_t> texels;  ///< (height x width x 8)
  };

  /// normal mapping: replaces hit->ns_W by the material's normal map at the hit, filtered over
  /// `footprint` as the base colour is; no change without a normal map. tangent frame (geom
  /// frame, then rotated by the geom's R_WG, SetGeomRotations): mesh texcoords, t = dp/du and
  /// b = -dp/dv of the hit triangle (the pseudo-inverse of SurfaceHit::duv_dp_G), Gram-Schmidt
  /// against the interpolated normal; planar mapping, the mapping's face axes. the mapped
  /// normal n = normalize(x t + y b + z n_s) with (x, y, z) = 2 c - 1, on the side of the
  /// geometric normal (flipped with it; a mapped normal that would face away from the viewer
  /// is bent back to the surface by UsableShadingNormal in the BSDF).
  void ApplyNormalMap(SurfaceHit* hit, const TextureFootprint& footprint = {}) const;

  /// linear rgb of texture `tex` at (s, t) in texture space (1 = one image), wrapped,
  /// trilinear at mip level `lod` (log2 of the footprint in level-0 texels; <= 0: bilinear in
  /// level 0). exposed for tests.
  Eigen::Vector3f Sample2D(int tex, float s, float t, float lod = 0) const;

  /// linear rgb of cube texture `tex` in direction q (any length > 0), clamped to the face,
  /// trilinear at mip level `lod` as Sample2D.
  Eigen::Vector3f SampleCube(int tex, const Eigen::Vector3f& q, float lod = 0) const;

 private:
  struct Mapping2D;
  // a material's packed maps: its levels, and which maps they hold.
  struct PackedMaps {
    std::vector<PackedLevel> levels;
    bool base = false, normal = false, metallic_roughness = false;
  };
  // how a footprint is filtered (file comment): n > 1 taps along (ds, dt) in the level
  // round(lod), else a trilinear lookup at lod.
  struct FilterPlan {
    float lod = 0;
    int n = 1;
    float ds = 0, dt = 0;
  };
  Mapping2D MapAt(const SurfaceHit& hit, const Material& m) const;
  // the material's factors and mirror weight, no textures.
  SurfaceMaterial Untextured(const SurfaceHit& hit, const Material& m) const;
  FilterPlan PlanFilter(int width, int height, const Mapping2D& map, bool aniso,
                        const Eigen::Vector3f& major_G, const Eigen::Vector3f& minor_G,
                        const TextureFootprint& footprint) const;
  // the 8 linear channels of the packed maps, filtered as FilterPlan says.
  void FilterPacked(const PackedMaps& packed, const Mapping2D& map, bool aniso,
                    const Eigen::Vector3f& major_G, const Eigen::Vector3f& minor_G,
                    const TextureFootprint& footprint, float out[8]) const;
  // multiplies in the occlusion and emissive maps of `maps` (each filtered alone).
  void ApplyOcclusionEmission(const PbrMaps& maps, const Mapping2D& map, bool aniso,
                              const Eigen::Vector3f& major_G, const Eigen::Vector3f& minor_G,
                              const TextureFootprint& footprint, SurfaceMaterial* out) const;
  // bends hit->ns_W by the filtered normal-map texel c (ApplyNormalMap).
  void BendNormal(const Mapping2D& map, const Eigen::Vector3f& c, SurfaceHit* hit) const;
  Eigen::Vector3f Filter2D(const TextureImage& image, const Mapping2D& map, bool aniso,
                           const Eigen::Vector3f& major_G, const Eigen::Vector3f& minor_G,
                           const TextureFootprint& footprint) const;

  const SceneDescription& scene_;
  Material default_material_;
  std::vector<Eigen::Vector3f> half_extent_G_;  // per geom: local bounding-box half extents
  const float* srgb_to_linear_;                 // 256 entries (SrgbDecodeTable)
  int max_anisotropy_ = 1;
  std::vector<PbrMaps> maps_;  // per material
  bool has_normal_maps_ = false;
  std::vector<int> packed_of_;  // per material: index into packed_, or -1
  std::vector<PackedMaps> packed_;
  std::vector<Eigen::Matrix3f> R_WG_;  // per geom, this frame (SetGeomRotations)
};

}  // namespace penumbra

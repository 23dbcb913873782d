#pragma once
// the material of a surface point: the geom's Material with its texture applied.
//
// texture mapping (chosen to match MuJoCo's OpenGL renderer where it is defined):
//  - textures are sRGB-encoded (IEC 61966-2-1); texels are decoded to linear before
//    bilinear filtering, and the filtered colour multiplies Material::base_color.
//  - 2d texture on a mesh with texcoords: (u, v) = texcoords (row 0 of the image at v = 0),
//    wrapped (repeat).
//  - 2d texture elsewhere: planar projection of the hit point in the geom frame onto the
//    plane of the dominant axis of the geom-frame normal (for planes and box faces: the face
//    plane). with texuniform the texture repeats texrepeat times per metre; without, texrepeat
//    times across the geom's extent along that axis (2 x half-size; an infinite plane counts
//    as uniform). wrapped (repeat), image rows running along -y of the face.
//  - cube texture: looked up by the direction q = p_G / h (h = half extents of the geom's
//    local bounding box; for a box each face shows a whole cube face, for a sphere q is the
//    normal), with the face orientation of OpenGL cube maps (OpenGL 4.6 core spec, table 8.19)
//    and the faces stacked in MuJoCo's order (+x, -x, +y, -y, +z, -z); clamped per face.
//  - skybox textures on geoms are treated as cube textures.

#include <Eigen/Core>
#include <vector>

#include "penumbra/render/bsdf.h"
#include "penumbra/render/ray_scene.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

/// the evaluated material of one surface point.
struct SurfaceMaterial {
  PbrParams pbr;                      ///< BRDF parameters, base colour textured
  Eigen::Vector3f emission{0, 0, 0};  ///< emitted radiance, cd/m^2 per channel
};

/// darkens and smooths an upward-facing surface for rain wetness w in [0, 1] (Lagarde, "Water
/// drop 2a - Dynamic rain and its effects" and "Water drop 2b", 2013: wet porous surfaces
/// absorb more light, diffuse albedo x lerp(1, 0.3, w'), and a water film makes them glossier,
/// gloss = 1 - roughness x lerp(1, 2.5, w') capped at 1). w' = w s, with s the facing weight
/// clamp((n_z - 0.3) / 0.4, 0, 1) of the unit shading normal n_W (world z up): vertical and
/// downward-facing surfaces stay dry. metals keep their albedo (only their gloss changes).
/// whether a surface is sheltered from the rain is not tested.
void ApplySurfaceWetness(float wetness, const Eigen::Vector3f& n_W, PbrParams* pbr);

/// evaluates materials and textures of a scene. immutable after construction, thread-safe.
class MaterialEvaluator {
 public:
  /// precomputes per-geom texture mapping data. `scene` must outlive this object.
  /// @throws Error if a material refers to a missing texture or a texture's pixel buffer
  /// does not match its size (cube textures: height = 6 width).
  explicit MaterialEvaluator(const SceneDescription& scene);

  /// material at `hit` (default Material when hit.material < 0).
  SurfaceMaterial Evaluate(const SurfaceHit& hit) const;

  /// linear rgb of texture `tex` at (s, t) in texture space (1 = one image), bilinear,
  /// wrapped. exposed for tests.
  Eigen::Vector3f Sample2D(int tex, float s, float t) const;

  /// linear rgb of cube texture `tex` in direction q (any length > 0), bilinear within a face.
  Eigen::Vector3f SampleCube(int tex, const Eigen::Vector3f& q) const;

 private:
  const SceneDescription& scene_;
  Material default_material_;
  std::vector<Eigen::Vector3f> half_extent_G_;  // per geom: local bounding-box half extents
  float srgb_to_linear_[256];
};

}  // namespace penumbra

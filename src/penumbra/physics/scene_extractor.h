#pragma once
// extraction of the static scene (SceneDescription) from a compiled MuJoCo model,
// and the mapping of MJCF appearance (OpenGL-style materials and lights) to
// penumbra's physically based materials and photometric lights.
//
// MJCF -> PBR material model (user-visible; the world file can override any field):
//   colour      rgba is display-referred sRGB: base_color = sRGB-decode(r, g, b) (IEC
//               61966-2-1 transfer function), alpha = a. a geom's rgba wins over its
//               material's rgba when it differs from MuJoCo's default (0.5 0.5 0.5 1),
//               as in MuJoCo's renderer.
//   roughness   = clamp(1 - shininess, 0.05, 1): MuJoCo's Phong shininess maps to smoothness.
//   reflectance = clamp(reflectance, 0, 1): the weight of a mirror layer that both render tiers
//               draw on planes and the +z faces of boxes, where MuJoCo draws its reflections
//               (render/material/material_eval.h, SurfaceMaterial::mirror).
//   specular    = specular (MuJoCo's default 0.5 is the glTF/Burley default, F0 = 0.04).
//   metallic    = 0 (MJCF has no metal notion).
//   emission    = emission * base_color * kMjcfEmissionLuminance (cd/m^2).
//   texture     texture id, texrepeat and texuniform carried over unchanged. the texture's
//               pixels are kept as MuJoCo holds them (8-bit sRGB RGB) with mip levels, and
//               textures with identical pixels share one image (scene/texture_image.h).
//   every geom gets a material: MJCF materials keep their ids and names (index i = MuJoCo
//   material i); a geom without a material gets one made from its rgba, named
//   "rgba(r g b a)"; a geom whose rgba overrides its material's gets "<material>#rgba(r g b a)".
//   generated materials are deduplicated by value.
//
// MJCF -> photometric lights (MuJoCo lights are OpenGL lights without units):
//   directional   Light::kDirectional, illuminance = kMjcfDirectionalLux * max(diffuse).
//   otherwise     a spot (MuJoCo lights are OpenGL spots with intensity cos^exponent inside
//                 `cutoff`): outer half-angle = cutoff, inner half-angle = the angle where
//                 cos^exponent falls to one half, acos(2^(-1/exponent)), capped at cutoff
//                 (exponent 0 gives a hard-edged cone). a cutoff >= 90 deg gives a point light.
//                 intensity (cd) = kMjcfDirectionalLux * max(diffuse) * max(r, 1 m)^2 with r the
//                 distance from the light to the model centre (stat.center) at qpos0: MuJoCo's
//                 default lights do not fall off with distance, so the intensity is chosen to
//                 give the model centre the illuminance a directional light of the same diffuse
//                 gives. MJCF attenuation is ignored (light falls off with 1/r^2).
//   colour = diffuse / max(diffuse); ambient and specular colours are ignored; castshadow
//   and active are carried over; mjcf_light = the MuJoCo light id (posed by the snapshot).

#include <string>

#include "penumbra/core/srgb.h"  // SrgbToLinear, the decoding of MJCF rgba
#include "penumbra/scene/scene_description.h"

struct mjModel_;
struct mjData_;

namespace penumbra {

/// illuminance (lux) of an MJCF directional light with diffuse 1: bright daylight-ish, so
/// MJCF scenes look as in MuJoCo next to a world-file sun of similar illuminance.
inline constexpr double kMjcfDirectionalLux = 10000.0;
/// luminance (cd/m^2) of an MJCF surface with emission 1 and white rgba: that of a white
/// Lambertian surface facing a kMjcfDirectionalLux light, E / pi, so emission 1 reads as
/// "fully lit", as in MuJoCo.
inline constexpr double kMjcfEmissionLuminance = kMjcfDirectionalLux / 3.14159265358979323846;
/// lower bound (m) of the distance used to size MJCF spot/point light intensities.
inline constexpr double kMjcfLampMinDistance = 1.0;
/// lower roughness bound of the shininess mapping.
inline constexpr float kMjcfMinRoughness = 0.05f;

/// PBR material from MJCF appearance values (see the file comment). `rgba` is the
/// effective colour (sRGB, alpha); `texture` is a SceneDescription texture index or -1.
Material MaterialFromMjcf(const std::string& name, const float rgba[4], float emission,
                          float specular, float shininess, float reflectance, int texture,
                          const float texrepeat[2], bool texuniform);

/// the static scene of model `m`; `d` must hold the result of mj_forward at qpos0 (used
/// for the light distances above). every field of SceneDescription except `sky` is filled:
/// bodies (index = MuJoCo body id), geoms (index = geom id), meshes, hfields, textures,
/// materials, lights (index = MuJoCo light id), MJCF cameras (index = MuJoCo camera id,
/// 640 x 480 intrinsics from fovy, rate 10 Hz, rgb only), centre and extent.
/// unnamed cameras are named "camera<id>".
SceneDescription ExtractScene(const mjModel_* m, const mjData_* d);

}  // namespace penumbra

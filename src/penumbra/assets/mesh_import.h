#pragma once
// mesh files read through assimp 5.2 (Debian libassimp-dev): OBJ/MTL, glTF 2.0 (.gltf/.glb),
// FBX, COLLADA (.dae), STL and PLY, converted to metres in a z-up, right-handed frame with
// physically based metallic-roughness materials (glTF 2.0 section 3.9; docs/assets.md).
//
// geometry: assimp triangulates, joins identical vertices, bakes the node hierarchy into the
// vertices (aiProcess_PreTransformVertices: one mesh per material and primitive) and makes
// normals where the file has none (smooth, 80 deg crease). then every position and normal p
// becomes R_up (M p) (scale for positions), M = diag(-1, 1, 1) for left-handed files (and
// triangle winding reversed), R_up the rotation of the file's up axis onto +z
// (MeshImportConfig). texcoords: (u, v) with v = 0 on the image's top row (glTF's convention;
// OBJ/FBX/COLLADA's v = 0 on the bottom row is flipped), only the first set.
//
// materials (aiMaterial -> ImportedMaterial):
//  - glTF 2.0 pbrMetallicRoughness: baseColorFactor x baseColorTexture (sRGB), metallicFactor
//    and roughnessFactor x metallicRoughnessTexture (linear; B = metallic, G = roughness),
//    normalTexture (linear, tangent space, +y towards the image's top row) with its scale,
//    occlusionTexture (linear, R) with its strength, emissiveFactor x emissiveTexture (sRGB),
//    times KHR_materials_emissive_strength.
//  - other formats: diffuse colour (Kd) x diffuse map (map_Kd), roughness from the Phong
//    exponent Ns as sqrt(sqrt(2 / (Ns + 2))) (Blinn-Phong to Beckmann, alpha = roughness^2),
//    metallic 0, normal map (MTL `norm`), emission (Ke) x emissive map (map_Ke). colours
//    are taken as linear.
//  - emission in cd/m^2: the emissive colour times MeshImportConfig::emissive_cd_m2.
// texture images: PNG or JPEG, external (relative to the mesh file) or embedded (.glb, FBX),
// decoded with OpenCV imgcodecs to 8-bit RGB; alpha is dropped (alpha modes are not
// supported: every surface is opaque). data maps (normal, metallic-roughness, occlusion) are
// stored as the renderer keeps every map (render/material/material_eval.h, "PBR maps"): each value
// v = code / 255 sRGB-encoded (EncodeSrgb8), so that mip levels average the values; the
// normal scale (x and y of 2 v - 1 times it) and the occlusion strength (1 + s (o - 1)) are
// applied to the texels here.

#include <memory>
#include <string>
#include <vector>

#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/texture_image.h"
#include "penumbra/world/mesh_import_config.h"

namespace penumbra {

/// a material of an imported mesh file.
struct ImportedMaterial {
  /// the file's material name with characters other than [A-Za-z0-9_.-] replaced by '_',
  /// made unique by a suffix "_<index>" when needed; "default" when unnamed.
  std::string name;
  /// the constant factors: base_color (linear), roughness, metallic, emission (cd/m^2).
  /// the texture index of this Material is not used (the images are below).
  Material factors;
  /// images or null (file comment: the data maps hold sRGB-encoded values, with the normal
  /// scale and occlusion strength applied).
  std::shared_ptr<const TextureImage> base_color, normal, metallic_roughness, occlusion, emissive;
};

/// a triangle mesh of an imported file, in the model frame (metres, z up).
struct ImportedMesh {
  TriangleMesh mesh;  ///< name "<index>_<file mesh name>" sanitised as material names
  int material = 0;   ///< index into ImportedAsset::materials
};

/// everything read from one mesh file.
struct ImportedAsset {
  std::string file;  ///< absolute path
  std::vector<ImportedMesh> meshes;
  std::vector<ImportedMaterial> materials;
  double scale = 1;     ///< metres per file unit applied
  std::string up_axis;  ///< the file's up axis applied ("y", "z", ...)
  int triangles = 0;    ///< triangles over all meshes
};

/// reads the mesh file `path` (any format of IsMeshModelFile) with `config`.
/// @throws ConfigError(path, 0, "", ...) naming the file and assimp's message when assimp
///         cannot read it, when it holds no triangles, when a referenced texture is missing
///         or not a readable image (naming the texture), or when a coordinate is not finite.
ImportedAsset ImportMeshFile(const std::string& path, const MeshImportConfig& config);

/// how the texels of a decoded image are stored (file comment).
enum class TextureMap {
  kColour,     ///< base colour, emissive: the sRGB codes as they are
  kData,       ///< metallic-roughness: each value v = code / 255, sRGB-encoded
  kNormal,     ///< data; x and y of n = 2 v - 1 scaled by `param` (glTF normalTexture.scale)
  kOcclusion,  ///< data; R becomes 1 + param (R - 1) (glTF occlusionTexture.strength)
};

/// decodes a PNG or JPEG file's bytes into an 8-bit RGB TextureImage stored as `map` says.
/// @throws Error naming `what` when the bytes are not a readable image.
std::shared_ptr<const TextureImage> DecodeTextureImage(const std::vector<unsigned char>& bytes,
                                                       TextureMap map, float param,
                                                       const std::string& what);

/// RGB codes (3 per texel) of map kind `map` as stored (the colour codes unchanged, data
/// values sRGB-encoded, see TextureMap), in place.
void StoreTexels(TextureMap map, float param, std::vector<uint8_t>* rgb);

}  // namespace penumbra

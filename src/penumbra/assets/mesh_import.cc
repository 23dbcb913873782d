#include "penumbra/assets/mesh_import.h"

#include <assimp/GltfMaterial.h>
#include <assimp/config.h>
#include <assimp/material.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include <algorithm>
#include <assimp/Importer.hpp>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <map>
#include <set>
#include <tuple>

#include "penumbra/assets/image_decode.h"
#include "penumbra/core/error.h"
#include "penumbra/core/image_file_limits.h"
#include "penumbra/core/input_file.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

std::string LowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

std::string Sanitize(const std::string& name) {
  std::string out;
  for (const char c : name)
    out +=
        (std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.') ? c : '_';
  return out;
}

// the rotation that takes the file's up axis to +z (MeshImportConfig::up_axis).
Eigen::Matrix3f UpRotation(const std::string& up) {
  Eigen::Matrix3f R;
  if (up == "z") {
    R.setIdentity();
  } else if (up == "y") {  // (x, y, z) -> (x, -z, y): +90 deg about x
    R << 1, 0, 0, 0, 0, -1, 0, 1, 0;
  } else if (up == "-y") {  // -90 deg about x
    R << 1, 0, 0, 0, 0, 1, 0, -1, 0;
  } else if (up == "x") {  // -90 deg about y: +x -> +z
    R << 0, 0, -1, 0, 1, 0, 1, 0, 0;
  } else if (up == "-x") {  // +90 deg about y
    R << 0, 0, 1, 0, 1, 0, -1, 0, 0;
  } else {  // "-z": 180 deg about x
    R << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  }
  return R;
}

// the FBX file's own up axis and unit from assimp's scene metadata ("" / 0 when absent).
void FbxFrame(const aiScene* scene, std::string* up, double* metres_per_unit) {
  if (scene->mMetaData == nullptr) return;
  int32_t axis = -1, sign = 1;
  if (scene->mMetaData->Get("UpAxis", axis) && axis >= 0 && axis <= 2) {
    scene->mMetaData->Get("UpAxisSign", sign);
    *up = std::string(sign < 0 ? "-" : "") + "xyz"[axis];
  }
  double unit = 0;
  float unit_f = 0;
  if (scene->mMetaData->Get("UnitScaleFactor", unit) && unit > 0) {
    *metres_per_unit = unit / 100.0;  // FBX: UnitScaleFactor is centimetres per unit
  } else if (scene->mMetaData->Get("UnitScaleFactor", unit_f) && unit_f > 0) {
    *metres_per_unit = unit_f / 100.0;
  }
}

std::vector<unsigned char> ReadFileBytes(const fs::path& path) {
  const std::string bytes = ReadInputFile(path, "texture file");
  return std::vector<unsigned char>(bytes.begin(), bytes.end());
}

// loads the images a scene's materials reference, once each (by path and encoding).
class TextureLoader {
 public:
  TextureLoader(const aiScene* scene, std::string file) : scene_(scene), file_(std::move(file)) {}

  // texture `type` slot 0 of `mat`, or null when it has none.
  std::shared_ptr<const TextureImage> Load(const aiMaterial* mat, aiTextureType type,
                                           TextureMap encoding, float param,
                                           const std::string& material_name) {
    aiString path;
    if (mat->GetTextureCount(type) == 0 || mat->GetTexture(type, 0, &path) != aiReturn_SUCCESS)
      return nullptr;
    const std::string p = path.C_Str();
    if (p.empty()) return nullptr;
    const auto key = std::make_tuple(p, encoding, param);
    if (auto it = cache_.find(key); it != cache_.end()) return it->second;
    const std::string what = "texture '" + p + "' of material '" + material_name + "'";
    std::shared_ptr<const TextureImage> image;
    try {
      if (const aiTexture* embedded = scene_->GetEmbeddedTexture(p.c_str())) {
        image = FromEmbedded(*embedded, encoding, param, what);
      } else {
        fs::path tp = fs::path(p);
        if (tp.is_relative()) tp = fs::path(file_).parent_path() / tp;
        std::error_code ec;
        if (!fs::is_regular_file(tp, ec))
          throw Error(what + ": file not found: " + tp.string() +
                      " (relative paths resolve against the mesh file's folder)");
        image =
            DecodeTextureImage(ReadFileBytes(tp), encoding, param, what + " (" + tp.string() + ")");
      }
    } catch (const ConfigError&) {
      throw;
    } catch (const Error& e) {
      throw ConfigError(file_, 0, "", e.what());
    }
    cache_.emplace(key, image);
    return image;
  }

 private:
  static std::shared_ptr<const TextureImage> FromEmbedded(const aiTexture& t, TextureMap encoding,
                                                          float param, const std::string& what) {
    if (t.mHeight == 0) {  // compressed (PNG / JPEG bytes)
      const auto* b = reinterpret_cast<const unsigned char*>(t.pcData);
      return DecodeTextureImage(std::vector<unsigned char>(b, b + t.mWidth), encoding, param, what);
    }
    // raw ARGB8888 texels (aiTexel: b g r a)
    std::vector<uint8_t> rgb(static_cast<size_t>(t.mWidth) * t.mHeight * 3);
    for (size_t i = 0; i < static_cast<size_t>(t.mWidth) * t.mHeight; ++i) {
      rgb[3 * i] = t.pcData[i].r;
      rgb[3 * i + 1] = t.pcData[i].g;
      rgb[3 * i + 2] = t.pcData[i].b;
    }
    StoreTexels(encoding, param, &rgb);
    return std::make_shared<const TextureImage>(static_cast<int>(t.mWidth),
                                                static_cast<int>(t.mHeight), 1, std::move(rgb));
  }

  const aiScene* scene_;
  std::string file_;
  std::map<std::tuple<std::string, TextureMap, float>, std::shared_ptr<const TextureImage>> cache_;
};

ImportedMaterial ReadMaterial(const aiMaterial* mat, bool gltf, const MeshImportConfig& config,
                              TextureLoader* textures, const std::string& name) {
  ImportedMaterial out;
  out.name = name;
  Material& f = out.factors;
  f.name = name;
  aiColor4D c;
  if (mat->Get(AI_MATKEY_BASE_COLOR, c) == aiReturn_SUCCESS ||
      mat->Get(AI_MATKEY_COLOR_DIFFUSE, c) == aiReturn_SUCCESS)
    f.base_color = Eigen::Vector3f(c.r, c.g, c.b).cwiseMax(0.0f).cwiseMin(1.0f);
  float v = 0;
  if (gltf) {
    f.metallic = mat->Get(AI_MATKEY_METALLIC_FACTOR, v) == aiReturn_SUCCESS ? v : 1.0f;
    f.roughness = mat->Get(AI_MATKEY_ROUGHNESS_FACTOR, v) == aiReturn_SUCCESS ? v : 1.0f;
  } else {
    f.metallic = 0;
    float ns = 0;
    f.roughness = mat->Get(AI_MATKEY_SHININESS, ns) == aiReturn_SUCCESS && ns > 0
                      ? std::sqrt(std::sqrt(2.0f / (ns + 2.0f)))
                      : 0.8f;
  }
  f.metallic = std::clamp(f.metallic, 0.0f, 1.0f);
  f.roughness = std::clamp(f.roughness, 0.0f, 1.0f);
  aiColor3D e(0, 0, 0);
  if (mat->Get(AI_MATKEY_COLOR_EMISSIVE, e) == aiReturn_SUCCESS) {
    float strength = 1;
    if (mat->Get(AI_MATKEY_EMISSIVE_INTENSITY, v) == aiReturn_SUCCESS && v >= 0) strength = v;
    f.emission = Eigen::Vector3f(e.r, e.g, e.b).cwiseMax(0.0f) * strength *
                 static_cast<float>(config.emissive_cd_m2);
  }
  out.base_color = textures->Load(mat, aiTextureType_BASE_COLOR, TextureMap::kColour, 0, name);
  if (!out.base_color)
    out.base_color = textures->Load(mat, aiTextureType_DIFFUSE, TextureMap::kColour, 0, name);
  float normal_scale = 1;
  if (gltf &&
      mat->Get(AI_MATKEY_GLTF_TEXTURE_SCALE(aiTextureType_NORMALS, 0), v) == aiReturn_SUCCESS)
    normal_scale = v;
  out.normal = textures->Load(mat, aiTextureType_NORMALS, TextureMap::kNormal, normal_scale, name);
  if (gltf) {
    // assimp 5.2's glTF importer: metallicRoughnessTexture in the UNKNOWN slot (also METALNESS)
    out.metallic_roughness = textures->Load(mat, aiTextureType_UNKNOWN, TextureMap::kData, 0, name);
    if (!out.metallic_roughness)
      out.metallic_roughness =
          textures->Load(mat, aiTextureType_METALNESS, TextureMap::kData, 0, name);
    float strength = 1;
    if (mat->Get(AI_MATKEY_GLTF_TEXTURE_STRENGTH(aiTextureType_LIGHTMAP, 0), v) == aiReturn_SUCCESS)
      strength = std::clamp(v, 0.0f, 1.0f);
    out.occlusion =
        textures->Load(mat, aiTextureType_LIGHTMAP, TextureMap::kOcclusion, strength, name);
    if (!out.occlusion)
      out.occlusion = textures->Load(mat, aiTextureType_AMBIENT_OCCLUSION, TextureMap::kOcclusion,
                                     strength, name);
  }
  out.emissive = textures->Load(mat, aiTextureType_EMISSIVE, TextureMap::kColour, 0, name);
  return out;
}

}  // namespace

void StoreTexels(TextureMap map, float param, std::vector<uint8_t>* rgb) {
  if (map == TextureMap::kColour) return;
  std::vector<uint8_t>& p = *rgb;
  for (size_t i = 0; i + 2 < p.size(); i += 3) {
    float v[3] = {p[i] / 255.0f, p[i + 1] / 255.0f, p[i + 2] / 255.0f};
    if (map == TextureMap::kNormal) {
      for (int c = 0; c < 2; ++c) v[c] = std::clamp(0.5f + (v[c] - 0.5f) * param, 0.0f, 1.0f);
    } else if (map == TextureMap::kOcclusion) {
      v[0] = std::clamp(1.0f + param * (v[0] - 1.0f), 0.0f, 1.0f);
    }
    for (int c = 0; c < 3; ++c) p[i + c] = EncodeSrgb8(v[c]);
  }
}

std::shared_ptr<const TextureImage> DecodeTextureImage(const std::vector<unsigned char>& bytes,
                                                       TextureMap map, float param,
                                                       const std::string& what) {
  // the declared size against the caps before decoding
  CheckImageBytesSize(std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()),
                      what);
  DecodedRgb8 img = DecodeImageRgb8(bytes, what);  // assets/image_decode.h
  StoreTexels(map, param, &img.rgb);
  return std::make_shared<const TextureImage>(img.width, img.height, 1, std::move(img.rgb));
}

ImportedAsset ImportMeshFile(const std::string& path, const MeshImportConfig& config) {
  ImportedAsset asset;
  asset.file = fs::absolute(path).lexically_normal().string();
  std::error_code ec;
  if (!fs::is_regular_file(asset.file, ec))
    throw ConfigError(asset.file, 0, "", "mesh file not found");
  const std::string ext = LowerExtension(asset.file);
  const bool gltf = ext == ".gltf" || ext == ".glb";

  Assimp::Importer importer;
  // points and lines are dropped; polygons become triangles
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE,
                              aiPrimitiveType_POINT | aiPrimitiveType_LINE);
  importer.SetPropertyFloat(AI_CONFIG_PP_GSN_MAX_SMOOTHING_ANGLE, 80.0f);
  const aiScene* scene = importer.ReadFile(
      asset.file, aiProcess_Triangulate | aiProcess_JoinIdenticalVertices |
                      aiProcess_PreTransformVertices | aiProcess_GenSmoothNormals |
                      aiProcess_SortByPType | aiProcess_FlipUVs | aiProcess_ValidateDataStructure);
  if (scene == nullptr || scene->mRootNode == nullptr ||
      (scene->mFlags & AI_SCENE_FLAGS_INCOMPLETE))
    throw ConfigError(asset.file, 0, "",
                      std::string("not a readable mesh file: assimp: ") +
                          importer.GetErrorString() +
                          "; expected a valid OBJ, glTF 2.0, FBX, COLLADA, STL or PLY file");

  // units and up axis: the config, else the format's convention
  std::string up = config.up_axis;
  double scale = config.scale;
  if (ext == ".fbx") {
    std::string fbx_up;
    double fbx_unit = 0;
    FbxFrame(scene, &fbx_up, &fbx_unit);
    if (up.empty()) up = fbx_up;
    if (scale == 0) scale = fbx_unit;
  }
  if (up.empty()) up = (ext == ".stl" || ext == ".ply") ? "z" : "y";
  if (scale == 0) scale = 1;
  asset.scale = scale;
  asset.up_axis = up;
  Eigen::Matrix3f M = UpRotation(up);
  if (config.left_handed) M = M * Eigen::Vector3f(-1, 1, 1).asDiagonal();
  const float s = static_cast<float>(scale);

  // materials, with unique sanitised names
  TextureLoader textures(scene, asset.file);
  std::set<std::string> used;
  std::vector<int> material_of(scene->mNumMaterials, -1);
  auto material_index = [&](unsigned i) {
    if (material_of[i] >= 0) return material_of[i];
    const aiMaterial* mat = scene->mMaterials[i];
    std::string name = Sanitize(mat->GetName().C_Str());
    if (name.empty()) name = "default";
    if (!used.insert(name).second) {
      name += "_" + std::to_string(i);
      used.insert(name);
    }
    asset.materials.push_back(ReadMaterial(mat, gltf, config, &textures, name));
    material_of[i] = static_cast<int>(asset.materials.size()) - 1;
    return material_of[i];
  };

  for (unsigned i = 0; i < scene->mNumMeshes; ++i) {
    const aiMesh* in = scene->mMeshes[i];
    if (!(in->mPrimitiveTypes & aiPrimitiveType_TRIANGLE) || in->mNumFaces == 0) continue;
    ImportedMesh out;
    out.mesh.name = std::to_string(asset.meshes.size()) + "_" + Sanitize(in->mName.C_Str());
    out.mesh.vertices.reserve(in->mNumVertices);
    for (unsigned k = 0; k < in->mNumVertices; ++k) {
      const aiVector3D& p = in->mVertices[k];
      const Eigen::Vector3f v = M * Eigen::Vector3f(p.x, p.y, p.z) * s;
      if (!v.allFinite())
        throw ConfigError(asset.file, 0, "",
                          "mesh '" + std::string(in->mName.C_Str()) + "' has a vertex that is " +
                              "not a finite number; expected finite coordinates");
      out.mesh.vertices.push_back(v);
    }
    if (in->HasNormals()) {
      out.mesh.normals.reserve(in->mNumVertices);
      for (unsigned k = 0; k < in->mNumVertices; ++k) {
        const aiVector3D& n = in->mNormals[k];
        Eigen::Vector3f v = M * Eigen::Vector3f(n.x, n.y, n.z);
        const float len = v.norm();
        out.mesh.normals.push_back(len > 0 && std::isfinite(len) ? Eigen::Vector3f(v / len)
                                                                 : Eigen::Vector3f::UnitZ());
      }
    }
    if (in->HasTextureCoords(0)) {
      out.mesh.texcoords.reserve(in->mNumVertices);
      for (unsigned k = 0; k < in->mNumVertices; ++k) {
        const aiVector3D& t = in->mTextureCoords[0][k];
        out.mesh.texcoords.emplace_back(std::isfinite(t.x) ? t.x : 0.0f,
                                        std::isfinite(t.y) ? t.y : 0.0f);
      }
    }
    for (unsigned f = 0; f < in->mNumFaces; ++f) {
      const aiFace& face = in->mFaces[f];
      if (face.mNumIndices != 3) continue;
      Eigen::Vector3i tri(static_cast<int>(face.mIndices[0]), static_cast<int>(face.mIndices[1]),
                          static_cast<int>(face.mIndices[2]));
      if (config.left_handed) std::swap(tri[1], tri[2]);
      out.mesh.faces.push_back(tri);
    }
    if (out.mesh.faces.empty()) continue;
    out.material = material_index(in->mMaterialIndex);
    asset.triangles += static_cast<int>(out.mesh.faces.size());
    asset.meshes.push_back(std::move(out));
  }
  if (asset.meshes.empty())
    throw ConfigError(asset.file, 0, "",
                      "assimp read the file but found no triangles in it; expected a surface mesh");
  return asset;
}

}  // namespace penumbra

#pragma once
// a small glTF 2.0 asset written by a test: a slab 1 m x 1 m (x and z of the file, y up, as
// glTF says), `thickness_m` thick below y = 0, whose top face carries the whole texture:
// texcoord (0, 0) (the image's top-left texel) at file (-0.5, 0, -0.5) and (1, 1) at
// (0.5, 0, 0.5). imported with up axis y this is world (x, y) = (-0.5, 0.5) for the image's
// top-left corner and (0.5, -0.5) for its bottom-right: seen from above with image right =
// world +x and image down = world -y, the slab shows the image as it is.
// the other faces map to texcoord (0, 0). files: <stem>.gltf, <stem>.bin and the PNGs given.

#include <cstdint>
#include <cstring>
#include <fstream>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "common/temp_dir.h"

namespace penumbra::testing {

/// RGB pixels (h x w x 3) for a glTF image.
struct RgbImage {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;
  /// a w x h image of one colour.
  static RgbImage Solid(int w, int h, uint8_t r, uint8_t g, uint8_t b) {
    RgbImage im{w, h, {}};
    for (int i = 0; i < w * h; ++i) im.rgb.insert(im.rgb.end(), {r, g, b});
    return im;
  }
};

/// writes `im` as a PNG at `path`.
inline void WritePng(const std::string& path, const RgbImage& im) {
  cv::Mat m(im.height, im.width, CV_8UC3);
  for (int y = 0; y < im.height; ++y)
    for (int x = 0; x < im.width; ++x)
      for (int c = 0; c < 3; ++c)
        m.at<cv::Vec3b>(y, x)[2 - c] = im.rgb[(static_cast<size_t>(y) * im.width + x) * 3 + c];
  cv::imwrite(path, m);
}

/// the maps of the slab's material (unset: none).
struct SlabMaps {
  const RgbImage* base_color = nullptr;
  const RgbImage* normal = nullptr;
  float normal_scale = 1;
  const RgbImage* metallic_roughness = nullptr;
  float metallic = 0, roughness = 1;
};

/// writes the slab into `dir` and returns the .gltf path.
inline std::string WriteGltfSlab(const TempDir& dir, const std::string& stem, const SlabMaps& maps,
                                 float thickness_m = 0.05f) {
  // 6 faces x 4 vertices: position, normal, texcoord
  struct V {
    float p[3], n[3], t[2];
  };
  std::vector<V> v;
  std::vector<uint16_t> idx;
  const float h = thickness_m;
  auto face = [&](const float c[4][3], const float n[3], bool textured) {
    const float uv[4][2] = {{0, 0}, {1, 0}, {1, 1}, {0, 1}};
    const uint16_t b = static_cast<uint16_t>(v.size());
    for (int k = 0; k < 4; ++k) {
      V x{};
      std::memcpy(x.p, c[k], sizeof x.p);
      std::memcpy(x.n, n, sizeof x.n);
      x.t[0] = textured ? uv[k][0] : 0;
      x.t[1] = textured ? uv[k][1] : 0;
      v.push_back(x);
    }
    idx.insert(idx.end(), {b, static_cast<uint16_t>(b + 2), static_cast<uint16_t>(b + 1), b,
                           static_cast<uint16_t>(b + 3), static_cast<uint16_t>(b + 2)});
  };
  // corners listed so that (c1 - c0) x (c3 - c0) is the inward normal for the winding
  // (b, b+2, b+1): the triangles are counter-clockwise seen from outside.
  {
    const float c[4][3] = {{-0.5f, 0, -0.5f}, {0.5f, 0, -0.5f}, {0.5f, 0, 0.5f}, {-0.5f, 0, 0.5f}};
    const float n[3] = {0, 1, 0};
    face(c, n, true);
  }
  {
    const float c[4][3] = {
        {-0.5f, -h, 0.5f}, {0.5f, -h, 0.5f}, {0.5f, -h, -0.5f}, {-0.5f, -h, -0.5f}};
    const float n[3] = {0, -1, 0};
    face(c, n, false);
  }
  {
    const float c[4][3] = {{-0.5f, 0, 0.5f}, {0.5f, 0, 0.5f}, {0.5f, -h, 0.5f}, {-0.5f, -h, 0.5f}};
    const float n[3] = {0, 0, 1};
    face(c, n, false);
  }
  {
    const float c[4][3] = {
        {0.5f, 0, -0.5f}, {-0.5f, 0, -0.5f}, {-0.5f, -h, -0.5f}, {0.5f, -h, -0.5f}};
    const float n[3] = {0, 0, -1};
    face(c, n, false);
  }
  {
    const float c[4][3] = {{0.5f, 0, 0.5f}, {0.5f, 0, -0.5f}, {0.5f, -h, -0.5f}, {0.5f, -h, 0.5f}};
    const float n[3] = {1, 0, 0};
    face(c, n, false);
  }
  {
    const float c[4][3] = {
        {-0.5f, 0, -0.5f}, {-0.5f, 0, 0.5f}, {-0.5f, -h, 0.5f}, {-0.5f, -h, -0.5f}};
    const float n[3] = {-1, 0, 0};
    face(c, n, false);
  }
  std::string bin;
  auto put = [&](const void* p, size_t n) { bin.append(static_cast<const char*>(p), n); };
  for (const V& x : v) put(x.p, 12);
  const size_t nrm_off = bin.size();
  for (const V& x : v) put(x.n, 12);
  const size_t uv_off = bin.size();
  for (const V& x : v) put(x.t, 8);
  const size_t idx_off = bin.size();
  for (uint16_t i : idx) put(&i, 2);
  dir.Write(stem + ".bin", bin);

  std::string images, textures, material;
  int count = 0;
  auto add = [&](const RgbImage* im, const std::string& name) {
    if (im == nullptr) return -1;
    const std::string png = stem + "_" + name + ".png";
    WritePng((dir.path() / png).string(), *im);
    images += std::string(count ? "," : "") + "{\"uri\":\"" + png + "\"}";
    textures += std::string(count ? "," : "") + "{\"source\":" + std::to_string(count) + "}";
    return count++;
  };
  const int base = add(maps.base_color, "base");
  const int normal = add(maps.normal, "normal");
  const int mr = add(maps.metallic_roughness, "mr");
  material = "{\"name\":\"slab_material\",\"pbrMetallicRoughness\":{\"metallicFactor\":" +
             std::to_string(maps.metallic) +
             ",\"roughnessFactor\":" + std::to_string(maps.roughness);
  if (base >= 0) material += ",\"baseColorTexture\":{\"index\":" + std::to_string(base) + "}";
  if (mr >= 0) material += ",\"metallicRoughnessTexture\":{\"index\":" + std::to_string(mr) + "}";
  material += "}";
  if (normal >= 0)
    material += ",\"normalTexture\":{\"index\":" + std::to_string(normal) +
                ",\"scale\":" + std::to_string(maps.normal_scale) + "}";
  material += "}";
  const std::string nv = std::to_string(v.size());
  std::string json =
      "{\"asset\":{\"version\":\"2.0\"},\"scene\":0,\"scenes\":[{\"nodes\":[0]}],"
      "\"nodes\":[{\"mesh\":0,\"name\":\"slab\"}],"
      "\"meshes\":[{\"name\":\"slab\",\"primitives\":[{\"attributes\":{\"POSITION\":0,"
      "\"NORMAL\":1,\"TEXCOORD_0\":2},\"indices\":3,\"material\":0}]}],"
      "\"materials\":[" +
      material + "],";
  if (count > 0) json += "\"textures\":[" + textures + "],\"images\":[" + images + "],";
  json += "\"buffers\":[{\"uri\":\"" + stem +
          ".bin\",\"byteLength\":" + std::to_string(bin.size()) +
          "}],"
          "\"bufferViews\":[{\"buffer\":0,\"byteOffset\":0,\"byteLength\":" +
          std::to_string(nrm_off) +
          "},"
          "{\"buffer\":0,\"byteOffset\":" +
          std::to_string(nrm_off) + ",\"byteLength\":" + std::to_string(uv_off - nrm_off) +
          "},"
          "{\"buffer\":0,\"byteOffset\":" +
          std::to_string(uv_off) + ",\"byteLength\":" + std::to_string(idx_off - uv_off) +
          "},"
          "{\"buffer\":0,\"byteOffset\":" +
          std::to_string(idx_off) + ",\"byteLength\":" + std::to_string(bin.size() - idx_off) +
          "}],"
          "\"accessors\":[{\"bufferView\":0,\"componentType\":5126,\"count\":" +
          nv + ",\"type\":\"VEC3\",\"min\":[-0.5," + std::to_string(-h) +
          ",-0.5],\"max\":[0.5,0,0.5]},"
          "{\"bufferView\":1,\"componentType\":5126,\"count\":" +
          nv +
          ",\"type\":\"VEC3\"},"
          "{\"bufferView\":2,\"componentType\":5126,\"count\":" +
          nv +
          ",\"type\":\"VEC2\"},"
          "{\"bufferView\":3,\"componentType\":5123,\"count\":" +
          std::to_string(idx.size()) + ",\"type\":\"SCALAR\"}]}";
  return dir.Write(stem + ".gltf", json);
}

}  // namespace penumbra::testing

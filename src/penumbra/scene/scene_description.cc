#include "penumbra/scene/scene_description.h"

#include <cmath>
#include <set>

namespace penumbra {

CameraIntrinsics CameraIntrinsics::FromFovy(int width, int height, double fovy_deg) {
  CameraIntrinsics k;
  k.width = width;
  k.height = height;
  k.fy = 0.5 * height / std::tan(0.5 * fovy_deg * M_PI / 180.0);
  k.fx = k.fy;
  k.cx = 0.5 * (width - 1);
  k.cy = 0.5 * (height - 1);
  return k;
}

double CameraIntrinsics::fovy_deg() const {
  return 2.0 * std::atan(0.5 * height / fy) * 180.0 / M_PI;
}

namespace {
template <typename V>
int FindByName(const V& v, const std::string& name) {
  for (size_t i = 0; i < v.size(); ++i)
    if (v[i].name == name) return static_cast<int>(i);
  return -1;
}
}  // namespace

int SceneDescription::FindMaterial(const std::string& name) const {
  return FindByName(materials, name);
}
int SceneDescription::FindBody(const std::string& name) const { return FindByName(bodies, name); }
int SceneDescription::FindCamera(const std::string& name) const {
  return FindByName(cameras, name);
}

TextureMemory CountTextureMemory(const std::vector<Texture>& textures) {
  TextureMemory m;
  std::set<const TextureImage*> seen;
  for (const Texture& t : textures) {
    if (!t.image) continue;
    ++m.textures;
    if (!seen.insert(t.image.get()).second) continue;
    ++m.images;
    m.texels += static_cast<size_t>(t.image->width()) * t.image->height();
    m.bytes += t.image->bytes();
  }
  return m;
}

}  // namespace penumbra

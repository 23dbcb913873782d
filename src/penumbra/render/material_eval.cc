#include "penumbra/render/material_eval.h"

#include <algorithm>
#include <cmath>
#include <string>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

// sRGB EOTF, IEC 61966-2-1: code value in [0, 1] to linear.
double SrgbToLinear(double c) {
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

// half extents of a geom's bounding box in its own frame (zero where a shape is flat).
Eigen::Vector3f GeomHalfExtents(const SceneDescription& scene, const Geom& g) {
  const Eigen::Vector3d& s = g.size;
  switch (g.shape) {
    case GeomShape::kPlane:
      return Eigen::Vector3d(s.x(), s.y(), 0).cast<float>();
    case GeomShape::kSphere:
      return Eigen::Vector3f::Constant(static_cast<float>(s.x()));
    case GeomShape::kCapsule:
      return Eigen::Vector3d(s.x(), s.x(), s.y() + s.x()).cast<float>();
    case GeomShape::kCylinder:
      return Eigen::Vector3d(s.x(), s.x(), s.y()).cast<float>();
    case GeomShape::kEllipsoid:
    case GeomShape::kBox:
      return s.cast<float>();
    case GeomShape::kMesh: {
      Eigen::Vector3f h = Eigen::Vector3f::Zero();
      if (g.mesh >= 0 && g.mesh < static_cast<int>(scene.meshes.size()))
        for (const Eigen::Vector3f& v : scene.meshes[g.mesh].vertices) h = h.cwiseMax(v.cwiseAbs());
      return h;
    }
    case GeomShape::kHeightField: {
      if (g.hfield < 0 || g.hfield >= static_cast<int>(scene.hfields.size()))
        return Eigen::Vector3f::Ones();
      const HeightField& hf = scene.hfields[g.hfield];
      return Eigen::Vector3d(hf.size_x, hf.size_y, std::max(hf.size_z, hf.size_base)).cast<float>();
    }
  }
  return Eigen::Vector3f::Ones();
}

}  // namespace

MaterialEvaluator::MaterialEvaluator(const SceneDescription& scene) : scene_(scene) {
  for (int i = 0; i < 256; ++i) srgb_to_linear_[i] = static_cast<float>(SrgbToLinear(i / 255.0));
  for (const Material& m : scene.materials) {
    if (m.texture < 0) continue;
    if (m.texture >= static_cast<int>(scene.textures.size()))
      throw Error("material '" + m.name + "' refers to missing texture " +
                  std::to_string(m.texture));
    const Texture& t = scene.textures[m.texture];
    const size_t expected = static_cast<size_t>(std::max(t.width, 0)) * std::max(t.height, 0) * 3;
    if (t.width < 1 || t.height < 1 || t.rgb_srgb.size() != expected)
      throw Error("texture '" + t.name +
                  "': expected width, height >= 1 and width x height x 3 bytes");
    if (t.kind != Texture::Kind::k2D && t.height != 6 * t.width)
      throw Error("cube texture '" + t.name +
                  "': expected six square faces stacked vertically (height = 6 width)");
  }
  half_extent_G_.reserve(scene.geoms.size());
  for (const Geom& g : scene.geoms) half_extent_G_.push_back(GeomHalfExtents(scene, g));
}

Eigen::Vector3f MaterialEvaluator::Sample2D(int tex, float s, float t) const {
  const Texture& T = scene_.textures[tex];
  const int w = T.width, h = T.height;
  // texel centres at (i + 0.5) / w; wrap the integer part away first to keep precision.
  const float x = (s - std::floor(s)) * w - 0.5f;
  const float y = (t - std::floor(t)) * h - 0.5f;
  const float x0f = std::floor(x), y0f = std::floor(y);
  const float fx = x - x0f, fy = y - y0f;
  // x0f in [-1, w - 1] and y0f in [-1, h - 1] (texel centres), so one step wraps them.
  int x0 = static_cast<int>(x0f), y0 = static_cast<int>(y0f);
  int x1 = x0 + 1, y1 = y0 + 1;
  x0 = x0 < 0 ? x0 + w : x0;
  y0 = y0 < 0 ? y0 + h : y0;
  x1 = x1 >= w ? x1 - w : x1;
  y1 = y1 >= h ? y1 - h : y1;
  const uint8_t* p = T.rgb_srgb.data();
  auto texel = [&](int xi, int yi) {
    const uint8_t* q = p + (static_cast<size_t>(yi) * w + xi) * 3;
    return Eigen::Vector3f(srgb_to_linear_[q[0]], srgb_to_linear_[q[1]], srgb_to_linear_[q[2]]);
  };
  return (1 - fy) * ((1 - fx) * texel(x0, y0) + fx * texel(x1, y0)) +
         fy * ((1 - fx) * texel(x0, y1) + fx * texel(x1, y1));
}

Eigen::Vector3f MaterialEvaluator::SampleCube(int tex, const Eigen::Vector3f& q) const {
  const Texture& T = scene_.textures[tex];
  const int w = T.width;
  const Eigen::Vector3f a = q.cwiseAbs();
  int face;
  float sc, tc, ma;
  // OpenGL 4.6 core spec, table 8.19 (face selection and (sc, tc) per major axis).
  if (a.x() >= a.y() && a.x() >= a.z()) {
    ma = a.x();
    face = q.x() >= 0 ? 0 : 1;
    sc = q.x() >= 0 ? -q.z() : q.z();
    tc = -q.y();
  } else if (a.y() >= a.z()) {
    ma = a.y();
    face = q.y() >= 0 ? 2 : 3;
    sc = q.x();
    tc = q.y() >= 0 ? q.z() : -q.z();
  } else {
    ma = a.z();
    face = q.z() >= 0 ? 4 : 5;
    sc = q.z() >= 0 ? q.x() : -q.x();
    tc = -q.y();
  }
  if (!(ma > 0)) return Eigen::Vector3f::Ones();
  const float s = 0.5f * (sc / ma + 1.0f), t = 0.5f * (tc / ma + 1.0f);
  // bilinear, clamped to the face.
  const float x = std::clamp(s * w - 0.5f, 0.0f, static_cast<float>(w - 1));
  const float y = std::clamp(t * w - 0.5f, 0.0f, static_cast<float>(w - 1));
  const int x0 = static_cast<int>(x), y0 = static_cast<int>(y);
  const int x1 = std::min(x0 + 1, w - 1), y1 = std::min(y0 + 1, w - 1);
  const float fx = x - x0, fy = y - y0;
  const uint8_t* p = T.rgb_srgb.data() + static_cast<size_t>(face) * w * w * 3;
  auto texel = [&](int xi, int yi) {
    const uint8_t* c = p + (static_cast<size_t>(yi) * w + xi) * 3;
    return Eigen::Vector3f(srgb_to_linear_[c[0]], srgb_to_linear_[c[1]], srgb_to_linear_[c[2]]);
  };
  return (1 - fy) * ((1 - fx) * texel(x0, y0) + fx * texel(x1, y0)) +
         fy * ((1 - fx) * texel(x0, y1) + fx * texel(x1, y1));
}

void ApplySurfaceWetness(float wetness, const Eigen::Vector3f& n_W, PbrParams* pbr) {
  const float facing = std::clamp((n_W.z() - 0.3f) / 0.4f, 0.0f, 1.0f);
  const float w = std::clamp(wetness, 0.0f, 1.0f) * facing;
  if (!(w > 0)) return;
  const float darken = 1.0f + (0.3f - 1.0f) * w;
  const float m = std::clamp(pbr->metallic, 0.0f, 1.0f);
  pbr->base_color *= (1.0f - m) * darken + m;
  const float gloss = std::min(1.0f, (1.0f - pbr->roughness) * (1.0f + 1.5f * w));
  pbr->roughness = 1.0f - gloss;
}

SurfaceMaterial MaterialEvaluator::Evaluate(const SurfaceHit& hit) const {
  const Material& m = hit.material >= 0 ? scene_.materials[hit.material] : default_material_;
  SurfaceMaterial out;
  out.pbr.base_color = m.base_color;
  out.pbr.roughness = m.roughness;
  out.pbr.metallic = m.metallic;
  out.pbr.specular = m.specular;
  out.emission = m.emission;
  if (m.texture < 0) return out;

  const Texture& tex = scene_.textures[m.texture];
  const Eigen::Vector3f& h = half_extent_G_[hit.geom];
  Eigen::Vector3f c;
  if (tex.kind == Texture::Kind::k2D) {
    float s, t;
    if (hit.has_uv) {
      s = hit.uv.x();
      t = hit.uv.y();
    } else {
      // planar projection along the dominant axis of the geom-frame normal: face axes
      // (a0, a1) = the next two axes in cyclic order, image rows along -a1.
      const Eigen::Vector3f an = hit.n_G.cwiseAbs();
      const int axis = (an.x() >= an.y() && an.x() >= an.z()) ? 0 : (an.y() >= an.z() ? 1 : 2);
      const int a0 = (axis + 1) % 3, a1 = (axis + 2) % 3;
      const bool infinite_plane =
          scene_.geoms[hit.geom].shape == GeomShape::kPlane && !(h[a0] > 0 && h[a1] > 0);
      if (m.texuniform || infinite_plane) {
        s = hit.p_G[a0] * m.texrepeat.x();
        t = -hit.p_G[a1] * m.texrepeat.y();
      } else {
        const float h0 = h[a0] > 0 ? h[a0] : 1.0f, h1 = h[a1] > 0 ? h[a1] : 1.0f;
        s = (0.5f * hit.p_G[a0] / h0 + 0.5f) * m.texrepeat.x();
        t = (0.5f - 0.5f * hit.p_G[a1] / h1) * m.texrepeat.y();
      }
    }
    c = Sample2D(m.texture, s, t);
  } else {
    const Eigen::Vector3f q(h.x() > 0 ? hit.p_G.x() / h.x() : hit.n_G.x(),
                            h.y() > 0 ? hit.p_G.y() / h.y() : hit.n_G.y(),
                            h.z() > 0 ? hit.p_G.z() / h.z() : hit.n_G.z());
    c = SampleCube(m.texture, q);
  }
  out.pbr.base_color = out.pbr.base_color.cwiseProduct(c);
  return out;
}

}  // namespace penumbra

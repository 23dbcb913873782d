#include "penumbra/render/material/material_eval.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <unordered_map>

#ifdef __AVX2__
#include <immintrin.h>
#endif

#include "penumbra/core/error.h"
#include "penumbra/render/material/texture_lanes.h"
#include "penumbra/render/material/texture_math.h"
#include "penumbra/render/material/wetness_math.h"
#include "penumbra/scene/texture_image.h"

namespace penumbra {
namespace {

// the shared texture formulas (render/material/texture_math.h) on the scene's texture levels.
inline TextureLevelView ViewOf(const TextureLevel& L) {
  return TextureLevelView{L.rgb_srgb.data(), L.width, L.height};
}
inline Eigen::Vector3f ToEigen(const Float3& c) { return Eigen::Vector3f(c.x, c.y, c.z); }

// bilinear lookup in one level, wrapped; (s, t) in images (1 = one image).
Eigen::Vector3f BilinearWrap(const TextureLevel& L, const float* decode, float s, float t) {
  return ToEigen(BilinearWrap(ViewOf(L), decode, s, t));
}

// bilinear lookup in face `face` of one level, clamped to the face; (s, t) in [0, 1].
Eigen::Vector3f BilinearFace(const TextureLevel& L, const float* decode, int face, float s,
                             float t) {
  return ToEigen(BilinearFace(ViewOf(L), decode, face, s, t));
}

// the mip level of a footprint on a mapping of rho texels per metre (file comment).
float TextureLod(const TextureFootprint& f, float rho) {
  return penumbra::TextureLod(f.width_m, f.cos_incidence, rho);
}

// the levels a trilinear lookup at `lod` reads, with their weights: add(level, weight) once or
// twice (TrilinearLevels of texture_math.h).
template <typename AddFn>
void TrilinearLevels(int num_levels, float lod, const AddFn& add) {
  int level[2];
  float weight[2];
  const int n = penumbra::TrilinearLevels(num_levels, lod, level, weight);
  for (int i = 0; i < n; ++i) add(level[i], weight[i]);
}

// trilinear: bilinear(level) in the two levels around `lod`, mixed by its fraction.
template <typename BilinearFn>
Eigen::Vector3f Trilinear(const TextureImage& image, float lod, const BilinearFn& bilinear) {
  Eigen::Vector3f c = Eigen::Vector3f::Zero();
  TrilinearLevels(image.num_levels(), lod,
                  [&](int l, float w) { c += w * bilinear(image.level(l)); });
  return c;
}

// the footprint ellipse's axes on the surface, geom frame (file comment, "anisotropic
// filtering"): major = t W / |n . v|, minor = b W. false when there is no width or the ray meets
// the surface head-on (no direction to stretch along).
bool FootprintAxes(const SurfaceHit& hit, const TextureFootprint& f, Eigen::Vector3f* major_G,
                   Eigen::Vector3f* minor_G) {
  if (!(f.width_m > 0)) return false;
  const Eigen::Vector3f& n = hit.n_G;
  const Eigen::Vector3f t = hit.d_G - hit.d_G.dot(n) * n;
  const float len = t.norm();
  if (!(len > 1e-4f)) return false;
  const Eigen::Vector3f t_unit = t / len;
  *major_G = t_unit * (f.width_m / std::max(f.cos_incidence, kMinCosIncidence));
  *minor_G = n.cross(t_unit) * f.width_m;
  return true;
}

// mean of n bilinear lookups in one level (wrapped) along the major axis (texture_math.h), the
// taps as SIMD lanes (texture_lanes.h: bit-identical to the shared formula).
Eigen::Vector3f BilinearWrapTaps(const TextureLevel& L, const float* decode, float s, float t,
                                 float ds, float dt, int n) {
  return ToEigen(BilinearWrapTapsLanes(ViewOf(L), decode, s, t, ds, dt, n));
}

// adds weight x the bilinear lookup (wrapped; (s, t) in images) of a packed level (w x h
// texels of 8 linear channels, MaterialEvaluator::PackedLevel) to the 8 channels of `acc`.
inline void AddBilinearPacked(const MaterialEvaluator::PackedLevel& L, float s, float t,
                              float weight, float* acc) {
  const auto [x0, y0, x1, y1, fx, fy] = WrapTexels(s, t, L.width, L.height);
  const size_t w = static_cast<size_t>(L.width);
  const uint16_t* p = L.texels.data();
  const uint16_t* a = p + (static_cast<size_t>(y0) * w + x0) * 8;
  const uint16_t* b = p + (static_cast<size_t>(y0) * w + x1) * 8;
  const uint16_t* c = p + (static_cast<size_t>(y1) * w + x0) * 8;
  const uint16_t* d = p + (static_cast<size_t>(y1) * w + x1) * 8;
  const float k = weight * MaterialEvaluator::PackedLevel::kScale;
  const float w00 = k * (1 - fx) * (1 - fy), w10 = k * fx * (1 - fy);
  const float w01 = k * (1 - fx) * fy, w11 = k * fx * fy;
#ifdef __AVX2__
  // the 8 channels of a texel as one register.
  auto texel = [](const uint16_t* q) {
    const __m128i v = _mm_loadu_si128(reinterpret_cast<const __m128i*>(q));
    return _mm256_cvtepi32_ps(_mm256_cvtepu16_epi32(v));
  };
  __m256 sum = _mm256_mul_ps(_mm256_set1_ps(w00), texel(a));
  sum = _mm256_add_ps(sum, _mm256_mul_ps(_mm256_set1_ps(w10), texel(b)));
  sum = _mm256_add_ps(sum, _mm256_mul_ps(_mm256_set1_ps(w01), texel(c)));
  sum = _mm256_add_ps(sum, _mm256_mul_ps(_mm256_set1_ps(w11), texel(d)));
  _mm256_storeu_ps(acc, _mm256_add_ps(_mm256_loadu_ps(acc), sum));
#else
  for (int j = 0; j < 8; ++j) acc[j] += w00 * a[j] + w10 * b[j] + w01 * c[j] + w11 * d[j];
#endif
}

}  // namespace

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

TextureFootprint ConeFootprint(float spread_rad, float distance_m, const Eigen::Vector3f& d_unit,
                               const SurfaceHit& hit) {
  TextureFootprint f;
  f.width_m = spread_rad * distance_m;
  f.cos_incidence = std::min(1.0f, std::abs(hit.ng_W.dot(d_unit)));
  return f;
}

MaterialEvaluator::MaterialEvaluator(const SceneDescription& scene, int max_anisotropy)
    : scene_(scene),
      srgb_to_linear_(SrgbDecodeTable()),
      max_anisotropy_(std::max(1, max_anisotropy)) {
  // the PBR maps by name (file comment): "<material>/<map>"
  std::unordered_map<std::string, int> by_name;
  for (size_t t = 0; t < scene.textures.size(); ++t)
    if (scene.textures[t].kind == Texture::Kind::k2D && scene.textures[t].image)
      by_name.emplace(scene.textures[t].name, static_cast<int>(t));
  maps_.resize(scene.materials.size());
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const std::string& name = scene.materials[i].name;
    if (name.empty() || by_name.empty()) continue;
    auto find = [&](const char* map) {
      const auto it = by_name.find(name + "/" + map);
      return it == by_name.end() ? -1 : it->second;
    };
    maps_[i].normal = find("normal");
    maps_[i].metallic_roughness = find("metallic_roughness");
    maps_[i].occlusion = find("occlusion");
    maps_[i].emissive = find("emissive");
    has_normal_maps_ |= maps_[i].normal >= 0;
  }
  for (const Material& m : scene.materials) {
    if (m.texture < 0) continue;
    if (m.texture >= static_cast<int>(scene.textures.size()))
      throw Error("material '" + m.name + "' refers to missing texture " +
                  std::to_string(m.texture));
    const Texture& t = scene.textures[m.texture];
    if (!t.image) throw Error("texture '" + t.name + "': expected an image, got none");
    if (t.kind != Texture::Kind::k2D &&
        (t.image->faces() != 6 || t.image->height() != 6 * t.image->width()))
      throw Error("cube texture '" + t.name +
                  "': expected six square faces stacked vertically (height = 6 width)");
  }
  // packed maps (file comment): a material's 2d base texture, normal and metallic-roughness
  // maps, at least two of them, of one size, interleaved as 8 linear 16-bit channels a texel,
  // level by level.
  packed_of_.assign(scene.materials.size(), -1);
  // the decoded value of every 8-bit code in steps of PackedLevel::kScale.
  uint16_t linear[256];
  for (int code = 0; code < 256; ++code)
    linear[code] = static_cast<uint16_t>(std::lround(srgb_to_linear_[code] / PackedLevel::kScale));
  for (size_t i = 0; i < scene.materials.size(); ++i) {
    const Material& m = scene.materials[i];
    auto image_2d = [&](int tex) -> const TextureImage* {
      if (tex < 0 || tex >= static_cast<int>(scene.textures.size())) return nullptr;
      const Texture& t = scene.textures[tex];
      return t.kind == Texture::Kind::k2D && t.image && t.image->faces() == 1 ? t.image.get()
                                                                              : nullptr;
    };
    if (m.texture >= 0 && image_2d(m.texture) == nullptr) continue;  // a cube texture
    const TextureImage* base = image_2d(m.texture);
    const TextureImage* normal = image_2d(maps_[i].normal);
    const TextureImage* mr = image_2d(maps_[i].metallic_roughness);
    const TextureImage* first = base ? base : (normal ? normal : mr);
    if ((base != nullptr) + (normal != nullptr) + (mr != nullptr) < 2) continue;
    auto same = [&](const TextureImage* im) {
      return im == nullptr || (im->width() == first->width() && im->height() == first->height() &&
                               im->num_levels() == first->num_levels());
    };
    if (!same(base) || !same(normal) || !same(mr)) continue;
    if (static_cast<int64_t>(first->width()) * first->height() > kMaxPackedTexels) continue;
    PackedMaps pm;
    pm.base = base != nullptr;
    pm.normal = normal != nullptr;
    pm.metallic_roughness = mr != nullptr;
    for (int l = 0; l < first->num_levels(); ++l) {
      const TextureLevel& L = first->level(l);
      PackedLevel& P = pm.levels.emplace_back();
      P.width = L.width;
      P.height = L.height;
      const size_t n = static_cast<size_t>(L.width) * L.height;
      P.texels.assign(8 * n, 0);
      auto put = [&](const TextureImage* im, int from, int count, int to) {
        if (im == nullptr) return;
        const uint8_t* src = im->level(l).rgb_srgb.data();
        for (size_t k = 0; k < n; ++k)
          for (int c = 0; c < count; ++c) P.texels[8 * k + to + c] = linear[src[3 * k + from + c]];
      };
      put(base, 0, 3, 0);
      put(normal, 0, 3, 3);
      put(mr, 1, 2, 6);
    }
    packed_of_[i] = static_cast<int>(packed_.size());
    packed_.push_back(std::move(pm));
  }
  half_extent_G_.reserve(scene.geoms.size());
  for (const Geom& g : scene.geoms) half_extent_G_.push_back(GeomHalfExtents(scene, g));
}

Eigen::Vector3f MaterialEvaluator::Sample2D(int tex, float s, float t, float lod) const {
  const float* decode = srgb_to_linear_;
  return Trilinear(*scene_.textures[tex].image, lod,
                   [&](const TextureLevel& L) { return BilinearWrap(L, decode, s, t); });
}

Eigen::Vector3f MaterialEvaluator::SampleCube(int tex, const Eigen::Vector3f& q, float lod) const {
  int face;
  float s, t;
  if (!CubeFaceCoords(Float3{q.x(), q.y(), q.z()}, &face, &s, &t)) return Eigen::Vector3f::Ones();
  const float* decode = srgb_to_linear_;
  return Trilinear(*scene_.textures[tex].image, lod,
                   [&](const TextureLevel& L) { return BilinearFace(L, decode, face, s, t); });
}

void ApplySurfaceWetness(float wetness, const Eigen::Vector3f& n_W, PbrParams* pbr) {
  // the shared formula (render/material/wetness_math.h; the CUDA realtime path calls it too).
  float scale, roughness;
  if (!SurfaceWetnessTerms(wetness, n_W.z(), pbr->metallic, pbr->roughness, &scale, &roughness))
    return;
  pbr->base_color *= scale;
  pbr->roughness = roughness;
}

// the 2d mapping of a material at a hit (render/material/material_eval.h, "texture mapping"):
// texture coordinates (s, t) in images, their gradient J (images per metre of geom-frame
// displacement), and what rho (texels per metre) is for a w x h image.
struct MaterialEvaluator::Mapping2D {
  enum class Kind { kTexcoords, kUniform, kPerFace };
  Kind kind = Kind::kTexcoords;
  float s = 0, t = 0;
  Eigen::Matrix<float, 2, 3> J = Eigen::Matrix<float, 2, 3>::Zero();
  float uv_per_m = 0;    // kTexcoords
  float rx = 1, ry = 1;  // texrepeat
  float h0 = 1, h1 = 1;  // kPerFace: half sizes of the face
  int a0 = -1, a1 = -1;  // planar: the face axes (image rows along -a1)

  PlanarMap planar;  // planar kinds (texture_math.h)

  // texels per metre of surface for a w x h image (the expressions of the isotropic lookup).
  float Rho(float w, float th) const {
    if (kind == Kind::kTexcoords) return TexcoordRho(uv_per_m, w, th);
    return planar.rho(w, th);
  }
};

MaterialEvaluator::Mapping2D MaterialEvaluator::MapAt(const SurfaceHit& hit,
                                                      const Material& m) const {
  Mapping2D map;
  if (hit.has_uv) {
    map.kind = Mapping2D::Kind::kTexcoords;
    map.s = hit.uv.x();
    map.t = hit.uv.y();
    map.uv_per_m = hit.uv_per_m;
    map.J = hit.duv_dp_G;
    return map;
  }
  // planar projection along the dominant axis of the geom-frame normal: face axes (a0, a1) =
  // the next two axes in cyclic order, image rows along -a1.
  const Eigen::Vector3f& h = half_extent_G_[hit.geom];
  const Eigen::Vector3f an = hit.n_G.cwiseAbs();
  const int axis = (an.x() >= an.y() && an.x() >= an.z()) ? 0 : (an.y() >= an.z() ? 1 : 2);
  const int a0 = (axis + 1) % 3, a1 = (axis + 2) % 3;
  map.a0 = a0;
  map.a1 = a1;
  map.rx = m.texrepeat.x();
  map.ry = m.texrepeat.y();
  const bool infinite_plane =
      scene_.geoms[hit.geom].shape == GeomShape::kPlane && !(h[a0] > 0 && h[a1] > 0);
  if (m.texuniform || infinite_plane) {
    map.kind = Mapping2D::Kind::kUniform;
    map.planar = PlanarMapUniform(hit.p_G[a0], hit.p_G[a1], infinite_plane ? 0.0f : h[a0],
                                  infinite_plane ? 0.0f : h[a1], m.texrepeat.x(), m.texrepeat.y());
  } else {
    map.kind = Mapping2D::Kind::kPerFace;
    const float h0 = h[a0] > 0 ? h[a0] : 1.0f, h1 = h[a1] > 0 ? h[a1] : 1.0f;
    map.h0 = h0;
    map.h1 = h1;
    map.planar =
        PlanarMapPerFace(hit.p_G[a0], hit.p_G[a1], h0, h1, m.texrepeat.x(), m.texrepeat.y());
  }
  map.s = map.planar.s;
  map.t = map.planar.t;
  map.J(0, a0) = map.planar.j0;
  map.J(1, a1) = map.planar.j1;
  return map;
}

MaterialEvaluator::FilterPlan MaterialEvaluator::PlanFilter(
    int width, int height, const Mapping2D& map, bool aniso, const Eigen::Vector3f& major_G,
    const Eigen::Vector3f& minor_G, const TextureFootprint& footprint) const {
  const float w = static_cast<float>(width);
  const float th = static_cast<float>(height);
  FilterPlan plan;
  if (aniso) {
    // the axes in texture units, then the taps (texture_math.h, shared with the GPU).
    const float j_s[3] = {map.J(0, 0), map.J(0, 1), map.J(0, 2)};
    const float j_t[3] = {map.J(1, 0), map.J(1, 1), map.J(1, 2)};
    float major_s, major_t, minor_s, minor_t;
    TexcoordAxis(j_s, j_t, major_G.data(), &major_s, &major_t);
    TexcoordAxis(j_s, j_t, minor_G.data(), &minor_s, &minor_t);
    const PlanarFilterPlan p =
        PlanAnisotropic(major_s, major_t, minor_s, minor_t, w, th, max_anisotropy_);
    if (p.ok) {
      plan.lod = p.lod;
      plan.n = p.n;
      plan.ds = p.ds;
      plan.dt = p.dt;
      return plan;
    }
  }
  plan.lod = TextureLod(footprint, map.Rho(w, th));
  return plan;
}

Eigen::Vector3f MaterialEvaluator::Filter2D(const TextureImage& image, const Mapping2D& map,
                                            bool aniso, const Eigen::Vector3f& major_G,
                                            const Eigen::Vector3f& minor_G,
                                            const TextureFootprint& footprint) const {
  const float* decode = srgb_to_linear_;
  const FilterPlan plan =
      PlanFilter(image.width(), image.height(), map, aniso, major_G, minor_G, footprint);
  if (plan.n > 1)
    return BilinearWrapTaps(image.level(TapLevel(image.num_levels(), plan.lod)), decode, map.s,
                            map.t, plan.ds, plan.dt, plan.n);
  return Trilinear(image, plan.lod,
                   [&](const TextureLevel& L) { return BilinearWrap(L, decode, map.s, map.t); });
}

void MaterialEvaluator::FilterPacked(const PackedMaps& packed, const Mapping2D& map, bool aniso,
                                     const Eigen::Vector3f& major_G, const Eigen::Vector3f& minor_G,
                                     const TextureFootprint& footprint, float out[8]) const {
  const PackedLevel& L0 = packed.levels.front();
  const FilterPlan plan = PlanFilter(L0.width, L0.height, map, aniso, major_G, minor_G, footprint);
  std::fill_n(out, 8, 0.0f);
  const int num_levels = static_cast<int>(packed.levels.size());
  if (plan.n > 1) {
    const PackedLevel& L = packed.levels[TapLevel(num_levels, plan.lod)];
    const float step = 1.0f / static_cast<float>(plan.n);
    const float o0 = 0.5f * step - 0.5f;
    for (int k = 0; k < plan.n; ++k) {
      const float o = o0 + static_cast<float>(k) * step;
      AddBilinearPacked(L, map.s + o * plan.ds, map.t + o * plan.dt, step, out);
    }
    return;
  }
  TrilinearLevels(num_levels, plan.lod, [&](int l, float w) {
    AddBilinearPacked(packed.levels[l], map.s, map.t, w, out);
  });
}

SurfaceMaterial MaterialEvaluator::Untextured(const SurfaceHit& hit, const Material& m) const {
  SurfaceMaterial out;
  out.pbr.base_color = m.base_color;
  out.pbr.roughness = m.roughness;
  out.pbr.metallic = m.metallic;
  out.pbr.specular = m.specular;
  out.emission = m.emission;
  if (m.reflectance > 0 && hit.geom >= 0) {
    const GeomShape shape = scene_.geoms[hit.geom].shape;
    if (shape == GeomShape::kPlane || (shape == GeomShape::kBox && hit.n_G.z() > 0.5f))
      out.mirror = std::min(m.reflectance, 1.0f);
  }
  return out;
}

SurfaceMaterial MaterialEvaluator::Evaluate(const SurfaceHit& hit,
                                            const TextureFootprint& footprint) const {
  const Material& m = hit.material >= 0 ? scene_.materials[hit.material] : default_material_;
  SurfaceMaterial out = Untextured(hit, m);
  static const PbrMaps kNoMaps;
  const PbrMaps& maps = hit.material >= 0 ? maps_[hit.material] : kNoMaps;
  const bool pbr_maps = maps.metallic_roughness >= 0 || maps.occlusion >= 0 || maps.emissive >= 0;
  // tendons (geom -1) are drawn untextured
  if ((m.texture < 0 && !pbr_maps) || hit.geom < 0) return out;

  Eigen::Vector3f major_G, minor_G;
  const bool aniso = max_anisotropy_ > 1 && FootprintAxes(hit, footprint, &major_G, &minor_G);
  Mapping2D map;
  bool mapped = false;
  auto mapping = [&]() -> const Mapping2D& {
    if (!mapped) map = MapAt(hit, m), mapped = true;
    return map;
  };
  if (m.texture >= 0) {
    const Texture& tex = scene_.textures[m.texture];
    Eigen::Vector3f c;
    if (tex.kind == Texture::Kind::k2D) {
      c = Filter2D(*tex.image, mapping(), aniso, major_G, minor_G, footprint);
    } else {
      const Eigen::Vector3f& h = half_extent_G_[hit.geom];
      const float w = static_cast<float>(tex.image->width());
      // the lookup direction and texels per metre (texture_math.h, shared with the GPU)
      auto q_of = [&](const Eigen::Vector3f& p_G) {
        const Float3 q = CubeLookupDirection(Float3{p_G.x(), p_G.y(), p_G.z()},
                                             Float3{hit.n_G.x(), hit.n_G.y(), hit.n_G.z()},
                                             Float3{h.x(), h.y(), h.z()});
        return Eigen::Vector3f(q.x, q.y, q.z);
      };
      const float rho = CubeRho(w, h.maxCoeff());
      if (aniso && rho > 0) {
        const float rho2 = rho * rho;
        const AnisoTaps taps =
            TapsFor(major_G.squaredNorm() * rho2, minor_G.squaredNorm() * rho2, max_anisotropy_);
        c.setZero();
        for (int k = 0; k < taps.n; ++k)
          c += SampleCube(m.texture, q_of(hit.p_G + TapOffset(k, taps.n) * major_G), taps.lod);
        c /= static_cast<float>(taps.n);
      } else {
        c = SampleCube(m.texture, q_of(hit.p_G), TextureLod(footprint, rho));
      }
    }
    out.pbr.base_color = out.pbr.base_color.cwiseProduct(c);
  }
  if (!pbr_maps) return out;
  if (maps.metallic_roughness >= 0) {
    const Eigen::Vector3f c = Filter2D(*scene_.textures[maps.metallic_roughness].image, mapping(),
                                       aniso, major_G, minor_G, footprint);
    out.pbr.roughness *= c.y();
    out.pbr.metallic *= c.z();
  }
  ApplyOcclusionEmission(maps, mapping(), aniso, major_G, minor_G, footprint, &out);
  return out;
}

void MaterialEvaluator::ApplyOcclusionEmission(const PbrMaps& maps, const Mapping2D& map,
                                               bool aniso, const Eigen::Vector3f& major_G,
                                               const Eigen::Vector3f& minor_G,
                                               const TextureFootprint& footprint,
                                               SurfaceMaterial* out) const {
  auto sample = [&](int tex) {
    return Filter2D(*scene_.textures[tex].image, map, aniso, major_G, minor_G, footprint);
  };
  if (maps.occlusion >= 0) out->occlusion = std::clamp(sample(maps.occlusion).x(), 0.0f, 1.0f);
  if (maps.emissive >= 0) out->emission = out->emission.cwiseProduct(sample(maps.emissive));
}

void MaterialEvaluator::ApplyNormalMap(SurfaceHit* hit, const TextureFootprint& footprint) const {
  if (hit->material < 0 || hit->geom < 0 || hit->geom >= static_cast<int>(R_WG_.size())) return;
  const int normal_map = maps_[hit->material].normal;
  if (normal_map < 0) return;
  const Mapping2D map = MapAt(*hit, scene_.materials[hit->material]);
  Eigen::Vector3f major_G, minor_G;
  const bool aniso = max_anisotropy_ > 1 && FootprintAxes(*hit, footprint, &major_G, &minor_G);
  BendNormal(map,
             Filter2D(*scene_.textures[normal_map].image, map, aniso, major_G, minor_G, footprint),
             hit);
}

void MaterialEvaluator::BendNormal(const Mapping2D& map, const Eigen::Vector3f& c,
                                   SurfaceHit* hit) const {
  if (hit->geom < 0 || hit->geom >= static_cast<int>(R_WG_.size())) return;
  const Eigen::Matrix3f& R_WG = R_WG_[hit->geom];
  // tangent t (increasing s) and bitangent b (towards the image's top row: decreasing t), geom
  // frame: the columns of the pseudo-inverse of J restricted to the surface.
  Eigen::Vector3f t_G, b_G;
  if (map.a0 >= 0) {
    t_G = Eigen::Vector3f::Zero();
    b_G = Eigen::Vector3f::Zero();
    t_G[map.a0] = map.J(0, map.a0) >= 0 ? 1.0f : -1.0f;
    b_G[map.a1] = map.J(1, map.a1) >= 0 ? -1.0f : 1.0f;
  } else {
    // the texcoords' tangent frame (texture_math.h, shared with the GPU)
    const float j_s[3] = {map.J(0, 0), map.J(0, 1), map.J(0, 2)};
    const float j_t[3] = {map.J(1, 0), map.J(1, 1), map.J(1, 2)};
    if (!TexcoordTangents(j_s, j_t, t_G.data(), b_G.data())) return;
  }
  // the GPU's BendNormal (texture_math.h) is this arithmetic on Float3; here Eigen's vectorised
  // dot and cross products round differently in the last bit (docs/gpu.md).
  const Eigen::Vector3f tn(2 * c.x() - 1, 2 * c.y() - 1, 2 * c.z() - 1);
  // outward shading normal, and the tangent frame around it (Gram-Schmidt), world frame.
  const Eigen::Vector3f n = hit->front_face ? hit->ns_W : Eigen::Vector3f(-hit->ns_W);
  Eigen::Vector3f t = R_WG * t_G;
  t -= t.dot(n) * n;
  const float lt = t.norm();
  if (!(lt > 0)) return;
  t /= lt;
  // b minus its components along n and t, normalised, is +-(n x t) (n, t orthonormal).
  const Eigen::Vector3f n_x_t = n.cross(t);
  const float b_along = (R_WG * b_G).dot(n_x_t);
  if (!(b_along != 0)) return;
  const Eigen::Vector3f b = b_along > 0 ? n_x_t : Eigen::Vector3f(-n_x_t);
  const Eigen::Vector3f mapped = tn.x() * t + tn.y() * b + std::max(tn.z(), 0.0f) * n;
  const float len = mapped.norm();
  if (!(len > 0) || !mapped.allFinite()) return;
  hit->ns_W = hit->front_face ? Eigen::Vector3f(mapped / len) : Eigen::Vector3f(-mapped / len);
}

SurfaceMaterial MaterialEvaluator::EvaluateAndMapNormal(SurfaceHit* hit,
                                                        const TextureFootprint& footprint) const {
  const int packed = hit->material >= 0 && hit->geom >= 0 ? packed_of_[hit->material] : -1;
  if (packed < 0) {
    if (has_normal_maps_) ApplyNormalMap(hit, footprint);
    return Evaluate(*hit, footprint);
  }
  // one mapping, one footprint and one set of taps for the base colour, normal and
  // metallic-roughness maps (file comment, "packed maps").
  const Material& m = scene_.materials[hit->material];
  const PackedMaps& pm = packed_[packed];
  SurfaceMaterial out = Untextured(*hit, m);
  Eigen::Vector3f major_G, minor_G;
  const bool aniso = max_anisotropy_ > 1 && FootprintAxes(*hit, footprint, &major_G, &minor_G);
  const Mapping2D map = MapAt(*hit, m);
  float c[8];
  FilterPacked(pm, map, aniso, major_G, minor_G, footprint, c);
  if (pm.base)
    out.pbr.base_color = out.pbr.base_color.cwiseProduct(Eigen::Vector3f(c[0], c[1], c[2]));
  if (pm.metallic_roughness) {
    out.pbr.roughness *= c[6];
    out.pbr.metallic *= c[7];
  }
  ApplyOcclusionEmission(maps_[hit->material], map, aniso, major_G, minor_G, footprint, &out);
  if (pm.normal) BendNormal(map, Eigen::Vector3f(c[3], c[4], c[5]), hit);
  return out;
}

}  // namespace penumbra

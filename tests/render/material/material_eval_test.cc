// textures and materials at surface points.

#include "penumbra/render/material/material_eval.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"

namespace penumbra {
namespace {

// a 2 x 2 texture: (0,0) black, (1,0) white, (0,1) red, (1,1) green (sRGB codes).
Texture Quad() {
  Texture t;
  t.name = "quad";
  t.image = std::make_shared<const TextureImage>(
      2, 2, 1, std::vector<uint8_t>{0, 0, 0, 255, 255, 255, 255, 0, 0, 0, 255, 0});
  return t;
}

// a cube texture with one solid colour per face, code 10 (face + 1) in red.
Texture Cube() {
  Texture t;
  t.name = "cube";
  t.kind = Texture::Kind::kCube;
  std::vector<uint8_t> rgb;
  for (int f = 0; f < 6; ++f)
    for (int i = 0; i < 16; ++i) rgb.insert(rgb.end(), {static_cast<uint8_t>(10 * (f + 1)), 0, 0});
  t.image = std::make_shared<const TextureImage>(4, 24, 6, std::move(rgb));
  return t;
}

double Srgb(int code) {
  const double c = code / 255.0;
  return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4);
}

SceneDescription OneGeom(GeomShape shape, Eigen::Vector3d size, Texture tex) {
  SceneDescription s;
  s.bodies.push_back({"world", -1, true});
  s.textures.push_back(tex);
  Material m;
  m.base_color = {1, 1, 1};
  m.texture = 0;
  s.materials.push_back(m);
  Geom g;
  g.shape = shape;
  g.size = size;
  g.material = 0;
  s.geoms.push_back(g);
  return s;
}

SurfaceHit HitAt(Eigen::Vector3f p_G, Eigen::Vector3f n_G) {
  SurfaceHit h;
  h.geom = 0;
  h.material = 0;
  h.p_G = p_G;
  h.n_G = n_G;
  return h;
}

TEST(MaterialEvalTest, Sample2DIsBilinearInLinearSpaceAndWraps) {
  const SceneDescription s = OneGeom(GeomShape::kPlane, {1, 1, 0}, Quad());
  const MaterialEvaluator me(s);
  // texel centres give the decoded texel.
  EXPECT_NEAR(me.Sample2D(0, 0.75f, 0.25f).x(), 1.0, 1e-6);
  EXPECT_NEAR(me.Sample2D(0, 0.25f, 0.75f).x(), 1.0, 1e-6);
  EXPECT_NEAR(me.Sample2D(0, 0.25f, 0.75f).y(), 0.0, 1e-6);
  EXPECT_NEAR(me.Sample2D(0, 0.75f, 0.75f).y(), 1.0, 1e-6);
  // halfway between black and white: mean of the linear values, not of the codes.
  EXPECT_NEAR(me.Sample2D(0, 0.5f, 0.25f).x(), 0.5, 1e-6);
  // wrapping: s = 1.75 is s = 0.75; s = 0 blends the first and last columns.
  EXPECT_EQ(me.Sample2D(0, 1.75f, 0.25f), me.Sample2D(0, 0.75f, 0.25f));
  EXPECT_NEAR(me.Sample2D(0, 0.0f, 0.25f).x(), 0.5, 1e-6);
}

TEST(MaterialEvalTest, PlaneTexrepeatAndTexuniform) {
  SceneDescription s = OneGeom(GeomShape::kPlane, {2, 2, 0}, Quad());
  s.materials[0].texrepeat = {1, 1};
  {
    // not uniform: the image spans the plane once; (+x, +y) quarter = image top right = white.
    const MaterialEvaluator me(s);
    EXPECT_NEAR(me.Evaluate(HitAt({1, 1, 0}, {0, 0, 1})).pbr.base_color.x(), 1.0, 1e-6);
    EXPECT_NEAR(me.Evaluate(HitAt({-1, -1, 0}, {0, 0, 1})).pbr.base_color.x(), 1.0, 1e-6);  // red
    EXPECT_NEAR(me.Evaluate(HitAt({-1, -1, 0}, {0, 0, 1})).pbr.base_color.y(), 0.0, 1e-6);
    EXPECT_NEAR(me.Evaluate(HitAt({-1, 1, 0}, {0, 0, 1})).pbr.base_color.norm(), 0.0,
                1e-6);  // black
  }
  s.materials[0].texuniform = true;
  s.materials[0].texrepeat = {4, 4};  // MuJoCo: texrepeat / 2 images per metre, 0.5 m per image
  {
    // from the plane's corner (-2, 2) (texture_math.h): s = 2 (x + 2), t = 2 (2 - y);
    // (0.375, -0.125): s = 4.75, t = 4.25 -> texel (1, 0) = white; one period (0.5 m) further
    // in x and y the same.
    const MaterialEvaluator me(s);
    const Eigen::Vector3f a = me.Evaluate(HitAt({0.375f, -0.125f, 0}, {0, 0, 1})).pbr.base_color;
    const Eigen::Vector3f b = me.Evaluate(HitAt({0.875f, 0.375f, 0}, {0, 0, 1})).pbr.base_color;
    EXPECT_NEAR((a - b).norm(), 0.0, 1e-6);
    EXPECT_NEAR(a.x(), 1.0, 1e-6);
    EXPECT_NEAR(a.z(), 1.0, 1e-6);
    // (0.125, -0.125): s = 4.25, t = 4.25 -> texel (0, 0) = black; (0.125, -0.375): s = 4.25,
    // t = 4.75 -> texel (0, 1) = red.
    EXPECT_NEAR(me.Evaluate(HitAt({0.125f, -0.125f, 0}, {0, 0, 1})).pbr.base_color.norm(), 0.0,
                1e-6);
    const Eigen::Vector3f red = me.Evaluate(HitAt({0.125f, -0.375f, 0}, {0, 0, 1})).pbr.base_color;
    EXPECT_NEAR(red.x(), 1.0, 1e-6);
    EXPECT_NEAR(red.y(), 0.0, 1e-6);
  }
  s.geoms[0].size = {0, 0, 0};  // an infinite plane: MuJoCo's half-image offset instead
  {
    // s = 2 x - 0.5, t = -2 y - 0.5; (0.625, -0.375): s = 0.75, t = 0.25 -> white;
    // (0.375, -0.375): s = t = 0.25 -> black; (0.375, -0.125): s = 0.25, t = 0.75 -> red.
    const MaterialEvaluator me(s);
    const Eigen::Vector3f a = me.Evaluate(HitAt({0.625f, -0.375f, 0}, {0, 0, 1})).pbr.base_color;
    EXPECT_NEAR(a.x(), 1.0, 1e-6);
    EXPECT_NEAR(a.z(), 1.0, 1e-6);
    EXPECT_NEAR(me.Evaluate(HitAt({0.375f, -0.375f, 0}, {0, 0, 1})).pbr.base_color.norm(), 0.0,
                1e-6);
    const Eigen::Vector3f red = me.Evaluate(HitAt({0.375f, -0.125f, 0}, {0, 0, 1})).pbr.base_color;
    EXPECT_NEAR(red.x(), 1.0, 1e-6);
    EXPECT_NEAR(red.y(), 0.0, 1e-6);
  }
}

TEST(MaterialEvalTest, CubeTextureShowsOneFacePerBoxFace) {
  const SceneDescription s = OneGeom(GeomShape::kBox, {0.5, 1, 2}, Cube());
  const MaterialEvaluator me(s);
  const struct {
    Eigen::Vector3f p, n;
    int face;
  } cases[] = {{{0.5f, 0.3f, -1}, {1, 0, 0}, 0}, {{-0.5f, 0.9f, 1.5f}, {-1, 0, 0}, 1},
               {{0.2f, 1, 0.1f}, {0, 1, 0}, 2},  {{0.4f, -1, -1.9f}, {0, -1, 0}, 3},
               {{-0.4f, 0.8f, 2}, {0, 0, 1}, 4}, {{0.1f, 0.1f, -2}, {0, 0, -1}, 5}};
  for (const auto& c : cases)
    EXPECT_NEAR(me.Evaluate(HitAt(c.p, c.n)).pbr.base_color.x(), Srgb(10 * (c.face + 1)), 1e-6)
        << c.face;
}

TEST(MaterialEvalTest, MeshTexcoordsAreUsed) {
  SceneDescription s = OneGeom(GeomShape::kMesh, {0, 0, 0}, Quad());
  s.meshes.push_back(TriangleMesh{});
  s.geoms[0].mesh = 0;
  const MaterialEvaluator me(s);
  SurfaceHit h = HitAt({0, 0, 0}, {0, 0, 1});
  h.has_uv = true;
  h.uv = {0.75f, 0.75f};  // texel (1, 1): green
  const Eigen::Vector3f c = me.Evaluate(h).pbr.base_color;
  EXPECT_NEAR(c.y(), 1.0, 1e-6);
  EXPECT_NEAR(c.x(), 0.0, 1e-6);
}

// one mesh geom with a 64 x 64 texture of vertical stripes 8 texels wide (black at texels
// 0-7, white at 8-15, ...), for the anisotropic lookups below.
SceneDescription StripedMesh() {
  std::vector<uint8_t> rgb;
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      const uint8_t c = (x / 8) % 2 ? 255 : 0;
      rgb.insert(rgb.end(), {c, c, c});
    }
  Texture stripes;
  stripes.name = "stripes";
  stripes.image = std::make_shared<const TextureImage>(64, 64, 1, std::move(rgb));
  SceneDescription s = OneGeom(GeomShape::kMesh, {0, 0, 0}, stripes);
  s.meshes.push_back(TriangleMesh{});
  s.geoms[0].mesh = 0;
  return s;
}

// anisotropic filtering on mesh texcoords: stripes 8 texels wide across s (64 x 64 texels, one
// texcoord unit per metre) seen at grazing incidence (|cos| 0.1, a footprint 2 x 20 texels).
// with the footprint's long axis along the stripes (t) the taps stay on the white stripe; across
// them (s), or with the isotropic lookup, the stripes average to grey.
TEST(MaterialEvalTest, AnisotropicLookupFollowsTheTexcoordGradient) {
  const SceneDescription s = StripedMesh();
  SurfaceHit h = HitAt({0, 0, 0}, {0, 0, 1});
  h.has_uv = true;
  h.uv = {12.0f / 64, 0.5f};  // the middle of the white stripe of texels 8-15
  h.uv_per_m = 1;
  h.duv_dp_G << 1, 0, 0, 0, 1, 0;
  TextureFootprint f;
  f.width_m = 2.0f / 64;
  f.cos_incidence = 0.1f;
  const float sin = std::sqrt(1 - 0.1f * 0.1f);
  auto grey = [&](const MaterialEvaluator& me, const Eigen::Vector3f& d_G) {
    h.d_G = d_G;
    return me.Evaluate(h, f).pbr.base_color.x();
  };
  const MaterialEvaluator iso(s, 1), aniso(s, 16);
  const Eigen::Vector3f along_t(0, sin, -0.1f), along_s(sin, 0, -0.1f);
  EXPECT_GT(grey(aniso, along_t), 0.9f);
  EXPECT_NEAR(grey(aniso, along_s), 0.5f, 0.15f);
  EXPECT_NEAR(grey(iso, along_t), 0.5f, 0.15f);
}

// the tap rule of the anisotropic lookup (material_eval.h, "anisotropic filtering"): N = the
// axis ratio rounded (below 1.5: one trilinear tap at the major axis' level), several taps
// bilinear in the one level nearest to log2(max(L_min, L_maj / N)).
TEST(MaterialEvalTest, AnisotropicTapsRoundTheRatioAndShareOneLevel) {
  const SceneDescription sc = StripedMesh();
  SurfaceHit h = HitAt({0, 0, 0}, {0, 0, 1});
  h.has_uv = true;
  const float s = 9.0f / 64, t = 0.5f;  // near the black-white edge at texel 8
  h.uv = {s, t};
  h.uv_per_m = 1;
  h.duv_dp_G << 1, 0, 0, 0, 1, 0;
  TextureFootprint f;
  f.width_m = 2.6f / 64;  // minor axis 2.6 texels
  const MaterialEvaluator me(sc, 16);
  auto evaluate = [&](float cos) {
    f.cos_incidence = cos;
    h.d_G = Eigen::Vector3f(std::sqrt(1 - cos * cos), 0, -cos);  // major axis along s
    return me.Evaluate(h, f).pbr.base_color.x();
  };
  // the mean of n taps along s over a major axis of `major_s` (texture units), each at `lod`.
  auto taps = [&](int n, float major_s, float lod) {
    float sum = 0;
    for (int k = 0; k < n; ++k)
      sum += me.Sample2D(0, s + ((k + 0.5f) / n - 0.5f) * major_s, t, lod).x();
    return sum / n;
  };
  // ratio 4: 4 taps at lambda = log2(2.6) = 1.38 -> level 1 (not a trilinear mix of 1 and 2).
  const float major4 = f.width_m / 0.25f;
  EXPECT_NEAR(evaluate(0.25f), taps(4, major4, 1.0f), 1e-5f);
  EXPECT_GT(std::abs(taps(4, major4, 1.0f) - taps(4, major4, std::log2(2.6f))), 1e-3f);
  // ratio 1.3: one trilinear tap at the major axis' level log2(3.38) (not two taps).
  const float cos13 = 1 / 1.3f, major13 = f.width_m / cos13;
  EXPECT_NEAR(evaluate(cos13), taps(1, major13, std::log2(2.6f * 1.3f)), 1e-5f);
  EXPECT_GT(std::abs(taps(1, major13, std::log2(2.6f * 1.3f)) - taps(2, major13, std::log2(2.6f))),
            1e-3f);
}

// a w x h texture of pseudo-random sRGB codes; a normal map's point mostly along +z (codes
// 160-255 for z, 60-195 for x and y), as real ones do.
std::shared_ptr<const TextureImage> Noise(int w, int h, uint64_t seed, bool normal = false) {
  Rng rng(HashKeys(seed, 1));
  std::vector<uint8_t> rgb(static_cast<size_t>(w) * h * 3);
  for (size_t i = 0; i < rgb.size(); ++i) {
    const int code = static_cast<int>(rng.NextU64() >> 56);
    rgb[i] = static_cast<uint8_t>(
        !normal ? code : (i % 3 == 2 ? 160 + code * 95 / 255 : 60 + code * 135 / 255));
  }
  return std::make_shared<const TextureImage>(w, h, 1, std::move(rgb));
}

TEST(MaterialEvalTest, PackedMapsMatchSeparateLookups) {
  // material 0 ("packed"): base, normal and metallic-roughness maps of one size (packed);
  // material 1 ("loose"): a normal map of another size (filtered map by map). on a box (per-face
  // mapping) and an infinite plane (uniform mapping), EvaluateAndMapNormal equals
  // ApplyNormalMap then Evaluate up to float rounding, for isotropic and anisotropic
  // footprints from head-on to grazing.
  SceneDescription s;
  s.bodies.push_back({"world", -1, true});
  auto add_texture = [&](const std::string& name, std::shared_ptr<const TextureImage> im) {
    Texture t;
    t.name = name;
    t.image = std::move(im);
    s.textures.push_back(t);
    return static_cast<int>(s.textures.size()) - 1;
  };
  for (const char* name : {"packed", "loose"}) {
    Material m;
    m.name = name;
    m.base_color = {0.9f, 0.8f, 0.7f};
    m.roughness = 0.8f;
    m.metallic = 0.5f;
    m.texrepeat = {3, 2};
    const bool packed = std::string(name) == "packed";
    m.texture = add_texture(std::string(name) + "/albedo", Noise(64, 32, packed ? 1 : 4));
    add_texture(std::string(name) + "/normal", Noise(packed ? 64 : 32, 32, packed ? 2 : 5, true));
    add_texture(std::string(name) + "/metallic_roughness", Noise(64, 32, packed ? 3 : 6));
    s.materials.push_back(m);
  }
  Geom box;
  box.shape = GeomShape::kBox;
  box.size = {0.5, 0.3, 0.2};
  Geom plane;
  plane.shape = GeomShape::kPlane;
  plane.size = {0, 0, 1};
  s.geoms = {box, plane};
  for (const int aniso : {1, 16}) {
    MaterialEvaluator eval(s, aniso);
    eval.SetGeomRotations({Eigen::Matrix3f::Identity(), Eigen::Matrix3f::Identity()});
    Rng rng(HashKeys(7, aniso));
    double max_base = 0, max_normal = 0, max_rm = 0;
    for (int i = 0; i < 4000; ++i) {
      SurfaceHit h;
      h.geom = i % 2;
      h.material = (i / 2) % 2;
      const float x = rng.Uniform() - 0.5f, y = 0.6f * rng.Uniform() - 0.3f;
      h.p_G = {x, y, 0.2f};
      h.n_G = {0, 0, 1};
      h.ng_W = h.ns_W = h.n_G;
      h.p_W = h.p_G;
      // from head-on to 89 degrees off the normal.
      const float theta = 1.55f * rng.Uniform(), phi = 6.28f * rng.Uniform();
      h.d_G = Eigen::Vector3f(std::sin(theta) * std::cos(phi), std::sin(theta) * std::sin(phi),
                              -std::cos(theta));
      TextureFootprint f;
      f.width_m = 0.05f * rng.Uniform() * rng.Uniform();
      f.cos_incidence = std::cos(theta);
      SurfaceHit separate = h;
      eval.ApplyNormalMap(&separate, f);
      const SurfaceMaterial a = eval.Evaluate(separate, f);
      SurfaceHit fused = h;
      const SurfaceMaterial b = eval.EvaluateAndMapNormal(&fused, f);
      max_base =
          std::max<double>(max_base, (a.pbr.base_color - b.pbr.base_color).cwiseAbs().maxCoeff());
      max_normal = std::max<double>(max_normal, (separate.ns_W - fused.ns_W).cwiseAbs().maxCoeff());
      max_rm = std::max<double>(max_rm, std::max(std::abs(a.pbr.roughness - b.pbr.roughness),
                                                 std::abs(a.pbr.metallic - b.pbr.metallic)));
      EXPECT_EQ(a.occlusion, b.occlusion);
      ASSERT_LT((separate.ns_W - h.ns_W).norm() + (fused.ns_W - h.ns_W).norm(), 4.0f);
    }
    // the packed channels hold the decoded codes in steps of 1/65535 (<= 7.7e-6 off).
    EXPECT_LT(max_base, 2e-5) << "aniso " << aniso;
    EXPECT_LT(max_normal, 1e-4) << "aniso " << aniso;
    EXPECT_LT(max_rm, 2e-5) << "aniso " << aniso;
  }
}

TEST(MaterialEvalTest, MaterialFieldsAndDefaults) {
  SceneDescription s = OneGeom(GeomShape::kSphere, {1, 0, 0}, Quad());
  s.materials[0].texture = -1;
  s.materials[0].base_color = {0.1f, 0.2f, 0.3f};
  s.materials[0].roughness = 0.25f;
  s.materials[0].metallic = 0.75f;
  s.materials[0].emission = {5, 6, 7};
  const MaterialEvaluator me(s);
  const SurfaceMaterial m = me.Evaluate(HitAt({1, 0, 0}, {1, 0, 0}));
  EXPECT_EQ(m.pbr.base_color, Eigen::Vector3f(0.1f, 0.2f, 0.3f));
  EXPECT_EQ(m.pbr.roughness, 0.25f);
  EXPECT_EQ(m.pbr.metallic, 0.75f);
  EXPECT_EQ(m.emission, Eigen::Vector3f(5, 6, 7));
  SurfaceHit h = HitAt({1, 0, 0}, {1, 0, 0});
  h.material = -1;
  EXPECT_EQ(me.Evaluate(h).pbr.base_color, Material{}.base_color);
}

TEST(MaterialEvalTest, BadTexturesThrow) {
  SceneDescription s = OneGeom(GeomShape::kPlane, {1, 1, 0}, Quad());
  s.materials[0].texture = 3;
  EXPECT_THROW(MaterialEvaluator{s}, Error);
  SceneDescription t = OneGeom(GeomShape::kPlane, {1, 1, 0}, Quad());
  t.textures[0].image = nullptr;
  EXPECT_THROW(MaterialEvaluator{t}, Error);
  // a cube texture whose image is not six square faces.
  SceneDescription c = OneGeom(GeomShape::kBox, {1, 1, 1}, Cube());
  c.textures[0].image =
      std::make_shared<const TextureImage>(4, 20, 1, std::vector<uint8_t>(4 * 20 * 3, 0));
  EXPECT_THROW(MaterialEvaluator{c}, Error);
}

}  // namespace
}  // namespace penumbra

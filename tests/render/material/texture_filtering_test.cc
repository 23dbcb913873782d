// texture filtering by ray cones (render/material/material_eval.h): MuJoCo's standard checker
// ground plane seen 15-60 m away must not alias (moire, bright dots from the edge marks), in both
// tiers and at any thread count, while a near checker keeps its contrast and (anisotropic
// filtering, the default max_anisotropy of RenderSettings) the grid lines running away from the
// camera keep theirs.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "penumbra/scene/texture_image.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using testing::AddGeom;
using testing::AddMaterial;
using testing::CameraLookingAlongX;
using testing::CameraLookingDown;
using testing::EmptyScene;
using testing::IdentitySnapshot;
using testing::MakeView;
using testing::TestSettings;

constexpr double kDeg = M_PI / 180.0;

// MuJoCo's builtin checker as Menagerie's scenes declare it (builtin="checker" mark="edge"
// rgb1="0.2 0.3 0.4" rgb2="0.1 0.2 0.3" markrgb="0.8 0.8 0.8" width="300" height="300"): 2 x 2
// checks, rgb1 top-left and bottom-right, the image border in the mark colour.
constexpr uint8_t kRgb1[3] = {51, 77, 102}, kRgb2[3] = {26, 51, 77}, kMark = 204;
std::shared_ptr<const TextureImage> MenagerieChecker() {
  const int n = 300;
  std::vector<uint8_t> rgb;
  rgb.reserve(n * n * 3);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x) {
      if (x == 0 || y == 0 || x == n - 1 || y == n - 1) {
        rgb.insert(rgb.end(), {kMark, kMark, kMark});
        continue;
      }
      const uint8_t* c = ((x < n / 2) == (y < n / 2)) ? kRgb1 : kRgb2;
      rgb.insert(rgb.end(), {c[0], c[1], c[2]});
    }
  return std::make_shared<const TextureImage>(n, n, 1, std::move(rgb));
}

// the infinite ground plane with that texture (texuniform, texrepeat 5 5: MuJoCo draws 0.4 m per
// image, 0.2 m checks, edge marks on the lines x, y = 0.2 m + k 0.4 m), a sun and a uniform sky.
SceneDescription CheckerFloor() {
  SceneDescription s = EmptyScene();
  s.sky.radiance = {0.3f, 0.3f, 0.3f};
  Texture tex;
  tex.name = "groundplane";
  tex.image = MenagerieChecker();
  s.textures.push_back(tex);
  const int mat = AddMaterial(&s, {1, 1, 1}, 1.0f);
  s.materials[mat].texture = 0;
  s.materials[mat].texuniform = true;
  s.materials[mat].texrepeat = {5, 5};
  AddGeom(&s, GeomShape::kPlane, {0, 0, 0.05}, Pose::Identity(), 0, mat);
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = Eigen::Vector3d(-0.5, -0.3, -0.8).normalized();
  sun.intensity = 10;
  s.lights.push_back(sun);
  return s;
}

// 320 x 240, fovy 20 deg, 1.2 m above the floor over the edge-mark line y = 0.2 m, looking along
// it pitched 2 deg down: the floor 15-60 m away fills about 40 rows below the horizon.
CameraView FarView() {
  Pose X_WO = CameraLookingAlongX(Eigen::Vector3d(0, 0.2, 1.2));
  X_WO.linear() =
      Eigen::AngleAxisd(2 * kDeg, Eigen::Vector3d::UnitY()).toRotationMatrix() * X_WO.linear();
  CameraView view = MakeView(X_WO, 320, 240, 20, true, false, false);
  view.outputs[ImageKind::kRange] = true;
  return view;
}

double Luminance(const float* c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// the standard deviation of luminance minus its 9 x 9 box mean over the pixels with range in
// [lo, hi] m (whole box inside the image), relative to the mean luminance there.
double RelativeResidualStd(const RenderedFrame& f, double lo, double hi, int* count) {
  const int w = f.radiance.width, h = f.radiance.height, r = 4;
  std::vector<double> residual;
  double sum_l = 0;
  for (int v = r; v < h - r; ++v)
    for (int u = r; u < w - r; ++u) {
      const float range = *f.range_m.at(u, v);
      if (!(range >= lo && range <= hi)) continue;
      double box = 0;
      for (int dv = -r; dv <= r; ++dv)
        for (int du = -r; du <= r; ++du) box += Luminance(f.radiance.at(u + du, v + dv));
      const double l = Luminance(f.radiance.at(u, v));
      residual.push_back(l - box / ((2 * r + 1) * (2 * r + 1)));
      sum_l += l;
    }
  *count = static_cast<int>(residual.size());
  if (residual.empty()) return 0;
  double mean = 0, var = 0;
  for (double x : residual) mean += x;
  mean /= residual.size();
  for (double x : residual) var += (x - mean) * (x - mean);
  return std::sqrt(var / residual.size()) / (sum_l / residual.size());
}

RenderedFrame RenderWith(const SceneDescription& s, RenderSettings settings, const CameraView& v) {
  auto r = MakeRenderer(s, settings);
  RenderedFrame f;
  r->Render(IdentitySnapshot(s), v, &f);
  return f;
}

RenderSettings PathSettings(int threads) {
  RenderSettings p = TestSettings(threads);
  p.tier = RenderSettings::Tier::kPathtraced;
  p.samples_per_pixel = 4;
  p.max_bounces = 1;
  p.denoise = false;
  return p;
}

// point sampling gives a relative residual of 1.15 (realtime) and 0.41 (pathtraced, 4 jittered
// samples per pixel) on the far floor; filtered by the pixel's cone 6e-6 and 0.046 (the latter
// Monte Carlo noise).
TEST(TextureFilteringTest, FarCheckerFloorDoesNotAlias) {
  const SceneDescription s = CheckerFloor();
  const CameraView view = FarView();
  for (const RenderSettings& settings : {TestSettings(1), PathSettings(1)}) {
    const RenderedFrame f = RenderWith(s, settings, view);
    int n = 0;
    const double far = RelativeResidualStd(f, 15, 60, &n);
    EXPECT_GT(n, 5000);
    EXPECT_LT(far, 0.1) << "tier " << static_cast<int>(settings.tier);
  }
}

// the filtered far floor shows the texture's mean albedo (texels averaged in linear light, the
// edge marks included): its mean luminance there is within 3 % of the same floor without the
// texture and with that mean as its colour (averaging sRGB codes would be ~25 % darker).
TEST(TextureFilteringTest, FarFloorKeepsTheTextureMean) {
  const SceneDescription s = CheckerFloor();
  SceneDescription plain = s;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  const std::vector<uint8_t>& px = s.textures[0].image->rgb_srgb();
  const float* decode = SrgbDecodeTable();
  for (size_t i = 0; i < px.size(); i += 3)
    mean += Eigen::Vector3d(decode[px[i]], decode[px[i + 1]], decode[px[i + 2]]);
  mean /= static_cast<double>(px.size() / 3);
  plain.materials[0].texture = -1;
  plain.materials[0].base_color = mean.cast<float>();
  auto far_mean = [](const RenderedFrame& f) {
    double sum = 0;
    int n = 0;
    for (int v = 0; v < f.radiance.height; ++v)
      for (int u = 0; u < f.radiance.width; ++u) {
        const float range = *f.range_m.at(u, v);
        if (range >= 15 && range <= 60) sum += Luminance(f.radiance.at(u, v)), ++n;
      }
    EXPECT_GT(n, 5000);
    return sum / std::max(n, 1);
  };
  const double textured = far_mean(RenderWith(s, TestSettings(1), FarView()));
  const double untextured = far_mean(RenderWith(plain, TestSettings(1), FarView()));
  EXPECT_NEAR(textured / untextured, 1.0, 0.03);
}

// a near checker keeps its contrast: seen from 1 m above (a pixel covers ~6 mm, a check 0.2 m)
// the bright and dark checks keep the texture's luminance ratio.
TEST(TextureFilteringTest, NearCheckerStaysSharp) {
  const SceneDescription s = CheckerFloor();
  const CameraView view = MakeView(CameraLookingDown(Eigen::Vector3d(0.013, 0.027, 1)), 160, 120,
                                   40, true, false, false);
  for (const RenderSettings& settings : {TestSettings(1), PathSettings(1)}) {
    const RenderedFrame f = RenderWith(s, settings, view);
    std::vector<double> l;
    for (int v = 0; v < f.radiance.height; ++v)
      for (int u = 0; u < f.radiance.width; ++u) l.push_back(Luminance(f.radiance.at(u, v)));
    std::sort(l.begin(), l.end());
    const double lo = l[l.size() / 10], hi = l[l.size() * 6 / 10];
    const float* decode = SrgbDecodeTable();
    auto y = [&](const uint8_t* c) {
      return 0.2126 * decode[c[0]] + 0.7152 * decode[c[1]] + 0.0722 * decode[c[2]];
    };
    // 10th percentile: a dark check; 60th: a bright one (the marks cover ~1 % of the floor).
    EXPECT_NEAR(hi / lo, y(kRgb1) / y(kRgb2), 0.05 * y(kRgb1) / y(kRgb2))
        << "tier " << static_cast<int>(settings.tier);
  }
}

// the contrast of the checker's edge-mark line y = 0.2 m (it runs along the view direction under
// the camera, so it projects to the middle column) on the floor 10-15 m away: per image row
// there, the brightest of the 5 columns around the middle over the median of the 13 around it
// (the next lines, 0.4 m to either side, are >= 18 columns away), minus 1, averaged over the
// rows.
double RunAwayLineContrast(const RenderedFrame& f, int* rows) {
  const int cu = f.radiance.width / 2;
  double sum = 0;
  *rows = 0;
  for (int v = 0; v < f.radiance.height; ++v) {
    const float range = *f.range_m.at(cu, v);
    if (!(range >= 10 && range <= 15)) continue;
    std::vector<double> l;
    double peak = 0;
    for (int du = -6; du <= 6; ++du) {
      l.push_back(Luminance(f.radiance.at(cu + du, v)));
      if (std::abs(du) <= 2) peak = std::max(peak, l.back());
    }
    std::nth_element(l.begin(), l.begin() + 6, l.end());
    sum += peak / l[6] - 1;
    ++*rows;
  }
  return *rows > 0 ? sum / *rows : 0;
}

// anisotropic filtering keeps the grid lines that run away from the camera, which the isotropic
// lookup (its level follows the footprint's long axis) blurs into the floor's mean, and the far
// floor still does not alias, in both tiers.
TEST(TextureFilteringTest, AnisotropicFilteringKeepsRunAwayLines) {
  const SceneDescription s = CheckerFloor();
  const CameraView view = FarView();
  for (const RenderSettings& base : {TestSettings(1), PathSettings(1)}) {
    RenderSettings iso = base, aniso = base;
    iso.max_anisotropy = 1;
    aniso.max_anisotropy = 16;
    const RenderedFrame fi = RenderWith(s, iso, view), fa = RenderWith(s, aniso, view);
    int rows = 0;
    const double ci = RunAwayLineContrast(fi, &rows);
    const double ca = RunAwayLineContrast(fa, &rows);
    EXPECT_GT(rows, 10);
    EXPECT_GT(ca, 0.2) << "tier " << static_cast<int>(base.tier) << ", isotropic " << ci;
    EXPECT_GT(ca, 3 * ci) << "tier " << static_cast<int>(base.tier);
    int n = 0;
    EXPECT_LT(RelativeResidualStd(fa, 15, 60, &n), 0.1) << "tier " << static_cast<int>(base.tier);
  }
}

TEST(TextureFilteringTest, ThreadCountDoesNotChangeFilteredImages) {
  const SceneDescription s = CheckerFloor();
  const CameraView view = FarView();
  for (bool path : {false, true}) {
    const RenderedFrame a = RenderWith(s, path ? PathSettings(1) : TestSettings(1), view);
    const RenderedFrame b = RenderWith(s, path ? PathSettings(3) : TestSettings(3), view);
    ASSERT_EQ(a.radiance.data.size(), b.radiance.data.size());
    EXPECT_EQ(0, std::memcmp(a.radiance.data.data(), b.radiance.data.data(),
                             a.radiance.data.size() * sizeof(float)))
        << (path ? "pathtraced" : "realtime");
  }
}

}  // namespace
}  // namespace penumbra

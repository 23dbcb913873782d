// Menagerie's standard floor (a 300 x 300 builtin checker with edge marks, texuniform, texrepeat
// 5 5) compiled by MuJoCo and drawn by Penumbra as MuJoCo's OpenGL renderer draws it: 0.2 m
// checks, the colour boundaries on the multiples of 0.2 m, the check at (0.1, 0.1) m dark
// (rgb2) and the one at (0.3, 0.1) m light (rgb1), and the light / dark contrast of the texture
// (lit diffusely: the texture's own ratio; Menagerie's 0.2 reflectance adds the mirrored sky).
// MuJoCo 4.0.0's own render of this floor (EGL, camera 2 m above looking down) has its colour
// boundaries at x = -1.405 ... 1.395 m in steps of 0.2 m, (0.1, 0.1) dark, (0.3, 0.1) light.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <string>
#include <vector>

#include "common/temp_dir.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/texture_image.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

// Menagerie's floor; `material_extra` is appended to the material's attributes.
std::string FloorXml(const std::string& material_extra = "") {
  return R"(<mujoco model="menagerie floor">
  <asset>
    <texture type="2d" name="groundplane" builtin="checker" mark="edge" rgb1="0.2 0.3 0.4"
             rgb2="0.1 0.2 0.3" markrgb="0.8 0.8 0.8" width="300" height="300"/>
    <material name="groundplane" texture="groundplane" texuniform="true" texrepeat="5 5"
              reflectance="0.2" )" +
         material_extra + R"(/>
  </asset>
  <worldbody>
    <geom name="floor" size="0 0 0.05" type="plane" material="groundplane"/>
  </worldbody>
</mujoco>
)";
}

constexpr int kWidth = 320, kHeight = 240;
constexpr double kHeightM = 2.0, kFovyDeg = 60;

double Luminance(const float* c) { return 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2]; }

// a camera kHeightM above the origin looking straight down, image right = world +x, image down =
// world -y (pixel centres at integer coordinates, scene/scene_description.h).
CameraView DownView() {
  CameraView v;
  v.X_WO = Pose::Identity();
  v.X_WO.linear() << 1, 0, 0, 0, -1, 0, 0, 0, -1;
  v.X_WO.translation() = Eigen::Vector3d(0, 0, kHeightM);
  v.intrinsics = CameraIntrinsics::FromFovy(kWidth, kHeight, kFovyDeg);
  v.outputs[ImageKind::kRgb] = true;
  v.outputs[ImageKind::kDepth] = false;
  return v;
}

// the checks along the image row at world y = y_m, the checks x in [0.2 k, 0.2 (k + 1)] m for
// k = -6 .. 5 (the image spans |x| < 1.54 m). each check is sampled at three points 0.05 m
// apart, x = 0.2 k + 0.05 / 0.10 / 0.15 m (clear of the boundaries and of the edge marks on them),
// each the mean luminance of the 3 x 3 pixels there.
struct FloorRow {
  std::vector<std::array<double, 3>> checks;  // k = -6 .. 5
  double light = 0, dark = 0;  // mean luminance of the odd (rgb1) and even (rgb2) checks
};

FloorRow MeasureRow(const RenderedFrame& f, const CameraView& view, double y_m) {
  const CameraIntrinsics& k = view.intrinsics;
  const int v = static_cast<int>(std::lround(k.cy - y_m * k.fy / kHeightM));
  auto at = [&](double x) {
    const int u = static_cast<int>(std::lround(k.cx + x * k.fx / kHeightM));
    double sum = 0;
    for (int dv = -1; dv <= 1; ++dv)
      for (int du = -1; du <= 1; ++du) sum += Luminance(f.radiance.at(u + du, v + dv));
    return sum / 9;
  };
  FloorRow row;
  int n_light = 0, n_dark = 0;
  for (int c = -6; c <= 5; ++c) {
    const double x0 = 0.2 * c;
    row.checks.push_back({at(x0 + 0.05), at(x0 + 0.10), at(x0 + 0.15)});
    const bool odd = (c % 2) != 0;
    (odd ? row.light : row.dark) += row.checks.back()[1];
    ++(odd ? n_light : n_dark);
  }
  row.light /= n_light;
  row.dark /= n_dark;
  return row;
}

// the floor of `xml` as a bare model (default sun and daylight sky), seen by DownView.
FloorRow RenderFloor(const std::string& xml) {
  penumbra::testing::TempDir dir;
  WorldConfig world = WorldForBareModel(dir.Write("floor.xml", xml));
  world.cameras.clear();
  SessionOptions options;
  options.add_controllers = false;
  Session session(world, options);
  const CameraView view = DownView();
  RenderedFrame frame;
  session.renderer()->Render(session.sim().Snapshot(), nullptr, view, &frame);
  return MeasureRow(frame, view, 0.1);
}

// the decoded luminance of the texture's light over its dark checks (texels 51,76,102 and
// 25,51,76 of MuJoCo's builtin checker).
double TextureContrast() {
  const float* decode = SrgbDecodeTable();
  const double light = 0.2126 * decode[51] + 0.7152 * decode[76] + 0.0722 * decode[102];
  const double dark = 0.2126 * decode[25] + 0.7152 * decode[51] + 0.0722 * decode[76];
  return light / dark;
}

TEST(MenagerieFloor, ChecksAreTwentyCentimetresAsMujocoDrawsThem) {
  const FloorRow row = RenderFloor(FloorXml());
  for (size_t i = 0; i < row.checks.size(); ++i) {
    const std::array<double, 3>& c = row.checks[i];
    const double x0 = 0.2 * (static_cast<int>(i) - 6);
    SCOPED_TRACE(::testing::Message() << "check at x = " << x0 << " .. " << x0 + 0.2
                                      << " m: " << c[0] << " " << c[1] << " " << c[2]);
    // one colour across the check (0.1 m checks would change colour within it)
    EXPECT_NEAR(c[0] / c[1], 1.0, 0.05);
    EXPECT_NEAR(c[2] / c[1], 1.0, 0.05);
    // and the other colour in the next check: dark (rgb2) for even k, so the check at
    // x = 0.1 m is dark and the one at 0.3 m light, as MuJoCo draws them
    if (i + 1 < row.checks.size()) {
      const double next = row.checks[i + 1][1];
      if ((static_cast<int>(i) - 6) % 2 == 0)
        EXPECT_GT(next / c[1], 1.1);
      else
        EXPECT_GT(c[1] / next, 1.1);
    }
  }
  // with reflectance 0.2 the floor mirrors the daylight sky (MuJoCo's OpenGL mirrors only
  // geoms), which adds the same light to both checks
  std::printf("[ measured ] Menagerie floor: light / dark check radiance %.3f (texture %.3f)\n",
              row.light / row.dark, TextureContrast());
  EXPECT_GT(row.light / row.dark, 1.3);
}

// the texture keeps its contrast: without the mirror and the specular highlight (lit only
// diffusely, as MuJoCo's OpenGL draws a floor with no geoms to reflect) the light and dark checks
// differ by the texture's own ratio. MuJoCo 4.0.0 keeps it too: its output codes 82,122,164 over
// 41,82,122 for texels 51,76,102 over 25,51,76.
TEST(MenagerieFloor, TheCheckerKeepsItsContrast) {
  const FloorRow matte = RenderFloor(
      R"(<mujoco><asset><texture type="2d" name="groundplane" builtin="checker" mark="edge"
         rgb1="0.2 0.3 0.4" rgb2="0.1 0.2 0.3" markrgb="0.8 0.8 0.8" width="300" height="300"/>
         <material name="groundplane" texture="groundplane" texuniform="true" texrepeat="5 5"
         specular="0"/></asset><worldbody><geom name="floor" size="0 0 0.05" type="plane"
         material="groundplane"/></worldbody></mujoco>)");
  ASSERT_GT(matte.dark, 0);
  std::printf("[ measured ] matte floor: light / dark check radiance %.3f (texture %.3f)\n",
              matte.light / matte.dark, TextureContrast());
  EXPECT_NEAR(matte.light / matte.dark, TextureContrast(), 0.05 * TextureContrast());
}

// a 2 x 1.6 m box (half sizes 1, 0.8, 0.05) with a light / dark checker at texrepeat 1.5 1.25,
// per face and texuniform, seen from 2 m above: light or dark at 36 points of its top face as
// MuJoCo 4.0.0 draws it (its own EGL render of this model): the checks counted from the face's
// corner, not its centre (texture_math.h, PlanarMap).
TEST(MenagerieFloor, CheckerOnABoxAsMujocoDrawsIt) {
  const std::vector<double> xs = {-0.8, -0.5, -0.2, 0.1, 0.45, 0.8};
  const std::vector<double> ys = {0.7, 0.45, 0.2, -0.1, -0.35, -0.6};
  for (const auto& [material, expected] :
       {std::pair<std::string, std::string>{"", "LLDDLLLLDDLLLLDDLLDDLLDDDDLLDDLLDDLL"},
        std::pair<std::string, std::string>{R"(texuniform="true")",
                                            "LLDDLLLLDDLLLLDDLLDDLLDDDDLLDDDDLLDD"}}) {
    SCOPED_TRACE(material);
    penumbra::testing::TempDir dir;
    WorldConfig world = WorldForBareModel(dir.Write(
        "box.xml",
        R"(<mujoco><asset><texture type="2d" name="ck" builtin="checker" rgb1="0.9 0.9 0.9"
           rgb2="0.1 0.1 0.1" width="64" height="64"/><material name="ck" texture="ck"
           texrepeat="1.5 1.25" )" +
            material +
            R"(/></asset><worldbody><geom type="box" size="1 0.8 0.05" pos="0 0 0.05"
           material="ck"/></worldbody></mujoco>)"));
    world.cameras.clear();
    SessionOptions options;
    options.add_controllers = false;
    Session session(world, options);
    const CameraView view = DownView();
    RenderedFrame frame;
    session.renderer()->Render(session.sim().Snapshot(), nullptr, view, &frame);
    const CameraIntrinsics& k = view.intrinsics;
    const double depth = kHeightM - 0.1;  // to the box's top face
    std::vector<double> l;
    for (double y : ys)
      for (double x : xs) {
        const int u = static_cast<int>(std::lround(k.cx + x * k.fx / depth));
        const int v = static_cast<int>(std::lround(k.cy - y * k.fy / depth));
        double sum = 0;
        for (int dv = -1; dv <= 1; ++dv)
          for (int du = -1; du <= 1; ++du) sum += Luminance(frame.radiance.at(u + du, v + dv));
        l.push_back(sum / 9);
      }
    const double mid =
        0.5 * (*std::min_element(l.begin(), l.end()) + *std::max_element(l.begin(), l.end()));
    std::string seen;
    for (double x : l) seen += x > mid ? 'L' : 'D';
    EXPECT_EQ(seen, expected);
  }
}

}  // namespace
}  // namespace penumbra

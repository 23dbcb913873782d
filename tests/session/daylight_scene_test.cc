// the bare-model default scene is lit by daylight by the numbers (the sun's
// direct-normal and the sky's diffuse illuminance, render/sky/sky_math.h), so a box's sun shadow on
// a clear day is as dark as measured ratios say; and the model's MJCF skybox is the environment the
// camera and a mirror floor see (as MuJoCo draws it).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/temp_dir.h"
#include "penumbra/render/renderer.h"
#include "penumbra/render/sky/sky_math.h"
#include "penumbra/render/sky/sky_model.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

// a grey floor (MuJoCo reflectance `reflectance`), a tall box, and a red-over-green gradient
// skybox.
std::string DaylightModel(double reflectance) {
  return "<mujoco><asset>"
         "<texture name=\"sky\" type=\"skybox\" builtin=\"gradient\" rgb1=\"0.9 0.1 0.1\" "
         "rgb2=\"0.1 0.8 0.1\" width=\"64\" height=\"384\"/>"
         "<material name=\"floor\" rgba=\"0.5 0.5 0.5 1\" reflectance=\"" +
         std::to_string(reflectance) +
         "\"/></asset><worldbody>"
         "<geom name=\"floor\" type=\"plane\" size=\"20 20 0.1\" material=\"floor\"/>"
         "<geom name=\"box\" type=\"box\" size=\"0.2 0.2 0.5\" pos=\"0 0 0.5\" "
         "rgba=\"0.6 0.6 0.6 1\"/></worldbody></mujoco>\n";
}

SessionOptions WithRendererOnly() {
  SessionOptions options;
  options.add_controllers = false;
  return options;
}

// optical frame at `p` looking along `forward` (unit), image y towards world -z where possible.
Pose LookAlong(const Eigen::Vector3d& p, const Eigen::Vector3d& forward) {
  const Eigen::Vector3d z = forward.normalized();
  Eigen::Vector3d down = -Eigen::Vector3d::UnitZ();
  if (std::abs(z.dot(down)) > 0.99) down = Eigen::Vector3d::UnitY() * -1.0;
  const Eigen::Vector3d x = down.cross(z).normalized();
  const Eigen::Vector3d y = z.cross(x);
  Pose X = Pose::Identity();
  X.linear().col(0) = x;
  X.linear().col(1) = y;
  X.linear().col(2) = z;
  X.translation() = p;
  return X;
}

CameraView ViewFor(const Pose& X_WO, int w, int h, double fovy) {
  CameraView v;
  v.X_WO = X_WO;
  v.intrinsics = CameraIntrinsics::FromFovy(w, h, fovy);
  v.outputs[ImageKind::kRgb] = true;
  v.outputs[ImageKind::kDepth] = false;
  v.outputs[ImageKind::kSegmentation] = true;
  return v;
}

// pixel of world point p_W in view v (no distortion).
Eigen::Vector2d Project(const CameraView& v, const Eigen::Vector3d& p_W) {
  const Eigen::Vector3d p = v.X_WO.inverse() * p_W;
  return {v.intrinsics.fx * p.x() / p.z() + v.intrinsics.cx,
          v.intrinsics.fy * p.y() / p.z() + v.intrinsics.cy};
}

// mean linear radiance of the (2r+1)^2 pixels around pixel c.
Eigen::Vector3d MeanAround(const ImageF& img, const Eigen::Vector2d& c, int r) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int n = 0;
  for (int dv = -r; dv <= r; ++dv)
    for (int du = -r; du <= r; ++du) {
      const int u = static_cast<int>(std::lround(c.x())) + du;
      const int v = static_cast<int>(std::lround(c.y())) + dv;
      if (u < 0 || v < 0 || u >= img.width || v >= img.height) continue;
      const float* px = img.at(u, v);
      sum += Eigen::Vector3d(px[0], px[1], px[2]);
      ++n;
    }
  return n > 0 ? Eigen::Vector3d(sum / n) : sum;
}

double LuminanceOf(const Eigen::Vector3d& c) {
  return 0.2126 * c.x() + 0.7152 * c.y() + 0.0722 * c.z();
}

TEST(DaylightScene, BoxShadowOnAClearDayIsAtLeast60PercentDarker) {
  penumbra::testing::TempDir dir;
  // a MuJoCo mirror floor (reflectance 0.2, as Menagerie scenes have) reflects the background.
  const WorldConfig world = WorldForBareModel(dir.Write("box.xml", DaylightModel(0.2)));
  Session session(world, WithRendererOnly());
  const SceneDescription& scene = session.scene();
  // the default sun carries the direct-normal illuminance of the elevation and turbidity.
  const Light* sun = nullptr;
  for (const Light& l : scene.lights)
    if (l.name == "default_sun") sun = &l;
  ASSERT_NE(sun, nullptr);
  const float elevation = static_cast<float>(world.sky.sun_elevation_deg);
  const float turbidity = static_cast<float>(world.sky.turbidity);
  EXPECT_FLOAT_EQ(sun->intensity, SunDirectNormalIlluminance(elevation, turbidity));
  EXPECT_GT(sun->intensity, 80000.0f);

  const Eigen::Vector3d to_sun = scene.sky.sun_direction_W.normalized();
  // a floor point whose ray to the sun passes through the box's core (in its shadow), and the
  // point mirrored about the box (lit: its ray to the sun leads away from the box).
  const Eigen::Vector3d core(0, 0, 0.9);
  const Eigen::Vector3d shadow = core - to_sun * (core.z() / to_sun.z());
  const Eigen::Vector3d lit(-shadow.x(), -shadow.y(), 0);
  ASSERT_GT(shadow.head<2>().norm(), 0.5);  // outside the box's footprint

  const CameraView view = ViewFor(LookAlong({0, 0, 8}, {0, 0, -1}), 96, 96, 40);
  RenderedFrame frame;
  session.renderer()->Render(session.sim().Snapshot(), nullptr, view, &frame);
  const int floor_id =
      frame.geom_id.at(static_cast<int>(std::lround(Project(view, shadow).x())),
                       static_cast<int>(std::lround(Project(view, shadow).y())))[0];
  ASSERT_EQ(floor_id, frame.geom_id.at(static_cast<int>(std::lround(Project(view, lit).x())),
                                       static_cast<int>(std::lround(Project(view, lit).y())))[0]);
  const double l_shadow = LuminanceOf(MeanAround(frame.radiance, Project(view, shadow), 1));
  const double l_lit = LuminanceOf(MeanAround(frame.radiance, Project(view, lit), 1));
  ASSERT_GT(l_lit, 0);
  const double darker = 1.0 - l_shadow / l_lit;
  RecordProperty("shadow_darker", std::to_string(darker));
  EXPECT_GE(darker, 0.6) << "shadow " << l_shadow << " cd/m^2, lit " << l_lit << " cd/m^2";
}

TEST(DaylightScene, MjcfSkyboxIsTheBackgroundAndTheMirrorFloorsReflection) {
  penumbra::testing::TempDir dir;
  // a perfect MuJoCo mirror floor: it shows only what it reflects.
  const WorldConfig world = WorldForBareModel(dir.Write("mirror.xml", DaylightModel(1.0)));
  Session session(world, WithRendererOnly());
  ASSERT_NE(MjcfSkyboxOf(session.scene()).image, nullptr);
  // looking level along +x from 1 m up: the upper half of the image is background, the lower
  // half the mirror floor, which reflects the sky above the horizon.
  const CameraView view = ViewFor(LookAlong({-6, 3, 1}, {1, 0, 0}), 64, 64, 60);
  RenderedFrame frame;
  session.renderer()->Render(session.sim().Snapshot(), nullptr, view, &frame);
  const Eigen::Vector2d sky_px(32, 4), floor_px(32, 60);
  EXPECT_EQ(frame.geom_id.at(32, 4)[0], -1);
  EXPECT_GE(frame.geom_id.at(32, 60)[0], 0);
  const Eigen::Vector3d background = MeanAround(frame.radiance, sky_px, 1);
  const Eigen::Vector3d reflection = MeanAround(frame.radiance, floor_px, 1);
  // the skybox's upper half is red (rgb1): the background above the horizon and its mirror
  // image in the floor are red, not the daylight sky's blue.
  for (const Eigen::Vector3d& c : {background, reflection}) {
    SCOPED_TRACE(::testing::Message() << c.transpose());
    EXPECT_GT(c.x(), 2.5 * c.y());
    EXPECT_GT(c.x(), 2.5 * c.z());
  }
}

}  // namespace
}  // namespace penumbra

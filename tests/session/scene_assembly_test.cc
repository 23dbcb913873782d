// the auto-framed camera of a bare model.

#include "penumbra/session/scene_assembly.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "common/temp_dir.h"
#include "penumbra/scene/camera_pose.h"

namespace penumbra {
namespace {

// a bare model: a floor plane and one upright box "robot" (half sizes 0.15, 0.1, 0.4 m) on it.
struct BareBox {
  SceneDescription scene;
  WorldSnapshot initial;
  Eigen::Vector3d half{0.15, 0.1, 0.4};
  Eigen::Vector3d center_W{0.2, -0.1, 0.4};
};

BareBox MakeBareBox() {
  BareBox b;
  SceneDescription& s = b.scene;
  s.bodies = {{"world", -1, true}, {"box/torso", 0, false}};
  s.materials.resize(1);
  s.materials[0].name = "grey";
  Geom floor;
  floor.name = "box/floor";
  floor.body = 0;
  floor.shape = GeomShape::kPlane;
  floor.size = {0, 0, 1};
  floor.material = 0;
  Geom box;
  box.name = "box/torso";
  box.id = 1;
  box.body = 1;
  box.shape = GeomShape::kBox;
  box.size = b.half;
  box.material = 0;
  s.geoms = {floor, box};
  s.center_W = b.center_W;
  s.extent_m = 1;
  Pose X_WT = Pose::Identity();
  X_WT.translation() = b.center_W;
  b.initial.X_WB = {Pose::Identity(), X_WT};
  return b;
}

// pixel of a world point in the camera (pinhole, no distortion); false if behind it.
bool Project(const CameraSpec& cam, const Pose& X_WO, const Eigen::Vector3d& p_W,
             Eigen::Vector2d* px) {
  const Eigen::Vector3d q = X_WO.inverse() * p_W;
  if (!(q.z() > 0)) return false;
  const CameraIntrinsics& k = cam.intrinsics;
  *px = {k.fx * q.x() / q.z() + k.cx, k.fy * q.y() / q.z() + k.cy};
  return true;
}

class AutoFrameTest : public ::testing::Test {
 protected:
  void SetUp() override {
    bare_ = MakeBareBox();
    world_ = WorldForBareModel(dir_.Write("box.xml", "<mujoco/>"));
    scene_ = AssembleScene(bare_.scene, world_, bare_.initial);
    ASSERT_EQ(scene_.cameras.size(), 1u);
    camera_ = scene_.cameras[0];
    ASSERT_EQ(camera_.name, "default");
    X_WO_ = CameraPoseInWorld(camera_, bare_.initial);
    // the box's silhouette: the bounding rectangle of its 8 projected corners.
    lo_ = Eigen::Vector2d::Constant(1e9), hi_ = Eigen::Vector2d::Constant(-1e9);
    for (int c = 0; c < 8; ++c) {
      const Eigen::Vector3d h = bare_.half;
      const Eigen::Vector3d p =
          bare_.center_W +
          Eigen::Vector3d(c & 1 ? h.x() : -h.x(), c & 2 ? h.y() : -h.y(), c & 4 ? h.z() : -h.z());
      Eigen::Vector2d px;
      ASSERT_TRUE(Project(camera_, X_WO_, p, &px));
      lo_ = lo_.cwiseMin(px), hi_ = hi_.cwiseMax(px);
    }
  }

  penumbra::testing::TempDir dir_;
  BareBox bare_;
  WorldConfig world_;
  SceneDescription scene_;
  CameraSpec camera_;
  Pose X_WO_;
  Eigen::Vector2d lo_, hi_;
};

// before: the camera framed a loose sphere around sphere-bounded geoms at 1.6x its radius, and
// the box spanned about a quarter of the image.
TEST_F(AutoFrameTest, TheModelSpansTheStatedShareOfTheImage) {
  const double w = camera_.intrinsics.width, h = camera_.intrinsics.height;
  const double fill = std::max((hi_.x() - lo_.x()) / w, (hi_.y() - lo_.y()) / h);
  EXPECT_NEAR(fill, kAutoFrameFill, 0.005) << lo_.transpose() << " " << hi_.transpose();
  // centred, inside the image.
  EXPECT_NEAR(0.5 * (lo_.x() + hi_.x()), 0.5 * w, 0.005 * w);
  EXPECT_NEAR(0.5 * (lo_.y() + hi_.y()), 0.5 * h, 0.005 * h);
  EXPECT_GE(lo_.minCoeff(), 0);
  EXPECT_LE(hi_.x(), w);
  EXPECT_LE(hi_.y(), h);
}

// before: the bare model's sun stood at the camera's azimuth (30 vs 31 deg), so the shadow lay
// behind the model, hidden.
TEST_F(AutoFrameTest, TheShadowFallsInViewBesideTheModel) {
  ASSERT_FALSE(scene_.lights.empty());
  const Eigen::Vector3d to_sun = scene_.sky.sun_direction_W.normalized();
  ASSERT_GT(to_sun.z(), 0.1);
  // where the shadow of the middle of the box's top face falls on the floor (z = 0).
  const Eigen::Vector3d top = bare_.center_W + Eigen::Vector3d(0, 0, bare_.half.z());
  const Eigen::Vector3d shadow = top - (top.z() / to_sun.z()) * to_sun;
  Eigen::Vector2d px;
  ASSERT_TRUE(Project(camera_, X_WO_, shadow, &px));
  const double w = camera_.intrinsics.width, h = camera_.intrinsics.height;
  EXPECT_GT(px.x(), 0);
  EXPECT_LT(px.x(), w);
  EXPECT_GT(px.y(), 0);
  EXPECT_LT(px.y(), h);
  // outside the model's silhouette rectangle.
  const bool inside = px.x() > lo_.x() && px.x() < hi_.x() && px.y() > lo_.y() && px.y() < hi_.y();
  EXPECT_FALSE(inside) << "shadow at " << px.transpose() << ", model " << lo_.transpose() << " .. "
                       << hi_.transpose();
}

}  // namespace
}  // namespace penumbra

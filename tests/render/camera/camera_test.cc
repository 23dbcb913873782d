// pinhole rays in the OpenCV convention.

#include "penumbra/render/camera/camera.h"

#include <gtest/gtest.h>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

TEST(CameraTest, RaysFollowTheIntrinsics) {
  CameraIntrinsics k;
  k.width = 640;
  k.height = 480;
  k.fx = 500;
  k.fy = 400;
  k.cx = 320.5;
  k.cy = 240.25;
  const Pose X_WO = PoseFromXyzRpyDeg({1, 2, 3}, {10, 20, 30});
  const Camera cam(X_WO, k);
  for (auto [u, v] :
       {std::pair{0.0f, 0.0f}, {639.0f, 479.0f}, {320.5f, 240.25f}, {100.0f, 400.0f}}) {
    const Ray r = cam.GenerateRay(u, v);
    EXPECT_NEAR((r.o.cast<double>() - X_WO.translation()).norm(), 0, 1e-6);
    const Eigen::Vector3d d_O = X_WO.linear().transpose() * r.d.cast<double>();
    EXPECT_NEAR(d_O.x(), (u - k.cx) / k.fx, 1e-6);
    EXPECT_NEAR(d_O.y(), (v - k.cy) / k.fy, 1e-6);
    EXPECT_NEAR(d_O.z(), 1.0, 1e-6);
    // the point at depth 2.5 along the ray projects back to (u, v) with z = 2.5.
    Eigen::Vector2d uv;
    double z;
    ASSERT_TRUE(cam.Project(r.o.cast<double>() + 2.5 * r.d.cast<double>(), &uv, &z));
    EXPECT_NEAR(uv.x(), u, 1e-3);
    EXPECT_NEAR(uv.y(), v, 1e-3);
    EXPECT_NEAR(z, 2.5, 1e-5);
  }
  Eigen::Vector2d uv;
  double z;
  EXPECT_FALSE(cam.Project(X_WO * Eigen::Vector3d(0, 0, -1), &uv, &z));
}

TEST(CameraTest, BadIntrinsicsThrow) {
  CameraIntrinsics k = CameraIntrinsics::FromFovy(64, 48, 60);
  k.fx = 0;
  EXPECT_THROW(Camera(Pose::Identity(), k), ConfigError);
  k = CameraIntrinsics::FromFovy(0, 48, 60);
  EXPECT_THROW(Camera(Pose::Identity(), k), ConfigError);
}

}  // namespace
}  // namespace penumbra

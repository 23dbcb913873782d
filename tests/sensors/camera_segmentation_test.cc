// ground-truth images are exact per pixel: every pixel's geom id, body (instance) id, semantic
// class, range and normal equal those of the first surface that the pixel-centre ray hits,
// computed analytically here for spheres and boxes, through a distorted lens.

#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "camera_sensor_test_util.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/renderer.h"

namespace penumbra {
namespace {

using testing::AddGeom;
using testing::AddMaterial;

struct Hit {
  double t = std::numeric_limits<double>::infinity();
  int geom = -1;
  Eigen::Vector3d n_W{0, 0, 0};
  double margin = std::numeric_limits<double>::infinity();  // distance to a silhouette, m
};

void SphereHit(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& c,
               double r, int geom, Hit* h) {
  const Eigen::Vector3d dn = d.normalized();
  const Eigen::Vector3d oc = o - c;
  const double b = oc.dot(dn);
  const double dist = (oc - b * dn).norm();  // distance from the centre to the ray line
  h->margin = std::min(h->margin, std::abs(dist - r));
  const double disc = b * b - (oc.squaredNorm() - r * r);
  if (disc < 0) return;
  const double s = -b - std::sqrt(disc);
  const double t = s / d.norm();
  if (s > 0 && t < h->t) {
    h->t = t;
    h->geom = geom;
    h->n_W = (o + s * dn - c) / r;
  }
}

void BoxHit(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& c,
            const Eigen::Vector3d& half, int geom, Hit* h) {
  double t0 = -1e30, t1 = 1e30;
  int axis = 0;
  for (int i = 0; i < 3; ++i) {
    double a = (c[i] - half[i] - o[i]) / d[i], b = (c[i] + half[i] - o[i]) / d[i];
    if (a > b) std::swap(a, b);
    if (a > t0) t0 = a, axis = i;
    t1 = std::min(t1, b);
  }
  h->margin = std::min(h->margin, std::abs(t1 - t0) * d.norm());
  if (t0 < t1 && t0 > 0 && t0 < h->t) {
    h->t = t0;
    h->geom = geom;
    h->n_W = Eigen::Vector3d::Zero();
    h->n_W[axis] = d[axis] > 0 ? -1 : 1;
  }
}

TEST(CameraSegmentationTest, IdsClassesRangeAndNormalsAreExactPerPixel) {
  SceneDescription s = testing::BlackScene();
  const int m = AddMaterial(&s, Eigen::Vector3f(0.5f, 0.5f, 0.5f));
  s.bodies.push_back({"ball", 0, false});
  s.bodies.push_back({"crate", 0, false});
  const int g0 = AddGeom(&s, GeomShape::kSphere, Eigen::Vector3d(0.5, 0, 0),
                         Eigen::Vector3d(4, 0.3, 0.2), m, 1);
  const int g1 = AddGeom(&s, GeomShape::kBox, Eigen::Vector3d(0.3, 0.4, 0.5),
                         Eigen::Vector3d(3, -0.6, -0.1), m, 2);
  const int g2 = AddGeom(&s, GeomShape::kSphere, Eigen::Vector3d(0.8, 0, 0),
                         Eigen::Vector3d(6, -0.2, 0.6), m, 0);
  s.geoms[g0].semantic_class = 3;
  s.geoms[g1].semantic_class = 5;
  s.geoms[g2].semantic_class = 7;
  RenderSettings rs;
  rs.tier = RenderSettings::Tier::kRealtime;
  auto renderer = MakeRenderer(s, rs);

  CameraView view;
  view.X_WO = testing::LookingAlongX(Eigen::Vector3d(0, 0, 0.05));
  view.intrinsics = CameraIntrinsics::FromFovy(160, 120, 50);
  view.intrinsics.k1 = -0.2;
  view.intrinsics.k2 = 0.05;
  view.intrinsics.p1 = 1e-3;
  view.outputs[ImageKind::kRgb] = false;
  view.outputs[ImageKind::kDepth] = view.outputs[ImageKind::kSegmentation] =
      view.outputs[ImageKind::kRange] = view.outputs[ImageKind::kNormals] = true;
  view.outputs[ImageKind::kInstanceSegmentation] = view.outputs[ImageKind::kSemanticSegmentation] =
      true;
  RenderedFrame f;
  renderer->Render(testing::Snapshot(s, 0), view, &f);

  const Camera cam(view.X_WO, view.intrinsics);
  const Eigen::Matrix3d R_OW = view.X_WO.linear().transpose();
  int checked = 0, skipped = 0, background = 0, hits[3] = {0, 0, 0};
  for (int v = 0; v < 120; ++v) {
    for (int u = 0; u < 160; ++u) {
      const Ray r = cam.GenerateRay(u, v);
      const Eigen::Vector3d o = r.o.cast<double>(), d = r.d.cast<double>();
      Hit h;
      SphereHit(o, d, s.geoms[g0].X_BG.translation(), 0.5, g0, &h);
      BoxHit(o, d, s.geoms[g1].X_BG.translation(), s.geoms[g1].size, g1, &h);
      SphereHit(o, d, s.geoms[g2].X_BG.translation(), 0.8, g2, &h);
      if (h.margin < 1e-5) {  // the centre ray grazes a silhouette within float rounding
        ++skipped;
        continue;
      }
      ++checked;
      const int want_id = h.geom < 0 ? -1 : s.geoms[h.geom].id;
      ASSERT_EQ(*f.geom_id.at(u, v), want_id) << u << "," << v;
      ASSERT_EQ(*f.body_id.at(u, v), h.geom < 0 ? -1 : s.geoms[h.geom].body) << u << "," << v;
      ASSERT_EQ(*f.semantic_class.at(u, v), h.geom < 0 ? 0 : s.geoms[h.geom].semantic_class);
      if (h.geom < 0) {
        ++background;
        EXPECT_EQ(*f.range_m.at(u, v), 0.0f);
        continue;
      }
      ++hits[h.geom];
      EXPECT_NEAR(*f.depth_m.at(u, v), h.t, 1e-5 * h.t);
      EXPECT_NEAR(*f.range_m.at(u, v), h.t * d.norm(), 1e-5 * h.t * d.norm());
      const Eigen::Vector3d n_O = R_OW * h.n_W;
      const float* n = f.normal_O.at(u, v);
      EXPECT_NEAR(n[0], n_O.x(), 1e-4);
      EXPECT_NEAR(n[1], n_O.y(), 1e-4);
      EXPECT_NEAR(n[2], n_O.z(), 1e-4);
      EXPECT_LT(n_O.dot(R_OW * d), 0);  // faces the camera
    }
  }
  std::printf(
      "checked %d pixels (%d background, %d/%d/%d on the three geoms), %d grazing skipped\n",
      checked, background, hits[0], hits[1], hits[2], skipped);
  EXPECT_GT(hits[0], 100);
  EXPECT_GT(hits[1], 100);
  EXPECT_GT(hits[2], 100);
  EXPECT_LT(skipped, 5);
}

}  // namespace
}  // namespace penumbra

// the sun-occluder map (render/sky/sun_occluder_map.h): it never skips a ray that
// would reach the sun (random rays against RayScene's exact occlusion test), it skips most sun
// rays inside a roofed room, and the realtime tier renders the same image with it as without.

#include "penumbra/render/sky/sun_occluder_map.h"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include "penumbra/render/backends/render_ablation_switch.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/embree/ray_scene.h"
#include "render/render_test_util.h"

namespace penumbra {
namespace {

using namespace penumbra::testing;

Pose SunMapPose(double x, double y, double z, double yaw_rad, double roll_rad) {
  Pose X = Translation(x, y, z);
  X.linear() = (Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()) *
                Eigen::AngleAxisd(roll_rad, Eigen::Vector3d::UnitX()))
                   .toRotationMatrix();
  return X;
}

// a room x, y in [-3, 3], z in [0, 2.6] under a roof box, walls 0.1 m thick with a 1 m wide
// window in the south wall (z 0.9 .. 1.9) and an open door in the west wall, a rotated static
// box inside, a moving body's box, a see-through box (alpha 0.3) and a hidden one (group 3)
// over the window; a directional sun from the south-south-west at 35 deg elevation with a
// 0.2665 deg disc (soft shadows).
SceneDescription SunMapRoom() {
  SceneDescription s = EmptyScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Constant(0.6f));
  const int glass = AddMaterial(&s, Eigen::Vector3f::Constant(0.9f));
  s.materials[glass].alpha = 0.3f;
  AddGeom(&s, GeomShape::kPlane, {0, 0, 1}, Pose::Identity(), 0, m);
  AddGeom(&s, GeomShape::kBox, {3.2, 3.2, 0.05}, Translation(0, 0, 2.65), 0, m);    // roof
  AddGeom(&s, GeomShape::kBox, {0.05, 3.1, 1.3}, Translation(3.05, 0, 1.3), 0, m);  // east
  AddGeom(&s, GeomShape::kBox, {3.1, 0.05, 1.3}, Translation(0, 3.05, 1.3), 0, m);  // north
  // west wall with a door (y in [-0.5, 0.5], z < 2)
  AddGeom(&s, GeomShape::kBox, {0.05, 1.3, 1.3}, Translation(-3.05, 1.8, 1.3), 0, m);
  AddGeom(&s, GeomShape::kBox, {0.05, 1.3, 1.3}, Translation(-3.05, -1.8, 1.3), 0, m);
  AddGeom(&s, GeomShape::kBox, {0.05, 0.5, 0.3}, Translation(-3.05, 0, 2.3), 0, m);
  // south wall around a window x in [-0.5, 0.5], z in [0.9, 1.9]
  AddGeom(&s, GeomShape::kBox, {1.3, 0.05, 1.3}, Translation(-1.8, -3.05, 1.3), 0, m);
  AddGeom(&s, GeomShape::kBox, {1.3, 0.05, 1.3}, Translation(1.8, -3.05, 1.3), 0, m);
  AddGeom(&s, GeomShape::kBox, {0.5, 0.05, 0.45}, Translation(0, -3.05, 0.45), 0, m);
  AddGeom(&s, GeomShape::kBox, {0.5, 0.05, 0.35}, Translation(0, -3.05, 2.25), 0, m);
  // a rotated static box (a cabinet)
  AddGeom(&s, GeomShape::kBox, {0.4, 0.25, 0.8}, SunMapPose(1.2, 1.0, 0.8, 0.6, 0.0), 0, m);
  // not occluders for the map: see-through and hidden boxes over the window, a moving box
  const int glass_box =
      AddGeom(&s, GeomShape::kBox, {0.5, 0.01, 0.5}, Translation(0, -3.05, 1.4), 0, glass);
  (void)glass_box;
  const int hidden =
      AddGeom(&s, GeomShape::kBox, {0.5, 0.01, 0.5}, Translation(0, -3.2, 1.4), 0, m);
  s.geoms[hidden].group = 3;
  const int robot = AddBody(&s, "robot");
  AddGeom(&s, GeomShape::kBox, {0.3, 0.2, 0.15}, SunMapPose(-1, -1, 0.4, 0.3, 0.2), robot, m);
  Light sun;
  sun.type = Light::Type::kDirectional;
  const double el = 35 * M_PI / 180, az = -110 * M_PI / 180;
  sun.direction_B =
      -Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
  sun.intensity = 50000;
  sun.angular_radius_deg = 0.2665f;
  s.lights.push_back(sun);
  s.sky.type = Sky::Type::kUniform;
  s.sky.radiance = Eigen::Vector3f::Constant(300);
  return s;
}

// a unit direction uniformly in the cone of half-angle `half_rad` around unit `axis`.
Eigen::Vector3f SunMapConeDir(const Eigen::Vector3f& axis, float half_rad, std::mt19937* rng) {
  std::uniform_real_distribution<float> u(0, 1);
  const float cos_t = 1 - u(*rng) * (1 - std::cos(half_rad));
  const float sin_t = std::sqrt(std::max(0.0f, 1 - cos_t * cos_t));
  const float phi = 2 * static_cast<float>(M_PI) * u(*rng);
  const Eigen::Vector3f a =
      std::abs(axis.x()) < 0.9f ? Eigen::Vector3f::UnitX() : Eigen::Vector3f::UnitY();
  const Eigen::Vector3f t = axis.cross(a).normalized(), b = axis.cross(t);
  return (cos_t * axis + sin_t * (std::cos(phi) * t + std::sin(phi) * b)).normalized();
}

TEST(SunOccluderMapTest, NeverSkipsARayThatReachesTheSun) {
  const SceneDescription s = SunMapRoom();
  WorldSnapshot snap = IdentitySnapshot(s);
  RayScene scene(s);
  scene.Update(snap);
  LightSampler lights(s);
  lights.Update(snap);
  SunOccluderMap map;
  map.Update(s, snap, lights, nullptr);
  ASSERT_FALSE(map.empty());
  EXPECT_EQ(map.light_index(), 0);
  EXPECT_EQ(map.num_boxes(), 11);  // the see-through, hidden and moving boxes are left out
  const Eigen::Vector3f to_sun = -lights.lights()[0].direction_W;
  std::mt19937 rng(37);
  std::uniform_real_distribution<float> ux(-4.0f, 4.0f), uz(-0.2f, 3.2f), u01(0, 1);
  int skipped = 0, inside_sun = 0, inside_skipped = 0, reaching = 0;
  for (int i = 0; i < 200000; ++i) {
    const Eigen::Vector3f o(ux(rng), ux(rng), uz(rng));
    // sun rays jittered over 5x the sun's disc, and a share of arbitrary directions
    Eigen::Vector3f d = SunMapConeDir(to_sun, 5 * 0.2665f * static_cast<float>(M_PI) / 180, &rng);
    if (i % 4 == 3) d = SunMapConeDir(Eigen::Vector3f::UnitZ(), static_cast<float>(M_PI), &rng);
    Ray r;
    r.o = o;
    r.d = d;
    r.tmax = std::numeric_limits<float>::infinity();
    const bool exact = scene.Occluded(r);
    const bool skip = map.Blocks(o, d);
    reaching += exact ? 0 : 1;
    ASSERT_FALSE(skip && !exact) << "skipped a ray that reaches the sky: o " << o.transpose()
                                 << " d " << d.transpose();
    skipped += skip ? 1 : 0;
    const bool inside = std::abs(o.x()) < 2.9f && std::abs(o.y()) < 2.9f && o.z() > 0.05f &&
                        o.z() < 2.5f && i % 4 != 3;
    inside_sun += inside ? 1 : 0;
    inside_skipped += inside && skip ? 1 : 0;
  }
  EXPECT_GT(reaching, 10000);  // the test has rays that reach the sky
  // inside the room most sun rays are skipped (all but those through the window and door).
  EXPECT_GT(inside_skipped, 0.8 * inside_sun) << inside_skipped << " of " << inside_sun;
  EXPECT_GT(skipped, 0);
  // non-finite rays and points outside the grid are never skipped
  EXPECT_FALSE(map.Blocks({NAN, 0, 1}, to_sun));
  EXPECT_FALSE(map.Blocks({50, 0, 1}, -to_sun));
  EXPECT_FALSE(map.Blocks({0, 0, 1}, Eigen::Vector3f::Zero()));
}

// BlocksLanes (16 rays at once, AVX-512 where built with it) gives every active lane exactly
// Blocks' verdict and inactive lanes false: packets of rays from one spot (one or two cells, as a
// tile row's shadow rays), from scattered points, sun-jittered and arbitrary directions, whole
// cells (rays from high under the roof), points outside the grid, non-finite and zero rays.
TEST(SunOccluderMapTest, LanesGiveEveryRayBlocksVerdict) {
  const SceneDescription s = SunMapRoom();
  WorldSnapshot snap = IdentitySnapshot(s);
  LightSampler lights(s);
  lights.Update(snap);
  SunOccluderMap map;
  map.Update(s, snap, lights, nullptr);
  ASSERT_FALSE(map.empty());
  const Eigen::Vector3f to_sun = -lights.lights()[0].direction_W;
  std::mt19937 rng(38);
  std::uniform_real_distribution<float> ux(-4.0f, 4.0f), uz(-0.2f, 3.2f), u01(0, 1);
  int blocked = 0, lanes = 0;
  for (int packet = 0; packet < 20000; ++packet) {
    Vec3Lanes o, d;
    const Eigen::Vector3f spot(ux(rng), ux(rng), packet % 5 == 0 ? 2.4f : uz(rng));
    for (int k = 0; k < kLanes; ++k) {
      // packets 0, 1 mod 3: rays from within 0.3 m of one spot; else scattered.
      const Eigen::Vector3f jitter(0.3f * u01(rng), 0.02f * u01(rng), 0.0f);
      const Eigen::Vector3f ok = packet % 3 != 2 ? Eigen::Vector3f(spot + jitter)
                                                 : Eigen::Vector3f(ux(rng), ux(rng), uz(rng));
      Eigen::Vector3f dk =
          SunMapConeDir(to_sun, 2 * 0.2665f * static_cast<float>(M_PI) / 180, &rng);
      if ((packet + k) % 7 == 3)
        dk = SunMapConeDir(Eigen::Vector3f::UnitZ(), static_cast<float>(M_PI), &rng);
      if ((packet + k) % 11 == 5) dk *= 3.0f;  // not unit
      o.Set(k, ok);
      d.Set(k, dk);
    }
    if (packet % 13 == 0) o.x[3] = NAN;
    if (packet % 17 == 0) d.Set(5, Eigen::Vector3f::Zero());
    if (packet % 19 == 0) o.Set(7, Eigen::Vector3f(50, 0, 1));
    if (packet % 23 == 0) d.z[9] = std::numeric_limits<float>::infinity();
    const LaneMask active(packet % 4 == 0 ? 0xffffu : static_cast<uint32_t>(rng()) & 0xffffu);
    const LaneMask got = map.BlocksLanes(o, d, active);
    for (int k = 0; k < kLanes; ++k) {
      const bool want = active[k] && map.Blocks(o.Lane(k), d.Lane(k));
      ASSERT_EQ(got[k], want) << "packet " << packet << " lane " << k << " o "
                              << o.Lane(k).transpose() << " d " << d.Lane(k).transpose();
      blocked += want ? 1 : 0;
      lanes += active[k] ? 1 : 0;
    }
  }
  // both verdicts occur often.
  EXPECT_GT(blocked, lanes / 10);
  EXPECT_LT(blocked, lanes - lanes / 10);
}

TEST(SunOccluderMapTest, FollowsTheStaticPosesAndTheSun) {
  SceneDescription s = SunMapRoom();
  const int shed = AddBody(&s, "shed", true);  // a static body holding one more roof
  AddGeom(&s, GeomShape::kBox, {1, 1, 0.05}, Pose::Identity(), shed, 0);
  WorldSnapshot snap = IdentitySnapshot(s);
  snap.X_WB[shed] = Translation(10, 0, 3);
  LightSampler lights(s);
  lights.Update(snap);
  SunOccluderMap map;
  map.Update(s, snap, lights, nullptr);
  const Eigen::Vector3f up = Eigen::Vector3f::UnitZ();
  // the map bounds include the shed; under it a ray straight up is blocked.
  EXPECT_TRUE(map.Blocks({10, 0, 2}, up));
  snap.X_WB[shed] = Translation(10, 5, 3);  // the shed moved: rebuilt with its new pose
  map.Update(s, snap, lights, nullptr);
  EXPECT_FALSE(map.Blocks({10, 0, 2}, up));
  // no directional light: the map is empty
  SceneDescription no_sun = s;
  no_sun.lights.clear();
  LightSampler none(no_sun);
  none.Update(snap);
  map.Update(no_sun, snap, none, nullptr);
  EXPECT_TRUE(map.empty());
  EXPECT_EQ(map.light_index(), -1);
}

TEST(SunOccluderMapTest, RealtimeImageIsTheSameWithFewerRays) {
  const SceneDescription s = SunMapRoom();
  RenderSettings on = TestSettings(2);
  on.backend = RenderSettings::Backend::kEmbree;
  auto a = MakeRenderer(s, on);
  auto b = MakeRenderer(s, on);
  RenderAblation off;
  off.sun_occluder = false;
  ASSERT_TRUE(SetRenderAblation(b.get(), off));
  Pose X = CameraLookingAlongX({-2.5, -0.5, 1.2});
  const CameraView view = MakeView(X, 96, 64, 75);
  RenderedFrame fa, fb;
  a->Render(IdentitySnapshot(s), view, &fa);
  b->Render(IdentitySnapshot(s), view, &fb);
  ASSERT_EQ(fa.radiance.data.size(), fb.radiance.data.size());
  EXPECT_EQ(fa.radiance.data, fb.radiance.data);
  EXPECT_EQ(fa.rgb.data, fb.rgb.data);
  EXPECT_EQ(fa.depth_m.data, fb.depth_m.data);
  EXPECT_EQ(fa.geom_id.data, fb.geom_id.data);
  EXPECT_LT(fa.rays, fb.rays - 96 * 64 / 4) << fa.rays << " vs " << fb.rays;
}

}  // namespace
}  // namespace penumbra

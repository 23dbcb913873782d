// the LiDAR traces only through the backend-neutral RayQuery (render/ray_query.h): a scan
// against an analytic query with no ray-tracing library behind it.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <span>

#include "penumbra/render/ray_query.h"
#include "penumbra/sensors/lidar_scanner.h"

namespace penumbra {
namespace {

// the inside of a sphere of radius kRadiusM about the world origin, material 0; counts the
// rays and batches it is asked to trace.
class ShellQuery final : public RayQuery {
 public:
  static constexpr double kRadiusM = 4.0;
  explicit ShellQuery(const SceneDescription& scene) : scene_(scene) {}
  const SceneDescription& scene() const override { return scene_; }
  void Update(const WorldSnapshot&) override { ++updates; }

  int updates = 0;
  mutable std::atomic<int64_t> rays{0}, batches{0};

 private:
  void IntersectBatch(std::span<const Ray> in, std::span<SurfaceHit> hits,
                      std::span<bool> did_hit) const override {
    ++batches;
    rays += static_cast<int64_t>(in.size());
    for (size_t i = 0; i < in.size(); ++i) {
      // |o + t d| = R, the root ahead of an origin inside the sphere
      const Eigen::Vector3d o = in[i].o.cast<double>(), d = in[i].d.cast<double>();
      const double a = d.squaredNorm(), b = o.dot(d), c = o.squaredNorm() - kRadiusM * kRadiusM;
      const double t = (-b + std::sqrt(b * b - a * c)) / a;
      did_hit[i] = t >= in[i].tmin && t <= in[i].tmax;
      SurfaceHit& h = hits[i];
      h.t = static_cast<float>(t);
      h.p_W = (o + t * d).cast<float>();
      h.ng_W = h.ns_W = -h.p_W.normalized();  // faces the ray, which comes from inside
      h.front_face = false;
      h.geom = 0;
      h.material = 0;
    }
  }

  const SceneDescription& scene_;
};

TEST(LidarRayQueryTest, ScansAnyRayQueryWithoutARayTracingBackend) {
  SceneDescription scene;
  scene.bodies.push_back({"world", -1, true});
  Material grey;
  grey.name = "grey";
  grey.base_color = Eigen::Vector3f::Constant(0.5f);
  scene.materials.push_back(grey);
  ShellQuery query(scene);
  query.Update(WorldSnapshot{});

  LidarConfig cfg;
  cfg.pattern = MakeLidarPattern("velodyne_vlp16");
  const LidarScanner lidar(cfg, 1);
  LidarScan scan;
  lidar.Scan(
      query, nullptr, [](double) { return Pose::Identity(); }, 0, &scan);

  // every beam was traced through the query, in batches, and returned from the shell at
  // normal incidence: range R, intensity = the grey's reflectivity (range-normalised)
  ASSERT_EQ(scan.rays, static_cast<int64_t>(cfg.pattern.beams.size()));
  // the shell is continuous: no beam is near an edge, none traces its footprint
  EXPECT_EQ(query.rays.load(), scan.rays);
  EXPECT_GT(query.batches.load(), 1);
  EXPECT_LT(query.batches.load(), scan.rays);
  ASSERT_EQ(static_cast<int64_t>(scan.points.size()), scan.rays);
  for (const LidarPoint& p : scan.points) {
    EXPECT_NEAR(Eigen::Vector3d(p.x, p.y, p.z).norm(), ShellQuery::kRadiusM, 1e-5);
    EXPECT_NEAR(p.intensity, 0.5, 1e-5);
    EXPECT_EQ(p.kind, LidarReturnKind::kSurface);
  }
}

}  // namespace
}  // namespace penumbra

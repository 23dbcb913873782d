// LiDAR on analytic scenes: exact ranges, angle tables, motion distortion, fog statistics,
// particles.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>

#include "penumbra/core/error.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/sensors/lidar_scanner.h"

namespace penumbra {
namespace {

constexpr double kPi = 3.14159265358979323846;

// a world-only scene: a ground plane z = 0, a wall plane x = 10 (facing -x), a sphere r = 1
// at (0, 5, 1); every material white-grey with base colour `grey`.
SceneDescription AnalyticScene(bool ground, bool wall, bool sphere, float grey = 0.8f) {
  SceneDescription s;
  Body world;
  world.name = "world";
  world.is_static = true;
  s.bodies.push_back(world);
  Material m;
  m.name = "grey";
  m.base_color = Eigen::Vector3f::Constant(grey);
  s.materials.push_back(m);
  int id = 0;
  if (ground) {
    Geom g;
    g.id = id++;
    g.shape = GeomShape::kPlane;
    g.size = {0, 0, 1};
    g.material = 0;
    s.geoms.push_back(g);
  }
  if (wall) {
    Geom g;
    g.id = id++;
    g.shape = GeomShape::kPlane;
    g.size = {0, 0, 1};
    g.material = 0;
    g.X_BG = PoseFromXyzRpyDeg({10, 0, 0}, {0, -90, 0});  // plane normal z -> -x
    s.geoms.push_back(g);
  }
  if (sphere) {
    Geom g;
    g.id = id++;
    g.shape = GeomShape::kSphere;
    g.size = {1, 0, 0};
    g.material = 0;
    g.X_BG = PoseFromXyzRpyDeg({0, 5, 1}, {0, 0, 0});
    s.geoms.push_back(g);
  }
  return s;
}

WorldSnapshot StaticSnapshot() {
  WorldSnapshot snap;
  snap.X_WB = {Pose::Identity()};
  return snap;
}

// analytic range of a ray (o, unit d) against the AnalyticScene, or +inf.
double AnalyticRange(const Eigen::Vector3d& o, const Eigen::Vector3d& d, bool ground, bool wall,
                     bool sphere) {
  double best = std::numeric_limits<double>::infinity();
  if (ground && d.z() < 0) best = std::min(best, -o.z() / d.z());
  if (wall && d.x() > 0) best = std::min(best, (10 - o.x()) / d.x());
  if (sphere) {
    const Eigen::Vector3d c(0, 5, 1);
    const double b = (o - c).dot(d), cc = (o - c).squaredNorm() - 1;
    const double disc = b * b - cc;
    if (disc >= 0) {
      const double t = -b - std::sqrt(disc);
      if (t > 0) best = std::min(best, t);
    }
  }
  return best;
}

// fans of beams (el 0) 3 mrad apart (about a VLP-16's 0.2 deg columns), divergence 3 mrad, each
// fan shifted by 0.1 mrad more (30 fans: every position of the edge between two beams), at the
// wall x = 10 with a box whose front face is at x = `front` covering y < 0 (its edge at
// azimuth 0).
LidarScan FanAtEdge(double front, int footprint_rays) {
  SceneDescription scene = AnalyticScene(false, true, false);
  Geom box;
  box.id = 7;
  box.shape = GeomShape::kBox;
  box.size = {0.05, 2.5, 2.0};
  box.material = 0;
  box.X_BG = PoseFromXyzRpyDeg({front + 0.05, -2.5, 0}, {0, 0, 0});
  scene.geoms.push_back(box);
  RayScene rs(scene);
  rs.Update(StaticSnapshot());
  LidarConfig cfg;
  cfg.pattern.name = "fan";
  cfg.pattern.rings = 1;
  cfg.pattern.spinning = false;
  cfg.pattern.beam_divergence_rad = 0.003;
  for (int g = 0; g < 30; ++g) {
    for (int i = -8; i <= 8; ++i) {
      LidarBeam b;
      b.azimuth_rad = static_cast<float>(i * 3e-3 + g * 1e-4);
      b.column = static_cast<int>(cfg.pattern.beams.size());
      cfg.pattern.beams.push_back(b);
    }
  }
  cfg.footprint_rays = footprint_rays;
  LidarScanner lidar(cfg, 1);
  LidarScan scan;
  lidar.Scan(
      rs, nullptr, [](double) { return Pose::Identity(); }, 0, &scan);
  return scan;
}

// mixed returns: a beam whose footprint straddles an edge less than a pulse length (3 m for
// 20 ns) in front of its background reports one point between the two surfaces; only beams
// within the footprint's reach of the edge do; the axis alone (footprint_rays 0) never does;
// an edge 6 m in front of the wall gives separate pulses, the stronger wins, no point between.
TEST(LidarTest, MixedReturnsBetweenSurfacesOnlyAtEdges) {
  auto between = [](const LidarScan& scan, double near, double far, double* max_abs_az) {
    int n = 0;
    *max_abs_az = 0;
    for (const LidarPoint& p : scan.points) {
      const double r = std::hypot(p.x, p.y, p.z);
      if (r > near + 0.02 && r < far - 0.02) {
        ++n;
        *max_abs_az = std::max(*max_abs_az, std::abs(std::atan2(static_cast<double>(p.y), p.x)));
      }
    }
    return n;
  };
  double reach = 0;
  const LidarScan mixed = FanAtEdge(9.0, 4);
  EXPECT_EQ(mixed.points.size(), 30u * 17u);
  const int n_mixed = between(mixed, 9.0, 10.0, &reach);
  std::printf("edge 1 m before the wall: %d mixed points, out to %.2f mrad\n", n_mixed,
              1e3 * reach);
  EXPECT_GE(n_mixed, 5);
  EXPECT_LE(reach, 0.7 * 0.0015 + 2e-4);  // the footprint ring's radius
  // off the edge the points are the surfaces' own (within the ring's range spread)
  for (const LidarPoint& p : mixed.points) {
    const double az = std::atan2(static_cast<double>(p.y), p.x), r = std::hypot(p.x, p.y, p.z);
    if (std::abs(az) < 2e-3) continue;
    const double expected = (az < 0 ? 9.0 : 10.0) / std::cos(az);
    EXPECT_NEAR(r, expected, 1e-3) << az;
  }
  EXPECT_EQ(between(FanAtEdge(9.0, 0), 9.0, 10.0, &reach), 0);
  EXPECT_EQ(between(FanAtEdge(4.0, 4), 4.0, 10.0, &reach), 0);
}

TEST(LidarTest, NoiseFreeRangesMatchAnalyticSceneAndDetectionThreshold) {
  const SceneDescription scene = AnalyticScene(true, true, true);
  RayScene rs(scene);
  rs.Update(StaticSnapshot());
  LidarConfig cfg;
  cfg.pattern = MakeLidarPattern("velodyne_vlp16");
  cfg.footprint_rays = 0;  // the beam's axis: the analytic range (mixed returns: below)
  LidarScanner lidar(cfg, 1);
  const Pose X_WS = PoseFromXyzRpyDeg({0, 0, 1}, {0, 0, 0});
  LidarScan scan;
  lidar.Scan(
      rs, nullptr, [&](double) { return X_WS; }, 0, &scan);
  ASSERT_EQ(scan.rays, 16 * 1800);
  std::vector<char> returned(scan.rays, 0);
  double max_err = 0;
  for (const LidarPoint& p : scan.points) {
    returned[p.beam] = 1;
    const Eigen::Vector3d dir = Eigen::Vector3d(p.x, p.y, p.z).normalized();
    const double expected = AnalyticRange(X_WS.translation(), dir, true, true, true);
    max_err = std::max(max_err, std::abs(Eigen::Vector3d(p.x, p.y, p.z).norm() - expected));
  }
  EXPECT_LT(max_err, 1e-3);
  std::printf("analytic scene: %zu points, max |range error| %.3g m\n", scan.points.size(),
              max_err);
  // detection: a beam returns iff its analytic power clears the threshold (1 % margin)
  int checked = 0;
  for (int i = 0; i < scan.rays; ++i) {
    float x, y, z;
    cfg.pattern.Direction(i, &x, &y, &z);
    const Eigen::Vector3d d(x, y, z);
    const double r = AnalyticRange(X_WS.translation(), d, true, true, true);
    if (!std::isfinite(r) || r > 100) {
      EXPECT_FALSE(returned[i]) << "beam " << i;
      continue;
    }
    const Eigen::Vector3d p = X_WS.translation() + r * d;
    Eigen::Vector3d n;
    if (std::abs(p.z()) < 1e-6)
      n = {0, 0, 1};
    else if (std::abs(p.x() - 10) < 1e-6)
      n = {-1, 0, 0};
    else
      n = (p - Eigen::Vector3d(0, 5, 1)).normalized();
    const double power = 0.8 * std::abs(n.dot(d)) / kPi / (r * r);
    if (power > 1.01 * lidar.threshold_power()) {
      EXPECT_TRUE(returned[i]) << "beam " << i;
      ++checked;
    } else if (power < 0.99 * lidar.threshold_power()) {
      EXPECT_FALSE(returned[i]) << "beam " << i;
    }
  }
  EXPECT_GT(checked, 10000);
}

TEST(LidarTest, RingAndAzimuthOfEveryPointMatchTheAngleTable) {
  for (const std::string preset : {"velodyne_vlp16", "ouster_os1_64", "ouster_os1_128"}) {
    const SceneDescription scene = AnalyticScene(true, true, true);
    RayScene rs(scene);
    rs.Update(StaticSnapshot());
    LidarConfig cfg;
    cfg.pattern = MakeLidarPattern(preset);
    const int rings = cfg.pattern.rings;
    const double lo = preset == "velodyne_vlp16" ? -15 : -22.5;
    const double step = preset == "velodyne_vlp16" ? 2.0 : 45.0 / (rings - 1);
    const int cols = cfg.pattern.columns;
    LidarScanner lidar(cfg, 1);
    LidarScan scan;
    lidar.Scan(
        rs, nullptr,
        [](double) {
          return PoseFromXyzRpyDeg({0, 0, 1}, {0, 0, 0});
        },
        0, &scan);
    ASSERT_GT(scan.points.size(), 1000u) << preset;
    double max_el = 0, max_az = 0;
    for (const LidarPoint& p : scan.points) {
      const double r = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z);
      const double el = std::asin(p.z / r) * 180 / kPi;
      max_el = std::max(max_el, std::abs(el - (lo + step * p.ring)));
      // column from the timestamp; azimuth clockwise from +x
      const int c = static_cast<int>(std::lround(p.time * 10.0 * cols));
      double az_expected = -360.0 * c / cols;
      double az = std::atan2(p.y, p.x) * 180 / kPi;
      double diff = std::remainder(az - az_expected, 360.0);
      max_az = std::max(max_az, std::abs(diff));
    }
    std::printf("%s: max elevation error %.3g deg, max azimuth error %.3g deg\n", preset.c_str(),
                max_el, max_az);
    EXPECT_LT(max_el, 1e-3) << preset;
    EXPECT_LT(max_az, 1e-3) << preset;
  }
}

TEST(LidarTest, MotionDistortionShiftsLateColumnsByVelocityTimesTime) {
  const SceneDescription scene = AnalyticScene(false, true, false);
  RayScene rs(scene);
  rs.Update(StaticSnapshot());
  LidarConfig cfg;
  cfg.pattern = MakeLidarPattern("ouster_os1_64");
  LidarScanner lidar(cfg, 1);
  const double v = 1.0;  // m/s along +x, towards the wall
  const Pose start = PoseFromXyzRpyDeg({0, 0, 1}, {0, 0, 0});
  const Pose end = PoseFromXyzRpyDeg({v * 0.1, 0, 1}, {0, 0, 0});
  LidarScan scan;
  lidar.Scan(
      rs, nullptr, [&](double t) { return InterpolatePose(start, end, t / 0.1); }, 0, &scan);
  ASSERT_GT(scan.points.size(), 1000u);
  double max_err = 0;
  float t_first = 1, t_last = 0;
  for (const LidarPoint& p : scan.points) {
    max_err = std::max(max_err, std::abs(p.x - (10.0 - v * p.time)));
    t_first = std::min(t_first, p.time);
    t_last = std::max(t_last, p.time);
  }
  EXPECT_LT(max_err, 1e-3);
  // the wall is seen by the first column (t = 0) and the last (t = 1023 / 10240 s), which
  // sees it v * t = 0.0999 m closer
  EXPECT_EQ(t_first, 0.0f);
  EXPECT_NEAR(t_last, 1023.0 / 10240.0, 1e-6);
  double x_first = 0, x_last = 0;
  for (const LidarPoint& p : scan.points) {
    if (p.time == t_first) x_first = std::max(x_first, static_cast<double>(p.x));
    if (p.time == t_last) x_last = std::max(x_last, static_cast<double>(p.x));
  }
  EXPECT_NEAR(x_first - x_last, v * t_last, 1e-3);
  std::printf("motion: max |x - (10 - v t)| %.3g m, first-last column shift %.5f m (v t %.5f)\n",
              max_err, x_first - x_last, v * t_last);
}

double NormalCdf(double x) { return 0.5 * std::erfc(-x / std::sqrt(2.0)); }

// an enclosing sphere of radius r around the sensor: every beam hits at range r, normal incidence.
SceneDescription Enclosure(double r, float grey) {
  SceneDescription s = AnalyticScene(false, false, false, grey);
  Geom g;
  g.id = 0;
  g.shape = GeomShape::kSphere;
  g.size = {r, 0, 0};
  g.material = 0;
  s.geoms.push_back(g);
  return s;
}

TEST(LidarTest, FogReturnFractionFollowsAttenuationAndReceiverNoise) {
  // hard-target detection in homogeneous fog: P = rho/pi exp(-2 sigma r)/r^2 + N(0, (k P_th)^2)
  // must reach P_th; the false-return (soft target) window is moved beyond the wall.
  const double r = 20.0;
  const float rho = 0.5f;
  const SceneDescription scene = Enclosure(r, rho);
  RayScene rs(scene);
  rs.Update(StaticSnapshot());
  LidarConfig cfg;
  cfg.pattern = MakeLidarPattern("ouster_os1_64");
  cfg.receiver_noise = 0.3;
  cfg.overlap_start_m = 50;
  cfg.overlap_full_m = 60;
  LidarScanner lidar(cfg, 7);
  const double p_th = lidar.threshold_power();
  // sigma_t giving P_hard = P_th (1 + x k) for x in {-1, 0, +1.5}
  for (double x : {-1.0, 0.0, 1.5}) {
    const double target = p_th * (1 + x * cfg.receiver_noise);
    const double sigma = -std::log(target * kPi * r * r / rho) / (2 * r);
    ASSERT_GT(sigma, 0);
    EffectsFrame fx;
    HomogeneousMedium fog;
    fog.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(sigma));
    fx.homogeneous_media.push_back(fog);
    LidarScan scan;
    lidar.Scan(
        rs, &fx, [](double) { return Pose::Identity(); }, 3, &scan);
    const double fraction = static_cast<double>(scan.points.size()) / scan.rays;
    const double expected = NormalCdf(x);
    // binomial stddev sqrt(p (1-p) / 65536) <= 0.002; tolerance 5 sigma
    EXPECT_NEAR(fraction, expected, 0.01) << "sigma_t " << sigma;
    std::printf("fog sigma_t %.4f 1/m at r = %.0f m: return fraction %.4f, model %.4f\n", sigma, r,
                fraction, expected);
    EXPECT_EQ(scan.medium_returns, 0);
    for (const LidarPoint& p : scan.points)
      ASSERT_NEAR(std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z), r, 1e-3);
  }
}

TEST(LidarTest, DenseFogReplacesDistantTargetsWithFalseReturnsAtTheSoftPeak) {
  const float rho = 0.5f;
  LidarConfig cfg;
  cfg.pattern = MakeLidarPattern("velodyne_vlp16");
  LidarScanner lidar(cfg, 3);
  const double sigma = 0.1;  // MOR = ln(20)/0.1 = 30 m
  EffectsFrame fx;
  HomogeneousMedium fog;
  fog.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(sigma));
  fx.homogeneous_media.push_back(fog);
  // analytic soft peak: max_R beta L xi(R) exp(-2 sigma R) / R^2 on [R1, r]
  const double beta = 0.046 / std::log(20.0) * sigma, L = 299792458.0 * 20e-9 / 2;
  const auto soft = [&](double R) {
    return beta * L * std::clamp((R - 1.0) / 4.0, 0.0, 1.0) * std::exp(-2 * sigma * R) / (R * R);
  };
  double peak = 0, peak_r = 0;
  for (double R = 1.0; R < 30; R += 1e-3)
    if (soft(R) > peak) peak = soft(R), peak_r = R;
  // far wall: P_hard << P_soft peak -> every point is a false return near peak_r
  {
    const double r = 25;
    ASSERT_LT(rho / kPi * std::exp(-2 * sigma * r) / (r * r), 0.1 * peak);
    const SceneDescription scene = Enclosure(r, rho);
    RayScene rs(scene);
    rs.Update(StaticSnapshot());
    LidarScan scan;
    lidar.Scan(
        rs, &fx, [](double) { return Pose::Identity(); }, 0, &scan);
    EXPECT_EQ(static_cast<int64_t>(scan.points.size()), scan.rays);
    EXPECT_EQ(scan.medium_returns, scan.rays);
    const double h = (r - 1.0) / 48;  // the model's sampling step
    for (const LidarPoint& p : scan.points)
      ASSERT_NEAR(std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z), peak_r, h);
  }
  // near wall: P_hard >> P_soft -> every point is on the wall
  {
    const double r = 3;
    ASSERT_GT(rho / kPi * std::exp(-2 * sigma * r) / (r * r), 10 * peak);
    const SceneDescription scene = Enclosure(r, rho);
    RayScene rs(scene);
    rs.Update(StaticSnapshot());
    LidarScan scan;
    lidar.Scan(
        rs, &fx, [](double) { return Pose::Identity(); }, 0, &scan);
    EXPECT_EQ(static_cast<int64_t>(scan.points.size()), scan.rays);
    EXPECT_EQ(scan.medium_returns, 0);
  }
}

TEST(LidarTest, SnowflakeOnABeamReturnsAtItsSurface) {
  const SceneDescription scene = AnalyticScene(false, true, false);
  RayScene rs(scene);
  rs.Update(StaticSnapshot());
  LidarConfig cfg;
  cfg.pattern = MakeLidarPattern("velodyne_vlp16");
  LidarScanner lidar(cfg, 1);
  const double el = 1.0 * kPi / 180;  // ring 8
  const Eigen::Vector3f c(static_cast<float>(3 * std::cos(el)), 0.0f,
                          static_cast<float>(1 + 3 * std::sin(el)));
  EffectsFrame fx;
  ParticleSet snow;
  snow.kind = ParticleKind::kSnow;
  snow.position_W = {c};
  snow.velocity_W = {Eigen::Vector3f::Zero()};
  snow.radius_m = {0.01f};
  fx.particles.push_back(snow);
  const auto pose = [](double) { return PoseFromXyzRpyDeg({0, 0, 1}, {0, 0, 0}); };
  LidarScan scan;
  lidar.Scan(rs, &fx, pose, 0, &scan);
  // 3 mrad divergence: at 3 m the beam radius is 4.5 mm, so the neighbouring columns
  // (0.2 deg = 10.5 mm away) also reach the 10 mm flake
  EXPECT_EQ(scan.particle_returns, 3);
  cfg.pattern.beam_divergence_rad = 0;
  LidarScanner thin(cfg, 1);
  thin.Scan(rs, &fx, pose, 0, &scan);
  ASSERT_EQ(scan.particle_returns, 1);
  for (const LidarPoint& p : scan.points) {
    if (p.kind != LidarReturnKind::kParticle) continue;
    EXPECT_EQ(p.ring, 8);
    EXPECT_EQ(p.beam, 8);  // column 0
    EXPECT_NEAR(std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z), 3.0 - 0.01, 1e-3);
  }
}

TEST(LidarTest, ParticlesAreFoundWhileTheSensorTurnsAndMoves) {
  // the sensor turns 90 deg and moves 0.5 m during the scan; every beam whose ray (from its own
  // firing pose) passes through a flake must return from it
  const SceneDescription scene = AnalyticScene(false, false, false);
  RayScene rs(scene);
  rs.Update(StaticSnapshot());
  LidarConfig cfg;
  cfg.pattern = MakeLidarPattern("velodyne_vlp16");
  cfg.pattern.beam_divergence_rad = 0;
  LidarScanner lidar(cfg, 1);
  const Pose a = PoseFromXyzRpyDeg({0, 0, 1}, {0, 0, 0});
  const Pose b = PoseFromXyzRpyDeg({0.5, 0, 1}, {0, 0, 90});
  const SensorPoseAt pose = [&](double t) { return InterpolatePose(a, b, t / 0.1); };
  EffectsFrame fx;
  ParticleSet snow;
  snow.kind = ParticleKind::kSnow;
  for (int k = 0; k < 12; ++k) {
    const double ang = k * 30.0 * kPi / 180;
    snow.position_W.emplace_back(static_cast<float>(4 * std::cos(ang)),
                                 static_cast<float>(4 * std::sin(ang)), 1.07f);
    snow.velocity_W.emplace_back(0, 0, 0);
    snow.radius_m.push_back(0.06f);
  }
  fx.particles.push_back(snow);
  LidarScan scan;
  lidar.Scan(rs, &fx, pose, 0, &scan);
  int expected = 0;
  for (int i = 0; i < scan.rays; ++i) {
    const Pose X = pose(cfg.pattern.beams[i].time_sec);
    float x, y, z;
    cfg.pattern.Direction(i, &x, &y, &z);
    const Eigen::Vector3d o = X.translation(), d = X.linear() * Eigen::Vector3d(x, y, z);
    for (const Eigen::Vector3f& c : snow.position_W) {
      const Eigen::Vector3d q = c.cast<double>();
      const double tc = (q - o).dot(d);
      if (tc > 0 && (q - o - tc * d).norm() < 0.06 - 1e-4) {
        ++expected;
        break;
      }
    }
  }
  EXPECT_GT(expected, 20);
  EXPECT_GE(scan.particle_returns, expected);
  EXPECT_LE(scan.particle_returns, expected + 12);  // grazing beams within 0.1 mm of the rim
}

TEST(LidarTest, NoiseAndDropoutAreSeededAndStatisticallyRight) {
  const SceneDescription scene = Enclosure(10, 0.8f);
  RayScene rs(scene);
  rs.Update(StaticSnapshot());
  LidarConfig cfg;
  cfg.pattern = MakeLidarPattern("ouster_os1_64");
  cfg.range_noise_stddev_m = 0.02;
  cfg.dropout_probability = 0.1;
  LidarScanner a(cfg, 11), b(cfg, 11), c(cfg, 12);
  LidarScan sa, sb, sc;
  const auto pose = [](double) { return Pose::Identity(); };
  a.Scan(rs, nullptr, pose, 0, &sa);
  b.Scan(rs, nullptr, pose, 0, &sb);
  c.Scan(rs, nullptr, pose, 0, &sc);
  ASSERT_EQ(sa.points.size(), sb.points.size());
  for (size_t i = 0; i < sa.points.size(); ++i) ASSERT_EQ(sa.points[i].x, sb.points[i].x);
  EXPECT_NE(sa.points.size() == sc.points.size() && sa.points[0].x == sc.points[0].x, true);
  const double kept = static_cast<double>(sa.points.size()) / sa.rays;
  EXPECT_NEAR(kept, 0.9, 0.006);  // binomial stddev 0.0012
  double sum = 0, sum2 = 0;
  for (const LidarPoint& p : sa.points) {
    const double e = std::sqrt(p.x * p.x + p.y * p.y + p.z * p.z) - 10.0;
    sum += e;
    sum2 += e * e;
  }
  const double nn = static_cast<double>(sa.points.size());
  EXPECT_NEAR(sum / nn, 0.0, 0.001);
  EXPECT_NEAR(std::sqrt(sum2 / nn), 0.02, 0.0005);
}

TEST(LidarTest, PresetsAndErrors) {
  EXPECT_EQ(MakeLidarPattern("velodyne_vlp16").beams.size(), 16u * 1800u);
  EXPECT_EQ(MakeLidarPattern("ouster_os1_128", {2048, 10}).beams.size(), 128u * 2048u);
  EXPECT_EQ(MakeLidarPattern("ouster_os1_64", {512, 20}).columns, 512);
  EXPECT_EQ(MakeLidarPattern("livox_mid40").beams.size(), 10000u);
  EXPECT_EQ(MakeLidarPattern("solid_state_raster").beams.size(), 600u * 125u);
  for (const LidarBeam& b : MakeLidarPattern("livox_mid40").beams)
    ASSERT_LE(std::hypot(b.azimuth_rad, b.elevation_rad), 19.2 * kPi / 180 + 1e-6);
  EXPECT_THROW(MakeLidarPattern("hdl64"), Error);
  EXPECT_THROW(MakeLidarPattern("ouster_os1_64", {1000, 10}), Error);
  EXPECT_THROW(MakeLidarPattern("ouster_os1_64", {2048, 20}), Error);
}

}  // namespace
}  // namespace penumbra

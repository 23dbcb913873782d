// mesh files as world-file models, through the composed MJCF,
// MuJoCo and both render tiers: a glTF's base colour texture lands where its texcoords say,
// its normal map bends the shading as the tangent frame says, an OBJ in centimetres with y up
// lands in metres with z up, and a malformed mesh fails naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <string>

#include "common/gltf_slab.h"
#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/render/renderer.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

using penumbra::testing::RgbImage;
using penumbra::testing::TempDir;

constexpr int kSize = 64;

// a camera 2 m above the origin looking straight down: image right = world +x, image down =
// world -y.
CameraView TopView() {
  CameraView view;
  view.X_WO.setIdentity();
  Eigen::Matrix3d R;
  R.col(0) = Eigen::Vector3d(1, 0, 0);
  R.col(1) = Eigen::Vector3d(0, -1, 0);
  R.col(2) = Eigen::Vector3d(0, 0, -1);
  view.X_WO.linear() = R;
  view.X_WO.translation() = Eigen::Vector3d(0, 0, 2);
  view.intrinsics = CameraIntrinsics::FromFovy(kSize, kSize, 40);
  view.outputs[ImageKind::kRgb] = true;
  return view;
}

// the world: the slab model, a sun travelling along `sun_dir` (10 000 lx, a point source),
// a dim uniform sky, the given tier.
std::string SlabWorld(const std::string& model_file, const std::string& tier,
                      const Eigen::Vector3d& sun_dir) {
  return "duration_sec: 0.01\n"
         "render: {tier: " +
         tier +
         ", samples_per_pixel: 4, max_bounces: 1, denoise: false,"
         " exposure: {mode: manual, ev100: 10}}\n"
         "sky: {type: uniform, color: [1, 1, 1], luminance_cd_m2: 10}\n"
         "models:\n  - {name: slab, file: " +
         model_file +
         "}\n"
         "lights:\n  - {name: sun, type: sun, illuminance_lux: 10000, angular_diameter_deg: 0,"
         " direction: [" +
         std::to_string(sun_dir.x()) + ", " + std::to_string(sun_dir.y()) + ", " +
         std::to_string(sun_dir.z()) + "]}\n";
}

RenderedFrame RenderWorld(const TempDir& dir, const std::string& yaml) {
  const std::string path = dir.Write("world.yaml", yaml);
  const WorldConfig world = LoadWorldFile(path);
  SessionOptions options;
  options.add_controllers = false;
  Session session(world, options);
  RenderedFrame frame;
  session.renderer()->Render(session.sim().Snapshot(), TopView(), &frame);
  return frame;
}

// mean linear radiance over the (2r+1)^2 pixels around (u, v).
Eigen::Vector3d MeanRadiance(const RenderedFrame& f, int u, int v, int r) {
  Eigen::Vector3d s = Eigen::Vector3d::Zero();
  int n = 0;
  for (int y = v - r; y <= v + r; ++y)
    for (int x = u - r; x <= u + r; ++x, ++n) {
      const float* p = f.radiance.at(x, y);
      s += Eigen::Vector3d(p[0], p[1], p[2]);
    }
  return s / n;
}

// a 64 x 64 image whose quadrants are red (top-left), green (top-right), blue (bottom-left)
// and white (bottom-right).
RgbImage Quadrants() {
  RgbImage im = RgbImage::Solid(64, 64, 0, 0, 0);
  for (int y = 0; y < 64; ++y)
    for (int x = 0; x < 64; ++x) {
      uint8_t* p = &im.rgb[(static_cast<size_t>(y) * 64 + x) * 3];
      const bool right = x >= 32, bottom = y >= 32;
      p[0] = (!right && !bottom) || (right && bottom) ? 255 : 0;
      p[1] = (right && !bottom) || (right && bottom) ? 255 : 0;
      p[2] = (!right && bottom) || (right && bottom) ? 255 : 0;
    }
  return im;
}

TEST(MeshModel, GltfBaseColourTextureLandsWhereTheTexcoordsSay) {
  for (const std::string tier : {"realtime", "pathtraced"}) {
    SCOPED_TRACE(tier);
    TempDir dir;
    const RgbImage base = Quadrants();
    penumbra::testing::SlabMaps maps;
    maps.base_color = &base;
    const std::string gltf = penumbra::testing::WriteGltfSlab(dir, "slab", maps);
    const RenderedFrame f = RenderWorld(dir, SlabWorld(gltf, tier, {0, 0, -1}));
    // quadrant centres of the slab, world (+-0.25, +-0.25, 0): 11 pixels off the image centre
    const double fx = 32.0 / std::tan(20.0 * M_PI / 180.0);
    const int d = static_cast<int>(std::lround(fx * 0.25 / 2.0));
    const int c0 = 32 - d, c1 = 32 + d;
    const Eigen::Vector3d red = MeanRadiance(f, c0, c0, 2);
    const Eigen::Vector3d green = MeanRadiance(f, c1, c0, 2);
    const Eigen::Vector3d blue = MeanRadiance(f, c0, c1, 2);
    const Eigen::Vector3d white = MeanRadiance(f, c1, c1, 2);
    // the lit albedo: 10 000 lx / pi on a white Lambertian surface, ~3183 cd/m^2
    EXPECT_GT(red.x(), 2000);
    EXPECT_LT(red.y(), 0.1 * red.x());
    EXPECT_LT(red.z(), 0.1 * red.x());
    EXPECT_GT(green.y(), 2000);
    EXPECT_LT(green.x(), 0.1 * green.y());
    EXPECT_LT(green.z(), 0.1 * green.y());
    EXPECT_GT(blue.z(), 2000);
    EXPECT_LT(blue.x(), 0.1 * blue.z());
    EXPECT_LT(blue.y(), 0.1 * blue.z());
    EXPECT_GT(white.minCoeff(), 2000);
    EXPECT_LT(white.maxCoeff() - white.minCoeff(), 0.05 * white.maxCoeff());
  }
}

// a uniform tangent-space normal map: the unit normal (sin a cos b, sin a sin b, cos a) coded
// as 8-bit (n + 1) / 2.
RgbImage NormalMap(double a_deg, double b_deg) {
  const double a = a_deg * M_PI / 180, b = b_deg * M_PI / 180;
  auto code = [](double v) { return static_cast<uint8_t>(std::lround((v + 1) / 2 * 255)); };
  return RgbImage::Solid(8, 8, code(std::sin(a) * std::cos(b)), code(std::sin(a) * std::sin(b)),
                         code(std::cos(a)));
}

double CentreLuminance(const TempDir& dir, const RgbImage* normal, const std::string& tier,
                       const Eigen::Vector3d& sun_dir, const std::string& stem) {
  const RgbImage base = RgbImage::Solid(8, 8, 200, 200, 200);
  penumbra::testing::SlabMaps maps;
  maps.base_color = &base;
  maps.normal = normal;
  const std::string gltf = penumbra::testing::WriteGltfSlab(dir, stem, maps);
  const RenderedFrame f = RenderWorld(dir, SlabWorld(gltf, tier, sun_dir));
  return MeanRadiance(f, 32, 32, 4).mean();
}

TEST(MeshModel, NormalMapTiltsTheShadingAlongTheTangentFrame) {
  // sun 45 deg above the horizon; a normal tilted 30 deg towards it sees it at 15 deg from
  // the normal, tilted away at 75 deg: Lambert's cosines 0.966 and 0.259 against 0.707 flat.
  // tangent x (red) runs along +u = world +x, y (green) towards the image's top = world +y.
  const double s = std::sqrt(0.5);
  for (const std::string tier : {"realtime", "pathtraced"}) {
    SCOPED_TRACE(tier);
    TempDir dir;
    const RgbImage flat = NormalMap(0, 0);
    const double plain = CentreLuminance(dir, nullptr, tier, {-s, 0, -s}, "plain");
    const double flat_mapped = CentreLuminance(dir, &flat, tier, {-s, 0, -s}, "flat");
    EXPECT_NEAR(flat_mapped / plain, 1.0, 0.02);
    struct Case {
      Eigen::Vector3d sun_dir;  // travel direction; the sun is on the other side
      double tilt_azimuth_deg;  // of the mapped normal, in the tangent frame
      double expected;          // cos(theta_mapped) / cos 45
    };
    const double towards = std::cos(15 * M_PI / 180) / s, away = std::cos(75 * M_PI / 180) / s;
    const Case cases[] = {
        {{-s, 0, -s}, 0, towards},   // sun on +x, normal tilted to +x (red > 0.5)
        {{-s, 0, -s}, 180, away},    // sun on +x, normal tilted to -x
        {{0, -s, -s}, 90, towards},  // sun on +y, normal tilted to +y (green > 0.5)
        {{0, -s, -s}, 270, away},    // sun on +y, normal tilted to -y
    };
    for (const Case& c : cases) {
      SCOPED_TRACE(c.tilt_azimuth_deg);
      const RgbImage tilted = NormalMap(30, c.tilt_azimuth_deg);
      const double base = CentreLuminance(dir, nullptr, tier, c.sun_dir, "base");
      const double mapped = CentreLuminance(dir, &tilted, tier, c.sun_dir, "tilted");
      // the sky (10 cd/m^2 against ~2000 from the sun) and the weak specular lobe of a rough
      // dielectric shift the ratio by a few percent
      EXPECT_NEAR(mapped / base, c.expected, 0.06 * c.expected);
    }
  }
}

TEST(MeshModel, ObjInCentimetresWithYUpLandsInMetresWithZUp) {
  TempDir dir;
  std::string obj = "mtllib box.mtl\nusemtl paint\n";
  for (int i = 0; i < 8; ++i)
    obj += "v " + std::to_string(i & 1 ? 100 : 0) + " " + std::to_string(i & 2 ? 200 : 0) + " " +
           std::to_string(i & 4 ? 50 : 0) + "\n";
  obj += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  dir.Write("box.obj", obj);
  dir.Write("box.mtl", "newmtl paint\nKd 0.2 0.4 0.6\n");
  const std::string yaml =
      "duration_sec: 0.01\n"
      "models:\n"
      "  - {name: box, file: box.obj, units: cm, up_axis: y, pose: {xyz: [1, 2, 0]}}\n";
  const WorldConfig world = LoadWorldFile(dir.Write("world.yaml", yaml));
  SessionOptions options;
  options.build_renderer = false;
  options.add_controllers = false;
  Session session(world, options);
  const SceneDescription& scene = session.scene();
  const WorldSnapshot snap = session.sim().Snapshot();
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(1e30), hi = Eigen::Vector3d::Constant(-1e30);
  int meshes = 0;
  for (const Geom& g : scene.geoms) {
    if (g.shape != GeomShape::kMesh) continue;
    ++meshes;
    EXPECT_EQ(g.name.rfind("box/0_", 0), 0u) << g.name;
    const Pose X_WG = snap.X_WB[g.body] * g.X_BG;
    for (const Eigen::Vector3f& v : scene.meshes[g.mesh].vertices) {
      const Eigen::Vector3d p = X_WG * v.cast<double>();
      lo = lo.cwiseMin(p);
      hi = hi.cwiseMax(p);
    }
    const Material& m = scene.materials[g.material];
    EXPECT_EQ(m.name, "box/paint");
    EXPECT_NEAR(m.base_color.x(), 0.2f, 1e-5f);
    EXPECT_NEAR(m.base_color.z(), 0.6f, 1e-5f);
  }
  EXPECT_EQ(meshes, 1);
  // 100 x 200 x 50 cm, y up: x in [0, 1], y in [-0.5, 0], z in [0, 2] m, then the pose
  EXPECT_NEAR(lo.x(), 1.0, 1e-5);
  EXPECT_NEAR(hi.x(), 2.0, 1e-5);
  EXPECT_NEAR(lo.y(), 1.5, 1e-5);
  EXPECT_NEAR(hi.y(), 2.0, 1e-5);
  EXPECT_NEAR(lo.z(), 0.0, 1e-5);
  EXPECT_NEAR(hi.z(), 2.0, 1e-5);
}

TEST(MeshModel, FlatMeshesLoad) {
  // a floor tile: MuJoCo's qhull cannot hull a flat point set, nor its compiler give a flat
  // mesh in a body an inertia; the generated model keeps it loadable
  TempDir dir;
  dir.Write("tile.obj", "v -0.5 -0.5 0\nv 0.5 -0.5 0\nv 0.5 0.5 0\nv -0.5 0.5 0\nf 1 2 3 4\n");
  const WorldConfig world = LoadWorldFile(dir.Write(
      "world.yaml", "duration_sec: 0.01\nmodels:\n  - {name: tile, file: tile.obj, up_axis: z}\n"));
  SessionOptions options;
  options.build_renderer = false;
  options.add_controllers = false;
  Session session(world, options);
  int meshes = 0;
  for (const Geom& g : session.scene().geoms) {
    if (g.shape != GeomShape::kMesh) continue;
    ++meshes;
    EXPECT_EQ(session.scene().meshes[g.mesh].faces.size(), 2u);
  }
  EXPECT_EQ(meshes, 1);
}

TEST(MeshModel, MalformedMeshFailsNamingTheWorldEntryAndTheFile) {
  TempDir dir;
  const std::string bad = dir.Write("chair.glb", "glTF\x02\x00\x00\x00 not really");
  const std::string path = dir.Write("world.yaml",
                                     "duration_sec: 0.01\n"
                                     "models:\n"
                                     "  - {name: chair, file: chair.glb}\n");
  const WorldConfig world = LoadWorldFile(path);
  SessionOptions options;
  options.build_renderer = false;
  try {
    Session session(world, options);
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    const std::string w = e.what();
    EXPECT_EQ(e.file(), path);
    EXPECT_EQ(e.line(), 3);
    EXPECT_EQ(e.key(), "models[0].file");
    EXPECT_NE(w.find(bad), std::string::npos) << w;
  }
}

TEST(MeshModel, MeshKeysAreCheckedAtLoad) {
  TempDir dir;
  dir.Write("box.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 2 3\nf 1 3 4\n");
  dir.Write("room.xml", "<mujoco><worldbody/></mujoco>\n");
  auto error_of = [&](const std::string& entry) {
    try {
      LoadWorldFile(dir.Write("world.yaml", "models:\n  - " + entry + "\n"));
    } catch (const ConfigError& e) {
      return std::string(e.what());
    }
    return std::string();
  };
  EXPECT_NE(error_of("{name: b, file: box.obj, units: furlong}").find("models[0].units"),
            std::string::npos);
  EXPECT_NE(error_of("{name: b, file: box.obj, up_axis: w}").find("models[0].up_axis"),
            std::string::npos);
  EXPECT_NE(error_of("{name: b, file: box.obj, scale: -1}").find("models[0].scale"),
            std::string::npos);
  EXPECT_NE(error_of("{name: b, file: box.obj, scale: 2, units: cm}").find("one of units and"),
            std::string::npos);
  EXPECT_NE(error_of("{name: r, file: room.xml, units: cm}").find("mesh files only"),
            std::string::npos);
  EXPECT_NE(error_of("{name: b, file: box.step}").find(".gltf"), std::string::npos);
  EXPECT_EQ(error_of("{name: b, file: box.obj, units: mm, up_axis: -z, handedness: left}"), "");
}

}  // namespace
}  // namespace penumbra

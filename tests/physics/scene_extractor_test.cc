// scene extraction: geom shapes and frames, the MJCF -> PBR material mapping,
// textures, lights and the MJCF camera optical frame.

#include "penumbra/physics/scene_extractor.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <fstream>

#include "common/temp_dir.h"
#include "penumbra/physics/simulation.h"

namespace penumbra {
namespace {

constexpr const char* kSceneXml = R"(
<mujoco model="scene">
  <asset>
    <texture name="checker" type="2d" builtin="checker" rgb1=".1 .2 .3" rgb2=".9 .8 .7" width="8" height="8"/>
    <texture name="cube" type="cube" builtin="flat" rgb1=".5 .5 .5" width="4" height="4"/>
    <texture name="sky" type="skybox" builtin="gradient" rgb1=".4 .6 .8" rgb2="0 0 0" width="16" height="16"/>
    <material name="shiny" rgba="0.5 0.2 0.04 0.9" specular="0.3" shininess="0.8" reflectance="0.5" emission="2"/>
    <material name="floor_mat" texture="checker" texrepeat="3 4" texuniform="true"/>
    <mesh name="tet" vertex="0 0 0  1 0 0  0 1 0  0 0 1"/>
    <hfield name="terrain" file="terrain.bin" size="1 2 0.5 0.1"/>
  </asset>
  <worldbody>
    <light name="sun" directional="true" diffuse=".5 .25 0" pos="0 0 5" dir="0 0 -1" castshadow="false"/>
    <light name="lamp" pos="0 0 4" dir="0 0 -1" cutoff="30" exponent="5" diffuse=".2 .4 .4"/>
    <light name="bulb" pos="1 0 3" dir="0 0 -1" cutoff="120" exponent="0"/>
    <geom name="floor" type="plane" size="5 5 0.2" material="floor_mat"/>
    <geom name="ground" type="hfield" hfield="terrain" pos="3 0 0"/>
    <camera name="overview" pos="3 0 1" xyaxes="0 1 0 0 0 1" fovy="60"/>
    <body name="stand" pos="0 0 0.5">
      <geom name="ball" type="sphere" size="0.1" pos="0.2 0 0" material="shiny"/>
      <geom name="pill" type="capsule" size="0.05 0.2" rgba="1 0 0 1"/>
      <geom name="egg" type="ellipsoid" size="0.1 0.2 0.3" rgba="1 0 0 1"/>
      <geom name="can" type="cylinder" size="0.1 0.15" euler="90 0 0" pos="0 0.5 0"/>
      <geom name="crate" type="box" size="0.1 0.2 0.3" material="shiny" rgba="0 1 0 1"/>
      <geom name="ghost" type="box" size="0.1 0.1 0.1" rgba="1 1 1 0"/>
      <geom name="rock" type="mesh" mesh="tet"/>
    </body>
    <body name="rover" pos="0 2 0.3" euler="0 0 90">
      <freejoint/>
      <geom type="box" size="0.2 0.1 0.05"/>
      <camera name="front" pos="0.2 0 0.1" euler="0 -90 -90" fovy="45"/>
      <body name="mast" pos="0 0 0.1"><geom type="sphere" size="0.02"/></body>
    </body>
    <body name="target" mocap="true" pos="1 1 1"><geom type="sphere" size="0.05"/></body>
  </worldbody>
</mujoco>)";

// MuJoCo's binary height field: int32 nrow, int32 ncol, float32 data (row-major)
std::string WriteTerrain() {
  const std::string dir = penumbra::testing::ProcessTempDir();
  std::ofstream f(dir + "/terrain.bin", std::ios::binary);
  const int32_t size[2] = {3, 4};
  f.write(reinterpret_cast<const char*>(size), sizeof(size));
  for (int i = 0; i < 12; ++i) {
    const float v = static_cast<float>(i);
    f.write(reinterpret_cast<const char*>(&v), sizeof(v));
  }
  return dir;
}

class SceneExtractorTest : public ::testing::Test {
 protected:
  SceneExtractorTest()
      : sim_(Simulation::LoadFromString(kSceneXml, std::nullopt, WriteTerrain())) {}
  const SceneDescription& scene() const { return sim_.scene(); }
  const Geom& geom(const std::string& name) const {
    for (const auto& g : scene().geoms)
      if (g.name == name) return g;
    throw std::runtime_error("no geom " + name);
  }
  Simulation sim_;
};

TEST(SrgbToLinear, MatchesIec61966Numerically) {
  EXPECT_EQ(SrgbToLinear(0.0f), 0.0f);
  EXPECT_NEAR(SrgbToLinear(1.0f), 1.0f, 1e-6);
  EXPECT_NEAR(SrgbToLinear(0.04f), 0.04f / 12.92f, 1e-7);  // linear segment
  EXPECT_NEAR(SrgbToLinear(0.5f), 0.2140411f, 1e-6);       // ((0.555) / 1.055)^2.4
  EXPECT_NEAR(SrgbToLinear(0.2f), 0.0331048f, 1e-6);
  EXPECT_NEAR(SrgbToLinear(0.04045f), 0.0031308f, 1e-6);  // continuity at the knee
}

TEST_F(SceneExtractorTest, BodiesAndStaticFlags) {
  const auto& b = scene().bodies;
  ASSERT_EQ(b.size(), 5u);
  EXPECT_EQ(b[0].parent, -1);
  EXPECT_TRUE(b[0].is_static);
  EXPECT_TRUE(b[scene().FindBody("stand")].is_static);
  EXPECT_FALSE(b[scene().FindBody("rover")].is_static);
  EXPECT_FALSE(b[scene().FindBody("mast")].is_static);    // welded to a moving body
  EXPECT_FALSE(b[scene().FindBody("target")].is_static);  // mocap
  EXPECT_EQ(b[scene().FindBody("mast")].parent, scene().FindBody("rover"));
}

TEST_F(SceneExtractorTest, EveryGeomTypeIsMapped) {
  EXPECT_EQ(geom("floor").shape, GeomShape::kPlane);
  EXPECT_EQ(geom("floor").size, Eigen::Vector3d(5, 5, 0.2));
  EXPECT_EQ(geom("ground").shape, GeomShape::kHeightField);
  EXPECT_EQ(geom("ball").shape, GeomShape::kSphere);
  EXPECT_EQ(geom("ball").size.x(), 0.1);
  EXPECT_EQ(geom("pill").shape, GeomShape::kCapsule);
  EXPECT_EQ(geom("pill").size.head<2>(), Eigen::Vector2d(0.05, 0.2));
  EXPECT_EQ(geom("egg").shape, GeomShape::kEllipsoid);
  EXPECT_EQ(geom("egg").size, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(geom("can").shape, GeomShape::kCylinder);
  EXPECT_EQ(geom("crate").shape, GeomShape::kBox);
  EXPECT_EQ(geom("crate").size, Eigen::Vector3d(0.1, 0.2, 0.3));
  EXPECT_EQ(geom("rock").shape, GeomShape::kMesh);
  for (size_t i = 0; i < scene().geoms.size(); ++i) {
    EXPECT_EQ(scene().geoms[i].id, static_cast<int>(i));
    EXPECT_GE(scene().geoms[i].material, 0);
    EXPECT_LT(scene().geoms[i].material, static_cast<int>(scene().materials.size()));
  }
  // geom frames in the body frame
  EXPECT_EQ(geom("ball").body, scene().FindBody("stand"));
  EXPECT_TRUE(geom("ball").X_BG.translation().isApprox(Eigen::Vector3d(0.2, 0, 0)));
  const Eigen::Matrix3d R_can = geom("can").X_BG.linear();
  EXPECT_TRUE((R_can * Eigen::Vector3d::UnitZ()).isApprox(-Eigen::Vector3d::UnitY(), 1e-9));
}

TEST_F(SceneExtractorTest, MeshAndHeightField) {
  const Geom& rock = geom("rock");
  ASSERT_GE(rock.mesh, 0);
  const TriangleMesh& mesh = scene().meshes[rock.mesh];
  EXPECT_EQ(mesh.name, "tet");
  EXPECT_EQ(mesh.vertices.size(), 4u);
  EXPECT_EQ(mesh.normals.size(), 4u);
  EXPECT_EQ(mesh.faces.size(), 4u);  // convex hull of a tetrahedron
  // MuJoCo re-centres the mesh; X_BG puts the vertices back where the MJCF placed them
  std::vector<Eigen::Vector3d> placed;
  for (const auto& v : mesh.vertices) placed.push_back(rock.X_BG * v.cast<double>());
  for (const Eigen::Vector3d& want : {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 0),
                                      Eigen::Vector3d(0, 1, 0), Eigen::Vector3d(0, 0, 1)}) {
    double best = 1e9;
    for (const auto& p : placed) best = std::min(best, (p - want).norm());
    EXPECT_LT(best, 1e-5) << want.transpose();
  }
  const Geom& ground = geom("ground");
  ASSERT_GE(ground.hfield, 0);
  const HeightField& h = scene().hfields[ground.hfield];
  EXPECT_EQ(h.rows, 3);
  EXPECT_EQ(h.cols, 4);
  EXPECT_EQ(h.size_x, 1);
  EXPECT_EQ(h.size_y, 2);
  EXPECT_EQ(h.size_z, 0.5);
  EXPECT_NEAR(h.size_base, 0.1, 1e-12);
  ASSERT_EQ(h.elevation.size(), 12u);
  // MuJoCo normalises elevation to [0, 1]
  for (int i = 0; i < 12; ++i) EXPECT_NEAR(h.elevation[i], i / 11.0, 1e-6) << i;
}

TEST_F(SceneExtractorTest, MaterialsFollowTheDocumentedMapping) {
  const auto& mats = scene().materials;
  const int shiny = scene().FindMaterial("shiny");
  ASSERT_GE(shiny, 0);
  const Material& m = mats[shiny];
  EXPECT_NEAR(m.base_color.x(), SrgbToLinear(0.5f), 1e-7);
  EXPECT_NEAR(m.base_color.x(), 0.2140411f, 1e-6);
  EXPECT_NEAR(m.base_color.y(), 0.0331048f, 1e-6);
  EXPECT_NEAR(m.base_color.z(), 0.04f / 12.92f, 1e-7);
  EXPECT_NEAR(m.alpha, 0.9f, 1e-7);
  EXPECT_NEAR(m.roughness, 1 - 0.8f, 1e-6);
  EXPECT_NEAR(m.reflectance, 0.5f, 1e-6);
  EXPECT_NEAR(m.specular, 0.3f, 1e-7);
  EXPECT_EQ(m.metallic, 0.0f);
  EXPECT_TRUE(m.emission.isApprox(m.base_color * float(2 * kMjcfEmissionLuminance), 1e-5));
  EXPECT_EQ(geom("ball").material, shiny);

  const Material& floor = mats[geom("floor").material];
  EXPECT_EQ(floor.name, "floor_mat");
  EXPECT_EQ(floor.texture, 0);
  EXPECT_EQ(floor.texrepeat, Eigen::Vector2f(3, 4));
  EXPECT_TRUE(floor.texuniform);
  EXPECT_NEAR(floor.roughness, 0.5f, 1e-6);  // MuJoCo default shininess 0.5
  EXPECT_NEAR(floor.specular, 0.5f, 1e-7);   // default specular 0.5 -> F0 = 0.04

  // rgba-only geoms share one generated material
  EXPECT_EQ(geom("pill").material, geom("egg").material);
  const Material& red = mats[geom("pill").material];
  EXPECT_EQ(red.name, "rgba(1 0 0 1)");
  EXPECT_EQ(red.base_color, Eigen::Vector3f(1, 0, 0));
  EXPECT_NEAR(red.roughness, 0.5f, 1e-6);
  // default geom colour (0.5 0.5 0.5 1) without a material
  EXPECT_NEAR(mats[geom("can").material].base_color.x(), 0.2140411f, 1e-6);
  // rgba overriding a material keeps the material's other properties
  const Material& green = mats[geom("crate").material];
  EXPECT_EQ(green.name, "shiny#rgba(0 1 0 1)");
  EXPECT_EQ(green.base_color, Eigen::Vector3f(0, 1, 0));
  EXPECT_NEAR(green.specular, 0.3f, 1e-7);
  EXPECT_NEAR(green.roughness, 0.2f, 1e-6);
  EXPECT_NEAR(green.reflectance, 0.5f, 1e-6);
  // invisible geoms are kept, marked by alpha
  EXPECT_EQ(mats[geom("ghost").material].alpha, 0.0f);
}

TEST_F(SceneExtractorTest, TexturesKeepMujocoPixels) {
  const auto& tex = scene().textures;
  ASSERT_EQ(tex.size(), 3u);
  const Texture& c = tex[0];
  EXPECT_EQ(c.name, "checker");
  EXPECT_EQ(c.kind, Texture::Kind::k2D);
  ASSERT_NE(c.image, nullptr);
  EXPECT_EQ(c.image->width(), 8);
  EXPECT_EQ(c.image->height(), 8);
  ASSERT_EQ(c.image->rgb_srgb().size(), 8u * 8u * 3u);
  auto px = [&](int u, int v, int ch) {
    return static_cast<int>(c.image->rgb_srgb()[(v * 8 + u) * 3 + ch]);
  };
  const float rgb1[3] = {.1f, .2f, .3f}, rgb2[3] = {.9f, .8f, .7f};
  // 2 x 2 checker: rgb1 in the top-left and bottom-right quadrants
  for (int v = 0; v < 8; ++v)
    for (int u = 0; u < 8; ++u) {
      const bool first = (u < 4) == (v < 4);
      for (int ch = 0; ch < 3; ++ch)
        EXPECT_NEAR(px(u, v, ch), 255.0f * (first ? rgb1[ch] : rgb2[ch]), 1.0) << u << "," << v;
    }
  EXPECT_EQ(tex[1].kind, Texture::Kind::kCube);
  EXPECT_EQ(tex[1].image->width(), 4);
  EXPECT_EQ(tex[1].image->height(), 24);  // six faces stacked
  EXPECT_EQ(tex[1].image->faces(), 6);
  EXPECT_EQ(tex[1].image->rgb_srgb().size(), 4u * 24u * 3u);
  EXPECT_NEAR(tex[1].image->rgb_srgb()[0], 127.5, 1.0);
  EXPECT_EQ(tex[2].kind, Texture::Kind::kSkybox);
  EXPECT_EQ(tex[2].image->height(), 6 * tex[2].image->width());
}

// identical pixels are stored once: textures with the same image share one TextureImage (with
// its mip levels, ~4 bytes per texel), and copies of the scene share it too.
TEST(SceneExtractorTextures, IdenticalImagesAreStoredOnce) {
  const Simulation sim = Simulation::LoadFromString(R"(
<mujoco>
  <asset>
    <texture name="a" type="2d" builtin="checker" rgb1=".1 .2 .3" rgb2=".9 .8 .7" width="64" height="64"/>
    <texture name="a_again" type="2d" builtin="checker" rgb1=".1 .2 .3" rgb2=".9 .8 .7" width="64" height="64"/>
    <texture name="b" type="2d" builtin="checker" rgb1=".3 .2 .1" rgb2=".9 .8 .7" width="64" height="64"/>
    <material name="ma" texture="a"/>
    <material name="ma2" texture="a_again"/>
    <material name="mb" texture="b"/>
  </asset>
  <worldbody>
    <geom type="box" size=".1 .1 .1" material="ma"/>
    <geom type="box" size=".1 .1 .1" pos="1 0 0" material="ma2"/>
    <geom type="box" size=".1 .1 .1" pos="2 0 0" material="mb"/>
  </worldbody>
</mujoco>)");
  const std::vector<Texture>& tex = sim.scene().textures;
  ASSERT_EQ(tex.size(), 3u);
  EXPECT_EQ(tex[0].image.get(), tex[1].image.get());
  EXPECT_NE(tex[0].image.get(), tex[2].image.get());
  const TextureMemory m = CountTextureMemory(tex);
  EXPECT_EQ(m.textures, 3);
  EXPECT_EQ(m.images, 2);
  EXPECT_EQ(m.texels, 2u * 64 * 64);
  // 8-bit RGB plus mip levels: 3 x 4/3 bytes per texel, not 16 (float RGBA).
  EXPECT_LE(m.bytes_per_texel(), 4.01);
  const SceneDescription copy = sim.scene();
  EXPECT_EQ(copy.textures[2].image.get(), tex[2].image.get());
}

TEST_F(SceneExtractorTest, LightsArePhotometric) {
  const auto& lights = scene().lights;
  ASSERT_EQ(lights.size(), 3u);
  const Light& sun = lights[0];
  EXPECT_EQ(sun.name, "sun");
  EXPECT_EQ(sun.type, Light::Type::kDirectional);
  EXPECT_EQ(sun.mjcf_light, 0);
  EXPECT_NEAR(sun.intensity, 0.5 * kMjcfDirectionalLux, 1e-3);
  EXPECT_TRUE(sun.color.isApprox(Eigen::Vector3f(1, 0.5f, 0)));
  EXPECT_TRUE(sun.direction_B.isApprox(Eigen::Vector3d(0, 0, -1)));
  EXPECT_FALSE(sun.cast_shadow);
  EXPECT_TRUE(sun.active);

  const Light& lamp = lights[1];
  EXPECT_EQ(lamp.type, Light::Type::kSpot);
  EXPECT_EQ(lamp.mjcf_light, 1);
  EXPECT_NEAR(lamp.spot_outer_deg, 30.0f, 1e-5);
  // half-intensity angle of cos^5: acos(0.5^(1/5)) = 29.4773 deg, below the cutoff
  EXPECT_NEAR(lamp.spot_inner_deg, std::acos(std::pow(0.5, 0.2)) * 180 / M_PI, 1e-4);
  EXPECT_NEAR(lamp.spot_inner_deg, 29.4773, 1e-3);
  EXPECT_TRUE(lamp.color.isApprox(Eigen::Vector3f(0.5f, 1, 1)));
  const double r = std::max((Eigen::Vector3d(0, 0, 4) - scene().center_W).norm(), 1.0);
  EXPECT_NEAR(lamp.intensity, kMjcfDirectionalLux * 0.4 * r * r, 1e-3 * lamp.intensity);
  EXPECT_TRUE(lamp.position_B.isApprox(Eigen::Vector3d(0, 0, 4)));

  EXPECT_EQ(lights[2].type, Light::Type::kPoint);                   // cutoff >= 90
  EXPECT_TRUE(lights[2].color.isApprox(Eigen::Vector3f(1, 1, 1)));  // default diffuse 0.7
}

TEST_F(SceneExtractorTest, MjcfCameraOpticalFrame) {
  const auto& cams = scene().cameras;
  ASSERT_EQ(cams.size(), 2u);
  const CameraSpec& cam = cams[scene().FindCamera("overview")];
  EXPECT_EQ(cam.mjcf_camera, 0);
  EXPECT_EQ(cam.body, 0);
  EXPECT_EQ(cam.intrinsics.width, 640);
  EXPECT_EQ(cam.intrinsics.height, 480);
  EXPECT_NEAR(cam.intrinsics.fy, 240.0 / std::tan(30 * M_PI / 180), 1e-9);
  // the camera at (3, 0, 1) looks along -x (its -z axis) at (0, 0, 1)
  const Pose X_WO = cam.X_BO;  // fixed to the world body
  const Eigen::Vector3d p = X_WO.inverse() * Eigen::Vector3d(0, 0, 1);
  EXPECT_TRUE(p.isApprox(Eigen::Vector3d(0, 0, 3), 1e-12)) << p.transpose();
  // world up is image up (optical -y); world +y is image right (optical +x)
  EXPECT_LT((X_WO.inverse() * Eigen::Vector3d(0, 0, 2)).y(), 0);
  EXPECT_GT((X_WO.inverse() * Eigen::Vector3d(0, 1, 1)).x(), 0);

  // a camera on a moving body: body pose x X_BO equals the snapshot's MuJoCo camera pose
  const CameraSpec& front = cams[scene().FindCamera("front")];
  EXPECT_EQ(front.body, scene().FindBody("rover"));
  for (int i = 0; i < 50; ++i) sim_.Step();
  const WorldSnapshot snap = sim_.Snapshot();
  const Pose via_body = snap.X_WB[front.body] * front.X_BO;
  Pose via_mj = snap.X_W_mjcam[front.mjcf_camera];
  via_mj.linear() = via_mj.linear() * RotationMujocoCameraFromOptical();
  EXPECT_TRUE(via_body.matrix().isApprox(via_mj.matrix(), 1e-9));
  // euler="0 -90 -90" on a body yawed by 90 deg: the camera looks along the body's +x = world +y
  const Eigen::Vector3d forward_W = via_body.linear().col(2);
  EXPECT_TRUE(forward_W.isApprox(Eigen::Vector3d(0, 1, 0), 1e-6)) << forward_W.transpose();
}

TEST_F(SceneExtractorTest, SnapshotPosesLightsAndBounds) {
  const WorldSnapshot snap = sim_.Snapshot();
  ASSERT_EQ(snap.light_position_W.size(), 3u);
  EXPECT_TRUE(snap.light_position_W[1].isApprox(Eigen::Vector3d(0, 0, 4)));
  EXPECT_TRUE(snap.light_direction_W[1].isApprox(Eigen::Vector3d(0, 0, -1)));
  EXPECT_TRUE(snap.X_WB[0].isApprox(Pose::Identity()));
  EXPECT_TRUE(
      snap.X_WB[scene().FindBody("target")].translation().isApprox(Eigen::Vector3d(1, 1, 1)));
  EXPECT_GT(scene().extent_m, 1.0);
}

}  // namespace
}  // namespace penumbra

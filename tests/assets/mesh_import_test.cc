// mesh files imported through assimp in metres, z up, with their PBR maps.
#include "penumbra/assets/mesh_import.h"

#include <gtest/gtest.h>

#include <string>

#include "common/gltf_slab.h"
#include "common/temp_dir.h"
#include "penumbra/assets/mesh_model.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using penumbra::testing::RgbImage;
using penumbra::testing::TempDir;

// a box 100 cm (x) by 200 cm (y, up) by 50 cm (z) with its corner at the origin, Y-up, in cm.
std::string BoxObjCm() {
  std::string s = "# box in centimetres, y up\nmtllib box.mtl\n";
  for (int i = 0; i < 8; ++i)
    s += "v " + std::to_string(i & 1 ? 100 : 0) + " " + std::to_string(i & 2 ? 200 : 0) + " " +
         std::to_string(i & 4 ? 50 : 0) + "\n";
  s += "usemtl wood\n";
  // quads, counter-clockwise from outside (1-based)
  s += "f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
  return s;
}

void Bounds(const ImportedAsset& a, Eigen::Vector3f* lo, Eigen::Vector3f* hi) {
  *lo = Eigen::Vector3f::Constant(1e30f);
  *hi = Eigen::Vector3f::Constant(-1e30f);
  for (const ImportedMesh& m : a.meshes)
    for (const Eigen::Vector3f& v : m.mesh.vertices) {
      *lo = lo->cwiseMin(v);
      *hi = hi->cwiseMax(v);
    }
}

TEST(MeshImport, ObjInCentimetresYUpLandsInMetresZUp) {
  TempDir dir;
  dir.Write("box.mtl", "newmtl wood\nKd 0.5 0.25 0.125\nNs 10\n");
  const std::string obj = dir.Write("box.obj", BoxObjCm());
  MeshImportConfig config;
  config.scale = 0.01;  // units: cm
  config.up_axis = "y";
  const ImportedAsset a = ImportMeshFile(obj, config);
  Eigen::Vector3f lo, hi;
  Bounds(a, &lo, &hi);
  // (x, y, z)_file cm -> (x, -z, y) m: x in [0, 1], y in [-0.5, 0], z in [0, 2]
  EXPECT_NEAR(lo.x(), 0.0f, 1e-6f);
  EXPECT_NEAR(hi.x(), 1.0f, 1e-6f);
  EXPECT_NEAR(lo.y(), -0.5f, 1e-6f);
  EXPECT_NEAR(hi.y(), 0.0f, 1e-6f);
  EXPECT_NEAR(lo.z(), 0.0f, 1e-6f);
  EXPECT_NEAR(hi.z(), 2.0f, 1e-6f);
  EXPECT_EQ(a.triangles, 12);
  EXPECT_EQ(a.up_axis, "y");
  EXPECT_DOUBLE_EQ(a.scale, 0.01);
  // outward faces stay outward (a proper rotation): every face normal points away from the centre
  const Eigen::Vector3f centre(0.5f, -0.25f, 1.0f);
  for (const ImportedMesh& m : a.meshes)
    for (const Eigen::Vector3i& f : m.mesh.faces) {
      const Eigen::Vector3f& p0 = m.mesh.vertices[f[0]];
      const Eigen::Vector3f n = (m.mesh.vertices[f[1]] - p0).cross(m.mesh.vertices[f[2]] - p0);
      EXPECT_GT(n.dot(p0 - centre), 0.0f);
    }
  ASSERT_EQ(a.materials.size(), 1u);
  EXPECT_EQ(a.materials[0].name, "wood");
  EXPECT_NEAR(a.materials[0].factors.base_color.x(), 0.5f, 1e-6f);
  EXPECT_NEAR(a.materials[0].factors.base_color.y(), 0.25f, 1e-6f);
  // Blinn-Phong exponent 10 -> roughness (2 / 12)^(1/4)
  EXPECT_NEAR(a.materials[0].factors.roughness, std::pow(2.0f / 12.0f, 0.25f), 1e-5f);
}

TEST(MeshImport, LeftHandedFilesAreMirroredAndKeepOutwardFaces) {
  TempDir dir;
  dir.Write("box.mtl", "newmtl wood\nKd 1 1 1\n");
  const std::string obj = dir.Write("box.obj", BoxObjCm());
  MeshImportConfig config;
  config.scale = 0.01;
  config.up_axis = "z";
  config.left_handed = true;
  const ImportedAsset a = ImportMeshFile(obj, config);
  Eigen::Vector3f lo, hi;
  Bounds(a, &lo, &hi);
  EXPECT_NEAR(lo.x(), -1.0f, 1e-6f);  // x negated
  EXPECT_NEAR(hi.x(), 0.0f, 1e-6f);
  EXPECT_NEAR(hi.y(), 2.0f, 1e-6f);
  EXPECT_NEAR(hi.z(), 0.5f, 1e-6f);
  const Eigen::Vector3f centre(-0.5f, 1.0f, 0.25f);
  for (const ImportedMesh& m : a.meshes)
    for (const Eigen::Vector3i& f : m.mesh.faces) {
      const Eigen::Vector3f& p0 = m.mesh.vertices[f[0]];
      const Eigen::Vector3f n = (m.mesh.vertices[f[1]] - p0).cross(m.mesh.vertices[f[2]] - p0);
      EXPECT_GT(n.dot(p0 - centre), 0.0f);
    }
}

TEST(MeshImport, MalformedMeshNamesTheFile) {
  TempDir dir;
  const std::string bad =
      dir.Write("broken.gltf", "{\"asset\": {\"version\": \"2.0\"}, \"meshes\": [");
  try {
    ImportMeshFile(bad, {});
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), bad);
    EXPECT_NE(std::string(e.what()).find("broken.gltf"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("expected"), std::string::npos) << e.what();
  }
  const std::string garbage = dir.Write("garbage.obj", "this is not\x01\x02 a mesh\nf 1 2 3\n");
  EXPECT_THROW(ImportMeshFile(garbage, {}), ConfigError);
  const std::string empty = dir.Write("empty.stl", "");
  try {
    ImportMeshFile(empty, {});
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("empty.stl"), std::string::npos) << e.what();
  }
}

TEST(MeshImport, MissingTextureNamesTextureAndMaterial) {
  TempDir dir;
  dir.Write("box.mtl", "newmtl wood\nKd 1 1 1\nmap_Kd planks.png\n");
  const std::string obj = dir.Write("box.obj", BoxObjCm());
  try {
    ImportMeshFile(obj, {});
    FAIL() << "expected a ConfigError";
  } catch (const ConfigError& e) {
    const std::string w = e.what();
    EXPECT_NE(w.find("planks.png"), std::string::npos) << w;
    EXPECT_NE(w.find("wood"), std::string::npos) << w;
    EXPECT_NE(w.find("box.obj"), std::string::npos) << w;
  }
}

TEST(MeshImport, GltfMaterialsBringTheirMapsAndFactors) {
  TempDir dir;
  const RgbImage base = RgbImage::Solid(8, 4, 200, 100, 50);
  const RgbImage normal = RgbImage::Solid(4, 4, 128, 128, 255);
  const RgbImage mr = RgbImage::Solid(2, 2, 0, 128, 255);
  penumbra::testing::SlabMaps maps;
  maps.base_color = &base;
  maps.normal = &normal;
  maps.normal_scale = 0.5f;
  maps.metallic_roughness = &mr;
  maps.metallic = 0.25f;
  maps.roughness = 0.75f;
  const std::string gltf = penumbra::testing::WriteGltfSlab(dir, "slab", maps);
  const ImportedAsset a = ImportMeshFile(gltf, {});
  EXPECT_EQ(a.up_axis, "y");  // glTF's default
  ASSERT_EQ(a.materials.size(), 1u);
  const ImportedMaterial& m = a.materials[0];
  EXPECT_EQ(m.name, "slab_material");
  ASSERT_TRUE(m.base_color && m.normal && m.metallic_roughness);
  EXPECT_EQ(m.base_color->width(), 8);
  EXPECT_EQ(m.base_color->height(), 4);
  // colour codes as in the file
  EXPECT_EQ(m.base_color->rgb_srgb()[0], 200);
  EXPECT_EQ(m.base_color->rgb_srgb()[1], 100);
  // data maps: the decoded value is the file's code / 255 (normal x, y scaled by 0.5 about 0.5)
  const float* decode = SrgbDecodeTable();
  EXPECT_NEAR(decode[m.metallic_roughness->rgb_srgb()[1]], 128 / 255.0f, 0.005f);
  EXPECT_NEAR(decode[m.metallic_roughness->rgb_srgb()[2]], 1.0f, 0.005f);
  EXPECT_NEAR(decode[m.normal->rgb_srgb()[2]], 1.0f, 0.005f);
  EXPECT_FLOAT_EQ(m.factors.metallic, 0.25f);
  EXPECT_FLOAT_EQ(m.factors.roughness, 0.75f);
  EXPECT_FALSE(m.occlusion);
  EXPECT_FALSE(m.emissive);
  // the top face (file +y) is at world z = 0 with texcoord (0, 0) at world (-0.5, 0.5)
  bool found = false;
  for (const ImportedMesh& mesh : a.meshes)
    for (size_t i = 0; i < mesh.mesh.vertices.size(); ++i) {
      const Eigen::Vector3f& v = mesh.mesh.vertices[i];
      if ((v - Eigen::Vector3f(-0.5f, 0.5f, 0)).norm() < 1e-6f &&
          mesh.mesh.normals[i].z() > 0.99f) {
        EXPECT_NEAR(mesh.mesh.texcoords[i].x(), 0.0f, 1e-6f);
        EXPECT_NEAR(mesh.mesh.texcoords[i].y(), 0.0f, 1e-6f);
        found = true;
      }
    }
  EXPECT_TRUE(found);
}

TEST(MeshImport, MshBytesFollowMujocosLayout) {
  TriangleMesh m;
  m.vertices = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}};
  m.texcoords = {{0, 0}, {1, 0}, {0, 1}};
  m.faces = {{0, 1, 2}};
  const std::string b = MshBytes(m);
  int32_t head[4];
  std::memcpy(head, b.data(), 16);
  EXPECT_EQ(head[0], 4);  // padded to MuJoCo's minimum of 4 vertices
  EXPECT_EQ(head[1], 0);
  EXPECT_EQ(head[2], 4);
  EXPECT_EQ(head[3], 1);
  EXPECT_EQ(b.size(), 16u + 4 * 12 + 4 * 8 + 12);
}

TEST(MeshImport, DataMapsStoreTheirValuesSoThatMipsAverageThem) {
  // a normal map texel tilted along x (code 255, 128, 128 -> n = (1, 0, 0)) next to a flat one
  // (128, 128, 255): stored, their 1 x 1 mip level decodes to the mean of the values
  std::vector<uint8_t> rgb = {255, 128, 128, 128, 128, 255};
  StoreTexels(TextureMap::kNormal, 1.0f, &rgb);
  const TextureImage image(2, 1, 1, rgb);
  const float* decode = SrgbDecodeTable();
  EXPECT_NEAR(decode[image.level(0).rgb_srgb[0]], 1.0f, 0.005f);
  EXPECT_NEAR(decode[image.level(0).rgb_srgb[3]], 128 / 255.0f, 0.005f);
  ASSERT_EQ(image.num_levels(), 2);
  EXPECT_NEAR(decode[image.level(1).rgb_srgb[0]], 0.5f * (1.0f + 128 / 255.0f), 0.005f);
  EXPECT_NEAR(decode[image.level(1).rgb_srgb[2]], 0.5f * (128 / 255.0f + 1.0f), 0.005f);
  // the normal scale halves x and y about 0.5; occlusion strength 0.25 lifts R towards 1
  std::vector<uint8_t> n = {255, 0, 255};
  StoreTexels(TextureMap::kNormal, 0.5f, &n);
  EXPECT_NEAR(decode[n[0]], 0.75f, 0.005f);
  EXPECT_NEAR(decode[n[1]], 0.25f, 0.005f);
  std::vector<uint8_t> o = {0, 0, 0};
  StoreTexels(TextureMap::kOcclusion, 0.25f, &o);
  EXPECT_NEAR(decode[o[0]], 0.75f, 0.005f);
}

}  // namespace
}  // namespace penumbra

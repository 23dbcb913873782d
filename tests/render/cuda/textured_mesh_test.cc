// meshes' vertex normals and texture coordinates in the CUDA backend, run on the CPU (no GPU
// needed), on the generated world of textured_mesh_world.h (a coarse sphere mesh with vertex
// normals and texcoords, a 2d checker texture and normal map, a cube-textured box, a skybox):
// - BvhRayQuery's hits (the PB_HOST_DEVICE HitShadingNormal / HitTexcoords the GPU runs) carry
//   the shading normal, texcoords, uv_per_m and duv_dp_G of Embree's RayScene;
// - the realtime rgb of the GPU path on the host (RenderRealtimeOnHost) matches the CPU backend
//   (rgb PSNR >= 40 dB, depth within 1 mm on >= 99.9 % of pixels), while the same path without
//   them (flat, untextured) stays below 30 dB; the box in its cube
//   texture and the skybox are in the frame too.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>
#include <memory>
#include <span>
#include <vector>

#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/cuda/realtime_host.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/frame/bvh_ray_query.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/material/material_eval.h"
#include "penumbra/render/sky/sky_model.h"
#include "realtime_parity.h"
#include "textured_mesh_world.h"

namespace penumbra {
namespace {

// the GPU path's frame of `view` run on the host over `gpu_scene`.
RenderedFrame HostPathFrame(const SceneDescription& gpu_scene, const WorldSnapshot& snap,
                            const CameraView& view) {
  RenderSettings settings;
  cuda::BvhScene bvh(gpu_scene);
  bvh.Update(snap);
  cuda::RealtimeFrameData data(gpu_scene, settings);
  ThreadPool pool(0);
  data.Prepare(snap, view, &pool);
  RenderedFrame f;
  cuda::RenderRealtimeOnHost(data, bvh, &pool, &f);
  return f;
}

TEST(TexturedMeshWorld, HasTheTexturedNormalMappedMeshTheCubeTexturedBoxAndTheSkybox) {
  Simulation sim = textured_mesh::Load();
  const SceneDescription& scene = sim.scene();
  ASSERT_EQ(scene.meshes.size(), 1u);
  EXPECT_EQ(scene.meshes[0].normals.size(), scene.meshes[0].vertices.size());
  EXPECT_EQ(scene.meshes[0].texcoords.size(), scene.meshes[0].vertices.size());
  const MaterialEvaluator materials(scene);
  int textured = 0, normal_mapped = 0, cube = 0;
  for (const Geom& g : scene.geoms) {
    if (g.material < 0 || scene.materials[g.material].texture < 0) continue;
    const Texture& t = scene.textures[scene.materials[g.material].texture];
    textured += g.shape == GeomShape::kMesh && t.kind == Texture::Kind::k2D;
    normal_mapped += g.shape == GeomShape::kMesh && materials.pbr_maps(g.material).normal >= 0;
    cube += g.shape == GeomShape::kBox && t.kind == Texture::Kind::kCube;
  }
  EXPECT_EQ(textured, 1);
  EXPECT_EQ(normal_mapped, 1);
  EXPECT_EQ(cube, 1);
  EXPECT_NE(MjcfSkyboxOf(scene).image, nullptr);
}

// every pixel-centre ray of the camera at 160x120 through both queries: where both hit the
// same geom, the shading normal within 1e-4 (and not the geometric one on the mesh), the
// texcoords within 1e-4 and uv_per_m and duv_dp_G equal (the same shared build code).
TEST(TexturedMeshBvh, HitsCarryEmbreesShadingNormalAndTexcoords) {
  Simulation sim = textured_mesh::Load();
  const SceneDescription& scene = sim.scene();
  const WorldSnapshot snap = sim.Snapshot();
  RayScene embree(scene);
  embree.Update(snap);
  cuda::BvhRayQuery bvh(scene);
  bvh.Update(snap);
  const CameraView view = textured_mesh::View(scene, snap, 160, 120);
  const Camera camera(view.X_WO, view.intrinsics);
  std::vector<Ray> rays;
  for (int v = 0; v < 120; ++v)
    for (int u = 0; u < 160; ++u) rays.push_back(camera.GenerateRay(u, v));
  std::vector<SurfaceHit> he(rays.size()), hb(rays.size());
  std::unique_ptr<bool[]> de(new bool[rays.size()]), db(new bool[rays.size()]);
  embree.Intersect(rays, he, std::span<bool>(de.get(), rays.size()));
  bvh.Intersect(rays, hb, std::span<bool>(db.get(), rays.size()));
  int mesh_hits = 0, smooth = 0, compared = 0, ns_bad = 0, uv_bad = 0, terms_bad = 0;
  float worst_ns = 0, worst_uv = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (!de[i] || !db[i] || he[i].geom != hb[i].geom) continue;
    ++compared;
    const float dn = (he[i].ns_W - hb[i].ns_W).cwiseAbs().maxCoeff();
    worst_ns = std::max(worst_ns, dn);
    ns_bad += dn > 1e-4f;
    if (he[i].has_uv != hb[i].has_uv) {
      ++uv_bad;
      continue;
    }
    if (!he[i].has_uv) continue;
    ++mesh_hits;
    smooth += (hb[i].ns_W - hb[i].ng_W).norm() > 1e-3f;
    const float du = (he[i].uv - hb[i].uv).cwiseAbs().maxCoeff();
    worst_uv = std::max(worst_uv, du);
    uv_bad += du > 1e-4f;
    terms_bad += he[i].uv_per_m != hb[i].uv_per_m || he[i].duv_dp_G != hb[i].duv_dp_G;
  }
  std::printf(
      "textured mesh 160x120: %d rays hit one geom in both, %d on the mesh (%d with ns != ng); "
      "worst |ns| diff %.2e, worst |uv| diff %.2e\n",
      compared, mesh_hits, smooth, worst_ns, worst_uv);
  EXPECT_GT(mesh_hits, 1000);
  EXPECT_GT(smooth, mesh_hits / 2);
  EXPECT_LE(ns_bad, compared / 1000);
  EXPECT_LE(uv_bad, mesh_hits / 1000);
  EXPECT_EQ(terms_bad, 0);
}

// the realtime rgb of the GPU path (on the host) against the CPU backend: >= 40 dB with the
// mesh's normals, texcoords and texture and the skybox; the flat, untextured path of before
// (the same scene without them, against the same CPU frame) stays below 30 dB.
TEST(TexturedMeshHostPath, MatchesCpuBackendWhereTheFlatUntexturedPathDoesNot) {
  Simulation sim = textured_mesh::Load();
  const SceneDescription& scene = sim.scene();
  const WorldSnapshot snap = sim.Snapshot();
  const CameraView view = textured_mesh::View(scene, snap, 160, 120);
  RenderSettings cpu_settings;
  cpu_settings.backend = RenderSettings::Backend::kEmbree;
  RenderedFrame want;
  MakeRenderer(scene, cpu_settings)->Render(snap, view, &want);
  const RenderedFrame got = HostPathFrame(scene, snap, view);
  const RenderedFrame again = HostPathFrame(scene, snap, view);
  const SceneDescription flat_scene = textured_mesh::FlatUntextured(scene);
  const RenderedFrame flat = HostPathFrame(flat_scene, snap, view);
  const double psnr = realtime_parity::Psnr(want.rgb, got.rgb);
  const double psnr_flat = realtime_parity::Psnr(want.rgb, flat.rgb);
  const double depth_bad = realtime_parity::DepthMismatch(want.depth_m, got.depth_m);
  std::printf(
      "textured mesh 160x120: rgb PSNR %.2f dB (flat untextured %.2f dB), depth > 1 mm on "
      "%.4f %% of pixels\n",
      psnr, psnr_flat, 100 * depth_bad);
  EXPECT_GE(psnr, 40.0);
  EXPECT_LT(psnr_flat, 30.0);
  EXPECT_LE(depth_bad, 0.001);
  EXPECT_EQ(got.rgb.data, again.rgb.data);
  EXPECT_EQ(got.radiance.data, again.radiance.data);
}

}  // namespace
}  // namespace penumbra

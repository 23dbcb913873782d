// meshes' vertex normals and texture coordinates on the GPU (ctest label `gpu`), on the
// generated world of textured_mesh_world.h: CudaRenderer's realtime rgb against the CPU backend
// at 640x480 (rgb PSNR >= 40 dB, depth within 1 mm on >= 99.9 % of pixels, two renders
// bit-identical; the flat, untextured frame of before stays below 30 dB), and CudaRayQuery's
// hits carry Embree's shading normals and texcoords. without a device every test prints
// "skipped: no CUDA device".

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>
#include <span>
#include <vector>

#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/cuda/cuda_ray_query.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/embree/ray_scene.h"
#include "realtime_parity.h"
#include "textured_mesh_world.h"

namespace penumbra {
namespace {

TEST(TexturedMeshGpu, RealtimeRgbMatchesCpuBackendAndRepeatsBitForBit) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  Simulation sim = textured_mesh::Load();
  const SceneDescription& scene = sim.scene();
  const WorldSnapshot snap = sim.Snapshot();
  const CameraView view = textured_mesh::View(scene, snap, 640, 480);
  RenderSettings cpu_settings;
  cpu_settings.backend = RenderSettings::Backend::kEmbree;
  RenderSettings gpu_settings;
  gpu_settings.backend = RenderSettings::Backend::kCuda;
  RenderedFrame want, got, again, flat;
  MakeRenderer(scene, cpu_settings)->Render(snap, view, &want);
  const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, gpu_settings);
  auto* g = dynamic_cast<cuda::CudaRenderer*>(gpu.get());
  ASSERT_NE(g, nullptr);
  gpu->Render(snap, view, &got);
  gpu->Render(snap, view, &again);
  EXPECT_EQ(g->gpu_frames(), 2);
  const SceneDescription flat_scene = textured_mesh::FlatUntextured(scene);
  MakeRenderer(flat_scene, gpu_settings)->Render(snap, view, &flat);
  const double psnr = realtime_parity::Psnr(want.rgb, got.rgb);
  const double psnr_flat = realtime_parity::Psnr(want.rgb, flat.rgb);
  const double depth_bad = realtime_parity::DepthMismatch(want.depth_m, got.depth_m);
  std::printf(
      "textured mesh 640x480 on the GPU: rgb PSNR %.2f dB (flat untextured %.2f dB), depth > "
      "1 mm on %.4f %% of pixels, second render %s\n",
      psnr, psnr_flat, 100 * depth_bad,
      got.rgb.data == again.rgb.data && got.radiance.data == again.radiance.data ? "bit-identical"
                                                                                 : "DIFFERENT");
  EXPECT_GE(psnr, 40.0);
  EXPECT_LT(psnr_flat, 30.0);
  EXPECT_LE(depth_bad, 0.001);
  EXPECT_EQ(got.rgb.data, again.rgb.data);
  EXPECT_EQ(got.radiance.data, again.radiance.data);
}

TEST(TexturedMeshGpu, RayQueryHitsCarryEmbreesShadingNormalAndTexcoords) {
  if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device";
  Simulation sim = textured_mesh::Load();
  const SceneDescription& scene = sim.scene();
  const WorldSnapshot snap = sim.Snapshot();
  RayScene embree(scene);
  embree.Update(snap);
  cuda::CudaRayQuery query(scene);
  query.Update(snap);
  const CameraView view = textured_mesh::View(scene, snap, 320, 240);
  const Camera camera(view.X_WO, view.intrinsics);
  std::vector<Ray> rays;
  for (int v = 0; v < 240; ++v)
    for (int u = 0; u < 320; ++u) rays.push_back(camera.GenerateRay(u, v));
  std::vector<SurfaceHit> he(rays.size()), hg(rays.size());
  std::unique_ptr<bool[]> de(new bool[rays.size()]), dg(new bool[rays.size()]);
  embree.Intersect(rays, he, std::span<bool>(de.get(), rays.size()));
  query.Intersect(rays, hg, std::span<bool>(dg.get(), rays.size()));
  int compared = 0, on_mesh = 0, bad = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (!de[i] || !dg[i] || he[i].geom != hg[i].geom) continue;
    ++compared;
    on_mesh += hg[i].has_uv;
    bad += he[i].has_uv != hg[i].has_uv ||
           (he[i].ns_W - hg[i].ns_W).cwiseAbs().maxCoeff() > 1e-4f ||
           (he[i].uv - hg[i].uv).cwiseAbs().maxCoeff() > 1e-4f;
  }
  std::printf("textured mesh 320x240 CudaRayQuery: %d hits compared, %d on the mesh, %d differ\n",
              compared, on_mesh, bad);
  EXPECT_GT(on_mesh, 4000);
  EXPECT_LE(bad, compared / 1000);
}

}  // namespace
}  // namespace penumbra

// the CUDA backend on a GPU (ctest label `gpu`): the device traversal gives the host
// traversal's hits (the same PB_HOST_DEVICE code on both processors), and the CUDA renderer's
// depth, segmentation, instance and semantic segmentation, range and normals agree with the
// CPU backend on the bundled default, house and warehouse worlds (depth within 1 mm and
// segmentation equal on >= 99.9 % of pixels; normals within 1e-3 on >= 99.9 %). without a
// device every test prints "skipped: no CUDA device".

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "path_parity.h"
#include "penumbra/core/exp_rn.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/cuda/cuda_ray_query.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/frame/bvh_ray_query.h"
#include "penumbra/scene/camera_pose.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

#define PB_REQUIRE_CUDA_DEVICE()                                                 \
  do {                                                                           \
    if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device"; \
  } while (0)

std::unique_ptr<Session> LoadBundled(const std::string& name) {
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  return std::make_unique<Session>(
      LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/" + name), so);
}

class CudaBackendWorlds : public ::testing::TestWithParam<std::string> {};

TEST_P(CudaBackendWorlds, DeviceTraversalGivesHostTraversalHits) {
  PB_REQUIRE_CUDA_DEVICE();
  const std::unique_ptr<Session> session = LoadBundled(GetParam());
  const WorldSnapshot snap = session->sim().Snapshot();
  cuda::BvhRayQuery host(session->scene());
  cuda::CudaRayQuery device(session->scene());
  host.Update(snap);
  device.Update(snap);
  std::vector<Ray> rays;
  for (int j = 0; j < 200; ++j)
    for (int i = 0; i < 200; ++i) {
      Ray r;
      r.o = {0, 0, 1.2f};
      const float a = 6.2831853f * i / 200, e = -0.8f + 1.2f * j / 200;
      r.d = {std::cos(a) * std::cos(e), std::sin(a) * std::cos(e), std::sin(e)};
      rays.push_back(r);
    }
  std::vector<SurfaceHit> hh(rays.size()), hd(rays.size());
  std::unique_ptr<bool[]> dh(new bool[rays.size()]), dd(new bool[rays.size()]);
  host.Intersect(rays, hh, std::span<bool>(dh.get(), rays.size()));
  device.Intersect(rays, hd, std::span<bool>(dd.get(), rays.size()));
  int mismatch = 0, hits = 0;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (dh[i] != dd[i]) {
      ++mismatch;
      continue;
    }
    if (!dh[i]) continue;
    ++hits;
    // the GPU contracts multiply-adds (FMA): the last bits of t may differ
    if (hh[i].geom != hd[i].geom || std::abs(hh[i].t - hd[i].t) > 1e-4f * (1 + hh[i].t)) ++mismatch;
  }
  EXPECT_GT(hits, static_cast<int>(rays.size()) / 2);
  EXPECT_LE(mismatch, static_cast<int>(rays.size()) / 1000);
  // occlusion agrees with the closest hits: a segment to just before the hit is clear, one
  // past it blocked
  std::vector<Ray> shorter, longer;
  for (size_t i = 0; i < rays.size(); ++i) {
    if (!dh[i] || hh[i].t < 0.1f) continue;
    Ray s = rays[i];
    s.tmax = hh[i].t * 0.99f;
    shorter.push_back(s);
    s.tmax = hh[i].t * 1.01f;
    longer.push_back(s);
  }
  std::unique_ptr<bool[]> os(new bool[shorter.size()]), ol(new bool[longer.size()]);
  device.Occluded(shorter, std::span<bool>(os.get(), shorter.size()));
  device.Occluded(longer, std::span<bool>(ol.get(), longer.size()));
  int wrong = 0;
  for (size_t i = 0; i < shorter.size(); ++i) wrong += os[i] ? 1 : 0;
  for (size_t i = 0; i < longer.size(); ++i) wrong += ol[i] ? 0 : 1;
  EXPECT_LE(wrong, static_cast<int>(shorter.size()) / 500);
}

TEST_P(CudaBackendWorlds, GroundTruthImagesMatchCpuBackend) {
  PB_REQUIRE_CUDA_DEVICE();
  const std::unique_ptr<Session> session = LoadBundled(GetParam());
  const SceneDescription& scene = session->scene();
  ASSERT_FALSE(scene.cameras.empty());
  RenderSettings cpu_settings;
  cpu_settings.backend = RenderSettings::Backend::kEmbree;
  RenderSettings gpu_settings;
  gpu_settings.backend = RenderSettings::Backend::kCuda;
  const std::unique_ptr<Renderer> cpu = MakeRenderer(scene, cpu_settings);
  const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, gpu_settings);
  ASSERT_NE(dynamic_cast<cuda::CudaRenderer*>(gpu.get()), nullptr);
  for (int step = 0; step < 2; ++step) {
    for (int s = 0; s < 200; ++s) session->sim().Step();
    const WorldSnapshot snap = session->sim().Snapshot();
    CameraView view;
    const CameraSpec& cam = scene.cameras.front();
    view.X_WO = CameraPoseInWorld(cam, snap);
    view.intrinsics = CameraIntrinsics::FromFovy(320, 240, 60);
    view.near_m = cam.near_m;
    view.outputs[ImageKind::kRgb] = false;
    view.outputs[ImageKind::kDepth] = view.outputs[ImageKind::kSegmentation] =
        view.outputs[ImageKind::kRange] = true;
    view.outputs[ImageKind::kNormals] = view.outputs[ImageKind::kInstanceSegmentation] = true;
    view.outputs[ImageKind::kSemanticSegmentation] = true;
    RenderedFrame a, b;
    cpu->Render(snap, view, &a);
    gpu->Render(snap, view, &b);
    EXPECT_EQ(static_cast<cuda::CudaRenderer*>(gpu.get())->gpu_frames(), step + 1);
    const int n = 320 * 240;
    ASSERT_EQ(b.depth_m.data.size(), a.depth_m.data.size());
    ASSERT_EQ(b.normal_O.data.size(), a.normal_O.data.size());
    int depth_bad = 0, seg_bad = 0, body_bad = 0, sem_bad = 0, range_bad = 0, normal_bad = 0,
        hits = 0, ties = 0;
    for (int i = 0; i < n; ++i) {
      hits += a.depth_m.data[i] > 0;
      depth_bad += std::abs(a.depth_m.data[i] - b.depth_m.data[i]) > 1e-3f;
      range_bad += std::abs(a.range_m.data[i] - b.range_m.data[i]) > 1e-3f;
      // coplanar overlapping geoms hit at the same depth (within 1e-5 relative) are a tie each
      // backend's BVH breaks its own way (the generated house's wall trims): counted apart
      const bool tie =
          std::abs(a.depth_m.data[i] - b.depth_m.data[i]) <= 1e-5f * (1 + a.depth_m.data[i]) &&
          a.depth_m.data[i] > 0 && a.geom_id.data[i] != b.geom_id.data[i];
      ties += tie;
      seg_bad += !tie && a.geom_id.data[i] != b.geom_id.data[i];
      body_bad += !tie && a.body_id.data[i] != b.body_id.data[i];
      sem_bad += !tie && a.semantic_class.data[i] != b.semantic_class.data[i];
      float dn = 0;
      for (int c = 0; c < 3; ++c)
        dn = std::max(dn, std::abs(a.normal_O.data[3 * i + c] - b.normal_O.data[3 * i + c]));
      normal_bad += dn > 1e-3f;
    }
    SCOPED_TRACE(GetParam() + " frame " + std::to_string(step));
    std::printf(
        "%s frame %d: %d pixels, %d hit; differ: depth %d, range %d, seg %d (+ %d "
        "same-depth ties), instance %d, semantic %d, normals %d\n",
        GetParam().c_str(), step, n, hits, depth_bad, range_bad, seg_bad, ties, body_bad, sem_bad,
        normal_bad);
    EXPECT_GT(hits, n / 2);
    EXPECT_LE(depth_bad, n / 1000);
    EXPECT_LE(range_bad, n / 1000);
    EXPECT_LE(seg_bad, n / 1000);
    EXPECT_LE(body_bad, n / 1000);
    EXPECT_LE(sem_bad, n / 1000);
    EXPECT_LE(normal_bad, n / 1000);
  }
}

INSTANTIATE_TEST_SUITE_P(Bundled, CudaBackendWorlds,
                         ::testing::Values("default.yaml", "house.yaml", "warehouse.yaml"));

// RenderPrimary's ways of bringing the ground truth back (pinned staging in bands of rows over
// the pool or one thread, or pageable copies) write the same bytes into every image, also where
// the frame's shape changes between calls (a frame reused, one resized) and where the rows do
// not split evenly into the bands.
// the shared exponential (core/exp_rn.h) gives the host's bits on the device, where expf need
// not (the rain streaks' culling decides drops with it on both processors).
TEST(CudaBackend, SharedExponentialGivesTheHostsBits) {
  PB_REQUIRE_CUDA_DEVICE();
  std::vector<float> x;
  const int n = 1 << 21;
  for (int i = 0; i <= n; ++i) x.push_back(-104.0f + (88.7f + 104.0f) * static_cast<float>(i) / n);
  for (float t = -20.0f; t <= 0.0f; t += 1.0f / 4096) x.push_back(t);
  const float inf = std::numeric_limits<float>::infinity();
  for (float t : {0.0f, -0.0f, 1e-30f, 88.72f, 88.75f, -100.0f, -104.5f, inf, -inf}) x.push_back(t);
  std::vector<float> device(x.size());
  cuda::ExpRnOnDevice(x.data(), device.data(), static_cast<int64_t>(x.size()));
  int differ = 0;
  for (size_t i = 0; i < x.size(); ++i) {
    const float host = ExpRn(x[i]);
    if (std::memcmp(&host, &device[i], sizeof(float)) == 0) continue;
    if (differ++ < 5)
      ADD_FAILURE() << "ExpRn(" << x[i] << "): host " << host << ", device " << device[i];
  }
  EXPECT_EQ(differ, 0) << "of " << x.size() << " arguments";
}

// the ground-truth images copied back in one band (97x61) and in bands (320x240), into new and
// reused images: every render the same bytes, most pixels hit.
TEST(CudaBackend, PrimaryCopiesWriteTheSameBytesEveryFrame) {
  PB_REQUIRE_CUDA_DEVICE();
  const std::unique_ptr<Session> session = LoadBundled("house.yaml");
  RenderSettings settings;
  settings.backend = RenderSettings::Backend::kCuda;
  const std::unique_ptr<Renderer> gpu = MakeRenderer(session->scene(), settings);
  const WorldSnapshot snap = session->sim().Snapshot();
  CameraView view;
  view.X_WO = CameraPoseInWorld(session->scene().cameras.front(), snap);
  view.outputs[ImageKind::kRgb] = false;
  for (ImageKind k :
       {ImageKind::kDepth, ImageKind::kSegmentation, ImageKind::kRange, ImageKind::kNormals,
        ImageKind::kInstanceSegmentation, ImageKind::kSemanticSegmentation})
    view.outputs[k] = true;
  const auto same = [](const RenderedFrame& a, const RenderedFrame& b) {
    return a.depth_m.data == b.depth_m.data && a.geom_id.data == b.geom_id.data &&
           a.range_m.data == b.range_m.data && a.normal_O.data == b.normal_O.data &&
           a.body_id.data == b.body_id.data && a.semantic_class.data == b.semantic_class.data;
  };
  for (const auto& [w, h] : {std::pair{97, 61}, std::pair{320, 240}}) {
    view.intrinsics = CameraIntrinsics::FromFovy(w, h, 60);
    RenderedFrame want;
    gpu->Render(snap, view, &want);
    ASSERT_EQ(want.normal_O.data.size(), static_cast<size_t>(3 * w * h));
    int hits = 0;
    for (float d : want.depth_m.data) hits += d > 0;
    EXPECT_GT(hits, w * h / 2);
    RenderedFrame reused;  // one frame rendered again (its images reused, then resized)
    for (int v = 0; v < 2; ++v) {
      SCOPED_TRACE("render " + std::to_string(v) + ", " + std::to_string(w) + "x" +
                   std::to_string(h));
      RenderedFrame fresh;
      gpu->Render(snap, view, &fresh);
      gpu->Render(snap, view, &reused);
      EXPECT_TRUE(same(fresh, want));
      EXPECT_TRUE(same(reused, want));
    }
  }
}

// the pathtraced tier's frames render on the GPU (path_shading.h), emissive geoms included, and
// those of a camera with lens distortion and a rolling shutter over a moving camera too (its
// ray tables, JitteredCameraRay).
TEST(CudaBackend, PathtracedFramesWithDistortedOrMovingCamerasRenderOnTheGpu) {
  PB_REQUIRE_CUDA_DEVICE();
  const std::unique_ptr<Session> session = LoadBundled("default.yaml");
  RenderSettings settings;
  settings.backend = RenderSettings::Backend::kCuda;
  settings.tier = RenderSettings::Tier::kPathtraced;
  settings.samples_per_pixel = 1;
  const WorldSnapshot snap = session->sim().Snapshot();
  CameraView view;
  view.X_WO = CameraPoseInWorld(session->scene().cameras.front(), snap);
  view.intrinsics = CameraIntrinsics::FromFovy(64, 48, 60);
  view.outputs[ImageKind::kRgb] = true;
  CameraView distorted = view;
  path_parity::DistortAndMove(&distorted);
  SceneDescription emissive = session->scene();
  for (Material& m : emissive.materials) m.emission = Eigen::Vector3f(1, 1, 1);
  const SceneDescription* scenes[] = {&session->scene(), &emissive};
  for (const SceneDescription* scene : scenes) {
    const std::unique_ptr<Renderer> gpu = MakeRenderer(*scene, settings);
    RenderedFrame f;
    gpu->Render(snap, view, &f);
    EXPECT_EQ(f.rgb.data.size(), 64u * 48u * 3u);
    gpu->Render(snap, distorted, &f);
    EXPECT_EQ(f.rgb.data.size(), 64u * 48u * 3u);
    const auto* g = static_cast<cuda::CudaRenderer*>(gpu.get());
    EXPECT_EQ(g->gpu_frames(), 2);
  }
}

}  // namespace
}  // namespace penumbra

// batch rendering on a GPU (render/cuda/cuda_batch_renderer.h; ctest label `gpu`): the cameras
// of two worlds (the default room and the house, two sessions) in one launch give the same
// bits as each camera in a batch of its own and agree with the single-camera CudaRenderer;
// two renderers render the same bits (determinism); overlapped batches keep their own images;
// the copy modes give the same images; a ticket whose slot was reused is refused; the realtime
// rgb of a batch (both worlds, frame keys of their own) is CudaRenderer's rgb and depth of each
// camera alone, bit for bit, run to run, also under effects: the lighting ones, and rain, fog
// and smoke (those worlds' cameras rendered alone, PerCameraEffects) beside a clear world.
// without a device every test prints "skipped: no CUDA device".

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_batch_bench.h"
#include "penumbra/render/cuda/cuda_batch_renderer.h"
#include "penumbra/scene/camera_pose.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

#define PB_REQUIRE_CUDA_DEVICE_FOR_BATCH()                                       \
  do {                                                                           \
    if (!ProbeCudaDevice().available) GTEST_SKIP() << "skipped: no CUDA device"; \
  } while (0)

constexpr int kBatchW = 96, kBatchH = 72;

struct BatchWorld {
  std::unique_ptr<Session> session;
  WorldSnapshot snap;
  CameraView view;
};

BatchWorld LoadBatchWorld(const std::string& name) {
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  BatchWorld w;
  w.session = std::make_unique<Session>(
      LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/" + name), so);
  for (int s = 0; s < 150; ++s) w.session->sim().Step();
  w.snap = w.session->sim().Snapshot();
  const CameraSpec& cam = w.session->scene().cameras.front();
  w.view.X_WO = CameraPoseInWorld(cam, w.snap);
  w.view.intrinsics = CameraIntrinsics::FromFovy(kBatchW, kBatchH, 70);
  w.view.near_m = cam.near_m;
  w.view.outputs[ImageKind::kRgb] = false;
  w.view.outputs[ImageKind::kDepth] = w.view.outputs[ImageKind::kSegmentation] = true;
  w.view.outputs[ImageKind::kInstanceSegmentation] =
      w.view.outputs[ImageKind::kSemanticSegmentation] = true;
  w.view.outputs[ImageKind::kRange] = w.view.outputs[ImageKind::kNormals] = true;
  return w;
}

cuda::BatchConfig AllTruth(int max_cameras, cuda::BatchCopy copy = cuda::BatchCopy::kPinned) {
  cuda::BatchConfig c;
  c.width = kBatchW;
  c.height = kBatchH;
  c.max_cameras = max_cameras;
  c.outputs.instance_segmentation = c.outputs.semantic_segmentation = c.outputs.range = true;
  c.outputs.normals = true;
  c.copy = copy;
  return c;
}

// a batch of the realtime rgb (and its depth) only, up to max_cameras cameras; its static maps
// traced as MakeRenderer's CudaRenderer traces them, so each camera can equal that renderer.
cuda::BatchConfig RgbOnly(int max_cameras) {
  cuda::BatchConfig c;
  c.width = kBatchW;
  c.height = kBatchH;
  c.max_cameras = max_cameras;
  c.outputs.segmentation = false;
  c.outputs.rgb = true;
  c.statics_query = StaticMapsQueryFactory();
  return c;
}

// the host bytes of a batch (every plane)
std::vector<uint8_t> BatchBytes(const cuda::BatchImages& img) {
  const int64_t n = img.layout->bytes(img.cameras);
  return std::vector<uint8_t>(img.base, img.base + n);
}

// camera k's images of a batch, as bytes, plane by plane
std::vector<uint8_t> CameraBytes(const cuda::BatchImages& img, int k) {
  std::vector<uint8_t> out;
  const int64_t n = 4 * img.layout->pixels();
  for (const void* p :
       {static_cast<const void*>(img.depth(k)), static_cast<const void*>(img.geom_id(k)),
        static_cast<const void*>(img.body_id(k)), static_cast<const void*>(img.semantic(k)),
        static_cast<const void*>(img.range(k))}) {
    const uint8_t* b = static_cast<const uint8_t*>(p);
    out.insert(out.end(), b, b + n);
  }
  const uint8_t* normals = reinterpret_cast<const uint8_t*>(img.normal_O(k));
  out.insert(out.end(), normals, normals + 3 * n);
  return out;
}

class BatchRendering : public ::testing::Test {
 protected:
  void SetUp() override {
    PB_REQUIRE_CUDA_DEVICE_FOR_BATCH();
    worlds_.push_back(LoadBatchWorld("default.yaml"));
    worlds_.push_back(LoadBatchWorld("house.yaml"));
  }
  // 8 views over both worlds: view k in world k % 2, turned by 2 pi k / 8
  std::vector<CameraView> Views() const {
    std::vector<CameraView> views;
    for (int k = 0; k < 8; ++k)
      views.push_back(cuda::OrbitView(worlds_[k % 2].view, 2 * M_PI * k / 8));
    return views;
  }
  // their pinhole cameras (they name no ray tables, so any renderer renders them)
  std::vector<cuda::BatchCamera> Cameras(cuda::BatchRenderer& r,
                                         std::vector<CameraView>* views) const {
    std::vector<cuda::BatchCamera> cams;
    const std::vector<CameraView> v = Views();
    for (int k = 0; k < 8; ++k) cams.push_back(r.CameraOf(k % 2, v[k]));
    if (views) *views = v;
    return cams;
  }
  // camera k's view (world k % 2) rendered by CudaRenderer alone
  RenderedFrame CudaRendererAlone(int k, const CameraView& view) const {
    RenderSettings gpu_settings;
    gpu_settings.backend = RenderSettings::Backend::kCuda;
    const BatchWorld& w = worlds_[k % 2];
    const std::unique_ptr<Renderer> single = MakeRenderer(w.session->scene(), gpu_settings);
    RenderedFrame f;
    single->Render(w.snap, view, &f);
    return f;
  }
  void AddWorlds(cuda::BatchRenderer* r) const {
    for (const BatchWorld& w : worlds_) r->UpdateWorld(r->AddWorld(w.session->scene()), w.snap);
  }
  std::vector<BatchWorld> worlds_;
};

TEST_F(BatchRendering, BatchedImagesEqualSingleCameraOnesBitForBit) {
  std::vector<CameraView> views;
  cuda::BatchRenderer r(AllTruth(8));
  AddWorlds(&r);
  const std::vector<cuda::BatchCamera> cams = Cameras(r, &views);
  ASSERT_EQ(r.num_worlds(), 2);
  const cuda::BatchImages all = r.Wait(r.Submit(cams));
  ASSERT_EQ(all.cameras, 8);
  const std::vector<uint8_t> batched = BatchBytes(all);
  for (int k = 0; k < 8; ++k) {
    SCOPED_TRACE("camera " + std::to_string(k));
    const cuda::BatchImages one = r.Wait(r.Submit(std::span(&cams[k], 1)));
    ASSERT_EQ(one.cameras, 1);
    cuda::BatchImages again = all;
    again.base = batched.data();
    EXPECT_TRUE(CameraBytes(one, 0) == CameraBytes(again, k));
    // the single-camera renderer (CudaRenderer) of the same view: same depth, same ids
    const RenderedFrame f = CudaRendererAlone(k, views[k]);
    const int n = kBatchW * kBatchH;
    int same_bits = 0, depth_bad = 0, seg_bad = 0, hits = 0;
    // the normals come from the same TracePixelTruth as CudaRenderer's: the same bits
    EXPECT_EQ(std::memcmp(f.normal_O.data.data(), one.normal_O(0), 12 * n), 0);
    for (int i = 0; i < n; ++i) {
      same_bits += std::memcmp(&f.depth_m.data[i], one.depth(0) + i, 4) == 0;
      depth_bad += std::abs(f.depth_m.data[i] - one.depth(0)[i]) > 1e-6f * (1 + f.depth_m.data[i]);
      seg_bad += f.geom_id.data[i] != one.geom_id(0)[i] || f.body_id.data[i] != one.body_id(0)[i] ||
                 f.semantic_class.data[i] != one.semantic(0)[i];
      hits += f.depth_m.data[i] > 0;
    }
    std::printf("camera %d (%s): %d of %d depth values the same bits as CudaRenderer's, %d hit\n",
                k, k % 2 ? "house" : "default", same_bits, n, hits);
    EXPECT_GT(hits, 0);
    EXPECT_LE(depth_bad, n / 1000);
    EXPECT_LE(seg_bad, n / 1000);
  }
}

TEST_F(BatchRendering, TwoRunsGiveTheSameBits) {
  std::vector<cuda::BatchCamera> cams;
  std::vector<uint8_t> first;
  for (int run = 0; run < 2; ++run) {
    cuda::BatchRenderer r(AllTruth(8));
    AddWorlds(&r);
    if (run == 0) cams = Cameras(r, nullptr);
    const std::vector<uint8_t> bytes = BatchBytes(r.Wait(r.Submit(cams)));
    if (run == 0)
      first = bytes;
    else
      EXPECT_TRUE(bytes == first) << "two runs of the same batch differ";
  }
}

TEST_F(BatchRendering, OverlappedBatchesKeepTheirOwnImages) {
  cuda::BatchRenderer r(AllTruth(8));
  AddWorlds(&r);
  const std::vector<cuda::BatchCamera> cams = Cameras(r, nullptr);
  // reference: each half alone, waited at once
  const std::vector<uint8_t> a = BatchBytes(r.Wait(r.Submit(std::span(cams).first(4))));
  const std::vector<uint8_t> b = BatchBytes(r.Wait(r.Submit(std::span(cams).last(4))));
  ASSERT_TRUE(a != b);
  // two in flight, then a third that reuses the first's slot
  const int64_t ta = r.Submit(std::span(cams).first(4));
  const int64_t tb = r.Submit(std::span(cams).last(4));
  EXPECT_TRUE(BatchBytes(r.Wait(ta)) == a);
  EXPECT_TRUE(BatchBytes(r.Wait(tb)) == b);
  const int64_t tc = r.Submit(std::span(cams).last(4));
  EXPECT_THROW(r.Wait(ta), Error);
  EXPECT_TRUE(BatchBytes(r.Wait(tc)) == b);
  EXPECT_TRUE(BatchBytes(r.Wait(tb)) == b);
  // the device-pointer API: the images stay on the device
  const cuda::BatchImages d = r.DeviceImages(tc);
  EXPECT_TRUE(d.on_device);
  EXPECT_NE(d.depth(3), nullptr);
  EXPECT_NE(r.ready_event(tc), nullptr);
  EXPECT_NE(r.stream(), nullptr);
  // a bad camera is refused before anything runs, naming it
  std::vector<cuda::BatchCamera> bad = cams;
  bad[5].world = 7;
  try {
    r.Submit(bad);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("camera 5: world 7"), std::string::npos) << e.what();
  }
}

TEST_F(BatchRendering, DeviceOnlyBatchesAreNotCopiedBack) {
  cuda::BatchRenderer r(AllTruth(8, cuda::BatchCopy::kNone));
  AddWorlds(&r);
  const std::vector<cuda::BatchCamera> cams = Cameras(r, nullptr);
  const int64_t t = r.Submit(cams);
  EXPECT_EQ(r.Wait(t).base, nullptr);
  EXPECT_NE(r.DeviceImages(t).base, nullptr);
  EXPECT_GT(r.kernel_ms(t), 0.0);
}

// cameras with lens distortion and moving cameras (rolling shutter) in a batch: the ray tables
// CameraOf makes, copied to the device with the batch (camera k % 4 == 2 distorted, k % 4 == 3
// distorted and moving)
void DistortOrMove(int k, CameraView* view) {
  if (k % 4 < 2) return;
  view->intrinsics.k1 = -0.28;
  view->intrinsics.k2 = 0.07;
  view->intrinsics.p1 = 0.002;
  if (k % 4 == 2) return;
  view->motion.end_sec = 0.03;
  view->motion.line_time_sec = 0.03 / kBatchH;
  view->motion.X_WO_end = view->X_WO;
  view->motion.X_WO_end.translation() += Eigen::Vector3d(0.15, 0.05, 0);
}

TEST_F(BatchRendering, RgbEqualsCudaRendererAloneBitForBit) {
  std::vector<CameraView> views = Views();
  // cameras of other frames (their random numbers are keyed by camera and frame), some with
  // white balance gains of their own, some with lens distortion or motion
  for (int k = 0; k < 8; ++k) {
    views[k].frame_index = 3 * k;
    if (k % 3 == 1) views[k].white_balance_gains = Eigen::Vector3f(1.15f, 1.0f, 0.8f);
    views[k].outputs[ImageKind::kRgb] = views[k].outputs[ImageKind::kDepth] = true;
    views[k].outputs[ImageKind::kSegmentation] = views[k].outputs[ImageKind::kRange] = false;
    views[k].outputs[ImageKind::kInstanceSegmentation] =
        views[k].outputs[ImageKind::kSemanticSegmentation] = false;
    DistortOrMove(k, &views[k]);
  }
  const cuda::BatchConfig config = RgbOnly(8);
  std::vector<uint8_t> first;
  for (int run = 0; run < 2; ++run) {
    cuda::BatchRenderer r(config);
    AddWorlds(&r);
    std::vector<cuda::BatchCamera> cams;
    for (int k = 0; k < 8; ++k) cams.push_back(r.CameraOf(k % 2, views[k]));
    EXPECT_GE(cams[2].xy_table, 0);
    EXPECT_EQ(cams[2].rows_table, -1);
    EXPECT_GE(cams[3].rows_table, 0);
    // one undistortion table per intrinsics: cameras 2, 3, 6, 7 share it
    EXPECT_EQ(cams[6].xy_table, cams[2].xy_table);
    const cuda::BatchImages img = r.Wait(r.Submit(cams));
    ASSERT_EQ(img.cameras, 8);
    ASSERT_NE(img.rgb(7), nullptr);
    ASSERT_EQ(img.geom_id(0), nullptr);
    const cuda::RealtimeBatchTimes t = r.stage_ms(0);
    EXPECT_GT(t.total, 0.0);
    const std::vector<uint8_t> bytes = BatchBytes(img);
    if (run == 1) {
      EXPECT_TRUE(bytes == first) << "two runs of the same rgb batch differ";
      break;
    }
    first = bytes;
    const int n = kBatchW * kBatchH;
    for (int k = 0; k < 8; ++k) {
      SCOPED_TRACE("camera " + std::to_string(k));
      const RenderedFrame f = CudaRendererAlone(k, views[k]);
      ASSERT_EQ(f.rgb.data.size(), static_cast<size_t>(3 * n));
      int rgb_diff = 0, depth_diff = 0, lit = 0;
      for (int i = 0; i < 3 * n; ++i) {
        rgb_diff += f.rgb.data[i] != img.rgb(k)[i];
        lit += img.rgb(k)[i] > 8;
      }
      for (int i = 0; i < n; ++i)
        depth_diff += std::memcmp(&f.depth_m.data[i], img.depth(k) + i, 4) != 0;
      std::printf(
          "rgb camera %d (%s): %d of %d rgb bytes and %d of %d depth values differ from "
          "CudaRenderer's; %d bytes > 8\n",
          k, k % 2 ? "house" : "default", rgb_diff, 3 * n, depth_diff, n, lit);
      EXPECT_EQ(rgb_diff, 0);
      EXPECT_EQ(depth_diff, 0);
      EXPECT_GT(lit, n / 10);
    }
  }
}

// the ground truth of distorted and moving cameras in a batch: the same depth, ids and normals
// as CudaRenderer's for the same view (whose rays come from the same tables), different from
// the pinhole camera's; a camera's tables belong to its renderer and a moving camera's rows to
// one frame.
TEST_F(BatchRendering, DistortedAndMovingCamerasTraceTheirOwnRays) {
  std::vector<CameraView> views;
  cuda::BatchRenderer r(AllTruth(8));
  AddWorlds(&r);
  const std::vector<cuda::BatchCamera> pinholes = Cameras(r, &views);
  std::vector<cuda::BatchCamera> cams;
  for (int k = 0; k < 8; ++k) {
    DistortOrMove(k, &views[k]);
    cams.push_back(r.CameraOf(k % 2, views[k]));
  }
  const std::vector<uint8_t> pinhole_bytes = BatchBytes(r.Wait(r.Submit(pinholes)));
  const int64_t t = r.Submit(cams);
  // a batch may go again before the next CameraOf: the same bits
  const std::vector<uint8_t> bytes = BatchBytes(r.Wait(t));
  EXPECT_TRUE(BatchBytes(r.Wait(r.Submit(cams))) == bytes);
  cuda::BatchImages img = r.Wait(t);
  img.base = bytes.data();
  cuda::BatchImages pin = img;
  pin.base = pinhole_bytes.data();
  const int n = kBatchW * kBatchH;
  for (int k = 0; k < 8; ++k) {
    SCOPED_TRACE("camera " + std::to_string(k));
    const RenderedFrame f = CudaRendererAlone(k, views[k]);
    EXPECT_EQ(std::memcmp(f.depth_m.data.data(), img.depth(k), 4 * n), 0);
    EXPECT_EQ(std::memcmp(f.geom_id.data.data(), img.geom_id(k), 4 * n), 0);
    EXPECT_EQ(std::memcmp(f.normal_O.data.data(), img.normal_O(k), 12 * n), 0);
    const bool moved = k % 4 >= 2;
    int differ = 0;
    for (int i = 0; i < n; ++i) differ += img.depth(k)[i] != pin.depth(k)[i];
    std::printf("camera %d (%s): %d of %d depth values differ from the pinhole camera's\n", k,
                moved ? "distorted or moving" : "pinhole", differ, n);
    if (moved)
      EXPECT_GT(differ, n / 4);
    else
      EXPECT_EQ(differ, 0);
  }
  // a new frame's CameraOf retires the last frame's rows; another renderer's tables are refused
  const cuda::BatchCamera next = r.CameraOf(1, views[3]);
  EXPECT_THROW(r.Submit(std::span(&cams[3], 1)), Error);
  EXPECT_NO_THROW(r.Wait(r.Submit(std::span(&next, 1))));
  EXPECT_NO_THROW(r.Wait(r.Submit(std::span(&cams[2], 1))));
  cuda::BatchRenderer other(AllTruth(8));
  AddWorlds(&other);
  EXPECT_THROW(other.Submit(std::span(&cams[2], 1)), Error);
  EXPECT_NO_THROW(other.Wait(other.Submit(std::span(&pinholes[2], 1))));
  // the table pointers are the renderer's to set
  cuda::BatchCamera bad = pinholes[0];
  bad.camera.xy = reinterpret_cast<const float*>(bytes.data());
  EXPECT_THROW(r.Submit(std::span(&bad, 1)), Error);
}

// a world's lighting effects (UpdateWorld's EffectsFrame: the flashlight world's flashlight and
// light events at 1 s) reach every rgb camera of that world in a batch: the same rgb and depth
// bytes as CudaRenderer rendering each camera alone under the same effects, and a visible change
// from the clear frame; a frame with fog (its cameras then rendered alone) gives CudaRenderer's
// bits under the fog too, and a frame with media is taken for the ground truth.
TEST(BatchRenderingEffects, LightingEffectsEqualCudaRendererAloneBitForBit) {
  PB_REQUIRE_CUDA_DEVICE_FOR_BATCH();
  auto [session, snap, base, fx] =
      realtime_parity::LoadFrameAt("effects/flashlight.yaml", 1.0, kBatchW, kBatchH);
  const SceneDescription& scene = session->scene();
  ASSERT_TRUE(fx && !fx->empty());
  std::vector<CameraView> views;
  std::vector<cuda::BatchCamera> cams;
  for (int k = 0; k < 4; ++k) {
    views.push_back(cuda::OrbitView(base, 2 * M_PI * k / 4));
    views.back().frame_index = k;
  }
  const cuda::BatchConfig config = RgbOnly(4);
  cuda::BatchRenderer r(config);
  r.AddWorld(scene);
  for (const CameraView& v : views) cams.push_back(r.CameraOf(0, v));
  r.UpdateWorld(0, snap);
  const std::vector<uint8_t> clear = BatchBytes(r.Wait(r.Submit(cams)));
  r.UpdateWorld(0, snap, fx.get());
  const cuda::BatchImages img = r.Wait(r.Submit(cams));
  EXPECT_FALSE(BatchBytes(img) == clear) << "the effects changed nothing";
  RenderSettings gpu_settings;
  gpu_settings.backend = RenderSettings::Backend::kCuda;
  const int n = kBatchW * kBatchH;
  for (int k = 0; k < 4; ++k) {
    SCOPED_TRACE("camera " + std::to_string(k));
    const std::unique_ptr<Renderer> single = MakeRenderer(scene, gpu_settings);
    RenderedFrame f;
    single->Render(snap, fx.get(), views[k], &f);
    ASSERT_EQ(f.rgb.data.size(), static_cast<size_t>(3 * n));
    EXPECT_EQ(std::memcmp(f.rgb.data.data(), img.rgb(k), 3 * n), 0);
    EXPECT_EQ(std::memcmp(f.depth_m.data.data(), img.depth(k), 4 * n), 0);
  }
  EffectsFrame fog = *fx;
  fog.homogeneous_media.emplace_back();
  fog.homogeneous_media.back().sigma_t_per_m = Eigen::Vector3f::Constant(0.1f);
  // a world with media: its cameras are rendered alone
  r.UpdateWorld(0, snap, &fog);
  const cuda::BatchImages foggy = r.Wait(r.Submit(cams));
  {
    const std::unique_ptr<Renderer> single = MakeRenderer(scene, gpu_settings);
    RenderedFrame f;
    single->Render(snap, &fog, views[1], &f);
    EXPECT_EQ(std::memcmp(f.rgb.data.data(), foggy.rgb(1), 3 * n), 0);
    EXPECT_EQ(std::memcmp(f.depth_m.data.data(), foggy.depth(1), 4 * n), 0);
    EXPECT_NE(std::memcmp(img.rgb(1), foggy.rgb(1), 3 * n), 0) << "the fog changed nothing";
  }
  EffectsFrame smoke = *fx;
  smoke.grid_media.emplace_back();
  cuda::BatchRenderer truth(AllTruth(4));
  truth.AddWorld(scene);
  EXPECT_NO_THROW(truth.UpdateWorld(0, snap, &fog));
  EXPECT_NO_THROW(truth.UpdateWorld(0, snap, &smoke));
}

// worlds whose effects have particles or media (rain, fog, smoke plume at 1 s) beside a clear
// world (the default room) in one rgb batch of 8 cameras (camera k in world k % 4, one of the
// rain's with a rolling shutter): each camera's rgb and depth are CudaRenderer's rendering it
// alone under its world's effects, bit for bit, run to run; the effects worlds' cameras were
// rendered alone (6 of 8) and their rgb differs from the same batch without effects (the clear
// world's does not); the ground truth (segmentation) does not see the effects; a camera of such
// a world without a view of this renderer's CameraOf, or with one of an earlier frame, is
// refused, a clear world's is not.
TEST(BatchRenderingEffects, RainFogAndSmokeEqualCudaRendererAloneBitForBit) {
  PB_REQUIRE_CUDA_DEVICE_FOR_BATCH();
  const char* names[] = {"effects/rain.yaml", "effects/fog.yaml", "effects/smoke_plume.yaml",
                         "default.yaml"};
  std::vector<realtime_parity::WorldFrame> worlds;
  for (const char* name : names)
    worlds.push_back(realtime_parity::LoadFrameAt(name, 1.0, kBatchW, kBatchH));
  const auto effects_of = [&](int w) -> const EffectsFrame* {
    const EffectsFrame* fx = worlds[w].fx.get();
    return fx != nullptr && !fx->empty() ? fx : nullptr;
  };
  for (int w = 0; w < 4; ++w) ASSERT_EQ(cuda::PerCameraEffects(effects_of(w)), w < 3) << names[w];
  std::vector<CameraView> views;
  for (int k = 0; k < 8; ++k) {
    views.push_back(cuda::OrbitView(worlds[k % 4].view, 0.3 * (k / 4)));
    views.back().frame_index = k;
  }
  realtime_parity::AddRollingShutter(&views[4]);
  cuda::BatchConfig config = RgbOnly(8);
  config.outputs.segmentation = true;
  const int n = kBatchW * kBatchH;
  std::vector<uint8_t> first;
  for (int run = 0; run < 2; ++run) {
    cuda::BatchRenderer r(config);
    for (int w = 0; w < 4; ++w)
      r.UpdateWorld(r.AddWorld(worlds[w].session->scene()), worlds[w].snap, effects_of(w));
    std::vector<cuda::BatchCamera> cams;
    for (int k = 0; k < 8; ++k) cams.push_back(r.CameraOf(k % 4, views[k]));
    const int64_t t = r.Submit(cams);
    const cuda::BatchImages img = r.Wait(t);
    EXPECT_EQ(r.alone_cameras(t), 6);
    EXPECT_GT(r.alone_ms(t), 0.0);
    const std::vector<uint8_t> bytes = BatchBytes(img);
    if (run == 1) {
      EXPECT_TRUE(bytes == first) << "two runs of the same effects batch differ";
      break;
    }
    first = bytes;
    // the same batch without effects: the rgb of the effects worlds' cameras changes, the
    // clear world's and every camera's segmentation do not
    cuda::BatchRenderer clear(config);
    for (int w = 0; w < 4; ++w)
      clear.UpdateWorld(clear.AddWorld(worlds[w].session->scene()), worlds[w].snap);
    std::vector<cuda::BatchCamera> clear_cams;
    for (int k = 0; k < 8; ++k) clear_cams.push_back(clear.CameraOf(k % 4, views[k]));
    const cuda::BatchImages plain = clear.Wait(clear.Submit(clear_cams));
    EXPECT_EQ(clear.alone_cameras(0), 0);
    for (int k = 0; k < 8; ++k) {
      SCOPED_TRACE(std::string("camera ") + std::to_string(k) + " in " + names[k % 4]);
      RenderSettings gpu_settings;
      gpu_settings.backend = RenderSettings::Backend::kCuda;
      const std::unique_ptr<Renderer> single =
          MakeRenderer(worlds[k % 4].session->scene(), gpu_settings);
      CameraView v = views[k];
      v.outputs[ImageKind::kRgb] = v.outputs[ImageKind::kDepth] = true;
      RenderedFrame f;
      single->Render(worlds[k % 4].snap, effects_of(k % 4), v, &f);
      ASSERT_EQ(f.rgb.data.size(), static_cast<size_t>(3 * n));
      int rgb_diff = 0, depth_diff = 0, by_effects = 0;
      for (int i = 0; i < 3 * n; ++i) {
        rgb_diff += f.rgb.data[i] != img.rgb(k)[i];
        by_effects += plain.rgb(k)[i] != img.rgb(k)[i];
      }
      for (int i = 0; i < n; ++i)
        depth_diff += std::memcmp(&f.depth_m.data[i], img.depth(k) + i, 4) != 0;
      std::printf(
          "effects camera %d (%s): %d of %d rgb bytes and %d of %d depth values differ from "
          "CudaRenderer's; %d rgb bytes differ from the batch without effects\n",
          k, names[k % 4], rgb_diff, 3 * n, depth_diff, n, by_effects);
      EXPECT_EQ(rgb_diff, 0);
      EXPECT_EQ(depth_diff, 0);
      if (k % 4 < 3)
        EXPECT_GT(by_effects, 3 * n / 100);
      else
        EXPECT_EQ(by_effects, 0);
      EXPECT_EQ(std::memcmp(plain.geom_id(k), img.geom_id(k), 4 * n), 0);
    }
    // the views are the renderer's: a hand-made camera of an effects world, or one of an
    // earlier frame's CameraOf, is refused; a clear world's camera is not
    cuda::BatchCamera hand = cams[1];
    hand.view_table = -1;
    EXPECT_THROW(r.Submit(std::span(&hand, 1)), Error);
    const cuda::BatchCamera next = r.CameraOf(0, views[0]);
    EXPECT_THROW(r.Submit(std::span(&cams[2], 1)), Error);
    EXPECT_NO_THROW(r.Wait(r.Submit(std::span(&cams[3], 1))));
    EXPECT_NO_THROW(r.Wait(r.Submit(std::span(&next, 1))));
  }
}

}  // namespace
}  // namespace penumbra

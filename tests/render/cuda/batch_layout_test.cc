// batch rendering's host-side bookkeeping (render/cuda/batch_layout.h): where each camera's
// image of each output lies in a batch's buffer, the checks of a batch's cameras (errors name
// the camera and the field), and the ring of slots whose images stay readable; and the pixel's
// ground truth (render/transport/primary_pixel.h, the PB_HOST_DEVICE code the batch kernel runs)
// run on the CPU over the default world's BvhScene against the CPU backend's images; which
// worlds' effects make a batch render their rgb cameras alone (PerCameraEffects: particles and
// media, not the lighting effects).

#include "penumbra/render/cuda/batch_layout.h"

#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/frame/bvh_scene.h"
#include "penumbra/render/transport/primary_pixel.h"
#include "penumbra/scene/camera_pose.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

cuda::BatchCamera ValidBatchCamera(int w, int h) {
  cuda::BatchCamera b;
  b.camera.ex = {1, 0, 0};
  b.camera.ey = {0, 1, 0};
  b.camera.ez = {0, 0, 1};
  b.camera.cx = 0.5f * (w - 1);
  b.camera.cy = 0.5f * (h - 1);
  b.camera.inv_fx = b.camera.inv_fy = 0.01f;
  b.camera.width = w;
  b.camera.height = h;
  return b;
}

std::string BatchErrorOf(const cuda::BatchLayout& l, const std::vector<cuda::BatchCamera>& cams,
                         int worlds) {
  try {
    l.Check(cams.data(), static_cast<int>(cams.size()), worlds);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(BatchLayout, PlanesArePackedCameraMajorForTheBatchSize) {
  cuda::BatchOutputs o;
  o.depth = true;
  o.segmentation = false;
  o.semantic_segmentation = true;
  o.range = true;
  const cuda::BatchLayout l(4, 3, 10, o);
  EXPECT_EQ(l.pixels(), 12);
  EXPECT_EQ(l.planes(), 3);
  EXPECT_TRUE(l.has(cuda::BatchPlane::kDepth));
  EXPECT_FALSE(l.has(cuda::BatchPlane::kSegmentation));
  EXPECT_FALSE(l.has(cuda::BatchPlane::kInstance));
  // a batch of 5: depth [0, 240), semantic [240, 480), range [480, 720) bytes
  EXPECT_EQ(l.bytes(5), 720);
  EXPECT_EQ(l.capacity_bytes(), 1440);
  EXPECT_EQ(l.plane_offset(cuda::BatchPlane::kDepth, 5), 0);
  EXPECT_EQ(l.plane_offset(cuda::BatchPlane::kSemantic, 5), 240);
  EXPECT_EQ(l.plane_offset(cuda::BatchPlane::kRange, 5), 480);
  EXPECT_EQ(l.image_offset(cuda::BatchPlane::kRange, 5, 2), 480 + 2 * 48);
  // the planes of a batch of 2 are packed for 2 cameras, so one copy of bytes(2) holds them
  EXPECT_EQ(l.plane_offset(cuda::BatchPlane::kSemantic, 2), 96);
  EXPECT_EQ(l.image_offset(cuda::BatchPlane::kRange, 2, 1), 192 + 48);
  EXPECT_THROW(l.plane_offset(cuda::BatchPlane::kSegmentation, 2), Error);
}

// rgb is 3 bytes a pixel, after the 4-byte planes (they stay 4-byte aligned).
TEST(BatchLayout, RgbIsThreeBytesAPixelAfterTheOtherPlanes) {
  cuda::BatchOutputs o;
  o.segmentation = false;
  o.rgb = true;
  const cuda::BatchLayout l(4, 3, 10, o);
  EXPECT_EQ(l.planes(), 2);
  EXPECT_TRUE(l.has(cuda::BatchPlane::kRgb));
  // a batch of 5: depth [0, 240), rgb [240, 420)
  EXPECT_EQ(l.bytes(5), 420);
  EXPECT_EQ(l.capacity_bytes(), 840);
  EXPECT_EQ(l.plane_offset(cuda::BatchPlane::kRgb, 5), 240);
  EXPECT_EQ(l.image_offset(cuda::BatchPlane::kRgb, 5, 2), 240 + 2 * 36);
  EXPECT_EQ(l.image_offset(cuda::BatchPlane::kDepth, 5, 2), 2 * 48);
  o.depth = false;
  o.range = true;
  const cuda::BatchLayout r(4, 3, 10, o);
  EXPECT_EQ(r.plane_offset(cuda::BatchPlane::kRange, 2), 0);
  EXPECT_EQ(r.plane_offset(cuda::BatchPlane::kRgb, 2), 96);
  EXPECT_EQ(r.bytes(2), 96 + 72);
  cuda::BatchOutputs rgb_only;
  rgb_only.depth = rgb_only.segmentation = false;
  rgb_only.rgb = true;
  EXPECT_EQ(cuda::BatchLayout(4, 3, 1, rgb_only).bytes(1), 36);
}

// normals are 12 bytes a pixel (3 floats), after range and before rgb.
TEST(BatchLayout, NormalsAreThreeFloatsAPixelBeforeRgb) {
  cuda::BatchOutputs o;
  o.segmentation = false;
  o.normals = true;
  o.rgb = true;
  const cuda::BatchLayout l(4, 3, 10, o);
  EXPECT_EQ(l.planes(), 3);
  EXPECT_TRUE(l.has(cuda::BatchPlane::kNormal));
  // a batch of 5: depth [0, 240), normals [240, 960), rgb [960, 1140)
  EXPECT_EQ(l.bytes(5), 1140);
  EXPECT_EQ(l.plane_offset(cuda::BatchPlane::kNormal, 5), 240);
  EXPECT_EQ(l.image_offset(cuda::BatchPlane::kNormal, 5, 2), 240 + 2 * 144);
  EXPECT_EQ(l.plane_offset(cuda::BatchPlane::kRgb, 5), 960);
  cuda::BatchOutputs normals_only;
  normals_only.depth = normals_only.segmentation = false;
  normals_only.normals = true;
  EXPECT_EQ(cuda::BatchLayout(4, 3, 1, normals_only).bytes(1), 144);
}

TEST(BatchLayout, BadConfigsAreRefused) {
  cuda::BatchOutputs none;
  none.depth = none.segmentation = false;
  EXPECT_THROW(cuda::BatchLayout(4, 4, 1, none), Error);
  EXPECT_THROW(cuda::BatchLayout(0, 4, 1, {}), Error);
  EXPECT_THROW(cuda::BatchLayout(4, 20000, 1, {}), Error);
  EXPECT_THROW(cuda::BatchLayout(4, 4, 0, {}), Error);
  EXPECT_THROW(cuda::BatchLayout(4, 4, 65536, {}), Error);
  EXPECT_NO_THROW(cuda::BatchLayout(4, 4, 65535, {}));
}

TEST(BatchLayout, CheckNamesTheCameraAndTheField) {
  const cuda::BatchLayout l(8, 6, 3, {});
  std::vector<cuda::BatchCamera> cams(2, ValidBatchCamera(8, 6));
  EXPECT_EQ(BatchErrorOf(l, cams, 1), "");
  EXPECT_NE(BatchErrorOf(l, {}, 1).find("0 cameras; expected 1 to 3"), std::string::npos);
  EXPECT_NE(BatchErrorOf(l, std::vector<cuda::BatchCamera>(4, ValidBatchCamera(8, 6)), 1)
                .find("4 cameras"),
            std::string::npos);
  cams[1].world = 2;
  EXPECT_NE(BatchErrorOf(l, cams, 2).find("camera 1: world 2; expected a world in [0, 2)"),
            std::string::npos);
  cams[1] = ValidBatchCamera(8, 6);
  cams[0].camera.width = 9;
  EXPECT_NE(BatchErrorOf(l, cams, 1).find("camera 0: size 9x6; expected the batch's 8x6"),
            std::string::npos);
  cams[0] = ValidBatchCamera(8, 6);
  cams[1].camera.o.y = NAN;
  EXPECT_NE(BatchErrorOf(l, cams, 1).find("camera 1: a pose that is not finite"),
            std::string::npos);
  cams[1] = ValidBatchCamera(8, 6);
  cams[1].camera.inv_fx = 0;
  EXPECT_NE(BatchErrorOf(l, cams, 1).find("camera 1: intrinsics"), std::string::npos);
  // ray tables are named by the renderer's CameraOf, not pointed to by the caller
  cams[1] = ValidBatchCamera(8, 6);
  const float table[2] = {0, 0};
  cams[1].camera.rows = table;
  EXPECT_NE(BatchErrorOf(l, cams, 1).find("camera 1: ray table pointers set; expected null"),
            std::string::npos);
}

TEST(BatchTickets, SlotsRotateAndTheLastTwoStayReadable) {
  cuda::BatchTickets t;
  EXPECT_FALSE(t.Readable(0));
  EXPECT_EQ(t.Take(), 0);
  EXPECT_EQ(t.Take(), 1);
  EXPECT_TRUE(t.Readable(0));
  EXPECT_TRUE(t.Readable(1));
  EXPECT_FALSE(t.Readable(2));
  EXPECT_EQ(t.Take(), 2);
  // ticket 2 reuses ticket 0's slot
  EXPECT_EQ(cuda::BatchTickets::SlotOf(2), cuda::BatchTickets::SlotOf(0));
  EXPECT_NE(cuda::BatchTickets::SlotOf(1), cuda::BatchTickets::SlotOf(2));
  EXPECT_FALSE(t.Readable(0));
  EXPECT_TRUE(t.Readable(1));
  EXPECT_TRUE(t.Readable(2));
  EXPECT_FALSE(t.Readable(-1));
  EXPECT_EQ(t.taken(), 3);
}

// the batch kernel's per-pixel code, run on the CPU over the default world's BvhScene, gives
// the CPU backend's depth and segmentation (within 1 mm, equal on >= 99.9 % of pixels) and
// its normals (within 0.1 degree on >= 99.9 % of pixels)
TEST(BatchPixelTruth, HostRunMatchesTheCpuBackend) {
  SessionOptions so;
  so.build_renderer = false;
  so.add_controllers = false;
  Session session(LoadWorldFile(std::string(PENUMBRA_SOURCE_DIR) + "/worlds/default.yaml"), so);
  for (int s = 0; s < 100; ++s) session.sim().Step();
  const WorldSnapshot snap = session.sim().Snapshot();
  const SceneDescription& scene = session.scene();
  cuda::BvhScene bvh(scene);
  bvh.Update(snap);
  CameraView view;
  view.X_WO = CameraPoseInWorld(scene.cameras.front(), snap);
  view.intrinsics = CameraIntrinsics::FromFovy(96, 72, 60);
  view.near_m = scene.cameras.front().near_m;
  view.outputs[ImageKind::kRgb] = false;
  view.outputs[ImageKind::kDepth] = view.outputs[ImageKind::kSegmentation] =
      view.outputs[ImageKind::kRange] = view.outputs[ImageKind::kNormals] = true;
  RenderSettings settings;
  settings.backend = RenderSettings::Backend::kEmbree;
  settings.threads = 1;
  const std::unique_ptr<Renderer> cpu = MakeRenderer(scene, settings);
  RenderedFrame f;
  cpu->Render(snap, view, &f);
  const Camera camera(view.X_WO, view.intrinsics, view.motion);
  const Camera::PinholeTerms t = camera.pinhole_terms();
  const auto f3 = [](const Eigen::Vector3f& v) { return cuda::F3{v.x(), v.y(), v.z()}; };
  const cuda::SceneView sv = bvh.view();
  const cuda::F3 axes_W[3] = {f3(t.ex_W), f3(t.ey_W), f3(t.ez_W)};
  const float cos_tol = std::cos(0.1f * static_cast<float>(M_PI) / 180.0f);
  int bad_depth = 0, bad_seg = 0, bad_range = 0, bad_normal = 0, hits = 0;
  for (int v = 0; v < 72; ++v)
    for (int u = 0; u < 96; ++u) {
      const cuda::TraceRay r =
          cuda::PinholePixelRay(f3(t.o_W), f3(t.ex_W), f3(t.ey_W), f3(t.ez_W), t.cx, t.cy, t.inv_fx,
                                t.inv_fy, static_cast<float>(view.near_m), u, v);
      const cuda::PixelTruth p = cuda::TracePixelTruth(sv, r, axes_W);
      const int i = v * 96 + u;
      const float* n = &f.normal_O.data[3 * i];
      const float dot = p.normal_O.x * n[0] + p.normal_O.y * n[1] + p.normal_O.z * n[2];
      // a miss is 0 0 0 in both; a hit a unit normal within the tolerance
      bad_normal += p.depth > 0 ? !(dot >= cos_tol) : (n[0] != 0 || n[1] != 0 || n[2] != 0);
      hits += p.depth > 0;
      bad_depth += std::abs(p.depth - f.depth_m.data[i]) > 1e-3f;
      bad_range += std::abs(p.range - f.range_m.data[i]) > 1e-3f;
      bad_seg += p.geom_id != f.geom_id.data[i];
    }
  EXPECT_GT(hits, 96 * 72 / 2);
  EXPECT_LE(bad_depth, 96 * 72 / 1000);
  EXPECT_LE(bad_range, 96 * 72 / 1000);
  EXPECT_LE(bad_seg, 96 * 72 / 1000);
  EXPECT_LE(bad_normal, 96 * 72 / 1000);
}

// the bundled effects worlds at 1 s: rain, fog and smoke (particles, homogeneous and grid media:
// each camera's own streaks and froxels) make a batch render their rgb cameras alone; the
// flashlight's lighting effects, a clear world and no effects do not; each kind alone decides.
TEST(BatchEffects, ParticlesAndMediaAreRenderedCameraByCamera) {
  for (const char* name : {"effects/rain.yaml", "effects/fog.yaml", "effects/smoke_plume.yaml",
                           "effects/flashlight.yaml", "house.yaml"}) {
    SCOPED_TRACE(name);
    const realtime_parity::WorldFrame f = realtime_parity::LoadFrameAt(name, 1.0, 32, 24);
    const std::string n = name;
    const bool per_camera = n.find("rain") != std::string::npos ||
                            n.find("fog") != std::string::npos ||
                            n.find("smoke") != std::string::npos;
    EXPECT_EQ(cuda::PerCameraEffects(f.fx.get()), per_camera);
  }
  EXPECT_FALSE(cuda::PerCameraEffects(nullptr));
  EffectsFrame fx;
  fx.extra_lights.emplace_back();
  fx.surface_wetness = 0.5f;
  EXPECT_FALSE(cuda::PerCameraEffects(&fx));
  EffectsFrame rain = fx, fog = fx, smoke = fx;
  rain.particles.emplace_back();
  fog.homogeneous_media.emplace_back();
  smoke.grid_media.emplace_back();
  EXPECT_TRUE(cuda::PerCameraEffects(&rain));
  EXPECT_TRUE(cuda::PerCameraEffects(&fog));
  EXPECT_TRUE(cuda::PerCameraEffects(&smoke));
}

}  // namespace
}  // namespace penumbra

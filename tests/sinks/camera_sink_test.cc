// the cameras as a pipeline sink: per-camera effects travel beside the immutable snapshot to
// the renderer, every image kind reaches the files through the frame writer, and a render
// error ends the run.
#include "penumbra/sinks/camera_sink.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <mutex>
#include <thread>

#include "common/run_loop.h"
#include "common/temp_dir.h"
#include "penumbra/core/error.h"
#include "penumbra/physics/physics_source.h"
#include "penumbra/pipeline/sim_loop.h"
#include "penumbra/session/scene_assembly.h"
#include "penumbra/session/session.h"

namespace penumbra {
namespace {

namespace fs = std::filesystem;

// fills every requested image with constants; records what it was given
class FakeRenderer : public Renderer {
 public:
  void Render(const WorldSnapshot& snapshot, const EffectsFrame* effects, const CameraView& view,
              RenderedFrame* out) override {
    if (++calls == fail_at) throw Error("renderer failed");
    steps.push_back(snapshot.step);
    effect_times.push_back(effects ? effects->time_sec : -1.0);
    const int W = view.intrinsics.width, H = view.intrinsics.height;
    const CameraOutputs& o = view.outputs;
    out->radiance = o[ImageKind::kRgb] ? ImageF(W, H, 3, 0.5f) : ImageF();
    out->rgb = o[ImageKind::kRgb] ? ImageU8(W, H, 3, 100) : ImageU8();
    out->depth_m = o[ImageKind::kDepth] ? ImageF(W, H, 1, 1.5f) : ImageF();
    out->geom_id = o[ImageKind::kSegmentation] ? ImageI32(W, H, 1, 2) : ImageI32();
    out->range_m = o[ImageKind::kRange] ? ImageF(W, H, 1, 2.0f) : ImageF();
    out->normal_O = o[ImageKind::kNormals] ? ImageF(W, H, 3, 0.0f) : ImageF();
    out->body_id = o[ImageKind::kInstanceSegmentation] ? ImageI32(W, H, 1, 1) : ImageI32();
    out->semantic_class = o[ImageKind::kSemanticSegmentation] ? ImageI32(W, H, 1, 0) : ImageI32();
    out->ev100 = 8;
  }
  int calls = 0;
  int fail_at = -1;
  std::vector<int64_t> steps;
  std::vector<double> effect_times;
};

struct SmallCameraWorld {
  SmallCameraWorld() {
    world = LoadWorldFile((fs::path(PENUMBRA_SOURCE_DIR) / "worlds" / "default.yaml").string());
    world.cameras.resize(1);
    CameraConfig& c = world.cameras[0];
    c.width = 32;
    c.height = 24;
    c.rate_hz = 20;
    // the ideal camera: one render per frame (a real profile's motion-blur sub-frames would
    // multiply the renderer calls these tests count)
    c.sensor = CameraSensorConfig();
    c.outputs = CameraOutputs{ImageKind::kRgb, ImageKind::kDepth, ImageKind::kSegmentation};
    c.outputs[ImageKind::kRange] = c.outputs[ImageKind::kNormals] = true;
    c.outputs[ImageKind::kInstanceSegmentation] = c.outputs[ImageKind::kSemanticSegmentation] =
        true;
    SessionOptions o;
    o.build_renderer = false;
    session = std::make_unique<Session>(world, o);
  }
  WorldConfig world;
  std::unique_ptr<Session> session;
};

TEST(CameraSinkTest, EffectsTravelBesideTheSnapshotAndEveryImageKindIsWritten) {
  const penumbra::testing::TempDir dir;
  SmallCameraWorld s;
  FakeRenderer renderer;
  std::thread::id effects_thread;
  std::mutex mu;
  std::vector<Eigen::Vector3d> viewers;
  const ViewerEffects effects = [&](const WorldSnapshot& snap, const Eigen::Vector3d& p_W) {
    std::lock_guard<std::mutex> lock(mu);
    effects_thread = std::this_thread::get_id();
    viewers.push_back(p_W);
    auto fx = std::make_shared<EffectsFrame>();
    fx->time_sec = snap.time_sec;
    return fx;
  };
  const SceneDescription& scene = s.session->scene();
  CameraSink sink(scene, s.world, s.session->sim().timestep(), &renderer, dir.path().string(),
                  effects);
  PhysicsSource source(&s.session->sim());
  const LoopFinish f = testing::RunLoop(&source, {&sink}, 0.3);
  ASSERT_FALSE(f.error) << ErrorMessage(f.error);

  // frames at 0, 0.05, ..., 0.3 s; each rendered with the effects evaluated for its own
  // snapshot, on the loop thread, at the camera's position
  ASSERT_EQ(renderer.steps.size(), 7u);
  for (size_t i = 0; i < renderer.steps.size(); ++i) {
    const double t = SimTimeOfStep(renderer.steps[i], s.session->sim().timestep());
    EXPECT_EQ(renderer.effect_times[i], t) << i;
  }
  EXPECT_NE(effects_thread, std::this_thread::get_id());
  ASSERT_EQ(viewers.size(), 7u);
  EXPECT_NE(viewers.front(), Eigen::Vector3d::Zero());

  EXPECT_EQ(sink.FramesWritten().at("front"), 7);
  const fs::path cam = dir.path() / "front";
  for (const char* kind : {"rgb", "depth", "segmentation", "range", "normals",
                           "instance_segmentation", "semantic_segmentation"})
    EXPECT_TRUE(fs::exists(cam / kind / "000006.png")) << kind;
  EXPECT_TRUE(fs::exists(dir.path() / "camera_info.json"));
}

TEST(CameraSinkTest, ARenderErrorEndsTheRunAndIsTheErrorReported) {
  const penumbra::testing::TempDir dir;
  SmallCameraWorld s;
  FakeRenderer renderer;
  renderer.fail_at = 3;
  CameraSink sink(s.session->scene(), s.world, s.session->sim().timestep(), &renderer,
                  dir.path().string(), {});
  PhysicsSource source(&s.session->sim());
  const LoopFinish f = testing::RunLoop(&source, {&sink}, 5.0);
  EXPECT_EQ(f.reason, LoopEndReason::kError);
  EXPECT_EQ(ErrorMessage(f.error), "renderer failed");
  EXPECT_LT(f.time_sec, 5.0) << "the loop stopped early";
  // the frames rendered before the failing one are written, the later ones are not rendered
  EXPECT_EQ(sink.FramesWritten().at("front"), 2);
  EXPECT_EQ(renderer.calls, 3);
}

}  // namespace
}  // namespace penumbra

// frames/s of the realtime tier under adverse conditions on the default world
// (worlds/default.yaml, its front camera, 640 x 480 rgb + depth, 2 render threads), with a
// synthetic EffectsFrame shaped like the `major` adversity preset: fog of MOR 12 m with height
// falloff 0.1 / m (base 1 m), a 64^3 smoke grid (sigma_t 1.5 / m, about half the box filled)
// over a 6.4 x 4.8 x 2.5 m box in the room, and 5000 rain streaks (r = 1 mm, 9 m/s, 10 ms
// exposure) in front of the camera. each part is also timed alone. cpu_ms_per_frame is the
// process CPU time per frame (all threads), the work to compare on a shared machine.
//
//   ./build/penumbra_microbench --benchmark_filter=Media   (from the repository root)

#include <benchmark/benchmark.h>

#include <cmath>
#include <ctime>
#include <filesystem>
#include <memory>

#include "penumbra/physics/simulation.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/media/media_common.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/camera_pose.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

struct World {
  SceneDescription scene;
  WorldSnapshot snapshot;
  CameraView view;
};

const World& DefaultWorld() {
  static const World* w = [] {
    auto* out = new World;
    // run from the repository root; the benchmark builds its own renderers
    SessionOptions options;
    options.build_renderer = false;
    Session session(LoadWorldFile("worlds/default.yaml"), options);  // session/session.h
    Simulation& sim = session.sim();
    while (sim.time() < 1.0) sim.Step();
    out->snapshot = sim.Snapshot();
    out->scene = session.scene();
    const CameraSpec& cam = out->scene.cameras.front();
    const double fovy = cam.intrinsics.fovy_deg();
    out->view.intrinsics = CameraIntrinsics::FromFovy(640, 480, fovy);
    out->view.outputs[ImageKind::kRgb] = true;
    out->view.outputs[ImageKind::kDepth] = true;
    out->view.X_WO = CameraPoseInWorld(cam, out->snapshot);
    out->view.exposure_time_sec = 0.01;
    return out;
  }();
  return *w;
}

enum Parts { kFog = 1, kSmoke = 2, kRain = 4 };

std::shared_ptr<const EffectsFrame> MajorLike(int parts, const Pose& X_WO) {
  auto fx = std::make_shared<EffectsFrame>();
  if (parts & kFog) {
    HomogeneousMedium fog;
    fog.sigma_t_per_m = Eigen::Vector3f::Constant(static_cast<float>(SigmaTFromMorM(12.0)));
    fog.albedo = Eigen::Vector3f::Constant(0.95f);
    fog.g = 0.3f;
    fog.height_falloff_per_m = 0.1f;
    fog.base_height_m = 1.0f;
    fx->homogeneous_media.push_back(fog);
  }
  if (parts & kSmoke) {
    GridMedium g;
    g.X_WG.translation() = Eigen::Vector3d(0, 0, 1.25);
    g.half_extents_m = Eigen::Vector3d(3.2, 2.4, 1.25);
    g.nx = g.ny = g.nz = 64;
    auto d = std::make_shared<std::vector<float>>(64 * 64 * 64);
    float mx = 0;
    for (int k = 0; k < 64; ++k)
      for (int j = 0; j < 64; ++j)
        for (int i = 0; i < 64; ++i) {
          const double x = i / 8.0, y = j / 8.0, z = k / 8.0;
          const double n =
              std::sin(1.3 * x + 0.7 * std::sin(2.1 * y)) * std::sin(1.7 * y + 1.1 * z) +
              0.5 * std::sin(2.3 * z + 1.9 * x);
          const float v = static_cast<float>(std::max(0.0, n));
          (*d)[(k * 64 + j) * 64 + i] = v;
          mx = std::max(mx, v);
        }
    g.density = d;
    g.max_density = mx;
    g.sigma_t_per_m = Eigen::Vector3f::Constant(1.5f);
    g.albedo = Eigen::Vector3f::Constant(0.8f);
    fx->grid_media.push_back(g);
  }
  if (parts & kRain) {
    ParticleSet rain;
    rain.kind = ParticleKind::kRain;
    rain.color = Eigen::Vector3f(0.9f, 0.92f, 0.95f);
    uint64_t s = 12345;
    auto u = [&] {
      s = s * 6364136223846793005ULL + 1442695040888963407ULL;
      return static_cast<float>((s >> 40) * 0x1.0p-24);
    };
    const Eigen::Matrix3f R = X_WO.linear().cast<float>();
    const Eigen::Vector3f o = X_WO.translation().cast<float>();
    for (int i = 0; i < 5000; ++i) {
      // in the camera's view: optical x in [-z, z] * 0.7, y in [-z, z] * 0.5, z in [0.3, 6] m.
      const float z = 0.3f + 5.7f * u();
      const Eigen::Vector3f p_O((2 * u() - 1) * 0.7f * z, (2 * u() - 1) * 0.5f * z, z);
      rain.position_W.push_back(o + R * p_O);
      rain.velocity_W.emplace_back(0.3f, 0.0f, -9.0f);
      rain.radius_m.push_back(0.001f);
    }
    fx->particles.push_back(rain);
  }
  return fx;
}

void BM_MediaRealtime(benchmark::State& state) {
  const World& w = DefaultWorld();
  RenderSettings rs;
  rs.tier = RenderSettings::Tier::kRealtime;
  rs.threads = 2;
  rs.seed = 7;
  auto r = MakeRenderer(w.scene, rs);
  const WorldSnapshot& snap = w.snapshot;
  const int parts = static_cast<int>(state.range(0));
  std::shared_ptr<const EffectsFrame> fx;
  if (parts != 0) fx = MajorLike(parts, w.view.X_WO);
  CameraView view = w.view;
  RenderedFrame f;
  for (int i = 0; i < 3; ++i) r->Render(snap, fx.get(), view, &f);  // warm-up
  int64_t frame = 0;
  // process CPU time (all threads): on a shared, loaded machine the wall time is not the work.
  const std::clock_t c0 = std::clock();
  for (auto _ : state) {
    view.frame_index = frame++;
    r->Render(snap, fx.get(), view, &f);
  }
  const double cpu_ms = 1e3 * static_cast<double>(std::clock() - c0) / CLOCKS_PER_SEC / frame;
  state.counters["frames_per_s"] =
      benchmark::Counter(static_cast<double>(frame), benchmark::Counter::kIsRate);
  state.counters["cpu_ms_per_frame"] = cpu_ms;
}
// 0 = clear, 1 fog, 2 smoke, 4 rain, 7 = all (major-like).
BENCHMARK(BM_MediaRealtime)
    ->Arg(0)
    ->Arg(1)
    ->Arg(2)
    ->Arg(4)
    ->Arg(7)
    ->Unit(benchmark::kMillisecond)
    ->UseRealTime();

}  // namespace
}  // namespace penumbra

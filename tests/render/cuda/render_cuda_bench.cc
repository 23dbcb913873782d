// render_cuda_bench: the CUDA backend beside the CPU backend on one machine, for
// scripts/gpu/check.sh (docs/gpu.md). for each world given (default: worlds/default.yaml and
// worlds/house.yaml), with the world's first camera after 1 s of simulation at 640x480 and
// 128x128:
//   - cuda depth+seg, Render(): the whole frame (instance update, upload, kernel, copy back);
//   - cuda depth+seg, kernel: the primary-ray kernel alone (CUDA events, images stay on the GPU);
//   - cuda all ground truth (depth, seg, instance, semantic, range, normals), Render();
//   - cuda rgb+depth (realtime tier), Render(): the whole frame (the primary geometry copied
//     to the host for the sky terms, shading, exposure, film, rgb, radiance and depth copied
//     back), and its kernels alone (CUDA events; the last frame's sky terms, no copies);
//   - cpu depth+seg and cpu rgb+depth (realtime tier), all cores;
// and the BVH build time. prints one markdown table. usage:
//   render_cuda_bench [--frames N] [world.yaml ...]

#include <fmt/format.h>

#include <chrono>
#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/physics/simulation.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/session/scene_assembly.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;

struct Row {
  std::string world, size, outputs, backend, how;
  double fps = 0;
};

// mean seconds per Render of `view` over `frames` frames after 3 warm-up frames.
double TimeRenders(Renderer* r, const WorldSnapshot& snap, const CameraView& view, int frames) {
  RenderedFrame f;
  for (int i = 0; i < 3; ++i) r->Render(snap, view, &f);
  const auto t0 = Clock::now();
  for (int i = 0; i < frames; ++i) r->Render(snap, view, &f);
  return std::chrono::duration<double>(Clock::now() - t0).count() / frames;
}

int Main(int argc, char** argv) {
  int frames = 50;
  std::vector<std::string> worlds;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--frames" && i + 1 < argc) {
      frames = std::atoi(argv[++i]);
    } else {
      worlds.push_back(a);
    }
  }
  if (worlds.empty())
    worlds = {std::string(PENUMBRA_SOURCE_DIR) + "/worlds/default.yaml",
              std::string(PENUMBRA_SOURCE_DIR) + "/worlds/house.yaml"};
  const CudaDeviceStatus dev = ProbeCudaDevice();
  fmt::print("device: {}\n", dev.available ? dev.name : "none (" + dev.why + ")");
  std::vector<Row> rows;
  std::vector<std::string> builds;
  for (const std::string& file : worlds) {
    SessionOptions so;
    so.build_renderer = false;
    Session session(LoadWorldFile(file), so);
    Simulation& sim = session.sim();
    while (sim.time() < 1.0) sim.Step();
    const WorldSnapshot snap = sim.Snapshot();
    const SceneDescription& scene = session.scene();
    const CameraSpec& cam = scene.cameras.front();
    const std::string name = file.substr(file.find_last_of('/') + 1);
    const double fovy_deg =
        2.0 * std::atan(0.5 * cam.intrinsics.height / cam.intrinsics.fy) * 180.0 / M_PI;
    RenderSettings cpu_settings;
    cpu_settings.backend = RenderSettings::Backend::kEmbree;
    cpu_settings.threads = 0;
    const std::unique_ptr<Renderer> cpu = MakeRenderer(scene, cpu_settings);
    std::unique_ptr<Renderer> gpu;
    if (dev.available) {
      RenderSettings gpu_settings;
      gpu_settings.backend = RenderSettings::Backend::kCuda;
      const auto t0 = Clock::now();
      gpu = MakeRenderer(scene, gpu_settings);
      const double s = std::chrono::duration<double>(Clock::now() - t0).count();
      auto* g = static_cast<cuda::CudaRenderer*>(gpu.get());
      builds.push_back(
          fmt::format("{}: {} triangles, BVH build {:.3f} s (CPU, one thread), "
                      "renderer set-up {:.3f} s (with the CPU fallback renderer)",
                      name, g->bvh().num_triangles(), g->bvh().build_seconds(), s));
    }
    for (auto [w, h] : {std::pair{640, 480}, std::pair{128, 128}}) {
      const std::string size = fmt::format("{}x{}", w, h);
      CameraView view;
      view.X_WO = CameraPoseInWorld(cam, snap);
      view.intrinsics = CameraIntrinsics::FromFovy(w, h, fovy_deg);
      view.near_m = cam.near_m;
      view.outputs.rgb = false;
      view.outputs.depth = view.outputs.segmentation = true;
      CameraView all = view;
      all.outputs.range = all.outputs.normals = true;
      all.outputs.instance_segmentation = all.outputs.semantic_segmentation = true;
      CameraView rgb = view;
      rgb.outputs.rgb = true;
      rgb.outputs.segmentation = false;
      const int n = w * h < 100000 ? frames * 10 : frames;
      if (gpu) {
        auto* g = static_cast<cuda::CudaRenderer*>(gpu.get());
        rows.push_back({name, size, "depth+seg", "cuda", "Render()",
                        1 / TimeRenders(gpu.get(), snap, view, n)});
        const double ms = g->device().TimePrimary(cuda::CudaRenderer::PinholeOf(view), n, true);
        rows.push_back({name, size, "depth+seg", "cuda", "kernel only", 1e3 / ms});
        rows.push_back({name, size, "all ground truth", "cuda", "Render()",
                        1 / TimeRenders(gpu.get(), snap, all, n)});
        rows.push_back({name, size, "rgb+depth realtime", "cuda", "Render()",
                        1 / TimeRenders(gpu.get(), snap, rgb, n)});
        const double rgb_ms = g->device_realtime().TimeKernels(&g->device(), n);
        rows.push_back({name, size, "rgb+depth realtime", "cuda", "kernels only", 1e3 / rgb_ms});
      }
      const int nc = std::max(3, n / 10);
      rows.push_back(
          {name, size, "depth+seg", "cpu", "Render()", 1 / TimeRenders(cpu.get(), snap, view, nc)});
      rows.push_back({name, size, "all ground truth", "cpu", "Render()",
                      1 / TimeRenders(cpu.get(), snap, all, nc)});
      rows.push_back({name, size, "rgb+depth realtime", "cpu", "Render()",
                      1 / TimeRenders(cpu.get(), snap, rgb, nc)});
    }
  }
  fmt::print("\n| world | size | outputs | backend | timed | frames/s | ms/frame |\n");
  fmt::print("|---|---|---|---|---|---:|---:|\n");
  for (const Row& r : rows)
    fmt::print("| {} | {} | {} | {} | {} | {:.0f} | {:.3f} |\n", r.world, r.size, r.outputs,
               r.backend, r.how, r.fps, 1e3 / r.fps);
  for (const std::string& b : builds) fmt::print("\n{}", b);
  fmt::print("\n");
  return 0;
}

}  // namespace
}  // namespace penumbra

int main(int argc, char** argv) { return penumbra::Main(argc, argv); }

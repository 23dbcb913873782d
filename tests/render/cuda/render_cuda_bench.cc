// render_cuda_bench: the CUDA backend beside the CPU backend on one machine, for
// scripts/gpu/check.sh (docs/gpu.md). for each world given (default: worlds/default.yaml and
// worlds/house.yaml), with the world's first camera after 1 s of simulation at 640x480 and
// 128x128:
//   - cuda depth+seg, Render(): the whole frame (instance update, upload, kernel, copy back);
//   - cuda depth+seg, kernel: the primary-ray kernel alone (CUDA events, images stay on the GPU);
//   - cuda all ground truth (depth, seg, instance, semantic, range, normals), Render();
//   - cuda rgb+depth (realtime tier), Render(): the whole frame (primary geometry, sky terms,
//     shading, exposure, film, rgb, radiance and depth copied back), and its kernels alone
//     (CUDA events, no copies);
//   - cpu depth+seg and cpu rgb+depth (realtime tier), all cores;
//   - for a world with effects at 1 s (e.g. worlds/effects/flashlight.yaml), rgb+depth under
//     them, cuda Render() and cpu Render(); with particles also the host's preparation, the
//     drops culled on the device with late streaks twice (the host's time making the streaks),
//     where one rain frame's time goes, a rolling-shutter camera turning during the readout
//     (realtime_parity::AddRollingShutter) and the pixels the splat keys, and the FNV-1a hashes
//     of the rgb, depth and
//     radiance and the EV100 of a frame;
//     with media
//     (homogeneous or grids), the time of their
//     realtime volumes' build (RealtimeMedia::Build at 640x480) with Embree's shadow rays, with
//     CudaRayQuery's and with BvhRayQuery's (the host traversal), and the CUDA backend's host
//     preparation of such a frame (CudaRenderer::last_prepare_ms, the build included);
//   - with --realtime, the FNV-1a hashes of the rgb and depth (to compare
//     builds: a change of the traversal or the kernels that keeps the images keeps them);
// and the BVH build time. prints one markdown table.
// --batch N[,N...] [--size WxH] [--sessions S]: batch rendering instead (cuda_batch_bench.h):
// batches of N cameras over S sessions of each world (default 1) at WxH (default 128x128),
// depth+seg and then realtime rgb+depth (with each realtime stage's GPU time), the copies
// overlapped with the next batch, the kernels alone and the CPU backend, each world under its
// effects at 1 s (a world with particles or media: its rgb cameras rendered alone, with their host
// time); then the device-to-host copy rates, pinned and pageable.
// --media [--size WxH]: for each world's effects frame with media (first camera at 1 s, WxH,
// default 640x480), Render() of rgb+depth with the media volumes (the world light volume and fog
// froxels, the grids' light volumes and froxels) built by the device's kernels, three times:
// frames/s,
// the host's preparation (CudaRenderer::last_prepare_ms), RealtimeMedia::Build's host time and
// its stages (RealtimeMedia::BuildTimes), the device's first stage by CUDA events (the media's
// uploads, with device-built volumes their kernels, and the geometry kernel:
// RealtimeStageTimes::geometry); whether two renders give the same bits; then, as in a run, a
// new frame every 1/30 s of sim time after the first (the session stepped on, each frame's
// snapshot and effects evaluated before the timing), so the grids' densities and emission are
// new arrays every frame and go to the device every frame: the same columns and the bytes
// uploaded a frame.
// --realtime [--size WxH]: the realtime tier's rgb+depth at WxH (default 640x480) in detail:
// Render() into the same RenderedFrame, into a new one every frame (as the camera sink renders)
// and without the radiance (CudaRenderer::set_radiance_output), and where its time goes
// (RealtimeStageTimes; the host's preparation before the kernels, CudaRenderer::last_prepare_ms),
// the kernels alone, the CPU backend, the FNV-1a hashes of the rgb, depth and radiance and the
// EV100, and how often the device's exposure differed from the host's (RealtimeExposureChecks);
// then a table of where Render()'s time goes (the host's preparation, the launches, the
// kernels' and the copies' end by CUDA events, the host's work after the last transfer) and the
// same for depth+seg.
// --parity [--size WxH]: the parity table against the CPU backend (cuda_parity.h, default
// 320x240; scripts/gpu/parity.sh).
// --pathtraced [--size WxH] [--spp N]: the pathtraced tier (default 320x240, 64 samples per
// pixel, 4 bounces, no denoiser): cuda Render() ms a frame (paths on the GPU, film on the host)
// and the path kernel alone (CUDA events), the CPU backend's Render() on all cores with the same
// samples (one frame), the radiance's mean relative difference (path_parity.h: 8x8 blocks, and
// the image mean) and whether two GPU renders are bit-identical; a world's effects at 1 s (media
// and particles included) in both; for particles a line with the streaks' count and the host's
// BVH build time.
// --lidar (the default rows; name one world): the realtime kernels alone before and after a
// LiDAR's CudaRayQuery of the scene traced a scan in the process, 3 rounds at each size.
// --lidar-first (the default rows): a LiDAR's CudaRayQuery made and tracing a scan right after
// the CUDA renderer, before its first frame (as a run's LiDAR sink), alive for the world's rows.
// --statics [--frames N]: the static maps' build through our host traversal and through Embree,
// N rounds interleaved (default 2; no GPU needed).
// usage:
//   render_cuda_bench [--frames N] [--batch N,... [--size WxH] [--sessions S] | --parity |
//                     --realtime [--size WxH] | --pathtraced [--size WxH] [--spp N]
//                     [--seed-floor]] [world.yaml ...]

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <string>
#include <thread>
#include <utility>
#include <vector>

#include "penumbra/core/output_file.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/physics/simulation.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/cuda/cuda_batch_bench.h"
#include "penumbra/render/cuda/cuda_batch_kernels.h"
#include "penumbra/render/cuda/cuda_ray_query.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/frame/bvh_ray_query.h"
#include "penumbra/render/frame/realtime_frame.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/media/media_realtime.h"
#include "penumbra/render/media/media_scene.h"
#include "penumbra/render/particles/shelter_map.h"
#include "penumbra/render/sky/sky_irradiance_volume.h"
#include "penumbra/scene/camera_pose.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"
#include "render/cuda/cuda_parity.h"
#include "render/cuda/path_parity.h"
#include "render/cuda/realtime_parity.h"

namespace penumbra {
namespace {

using Clock = std::chrono::steady_clock;

// the spread of the last TimeRenders' frames (ms): its median and its slowest frame, so that a
// mean moved by a few slow frames (a hiccup) can be told from a steadily slower run. a Row takes
// it once (TakeSpread) and leaves it empty: rows not timed by TimeRenders show none.
struct FrameSpread {
  double median_ms = 0, max_ms = 0;
};
FrameSpread last_spread;

FrameSpread TakeSpread() { return std::exchange(last_spread, FrameSpread()); }

struct Row {
  std::string world, size, outputs, backend, how;
  double fps = 0;
  // of the TimeRenders call that gave fps, when one did (initialised after fps)
  FrameSpread spread = TakeSpread();
};

// mean seconds per Render of `view` under `fx` (null: none) over `frames` frames after 3
// warm-up frames; each frame timed too (last_spread).
double TimeRenders(Renderer* r, const WorldSnapshot& snap, const CameraView& view, int frames,
                   const EffectsFrame* fx = nullptr) {
  RenderedFrame f;
  for (int i = 0; i < 3; ++i) r->Render(snap, fx, view, &f);
  std::vector<double> ms(frames);
  const auto t0 = Clock::now();
  auto t = t0;
  for (int i = 0; i < frames; ++i) {
    r->Render(snap, fx, view, &f);
    const auto now = Clock::now();
    ms[i] = std::chrono::duration<double, std::milli>(now - t).count();
    t = now;
  }
  std::sort(ms.begin(), ms.end());
  last_spread = {ms[ms.size() / 2], ms.back()};
  return std::chrono::duration<double>(t - t0).count() / frames;
}

// mean milliseconds of RealtimeMedia::Build for `view` under `fx` (its homogeneous and grid
// media) with its shadow rays through `query`, over `frames` builds after one warm-up, the
// cells and batches over all cores; the same volumes the CPU renderer builds each media frame.
double TimeMediaBuild(const SceneDescription& scene, const WorldSnapshot& snap,
                      const CameraView& view, const EffectsFrame& fx, const RayQuery& query,
                      int frames) {
  MediaScene media;
  media.Build(&fx);
  LightSampler lights(scene);
  lights.Update(snap, &fx);
  const Camera camera(view.X_WO, view.intrinsics);
  ThreadPool pool(0);
  RealtimeMedia rm;
  auto build = [&] {
    rm.Build(media, lights, query, camera, 1, scene.center_W.cast<float>(), scene.extent_m,
             Eigen::Vector3f::Constant(0.5f), nullptr, &pool);
  };
  build();
  const auto t0 = Clock::now();
  for (int i = 0; i < frames; ++i) build();
  return 1e3 * std::chrono::duration<double>(Clock::now() - t0).count() / frames;
}

// a world for a benchmark row: its session (no renderer) stepped to 1 s, the snapshot there
// and the file's name.
struct BenchWorld {
  std::unique_ptr<Session> session;
  WorldSnapshot snap;
  std::string name;
};

BenchWorld LoadBenchWorld(const std::string& file) {
  SessionOptions so;
  so.build_renderer = false;
  BenchWorld w;
  w.session = std::make_unique<Session>(LoadWorldFile(file), so);
  Simulation& sim = w.session->sim();
  while (sim.time() < 1.0) sim.Step();
  w.snap = sim.Snapshot();
  w.name = file.substr(file.find_last_of('/') + 1);
  return w;
}

// a positive integer argument, or 0
int PositiveArg(const std::string& s) {
  char* end = nullptr;
  const long v = std::strtol(s.c_str(), &end, 10);
  return end && *end == '\0' && v > 0 && v < (1 << 30) ? static_cast<int>(v) : 0;
}

// --media: the effects frames' media volumes built on the device and on the host (file comment)
int MediaMain(const std::vector<std::string>& worlds, int width, int height, int frames) {
  fmt::print(
      "\n| world | size | media volumes built | frames/s | ms/frame | host preparation ms | "
      "RealtimeMedia::Build ms | grid light volumes | world light volume | grid froxels | fog "
      "froxels | device: uploads, media kernels and geometry ms |\n"
      "|---|---|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  std::vector<std::string> notes;
  for (const std::string& file : worlds) {
    BenchWorld world = LoadBenchWorld(file);
    const WorldSnapshot& snap = world.snap;
    const SceneDescription& scene = world.session->scene();
    const CameraSpec& cam = scene.cameras.front();
    const std::string size = fmt::format("{}x{}", width, height);
    CameraView view;
    view.X_WO = CameraPoseInWorld(cam, snap);
    view.intrinsics = CameraIntrinsics::FromFovy(width, height, cam.intrinsics.fovy_deg());
    view.near_m = cam.near_m;
    view.outputs[ImageKind::kRgb] = view.outputs[ImageKind::kDepth] = true;
    const std::shared_ptr<const EffectsFrame> fx =
        world.session->effects().Evaluate(snap, view.X_WO.translation());
    if (!fx || (fx->homogeneous_media.empty() && fx->grid_media.empty())) {
      notes.push_back(world.name + ": no media in the effects frame at 1 s");
      continue;
    }
    RenderSettings gpu_settings;
    gpu_settings.backend = RenderSettings::Backend::kCuda;
    const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, gpu_settings);
    auto* g = static_cast<cuda::CudaRenderer*>(gpu.get());
    RenderedFrame dev_a, dev_b;
    gpu->Render(snap, fx.get(), view, &dev_a);
    cuda::RealtimeFrameData& data = g->realtime_frame();
    gpu->Render(snap, fx.get(), view, &dev_b);
    const bool repeat = dev_a.rgb.data == dev_b.rgb.data &&
                        dev_a.radiance.data == dev_b.radiance.data &&
                        dev_a.depth_m.data == dev_b.depth_m.data;
    notes.push_back(fmt::format("{} {}: two renders bit-identical (rgb, radiance, depth): {}",
                                world.name, size, repeat ? "yes" : "NO"));
    // one row: `frames` frames rendered by render_frame(i) after 3 untimed ones (i = -1), with
    // the host's preparation, the media build and its stages and the device's first stage
    auto timed_row = [&](const std::string& label, auto render_frame) {
      for (int i = 0; i < 3; ++i) render_frame(-1);
      double prepare = 0, build = 0, geometry = 0;
      RealtimeMedia::BuildTimes st;
      const auto t0 = Clock::now();
      for (int i = 0; i < frames; ++i) {
        render_frame(i);
        prepare += g->last_prepare_ms();
        build += data.media_build_ms();
        geometry += g->device_realtime().last_stage_times().geometry;
        const RealtimeMedia::BuildTimes& t = data.media_build_times();
        st.grid_light += t.grid_light, st.light_volume += t.light_volume;
        st.grid_froxels += t.grid_froxels, st.fog_froxels += t.fog_froxels;
      }
      const double s = std::chrono::duration<double>(Clock::now() - t0).count() / frames;
      fmt::print(
          "| {} | {} | {} | {:.0f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | "
          "{:.3f} | {:.3f} |\n",
          world.name, size, label, 1 / s, 1e3 * s, prepare / frames, build / frames,
          st.grid_light / frames, st.light_volume / frames, st.grid_froxels / frames,
          st.fog_froxels / frames, geometry / frames);
    };
    RenderedFrame f;
    for (int round = 0; round < 3; ++round)
      timed_row("the volumes as kernels", [&](int) { gpu->Render(snap, fx.get(), view, &f); });
    // as in a run: a new snapshot and effects frame every 1/30 s of sim time (new grid arrays
    // every frame, uploaded every frame), evaluated before the timing.
    Simulation& sim = world.session->sim();
    std::vector<WorldSnapshot> snaps;
    std::vector<CameraView> views;
    std::vector<std::shared_ptr<const EffectsFrame>> fxs;
    for (int i = 0; i < frames; ++i) {
      const double until = sim.time() + 1.0 / 30.0;
      while (sim.time() < until) sim.Step();
      snaps.push_back(sim.Snapshot());
      views.push_back(view);
      views.back().X_WO = CameraPoseInWorld(cam, snaps.back());
      fxs.push_back(
          world.session->effects().Evaluate(snaps.back(), views.back().X_WO.translation()));
    }
    size_t grid_bytes = 0;
    for (const GridMedium& gm : fxs.back() ? fxs.back()->grid_media : fx->grid_media)
      grid_bytes += sizeof(float) * ((gm.density ? gm.density->size() : 0) +
                                     (gm.emission ? gm.emission->size() : 0));
    timed_row(
        fmt::format("device, a new frame every 1/30 s (grids uploaded every frame: {:.2f} MB)",
                    grid_bytes / 1e6),
        [&](int i) {
          // the untimed frames: the frame at 1 s (another grid than the timed frames')
          if (i < 0)
            gpu->Render(snap, fx.get(), view, &f);
          else
            gpu->Render(snaps[i], fxs[i].get(), views[i], &f);
        });
  }
  for (const std::string& n : notes) fmt::print("\n{}", n);
  fmt::print("\n");
  return 0;
}

// --realtime: the realtime tier's Render() stages and kernels (file comment)
int RealtimeMain(const std::vector<std::string>& worlds, int width, int height, int frames) {
  fmt::print(
      "\n| world | size | variant | frames/s | ms/frame | geometry ms | sky ms | shade ms "
      "| film+copies ms (copies after the row sums) | rgb as default "
      "|\n|---|---|---|---:|---:|---:|---:|---:|---:|---|\n");
  // where Render()'s host time goes (RealtimeStageTimes, CudaRenderer::last_prepare_ms):
  // printed after the variants' table
  std::vector<std::string> host_rows;
  for (const std::string& file : worlds) {
    const BenchWorld world = LoadBenchWorld(file);
    const WorldSnapshot& snap = world.snap;
    const SceneDescription& scene = world.session->scene();
    const CameraSpec& cam = scene.cameras.front();
    const std::string& name = world.name;
    const std::string size = fmt::format("{}x{}", width, height);
    const double fovy_deg = cam.intrinsics.fovy_deg();
    CameraView view;
    view.X_WO = CameraPoseInWorld(cam, snap);
    view.intrinsics = CameraIntrinsics::FromFovy(width, height, fovy_deg);
    view.near_m = cam.near_m;
    view.outputs[ImageKind::kRgb] = view.outputs[ImageKind::kDepth] = true;
    RenderSettings gpu_settings;
    gpu_settings.backend = RenderSettings::Backend::kCuda;
    const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, gpu_settings);
    auto* g = static_cast<cuda::CudaRenderer*>(gpu.get());
    cuda::DeviceRealtime& rt = g->device_realtime();
    RenderedFrame want, again;
    gpu->Render(snap, view, &want);
    gpu->Render(snap, view, &again);
    const bool repeatable = want.rgb.data == again.rgb.data &&
                            want.radiance.data == again.radiance.data &&
                            want.depth_m.data == again.depth_m.data;
    // Render(): into the same RenderedFrame every frame; into a new one every frame (as the
    // camera sink's CameraImages: the images allocated, zero-filled and first touched each
    // frame); without the radiance (CudaRenderer::set_radiance_output)
    const char* const render_variants[] = {"", ", a new RenderedFrame every frame",
                                           ", no radiance asked for"};
    double prepare_ms = 0;  // the default's host preparation before the kernels
    for (int v = 0; v < 3; ++v) {
      const bool fresh = v == 1, no_radiance = v == 2;
      g->set_radiance_output(!no_radiance);
      RenderedFrame f;
      for (int i = 0; i < 3; ++i) gpu->Render(snap, view, &f);
      cuda::RealtimeStageTimes sum;
      double prepare = 0, total = 0;
      const auto t0 = Clock::now();
      for (int i = 0; i < frames; ++i) {
        if (fresh) f = RenderedFrame();
        gpu->Render(snap, view, &f);
        const cuda::RealtimeStageTimes& t = rt.last_stage_times();
        sum.geometry += t.geometry, sum.sky += t.sky, sum.shade += t.shade, sum.film += t.film;
        sum.outputs += t.outputs;
        sum.launched += t.launched, sum.kernels_end += t.kernels_end;
        sum.copies_end += t.copies_end, total += t.total;
        prepare += g->last_prepare_ms();
      }
      const double s = std::chrono::duration<double>(Clock::now() - t0).count() / frames;
      const bool same = f.rgb.data == want.rgb.data;
      if (v == 0) prepare_ms = prepare / frames;
      const std::string extra = render_variants[v];
      fmt::print(
          "| {} | {} | cuda Render(){} | {:.0f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | "
          "{:.3f} ({:.3f}) | {} |\n",
          name, size, extra, 1 / s, 1e3 * s, sum.geometry / frames, sum.sky / frames,
          sum.shade / frames, sum.film / frames, sum.outputs / frames, same ? "yes" : "NO");
      const double wall = 1e3 * s, inside = total / frames;
      host_rows.push_back(fmt::format(
          "| {} | {} | Render(){} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | {:.3f} | "
          "{:.3f} |",
          name, size, extra, wall, prepare / frames, wall - inside, sum.launched / frames,
          sum.kernels_end / frames, sum.copies_end / frames, inside - sum.copies_end / frames,
          sum.outputs / frames));
    }
    g->set_radiance_output(true);
    fmt::print(
        "| {} | {} | cuda Render(), host preparation before the kernels (default) | | {:.3f} "
        "| | | | | |\n",
        name, size, prepare_ms);
    // depth + segmentation (the ground-truth kernel), into the same RenderedFrame and into a
    // new one every frame
    {
      CameraView truth = view;
      truth.outputs = CameraOutputs::None();
      truth.outputs[ImageKind::kDepth] = truth.outputs[ImageKind::kSegmentation] = true;
      const std::vector<std::string> pv = {"same frame", "a new RenderedFrame every frame"};
      RenderedFrame ref;
      gpu->Render(snap, truth, &ref);
      for (const std::string& what : pv) {
        RenderedFrame f;
        for (int i = 0; i < 3; ++i) gpu->Render(snap, truth, &f);
        cuda::PrimaryTimes sum;
        const int pf = std::max(10, frames * 4);
        const auto t0 = Clock::now();
        const bool fresh_frames = what.find("new RenderedFrame") != std::string::npos;
        for (int i = 0; i < pf; ++i) {
          if (fresh_frames) f = RenderedFrame();
          gpu->Render(snap, truth, &f);
          const cuda::PrimaryTimes& t = g->device().last_primary_times();
          sum.kernel += t.kernel, sum.copies += t.copies, sum.total += t.total;
        }
        const double s = std::chrono::duration<double>(Clock::now() - t0).count() / pf;
        const bool same = f.depth_m.data == ref.depth_m.data && f.geom_id.data == ref.geom_id.data;
        host_rows.push_back(fmt::format(
            "| {} | {} | depth+seg, {} | {:.3f} | | {:.3f} | | {:.3f} | {:.3f} | {:.3f} | {} |",
            name, size, what, 1e3 * s, 1e3 * s - sum.total / pf, sum.kernel / pf, sum.copies / pf,
            (sum.total - sum.copies) / pf, same ? "same bytes" : "DIFFER"));
      }
    }
    // the kernels alone
    gpu->Render(snap, view, &want);
    const int kernel_frames = std::max(10, frames * 4);
    const double kernel_ms = rt.TimeKernels(&g->device(), kernel_frames);
    fmt::print("| {} | {} | kernels | {:.0f} | {:.3f} | | | | | |\n", name, size, 1e3 / kernel_ms,
               kernel_ms);
    RenderSettings cpu_settings;
    cpu_settings.backend = RenderSettings::Backend::kEmbree;
    cpu_settings.threads = 0;
    const std::unique_ptr<Renderer> cpu = MakeRenderer(scene, cpu_settings);
    const double cpu_s = TimeRenders(cpu.get(), snap, view, std::max(3, frames / 10));
    fmt::print("| {} | {} | cpu Render(), all cores | {:.0f} | {:.3f} | | | | | |\n", name, size,
               1 / cpu_s, 1e3 * cpu_s);
    fmt::print("| {} | {} | cuda, two renders bit-identical | {} | | | | | | |\n", name, size,
               repeatable ? "yes" : "NO");
    // the default options' images, to compare builds (a traversal change must keep these)
    const auto bytes = [](const auto& v) {
      return std::string_view(reinterpret_cast<const char*>(v.data()), sizeof(v[0]) * v.size());
    };
    fmt::print("| {} | {} | cuda, FNV-1a of rgb / depth | {:016x} / {:016x} | | | | | | |\n", name,
               size, Fnv1a64(bytes(want.rgb.data)), Fnv1a64(bytes(want.depth_m.data)));
    fmt::print("| {} | {} | cuda, FNV-1a of radiance, EV100 | {:016x}, {:.17g} | | | | | | |\n",
               name, size, Fnv1a64(bytes(want.radiance.data)), want.ev100);
    const cuda::RealtimeExposureChecks& x = rt.exposure_checks();
    fmt::print(
        "| {} | {} | cuda, device exposures: frames, EV100 differs, developed again | {}, "
        "{}, {} | | | | | | |\n",
        name, size, x.frames, x.ev100_differs, x.redeveloped);
  }
  fmt::print(
      "\nWhere Render()'s time goes, ms a frame (host clock: wall = the benchmark's clock around "
      "Render(), prepare = CudaRenderer's host work before the kernels are queued, outside = "
      "wall minus DeviceRealtime::Render's own clock (the renderer's work around it), launched = "
      "DeviceRealtime::Render's start until everything is queued; CUDA events from the frame's "
      "first event: kernels end, copies end (the last transfer to page-locked memory); after "
      "copies = DeviceRealtime::Render's total minus copies end: the host's copies, waits and "
      "checks after the last transfer; host copies = from the launches' end to the last copy, "
      "waits included). depth+seg rows: wall, outside = wall minus RenderPrimary, kernel and "
      "copies end (events), after copies = RenderPrimary's host clock minus copies end.\n\n"
      "| world | size | variant | wall | prepare | outside | launched | kernels end | copies "
      "end | after copies | host copies / images "
      "|\n|---|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n");
  for (const std::string& r : host_rows) fmt::print("{}\n", r);
  return 0;
}

// --batch: K cameras over `sessions` sessions of each world, in batches
int BatchMain(const std::vector<std::string>& worlds, const std::vector<int>& counts, int width,
              int height, int sessions, int frames) {
  for (const std::string& file : worlds) {
    std::vector<std::unique_ptr<Session>> owned;
    std::vector<std::unique_ptr<Renderer>> cpus;
    std::vector<std::shared_ptr<const EffectsFrame>> effects;
    std::vector<cuda::BatchBenchWorld> bench_worlds;
    for (int s = 0; s < sessions; ++s) {
      SessionOptions so;
      so.build_renderer = false;
      so.add_controllers = false;
      owned.push_back(std::make_unique<Session>(LoadWorldFile(file), so));
      Simulation& sim = owned.back()->sim();
      while (sim.time() < 1.0) sim.Step();
      const SceneDescription& scene = owned.back()->scene();
      RenderSettings cpu_settings;
      cpu_settings.backend = RenderSettings::Backend::kEmbree;
      cpu_settings.threads = 0;
      cpus.push_back(MakeRenderer(scene, cpu_settings));
      cuda::BatchBenchWorld w;
      w.scene = &scene;
      w.snapshot = sim.Snapshot();
      const CameraSpec& cam = scene.cameras.front();
      w.view.X_WO = CameraPoseInWorld(cam, w.snapshot);
      w.view.intrinsics = cam.intrinsics;
      w.view.near_m = cam.near_m;
      // the world's effects at the snapshot (rain, fog, smoke: an rgb batch renders those
      // cameras alone, PerCameraEffects); none for a clear world
      effects.push_back(owned.back()->effects().Evaluate(w.snapshot, w.view.X_WO.translation()));
      if (effects.back() && !effects.back()->empty()) w.effects = effects.back().get();
      w.cpu = s == 0 ? cpus.back().get() : nullptr;  // the CPU row: one session's renderer
      bench_worlds.push_back(w);
    }
    if (sessions > 1)
      for (cuda::BatchBenchWorld& w : bench_worlds) w.cpu = cpus.front().get();
    // depth + segmentation, then the realtime tier's rgb + depth
    cuda::BatchOutputs truth, rgb;
    rgb.segmentation = false;
    rgb.rgb = true;
    for (const cuda::BatchOutputs& outputs : {truth, rgb}) {
      const std::vector<cuda::BatchBenchRow> rows = cuda::RunBatchBench(
          bench_worlds, width, height, counts, frames, outputs, StaticMapsQueryFactory());
      const std::string name = file.substr(file.find_last_of('/') + 1);
      fmt::print("\n{}", cuda::FormatBatchBench(
                             sessions > 1 ? fmt::format("{} x{} sessions", name, sessions) : name,
                             width, height, outputs, rows));
    }
  }
  fmt::print("\n| copy back, device to host | MiB | GB/s |\n|---|---:|---:|\n");
  for (const int64_t mib : {1, 16, 128}) {
    const cuda::CopyRates r = cuda::MeasureCopyRates(mib << 20, 20);
    fmt::print("| pinned (cudaMallocHost) | {} | {:.1f} |\n", mib, r.pinned_gbps);
    fmt::print("| pageable (new[]) | {} | {:.1f} |\n", mib, r.pageable_gbps);
  }
  return 0;
}

// --pathtraced: the pathtraced tier on the GPU beside the CPU backend (file comment)
int PathtracedMain(const std::vector<std::string>& worlds, int width, int height, int spp,
                   int frames, bool seed_floor) {
  fmt::print(
      "\n| world | size | spp | cuda Render() ms | cuda path kernel ms | cpu Render() ms ({} "
      "threads) | speed-up | radiance mean rel. diff (8x8 blocks) | image mean | cuda repeats "
      "bits |\n|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n",
      std::thread::hardware_concurrency());
  std::vector<std::string> floors;
  for (const std::string& file : worlds) {
    const BenchWorld world = LoadBenchWorld(file);
    const WorldSnapshot& snap = world.snap;
    const SceneDescription& scene = world.session->scene();
    const CameraSpec& cam = scene.cameras.front();
    const std::string& name = world.name;
    CameraView view;
    view.X_WO = CameraPoseInWorld(cam, snap);
    view.intrinsics = CameraIntrinsics::FromFovy(width, height, cam.intrinsics.fovy_deg());
    view.near_m = cam.near_m;
    view.outputs[ImageKind::kRgb] = view.outputs[ImageKind::kDepth] = true;
    // the world's effects at the snapshot (media included: on the GPU)
    const std::shared_ptr<const EffectsFrame> effects =
        world.session->effects().Evaluate(snap, view.X_WO.translation());
    const EffectsFrame* fx = effects.get();
    RenderSettings cpu_settings = path_parity::PathSettings(RenderSettings::Backend::kEmbree, spp);
    cpu_settings.threads = 0;
    const RenderSettings gpu_settings =
        path_parity::PathSettings(RenderSettings::Backend::kCuda, spp);
    const std::unique_ptr<Renderer> gpu = MakeRenderer(scene, gpu_settings);
    auto* g = static_cast<cuda::CudaRenderer*>(gpu.get());
    RenderedFrame a, b, want;
    gpu->Render(snap, fx, view, &a);
    gpu->Render(snap, fx, view, &b);
    const bool repeats = a.radiance.data == b.radiance.data && a.rgb.data == b.rgb.data;
    const double gpu_ms = 1e3 * TimeRenders(gpu.get(), snap, view, frames, fx);
    const double kernel_ms = g->device_path().TimeKernel(&g->device(), frames);
    // the particle streaks: their count, the host's BVH build of the last frame
    // and the host's whole preparation of it
    const cuda::PathStreakBuild& streaks = g->realtime_frame().path_streaks();
    if (!streaks.empty())
      floors.push_back(fmt::format(
          "{}: {} particle streaks, their BVH built on the host in {:.2f} ms; the frame's host "
          "preparation {:.2f} ms",
          name, streaks.View().num, streaks.build_ms(), g->last_prepare_ms()));
    const std::unique_ptr<Renderer> cpu = MakeRenderer(scene, cpu_settings);
    const auto t0 = Clock::now();
    cpu->Render(snap, fx, view, &want);
    const double cpu_ms = 1e3 * std::chrono::duration<double>(Clock::now() - t0).count();
    if (seed_floor) {
      RenderSettings other = cpu_settings;
      other.seed = cpu_settings.seed + 1;
      RenderedFrame c;
      MakeRenderer(scene, other)->Render(snap, fx, view, &c);
      floors.push_back(fmt::format(
          "{}: two CPU renders with seeds {} and {}: mean relative difference {:.3f} % (8x8 "
          "blocks), {:.3f} % (image mean)",
          name, cpu_settings.seed, other.seed,
          100 * path_parity::TileRelativeDifference(c.radiance, want.radiance),
          100 * path_parity::MeanRelativeDifference(c.radiance, want.radiance)));
    }
    fmt::print(
        "| {} | {}x{} | {} | {:.1f} | {:.1f} | {:.0f} | {:.1f}x | {:.3f} % | {:.3f} % | {} |\n",
        name, width, height, spp, gpu_ms, kernel_ms, cpu_ms, cpu_ms / gpu_ms,
        100 * path_parity::TileRelativeDifference(a.radiance, want.radiance),
        100 * path_parity::MeanRelativeDifference(a.radiance, want.radiance),
        repeats ? "yes" : "NO");
  }
  for (const std::string& f : floors) fmt::print("{}\n", f);
  return 0;
}

// a LiDAR's scan through `query` posed at `snap`: 32 x 1800 rays from `origin_W`, elevations
// -15..15 deg, every azimuth, up to 100 m (the hits are not kept).
void TraceLidarScan(RayQuery* query, const WorldSnapshot& snap, const Eigen::Vector3d& origin_W) {
  query->Update(snap);
  std::vector<Ray> scan;
  for (int e = 0; e < 32; ++e)
    for (int a = 0; a < 1800; ++a) {
      const float el = static_cast<float>((-15.0 + e * (30.0 / 31)) * M_PI / 180),
                  az = static_cast<float>(a * (2 * M_PI / 1800));
      Ray r;
      r.o = origin_W.cast<float>();
      r.d = Eigen::Vector3f(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
      r.tmax = 100;
      scan.push_back(r);
    }
  std::vector<SurfaceHit> hits(scan.size());
  std::unique_ptr<bool[]> did(new bool[scan.size()]);
  query->Intersect(scan, hits, std::span<bool>(did.get(), scan.size()));
}

// --statics: the static maps a new realtime renderer builds before its first frame (the sky
// irradiance volume and, for worlds with particles, the shelter map), traced through our
// traversal on the host's threads (BvhRayQuery, CudaRenderer's default) and through Embree
// (RayScene, the CPU backend's and MakeRenderer's), interleaved `rounds` times: build ms and
// the valid probes of each. needs no GPU.
int StaticsMain(const std::vector<std::string>& worlds, int rounds, int host_threads) {
  ThreadPool pool(host_threads);
  fmt::print(
      "\nhost threads: {}\n\n| world | query | sky volume build ms | valid probes | "
      "shelter map build ms |\n|---|---|---:|---:|---:|\n",
      pool.num_threads());
  for (const std::string& file : worlds) {
    const BenchWorld world = LoadBenchWorld(file);
    const SceneDescription& scene = world.session->scene();
    const std::pair<const char*, RayQueryFactory> queries[] = {
        {"BvhRayQuery (host traversal)", cuda::BvhRayQueryFactory(&pool)},
        {"Embree (RayScene)", StaticMapsQueryFactory()}};
    for (int r = 0; r < rounds; ++r)
      for (const auto& [label, make] : queries) {
        SkyIrradianceVolume volume(make);
        const auto t0 = Clock::now();
        volume.Build(scene, world.snap.X_WB, &pool);
        const auto t1 = Clock::now();
        ShelterMap shelter(make);
        shelter.Build(scene, world.snap.X_WB, &pool);
        const auto t2 = Clock::now();
        fmt::print("| {} | {} | {:.1f} | {} of {} | {:.1f} |\n", world.name, label,
                   std::chrono::duration<double, std::milli>(t1 - t0).count(),
                   volume.num_valid_probes(), volume.num_probes(),
                   std::chrono::duration<double, std::milli>(t2 - t1).count());
      }
  }
  return 0;
}

int Main(int argc, char** argv) {
  int frames = 50;
  int width = 0, height = 0, sessions = 1;
  bool parity = false, realtime = false, pathtraced = false, seed_floor = false, media = false;
  int spp = 64;
  // the single-camera rows: the CUDA renderer's host threads (RenderSettings::threads; 0 = all
  // cores), and whether the CPU backend's rows run too
  int host_threads = 0;
  bool cpu_rows = true, statics = false, frames_given = false, lidar_rows = false,
       lidar_first = false;
  std::vector<int> batch;
  std::vector<std::string> worlds;
  const auto usage = [](const std::string& why) {
    fmt::print(stderr,
               "render_cuda_bench: {}\nusage: render_cuda_bench [--frames N] [--batch N,... "
               "[--size WxH] [--sessions S] | --parity [--size WxH] | --realtime [--size WxH] | "
               "--media [--size WxH] | "
               "--pathtraced [--size WxH] [--spp N] | --statics] "
               "[--host-threads N] [--no-cpu] [--lidar | --lidar-first] [world.yaml ...]\n",
               why);
    return 2;
  };
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--frames" && has_value) {
      frames = PositiveArg(argv[++i]);
      frames_given = true;
      if (frames == 0) return usage("--frames: expected a positive integer");
    } else if (a == "--host-threads" && has_value) {
      host_threads = PositiveArg(argv[++i]);
      if (host_threads == 0) return usage("--host-threads: expected a positive integer");
    } else if (a == "--lidar") {
      lidar_rows = true;
    } else if (a == "--lidar-first") {
      lidar_first = true;
    } else if (a == "--statics") {
      statics = true;
    } else if (a == "--no-cpu") {
      cpu_rows = false;
    } else if (a == "--sessions" && has_value) {
      sessions = PositiveArg(argv[++i]);
      if (sessions == 0) return usage("--sessions: expected a positive integer");
    } else if (a == "--size" && has_value) {
      const std::string v = argv[++i];
      const size_t x = v.find('x');
      width = x == std::string::npos ? 0 : PositiveArg(v.substr(0, x));
      height = x == std::string::npos ? 0 : PositiveArg(v.substr(x + 1));
      if (width == 0 || height == 0) return usage("--size '" + v + "': expected WxH, e.g. 128x128");
    } else if (a == "--batch" && has_value) {
      std::string v = argv[++i];
      size_t pos = 0;
      while (pos <= v.size()) {
        const size_t end = std::min(v.find(',', pos), v.size());
        const int k = PositiveArg(v.substr(pos, end - pos));
        if (k == 0 || k > 65535) return usage("--batch '" + v + "': expected N[,N...], 1 to 65535");
        batch.push_back(k);
        pos = end + 1;
      }
    } else if (a == "--realtime") {
      realtime = true;
    } else if (a == "--media") {
      media = true;
    } else if (a == "--parity") {
      parity = true;
    } else if (a == "--pathtraced") {
      pathtraced = true;
    } else if (a == "--seed-floor") {
      seed_floor = true;
    } else if (a == "--spp" && has_value) {
      spp = PositiveArg(argv[++i]);
      if (spp == 0) return usage("--spp: expected a positive integer");
    } else if (a.rfind("--", 0) == 0) {
      return usage("unknown option '" + a + "'");
    } else {
      worlds.push_back(a);
    }
  }
  if (worlds.empty())
    worlds = {std::string(PENUMBRA_SOURCE_DIR) + "/worlds/default.yaml",
              std::string(PENUMBRA_SOURCE_DIR) + "/worlds/house.yaml"};
  if (statics) return StaticsMain(worlds, frames_given ? frames : 2, host_threads);
  const CudaDeviceStatus dev = ProbeCudaDevice();
  fmt::print("device: {}\n", dev.available ? dev.name : "none (" + dev.why + ")");
  if ((parity || realtime || media || pathtraced || !batch.empty()) && !dev.available) {
    fmt::print(stderr,
               "render_cuda_bench: --batch, --parity, --realtime and --pathtraced need a CUDA "
               "device\n");
    return 1;
  }
  if (pathtraced) {
    if (width == 0) width = 320, height = 240;
    return PathtracedMain(worlds, width, height, spp, std::min(frames, 5), seed_floor);
  }
  if (realtime) {
    if (width == 0) width = 640, height = 480;
    return RealtimeMain(worlds, width, height, frames);
  }
  if (media) {
    if (width == 0) width = 640, height = 480;
    return MediaMain(worlds, width, height, frames);
  }
  if (parity) {
    if (width == 0) width = 320, height = 240;
    std::vector<cuda_parity::ParityRow> rows;
    for (const std::string& w : worlds)
      rows.push_back(cuda_parity::MeasureParity(w, width, height));
    fmt::print("\n{}", cuda_parity::FormatParity(rows, width, height));
    return 0;
  }
  if (!batch.empty()) {
    if (width == 0) width = height = 128;
    return BatchMain(worlds, batch, width, height, sessions, frames);
  }
  std::vector<Row> rows;
  std::vector<std::string> builds;
  for (const std::string& file : worlds) {
    const BenchWorld world = LoadBenchWorld(file);
    const WorldSnapshot& snap = world.snap;
    const SceneDescription& scene = world.session->scene();
    const CameraSpec& cam = scene.cameras.front();
    const std::string& name = world.name;
    const double fovy_deg = cam.intrinsics.fovy_deg();
    RenderSettings cpu_settings;
    cpu_settings.backend = RenderSettings::Backend::kEmbree;
    cpu_settings.threads = 0;
    const std::unique_ptr<Renderer> cpu = cpu_rows ? MakeRenderer(scene, cpu_settings) : nullptr;
    std::unique_ptr<Renderer> gpu;
    std::unique_ptr<cuda::CudaRayQuery> lidar_query;  // --lidar-first
    if (dev.available) {
      RenderSettings gpu_settings;
      gpu_settings.backend = RenderSettings::Backend::kCuda;
      gpu_settings.threads = host_threads;
      const auto t0 = Clock::now();
      gpu = MakeRenderer(scene, gpu_settings);
      const double s = std::chrono::duration<double>(Clock::now() - t0).count();
      auto* g = static_cast<cuda::CudaRenderer*>(gpu.get());
      // --lidar-first: a LiDAR's CudaRayQuery made and tracing before the renderer's first frame
      // (as a run's LiDAR sink makes it at set-up), alive for all the world's rows
      if (lidar_first) {
        lidar_query = std::make_unique<cuda::CudaRayQuery>(scene);
        TraceLidarScan(lidar_query.get(), snap, CameraPoseInWorld(cam, snap).translation());
      }
      // the renderer's BVH is built over its pool; the same scene on one thread beside it
      const cuda::BvhScene serial(scene);
      builds.push_back(fmt::format(
          "{}: {} triangles, BVH build {:.3f} s (CPU, the renderer's {} threads; one thread "
          "{:.3f} s), renderer set-up {:.3f} s (MakeRenderer: BVH, device copies, frame data)",
          name, g->bvh().num_triangles(), g->bvh().build_seconds(), g->host_threads(),
          serial.build_seconds(), s));
    }
    for (auto [w, h] : {std::pair{640, 480}, std::pair{128, 128}}) {
      const std::string size = fmt::format("{}x{}", w, h);
      CameraView view;
      view.X_WO = CameraPoseInWorld(cam, snap);
      view.intrinsics = CameraIntrinsics::FromFovy(w, h, fovy_deg);
      view.near_m = cam.near_m;
      view.outputs[ImageKind::kRgb] = false;
      view.outputs[ImageKind::kDepth] = view.outputs[ImageKind::kSegmentation] = true;
      CameraView all = view;
      all.outputs[ImageKind::kRange] = all.outputs[ImageKind::kNormals] = true;
      all.outputs[ImageKind::kInstanceSegmentation] =
          all.outputs[ImageKind::kSemanticSegmentation] = true;
      CameraView rgb = view;
      rgb.outputs[ImageKind::kRgb] = true;
      rgb.outputs[ImageKind::kSegmentation] = false;
      const int n = w * h < 100000 ? frames * 10 : frames;
      const std::shared_ptr<const EffectsFrame> fx =
          world.session->effects().Evaluate(snap, view.X_WO.translation());
      const bool with_fx = fx && !fx->empty();
      const std::string fx_outputs = "rgb+depth realtime + effects (on GPU)";
      if (gpu && w == 640) {
        // the new renderer's first realtime frame (under the world's effects) against its
        // second: the one-off builds on the host (the sky irradiance volume, the shelter map)
        // and the first uploads
        auto* g = static_cast<cuda::CudaRenderer*>(gpu.get());
        RenderedFrame first;
        const auto t0 = Clock::now();
        gpu->Render(snap, with_fx ? fx.get() : nullptr, rgb, &first);
        const double first_ms =
            std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        const double volume_ms = g->realtime_frame().volume_update_ms();
        const double shelter_ms = g->realtime_frame().shelter_update_ms();
        const auto t1 = Clock::now();
        gpu->Render(snap, with_fx ? fx.get() : nullptr, rgb, &first);
        const double second_ms =
            std::chrono::duration<double, std::milli>(Clock::now() - t1).count();
        builds.push_back(fmt::format(
            "{} {}{}: the renderer's first realtime frame {:.1f} ms (sky irradiance volume "
            "{:.1f} ms, shelter map {:.1f} ms, both on the host), its second {:.2f} ms",
            name, size, with_fx ? " with its effects" : "", first_ms, volume_ms, shelter_ms,
            second_ms));
      }
      if (gpu && with_fx) {
        rows.push_back({name, size, fx_outputs, "cuda", "Render()",
                        1 / TimeRenders(gpu.get(), snap, rgb, n, fx.get())});
        if (!fx->particles.empty()) {
          // the particle streaks splatted on the device
          auto* g = static_cast<cuda::CudaRenderer*>(gpu.get());
          const double prep_device = g->last_prepare_ms();
          const double late_ms = g->last_late_streaks_ms();
          const int streaks = g->realtime_frame().splat_streaks().View().num;
          // the drops culled on the device (late streaks), two rounds: the host's time making
          // the streaks (last_late_streaks_ms) and DeviceStreakCull's
          double cull_device_ms[2] = {0, 0}, cull_run_ms[2] = {0, 0}, cull_stage_ms[2] = {0, 0};
          for (int round = 0; round < 2; ++round) {
            rows.push_back({name, size,
                            fmt::format("rgb+depth realtime + effects (on GPU), late streaks, "
                                        "drops culled on the device{}",
                                        round == 0 ? "" : ", again"),
                            "cuda", "Render()",
                            1 / TimeRenders(gpu.get(), snap, rgb, n, fx.get())});
            cull_device_ms[round] = g->last_late_streaks_ms();
            cull_run_ms[round] = g->device_drop_cull()->run_ms();
            cull_stage_ms[round] = g->device_drop_cull()->stage_ms();
          }
          builds.push_back(fmt::format(
              "{} {}: late streaks' host time a frame (last timed frame, two rounds): drops "
              "culled on the device {:.3f} / {:.3f} ms (DeviceStreakCull::Queue {:.3f} / {:.3f} "
              "ms, of which staging {:.3f} / {:.3f} ms); {} streaks, {} rain drops culled",
              name, size, cull_device_ms[0], cull_device_ms[1], cull_run_ms[0], cull_run_ms[1],
              cull_stage_ms[0], cull_stage_ms[1], g->realtime_frame().splat_streaks().View().num,
              g->realtime_frame().streaks_culled()));
          // where one rain frame's time goes (device culling, late streaks: the defaults), the
          // median of 21 frames by wall time: the host's clock from Render's start, the frame's
          // device stages from its first event, the drops' transfer and culling on their stream
          {
            struct Split {
              double wall, prepare, late_start, late, stage, upload, cull, launched, kernels_end,
                  copies_end;
            };
            std::vector<Split> splits;
            RenderedFrame f;
            for (int i = 0; i < 21; ++i) {
              const auto t0 = Clock::now();
              gpu->Render(snap, fx.get(), rgb, &f);
              const double wall =
                  std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
              const cuda::DeviceStreakCull* dc = g->device_drop_cull();
              const cuda::RealtimeStageTimes& st = g->device_realtime().last_stage_times();
              splits.push_back({wall, g->last_prepare_ms(), g->last_late_streaks_start_ms(),
                                g->last_late_streaks_ms(), dc->stage_ms(), dc->device_upload_ms(),
                                dc->device_cull_ms(), st.launched, st.kernels_end, st.copies_end});
            }
            std::sort(splits.begin(), splits.end(),
                      [](const Split& a, const Split& b) { return a.wall < b.wall; });
            const Split& m = splits[splits.size() / 2];
            builds.push_back(fmt::format(
                "{} {}: one rain frame (median of 21 by wall time) {:.3f} ms: host preparation "
                "{:.3f} ms, DeviceRealtime::Render's queuing {:.3f} ms (late streaks included); "
                "late "
                "streaks from {:.3f} ms after Render's start for {:.3f} ms "
                "(of which staging the drops {:.3f} ms); device, from the frame's first event: "
                "kernels end {:.3f} ms, copies end {:.3f} ms; the drops' transfer {:.3f} ms and "
                "their culling {:.3f} ms on the culling's stream",
                name, size, m.wall, m.prepare, m.launched, m.late_start, m.late, m.stage,
                m.kernels_end, m.copies_end, m.upload, m.cull));
          }
          // a rolling-shutter camera that turns 0.25 rad and moves 16 cm during its 30 ms
          // readout (realtime_parity::AddRollingShutter): the device splat, whose boxes and row
          // columns follow the rows' poses
          CameraView rolling = rgb;
          realtime_parity::AddRollingShutter(&rolling);
          rows.push_back({name, size,
                          "rgb+depth realtime + effects (on GPU), rolling shutter turning", "cuda",
                          "Render()", 1 / TimeRenders(gpu.get(), snap, rolling, n, fx.get())});
          std::vector<unsigned long long> rolling_keys;
          size_t rolling_keyed = 0;
          if (g->device_realtime().DownloadStreakKeys(&rolling_keys))
            for (unsigned long long key : rolling_keys) rolling_keyed += key != kNoStreakKey;
          const double rolling_prep = g->last_prepare_ms(),
                       rolling_late = g->last_late_streaks_ms();
          const int rolling_streaks = g->realtime_frame().splat_streaks().View().num;
          builds.push_back(fmt::format(
              "{} {}: rolling shutter turning: {} streaks, {} pixels keyed by the device splat; "
              "host preparation {:.2f} ms a frame, {:.2f} ms making the streaks while the GPU "
              "works",
              name, size, rolling_streaks, rolling_keyed, rolling_prep, rolling_late));
          builds.push_back(fmt::format(
              "{} {}: particles: {} streaks after the host's culling; host preparation {:.2f} ms "
              "a frame (late streaks: before the kernels, and {:.2f} ms making the streaks while "
              "the GPU works; CudaRenderer::last_prepare_ms and last_late_streaks_ms of the last "
              "timed frame)",
              name, size, streaks, prep_device, late_ms));
          // every output of a frame, to compare builds
          RenderedFrame late_frame;
          gpu->Render(snap, fx.get(), rgb, &late_frame);
          const auto bytes = [](const auto& v) {
            return std::string_view(reinterpret_cast<const char*>(v.data()),
                                    sizeof(v[0]) * v.size());
          };
          builds.push_back(fmt::format(
              "{} {}: effects frame: FNV-1a of rgb / depth / radiance {:016x} / {:016x} / "
              "{:016x}, EV100 {:.17g}",
              name, size, Fnv1a64(bytes(late_frame.rgb.data)),
              Fnv1a64(bytes(late_frame.depth_m.data)), Fnv1a64(bytes(late_frame.radiance.data)),
              late_frame.ev100));
        }
        if (!fx->homogeneous_media.empty() || !fx->grid_media.empty())
          builds.push_back(fmt::format(
              "{} {}: effects frame with media on the GPU: host preparation {:.2f} ms a frame "
              "(the last of the timed frames; RealtimeFrameData::Prepare, media volumes included)",
              name, size, static_cast<cuda::CudaRenderer*>(gpu.get())->last_prepare_ms()));
      }
      // the media volumes' build over Embree and over the GPU's RayQuery
      // (docs/journal/2026-11-26-gpu-effects.md,
      // "Homogeneous media: the shared part")
      if (dev.available && with_fx && (!fx->homogeneous_media.empty() || !fx->grid_media.empty()) &&
          w == 640) {
        RayScene embree(scene);
        embree.Update(snap);
        cuda::CudaRayQuery query(scene);
        query.Update(snap);
        const int nb = std::max(3, frames / 5);
        const double ms_cpu = TimeMediaBuild(scene, snap, rgb, *fx, embree, nb);
        const double ms_gpu = TimeMediaBuild(scene, snap, rgb, *fx, query, nb);
        cuda::BvhRayQuery host_query(scene);
        host_query.Update(snap);
        const double ms_host = TimeMediaBuild(scene, snap, rgb, *fx, host_query, nb);
        builds.push_back(fmt::format(
            "{}: media volumes (RealtimeMedia::Build, {}x{} camera, all cores): {:.2f} ms with "
            "Embree's shadow rays, {:.2f} ms with CudaRayQuery's, {:.2f} ms with BvhRayQuery's "
            "(host traversal) ({} builds each)",
            name, w, h, ms_cpu, ms_gpu, ms_host, nb));
      }
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
        // as the camera sink asks: the radiance left on the device (CameraView::want_radiance)
        CameraView sink_view = rgb;
        sink_view.want_radiance = false;
        rows.push_back({name, size, "rgb+depth realtime, no radiance (as the camera sink asks)",
                        "cuda", "Render()", 1 / TimeRenders(gpu.get(), snap, sink_view, n)});
        const double rgb_ms = g->device_realtime().TimeKernels(&g->device(), n);
        rows.push_back({name, size, "rgb+depth realtime", "cuda", "kernels only", 1e3 / rgb_ms});
      }
      const int nc = std::max(3, n / 10);
      if (!cpu_rows) continue;
      rows.push_back(
          {name, size, "depth+seg", "cpu", "Render()", 1 / TimeRenders(cpu.get(), snap, view, nc)});
      rows.push_back({name, size, "all ground truth", "cpu", "Render()",
                      1 / TimeRenders(cpu.get(), snap, all, nc)});
      rows.push_back({name, size, "rgb+depth realtime", "cpu", "Render()",
                      1 / TimeRenders(cpu.get(), snap, rgb, nc)});
      if (with_fx)
        rows.push_back({name, size, "rgb+depth realtime + effects", "cpu", "Render()",
                        1 / TimeRenders(cpu.get(), snap, rgb, nc, fx.get())});
    }
    if (gpu && lidar_rows) {
      // the realtime kernels alone at both sizes, 3 rounds, then a LiDAR's CudaRayQuery (its own
      // BVH and device copy of the scene, as MakeRayQuery makes for a LiDAR on backend cuda)
      // traces one 32 x 1800 scan and stays alive, then the same 3 rounds. what the process did
      // before stays with it (under lazy module loading a query made before the first frame
      // slowed the kernels for good: "Eager module loading", docs/gpu.md), so the rows before
      // the query come first, and a run should name one world.
      auto* g = static_cast<cuda::CudaRenderer*>(gpu.get());
      auto time_kernels = [&](const char* label) {
        for (int round = 0; round < 3; ++round)
          for (auto [w, h] : {std::pair{640, 480}, std::pair{128, 128}}) {
            CameraView rgb;
            rgb.X_WO = CameraPoseInWorld(cam, snap);
            rgb.intrinsics = CameraIntrinsics::FromFovy(w, h, fovy_deg);
            rgb.near_m = cam.near_m;
            rgb.outputs[ImageKind::kRgb] = rgb.outputs[ImageKind::kDepth] = true;
            RenderedFrame f;
            gpu->Render(snap, rgb, &f);
            const int n = w * h < 100000 ? frames * 10 : frames;
            const double ms = g->device_realtime().TimeKernels(&g->device(), n);
            rows.push_back(
                {name, fmt::format("{}x{}", w, h), label, "cuda", "kernels only", 1e3 / ms});
          }
      };
      time_kernels("rgb+depth realtime, no LiDAR query yet");
      cuda::CudaRayQuery lidar(scene);
      TraceLidarScan(&lidar, snap, CameraPoseInWorld(cam, snap).translation());
      time_kernels("rgb+depth realtime, a LiDAR's CudaRayQuery alive");
    }
  }
  // ms/frame: the mean, then for Render() rows the median and the slowest frame
  fmt::print(
      "\n| world | size | outputs | backend | timed | frames/s | ms/frame (mean; median, max) "
      "|\n");
  fmt::print("|---|---|---|---|---|---:|---:|\n");
  for (const Row& r : rows) {
    const std::string spread =
        r.spread.max_ms > 0 ? fmt::format("; {:.3f}, {:.3f}", r.spread.median_ms, r.spread.max_ms)
                            : std::string();
    fmt::print("| {} | {} | {} | {} | {} | {:.0f} | {:.3f}{} |\n", r.world, r.size, r.outputs,
               r.backend, r.how, r.fps, 1e3 / r.fps, spread);
  }
  for (const std::string& b : builds) fmt::print("\n{}", b);
  fmt::print("\n");
  return 0;
}

}  // namespace
}  // namespace penumbra

int main(int argc, char** argv) { return penumbra::Main(argc, argv); }

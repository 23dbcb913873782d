#include "penumbra/render/cuda/cuda_batch_bench.h"

#include <fmt/format.h>

#include <Eigen/Geometry>
#include <chrono>
#include <cmath>
#include <utility>

#include "penumbra/render/cuda/cuda_batch_renderer.h"

namespace penumbra::cuda {
namespace {

using BenchClock = std::chrono::steady_clock;

double SecondsSince(BenchClock::time_point t0) {
  return std::chrono::duration<double>(BenchClock::now() - t0).count();
}

std::string OutputsLabel(const BatchOutputs& o) {
  std::string s;
  const auto add = [&](bool on, const char* name) {
    if (!on) return;
    if (!s.empty()) s += "+";
    s += name;
  };
  add(o.rgb, "rgb");
  add(o.depth, "depth");
  add(o.segmentation, "seg");
  add(o.instance_segmentation, "instance");
  add(o.semantic_segmentation, "semantic");
  add(o.range, "range");
  return s;
}

// wall seconds per batch of `batches` batches of `cams`, each Submit overlapping the previous
// batch's copy back; *kernel_ms: the kernels' mean (CUDA events); *stages (rgb batches, may be
// null): the realtime stages' means; *alone_ms and *alone (may be null): the mean host time of
// the cameras rendered alone and their count per batch
double TimePipeline(BatchRenderer* r, std::span<const BatchCamera> cams, int batches,
                    double* kernel_ms, RealtimeBatchTimes* stages, double* alone_ms = nullptr,
                    int* alone = nullptr) {
  for (int i = 0; i < 2; ++i) r->Wait(r->Submit(cams));  // warm-up
  double kernel_sum = 0, alone_sum = 0;
  int alone_cameras = 0;
  RealtimeBatchTimes st;
  const bool rgb = r->layout().outputs().rgb;
  const auto waited = [&](int64_t t) {
    r->Wait(t);
    kernel_sum += r->kernel_ms(t);
    alone_sum += r->alone_ms(t);
    alone_cameras = r->alone_cameras(t);
    if (!rgb) return;
    const RealtimeBatchTimes x = r->stage_ms(t);
    st.geometry += x.geometry, st.sky += x.sky, st.shade += x.shade;
    st.visibility += x.visibility, st.mirror += x.mirror, st.row_sums += x.row_sums;
    st.exposure += x.exposure, st.film += x.film, st.total += x.total;
  };
  const auto t0 = BenchClock::now();
  int64_t previous = -1;
  for (int i = 0; i < batches; ++i) {
    const int64_t t = r->Submit(cams);
    if (previous >= 0) waited(previous);
    previous = t;
  }
  waited(previous);
  const double s = SecondsSince(t0) / batches;
  if (kernel_ms) *kernel_ms = kernel_sum / batches;
  if (alone_ms) *alone_ms = alone_sum / batches;
  if (alone) *alone = alone_cameras;
  if (stages) {
    for (double* x : {&st.geometry, &st.sky, &st.shade, &st.visibility, &st.mirror, &st.row_sums,
                      &st.exposure, &st.film, &st.total})
      *x /= batches;
    *stages = st;
  }
  return s;
}

}  // namespace

CameraView OrbitView(const CameraView& view, double yaw_rad) {
  CameraView v = view;
  v.X_WO.linear() =
      Eigen::AngleAxisd(yaw_rad, Eigen::Vector3d::UnitZ()).toRotationMatrix() * view.X_WO.linear();
  return v;
}

std::vector<CameraView> BatchBenchViews(std::span<const BatchBenchWorld> worlds, int count,
                                        std::vector<int>* world_of) {
  std::vector<CameraView> views;
  world_of->clear();
  const int n = static_cast<int>(worlds.size());
  for (int k = 0; k < count; ++k) {
    const int w = k % n;
    views.push_back(OrbitView(worlds[w].view, 2 * M_PI * k / count));
    world_of->push_back(w);
  }
  return views;
}

std::vector<BatchBenchRow> RunBatchBench(std::span<const BatchBenchWorld> worlds, int width,
                                         int height, std::span<const int> camera_counts,
                                         int batches, const BatchOutputs& outputs,
                                         const RayQueryFactory& statics_query) {
  std::vector<BatchBenchRow> rows;
  int max_cameras = 1;
  for (int k : camera_counts) max_cameras = std::max(max_cameras, k);
  {
    BatchConfig config;
    config.width = width;
    config.height = height;
    config.max_cameras = max_cameras;
    config.outputs = outputs;
    config.copy = BatchCopy::kPinned;
    config.statics_query = statics_query;
    BatchRenderer r(config);
    for (const BatchBenchWorld& w : worlds) {
      const int i = r.AddWorld(*w.scene, w.settings);
      r.UpdateWorld(i, w.snapshot, w.effects);
    }
    for (int count : camera_counts) {
      std::vector<int> world_of;
      std::vector<CameraView> views = BatchBenchViews(worlds, count, &world_of);
      std::vector<BatchCamera> cams;
      for (int k = 0; k < count; ++k) {
        views[k].intrinsics =
            CameraIntrinsics::FromFovy(width, height, views[k].intrinsics.fovy_deg());
        cams.push_back(r.CameraOf(world_of[k], views[k]));
      }
      double kernel_ms = 0, alone_ms = 0;
      int alone = 0;
      RealtimeBatchTimes st;
      const double s = TimePipeline(&r, cams, batches, &kernel_ms, &st, &alone_ms, &alone);
      rows.push_back({count, "cuda", "batch, pinned copy overlapped", count / s, 1e3 * s});
      rows.push_back({count, "cuda", "kernel only", count / (kernel_ms * 1e-3), kernel_ms});
      // where an rgb batch's GPU time goes: frames/s if the batch were that stage alone
      if (outputs.rgb) {
        const std::pair<const char*, double> stages[] = {
            {"stage: geometry", st.geometry},   {"stage: sky terms", st.sky},
            {"stage: shading", st.shade},       {"stage: shared visibility", st.visibility},
            {"stage: mirror layer", st.mirror}, {"stage: row sums", st.row_sums},
            {"stage: exposure", st.exposure},   {"stage: film", st.film}};
        for (const auto& [what, ms] : stages)
          rows.push_back({count, "cuda", what, ms > 0 ? count / (ms * 1e-3) : 0.0, ms});
        // the cameras of worlds with particles or media, rendered one by one (host wall time)
        if (alone > 0)
          rows.push_back({count, "cuda", fmt::format("cameras rendered alone ({})", alone),
                          alone / (alone_ms * 1e-3), alone_ms});
      }
    }
  }
  // the CPU backend: the same views one after another (each Render on all its threads)
  for (int count : camera_counts) {
    std::vector<int> world_of;
    std::vector<CameraView> views = BatchBenchViews(worlds, count, &world_of);
    bool any = false;
    for (const BatchBenchWorld& w : worlds) any = any || w.cpu;
    if (!any) continue;
    RenderedFrame f;
    // the effects with rgb only: the ground truth does not see them (the CPU would still build
    // the media)
    const auto effects_of = [&](int w) { return outputs.rgb ? worlds[w].effects : nullptr; };
    const int cpu_batches = std::max(1, std::min(batches, 2048 / count));
    for (int k = 0; k < count; ++k) {
      views[k].intrinsics =
          CameraIntrinsics::FromFovy(width, height, views[k].intrinsics.fovy_deg());
      views[k].outputs[ImageKind::kRgb] = outputs.rgb;
      views[k].outputs[ImageKind::kDepth] = outputs.depth;
      views[k].outputs[ImageKind::kSegmentation] = outputs.segmentation;
      views[k].outputs[ImageKind::kInstanceSegmentation] = outputs.instance_segmentation;
      views[k].outputs[ImageKind::kSemanticSegmentation] = outputs.semantic_segmentation;
      views[k].outputs[ImageKind::kRange] = outputs.range;
      views[k].outputs[ImageKind::kNormals] = false;
    }
    for (int k = 0; k < std::min(count, 4); ++k)  // warm-up
      if (Renderer* cpu = worlds[world_of[k]].cpu)
        cpu->Render(worlds[world_of[k]].snapshot, effects_of(world_of[k]), views[k], &f);
    const auto t0 = BenchClock::now();
    int rendered = 0;
    for (int b = 0; b < cpu_batches; ++b)
      for (int k = 0; k < count; ++k)
        if (Renderer* cpu = worlds[world_of[k]].cpu) {
          cpu->Render(worlds[world_of[k]].snapshot, effects_of(world_of[k]), views[k], &f);
          ++rendered;
        }
    const double s = SecondsSince(t0);
    rows.push_back(
        {count, "cpu", "Render() per camera, all cores", rendered / s, 1e3 * s / cpu_batches});
  }
  return rows;
}

std::string FormatBatchBench(const std::string& label, int width, int height,
                             const BatchOutputs& outputs, std::span<const BatchBenchRow> rows) {
  std::string s =
      "| world | size | outputs | cameras | backend | timed | frames/s | ms/batch |\n"
      "|---|---|---|---:|---|---|---:|---:|\n";
  for (const BatchBenchRow& r : rows)
    s += fmt::format("| {} | {}x{} | {} | {} | {} | {} | {:.0f} | {:.3f} |\n", label, width, height,
                     OutputsLabel(outputs), r.cameras, r.backend, r.timed, r.frames_per_sec,
                     r.ms_per_batch);
  return s;
}

}  // namespace penumbra::cuda

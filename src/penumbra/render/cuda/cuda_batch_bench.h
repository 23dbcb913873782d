#pragma once
// the batch-rendering benchmark shared by `penumbra bench render --batch N` (bench/bench.cc) and
// render_cuda_bench (scripts/gpu/check.sh): K cameras spread over N worlds rendered by
// BatchRenderer, its copies back overlapped with the next kernel, the kernel alone, and the CPU
// backend rendering the same views one by one. a benchmark, never a pass/fail test.

#include <span>
#include <string>
#include <vector>

#include "penumbra/render/cuda/batch_layout.h"
#include "penumbra/render/ray_query.h"
#include "penumbra/render/render_settings.h"
#include "penumbra/render/renderer.h"
#include "penumbra/scene/scene_description.h"
#include "penumbra/scene/world_snapshot.h"

namespace penumbra::cuda {

/// one world of the benchmark: its scene, the snapshot it is rendered at, the base view of its
/// cameras (their pose is X_WO turned about the world z axis through the camera, see
/// OrbitView) and, optionally, a CPU renderer of the same scene to time beside the GPU.
struct BatchBenchWorld {
  const SceneDescription* scene = nullptr;
  /// the realtime rgb's settings (BatchRenderer::AddWorld; rgb batches only): film, seed,
  /// anisotropy, as the world's renderer has them
  RenderSettings settings;
  WorldSnapshot snapshot;
  /// the effects of the snapshot (null: none; BatchRenderer::UpdateWorld's: with particles or
  /// media, PerCameraEffects, an rgb batch renders the world's cameras alone); the CPU rows of
  /// rgb batches render them too. must outlive RunBatchBench.
  const EffectsFrame* effects = nullptr;
  CameraView view;
  Renderer* cpu = nullptr;  ///< null: no CPU row for this world
};

/// one measured row: frames/s are camera images per second.
struct BatchBenchRow {
  int cameras = 0;
  std::string backend;  ///< "cuda" or "cpu"
  std::string timed;    ///< what the time covers
  double frames_per_sec = 0;
  double ms_per_batch = 0;
};

/// `view` turned by `yaw_rad` about the world z axis through its optical centre.
CameraView OrbitView(const CameraView& view, double yaw_rad);

/// the views of a batch of `count` cameras over `worlds`: camera k in world k % N, turned by
/// 2 pi k / count (OrbitView of that world's view); `world_of` receives each camera's world.
std::vector<CameraView> BatchBenchViews(std::span<const BatchBenchWorld> worlds, int count,
                                        std::vector<int>* world_of);

/// times batches of each count of `camera_counts` (width x height, `outputs`): `batches`
/// batches each with pinned copies overlapped with the next kernel (wall clock from the first
/// Submit to the last Wait), the kernel alone (CUDA events;
/// with rgb all the batch's kernels, its exposures included), with rgb each realtime
/// stage's GPU time (rows "stage: ..."; RealtimeBatchTimes), with rgb and cameras rendered
/// alone (worlds with PerCameraEffects) the host time of those (row "cameras rendered alone",
/// frames/s of those cameras; BatchRenderer::alone_ms), and the CPU renderers rendering
/// the same views one at a time (at least one batch; with rgb the realtime tier's rgb and
/// depth). `statics_query`: BatchConfig::statics_query (the bench passes MakeRenderer's,
/// StaticMapsQueryFactory).
/// @throws Error if the CUDA runtime fails.
std::vector<BatchBenchRow> RunBatchBench(std::span<const BatchBenchWorld> worlds, int width,
                                         int height, std::span<const int> camera_counts,
                                         int batches, const BatchOutputs& outputs,
                                         const RayQueryFactory& statics_query = RayQueryFactory());

/// the rows as a markdown table (world label in the first column).
std::string FormatBatchBench(const std::string& label, int width, int height,
                             const BatchOutputs& outputs, std::span<const BatchBenchRow> rows);

}  // namespace penumbra::cuda

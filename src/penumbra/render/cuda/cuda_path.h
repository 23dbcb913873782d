#pragma once
// the pathtraced tier on the GPU (render/transport/path_trace.h per pixel, path_frame.h on the
// host): the device copy of the sky's sampling tables and the path kernels. a frame of n pixels
// splits each pixel's samples into PathRunsPerPixel(n, spp, 2^18) runs of consecutive samples, so
// that about 2^18 threads trace at once (a 128x96 frame at 1024 spp: 22 runs of 47 samples; frames
// with media run the kernel's TracePath<true> instance, frames with particle streaks its
// TracePath<..., true> instances, frames with neither the one of before); one thread a
// run sums its samples in sample order in double (PathSampleRange), then one thread a pixel adds
// its runs in run order and writes the pixel (PathFinishPixel). no atomics: frames are
// bit-identical run to run on one GPU (the run split moves the double sums' last bits against
// the host path's single run). implemented in path_kernels.cu; plain structs
// only here (no Eigen, no CUDA headers). every function throws penumbra::Error naming the CUDA
// call when the runtime reports an error.

#include <cstdint>

#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/frame/path_buffers.h"
#include "penumbra/render/transport/path_trace.h"

namespace penumbra::cuda {

/// the device side of the pathtraced tier.
class DevicePath : NonCopyable {
 public:
  DevicePath();
  ~DevicePath();

  /// copies the sky's sampling tables (host pointers) to the device; call again whenever the
  /// frame's sky changes (RealtimeFrameData::sky_generation). returns the device copy's pod.
  const SkySamplingPod& UploadSkySampling(const SkySamplingPod& host);

  /// copies the emissive geoms of `host` (host pointers; not its poses) to the device; returns
  /// their device view, whose poses UploadEmitterPoses sets.
  const PathEmitters& UploadEmitters(const PathEmitters& host);
  /// copies a frame's emitter poses (12 doubles an emitter, UploadEmitters' count) and returns
  /// the device view with them (after UploadEmitters).
  const PathEmitters& UploadEmitterPoses(const double* poses);

  /// copies a frame's media (MediaScene::View: host pointers; the grids' density and emission
  /// arrays end to end) to the device and returns their device view (valid until the next
  /// call). call it every frame with media (the grids' arrays change with the effects' time).
  const MediaSceneView& UploadMedia(const MediaSceneView& host);

  /// copies a frame's particle streaks (PathStreakBuild::View: host pointers) to the device
  /// and returns their device view (valid until the next call; num 0: none, nothing copied).
  /// call it every frame with particles (the streaks move with the effects' time).
  const PathStreaks& UploadStreaks(const PathStreaks& host);

  /// renders the frame `pf` (device pointers everywhere but the outputs, which are set here)
  /// on `scene`'s stream and copies its radiance, albedo, normal and depth into `out` (resized
  /// to the camera's pixels); waits for the copies.
  void Render(DeviceScene* scene, const PathFrameView& pf, PathBuffers* out);

  /// `count` runs of the last Render's kernel (no copies), timed with CUDA events: mean
  /// milliseconds per frame (benchmarks).
  double TimeKernel(DeviceScene* scene, int count);

 private:
  struct Impl;
  Impl* impl_;
};

}  // namespace penumbra::cuda

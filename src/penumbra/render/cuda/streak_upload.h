#pragma once
// a frame's particle streaks (path_streaks.h's PathStreaks: the BVH's nodes where it has one, the
// StreakPods, their particle sets, the rain's radiance where precomputed) copied to the device,
// for the pathtraced kernels (DevicePath::UploadStreaks, branch gpu16) and the realtime tier's
// splat (DeviceRealtime::Render, StreakSplatView, branch gpu18). includes the CUDA runtime header
// (cuda_device_buffer.h): only .cu files include this.

#include <cuda_runtime.h>

#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/cuda/path_streaks.h"

namespace penumbra::cuda {

/// the device buffers of a frame's streaks (they grow as needed, never shrink).
struct StreakBuffers {
  Buffer nodes, pods, sets, rain;

  /// copies the arrays of `h` (host pointers; num 0: nothing) on `stream` (pageable memory:
  /// staged before the call returns) and returns h with their device pointers (null where h
  /// has none: no BVH nodes, no rain).
  /// @throws Error on a CUDA failure.
  PathStreaks Upload(const PathStreaks& h, cudaStream_t stream) {
    PathStreaks d = h;
    if (h.num <= 0) return d;
    nodes.Upload(h.nodes, sizeof(BvhWideNode) * h.root.num_nodes, stream);
    pods.Upload(h.streaks, sizeof(StreakPod) * h.num, stream);
    sets.Upload(h.sets, sizeof(StreakSetPod) * h.num_sets, stream);
    rain.Upload(h.rain, sizeof(Float3) * h.num_rain, stream);
    d.nodes = h.root.num_nodes > 0 ? nodes.as<BvhWideNode>() : nullptr;
    d.streaks = pods.as<StreakPod>();
    d.sets = sets.as<StreakSetPod>();
    d.rain = h.num_rain > 0 ? rain.as<Float3>() : nullptr;
    return d;
  }
};

}  // namespace penumbra::cuda

#pragma once
// a frame's particle streaks (path_streaks.h's PathStreaks: the BVH's nodes where it has one, the
// StreakPods, their particle sets, the rain's radiance where precomputed) copied to the device,
// for the pathtraced kernels (DevicePath::UploadStreaks) and the realtime tier's splat
// (DeviceRealtime::Render, StreakSplatView). includes the CUDA runtime header
// (cuda_device_buffer.h): only .cu files include this.

#include <cuda_runtime.h>

#include <cstring>

#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/transport/path_streaks.h"

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

  /// h's particle sets copied on `stream`, its streaks already on the device (the device
  /// culling's, read in place: StreakSplatView::count; no BVH, no rain): through
  /// the page-locked *pin (grown as needed; not written again before the copy is done) when
  /// pin is not null, else from h's pageable array (staged before the call returns). returns h
  /// with the sets' device pointer (num: h's, a bound).
  /// @throws Error on a CUDA failure.
  PathStreaks UploadSets(const PathStreaks& h, PinnedBuffer* pin, cudaStream_t stream) {
    PathStreaks d = h;
    if (h.num <= 0 || h.num_sets <= 0) return d;
    const size_t bytes = sizeof(StreakSetPod) * h.num_sets;
    const void* src = h.sets;
    if (pin != nullptr) {
      pin->Reserve(bytes);
      std::memcpy(pin->p, h.sets, bytes);
      src = pin->p;
    }
    sets.Upload(src, bytes, stream);
    d.sets = sets.as<StreakSetPod>();
    return d;
  }

  /// h with its arrays (nodes, streaks, sets, rain) copied end to end, each 16-byte aligned,
  /// into the page-locked *pin (grown as needed), so that an Upload of the result does not wait
  /// for a busy stream (DeviceRealtime::Render's late streaks). *pin must not be written again
  /// before the copies from it are done. @throws Error on a CUDA failure (cudaMallocHost).
  static PathStreaks Stage(const PathStreaks& h, PinnedBuffer* pin) {
    PathStreaks d = h;
    if (h.num <= 0) return d;
    const size_t nodes_bytes = sizeof(BvhWideNode) * h.root.num_nodes;
    const size_t bytes[4] = {nodes_bytes, sizeof(StreakPod) * h.num,
                             sizeof(StreakSetPod) * h.num_sets, sizeof(Float3) * h.num_rain};
    const void* src[4] = {h.nodes, h.streaks, h.sets, h.rain};
    size_t at[4], total = 0;
    for (int k = 0; k < 4; ++k) {
      at[k] = total;
      total += (bytes[k] + 15) / 16 * 16;
    }
    pin->Reserve(total > 0 ? total : 1);
    char* base = pin->as<char>();
    for (int k = 0; k < 4; ++k)
      if (bytes[k] > 0 && src[k] != nullptr) std::memcpy(base + at[k], src[k], bytes[k]);
    d.nodes = h.nodes != nullptr ? reinterpret_cast<const BvhWideNode*>(base + at[0]) : nullptr;
    d.streaks = reinterpret_cast<const StreakPod*>(base + at[1]);
    d.sets = h.sets != nullptr ? reinterpret_cast<const StreakSetPod*>(base + at[2]) : nullptr;
    d.rain = h.rain != nullptr ? reinterpret_cast<const Float3*>(base + at[3]) : nullptr;
    return d;
  }
};

}  // namespace penumbra::cuda

#pragma once
// the drops of a frame's particle sets culled on the device: one thread per drop
// runs the CPU's per-drop decision (render/particles/streak_cull_math.h's StreakCullDrop, which
// ParticleStreaks::Build calls too) and an order-keeping compaction (cub::DeviceScan's exclusive
// sum over the kept flags, no atomics) writes the drawn streaks in the host's (set, index)
// order as StreakPods (a = the drop's position, b = its streak end, r = the widened radius,
// alpha, prim = the streak's index, set), so the streaks are the host culling's to the bit. the
// culled rain is counted by cub::DeviceReduce::Sum and the first non-finite drop found by
// cub::DeviceReduce::Min. Queue leaves the streaks and their count on the device for the
// frame's splat and Finish reads the counts back later. the decision's file
// (cuda_streak_cull.cu) is compiled with -fmad=false and the shared functions round every
// product and sum on their own (MulRn, AddRn) as well.

#include <cstdint>
#include <memory>
#include <vector>

#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/particles/streak_cull_math.h"
#include "penumbra/render/transport/path_streaks.h"

namespace penumbra::cuda {

/// one particle set's drops as host arrays (ParticleSet's position_W, velocity_W, radius_m).
struct DropSet {
  const float* p = nullptr;  ///< 3 per drop: position, world m
  const float* v = nullptr;  ///< 3 per drop: velocity, world m/s
  const float* r = nullptr;  ///< per drop: radius, m
  int64_t n = 0;             ///< drops
};

/// a frame's drop culling on the device; its buffers grow as needed and are kept between
/// frames. not thread-safe.
class DeviceStreakCull : NonCopyable {
 public:
  DeviceStreakCull();
  ~DeviceStreakCull();

  /// decides every drop of the num_sets `sets` (host arrays; set s has the flags flags[s]) by
  /// `frame` (ParticleStreaks' StreakCullSetup of this frame: its media and shelter roof, host
  /// arrays, are read here) on the device and waits for it: Queue, then Finish. the streaks
  /// stay on the device (device_streaks(), size()); Download copies them.
  /// @throws ConfigError (key effects.particles[s]) as ParticleStreaks::Build when a drop has a
  /// non-finite value (naming the first such drop). @throws Error on a CUDA failure.
  void Run(const DropSet* sets, int32_t num_sets, const StreakCullFrame& frame,
           const StreakCullSet* flags, const ParallelFn& parallel = ParallelFn());

  /// as Run without the wait: the drops (copied into page-locked staging in
  /// chunks over `parallel`, may be empty: serially), the sets' flags and the media go over in
  /// one transfer, the roof only when the map changed (ShelterPod's pointer, size or version),
  /// and the decision, the compaction and the copy back of the counts (streaks, culled rain,
  /// first non-finite drop) are queued on this object's stream; `wait_stream` (a cudaStream_t,
  /// may be null), if given, waits for them (cudaStreamWaitEvent: its work queued after this
  /// call reads the streaks and their count). the streaks are then at device_streaks(), at most
  /// bound() of them, their count at device_count(); size(), culled() and a non-finite drop's
  /// error come with Finish. waits first for an earlier Queue's work (its staging is reused).
  /// @throws Error on a CUDA failure.
  void Queue(const DropSet* sets, int32_t num_sets, const StreakCullFrame& frame,
             const StreakCullSet* flags, const ParallelFn& parallel = ParallelFn(),
             void* wait_stream = nullptr);
  /// waits for the last Queue's work (nothing when none is pending; a frame that waited for it
  /// on its own stream finds it done) and reads its counts: size() and culled().
  /// @throws ConfigError (key effects.particles[s]) as ParticleStreaks::Build when a drop has a
  /// non-finite value (naming the first such drop; size() and culled() are then 0).
  /// @throws Error on a CUDA failure.
  void Finish();

  /// streaks kept by the last Run or finished Queue.
  int size() const { return count_; }
  /// rain streaks culled as invisible by the last Run or finished Queue (ParticleStreaks::culled).
  int culled() const { return culled_; }
  /// the drops of the last Run or Queue: a bound of its streaks' count (0: no drops, nothing
  /// queued).
  int bound() const { return bound_; }
  /// the last Run's or Queue's streaks on the device (index order; bound() places; null when
  /// there were no drops): valid until the next Run or Queue.
  const StreakPod* device_streaks() const;
  /// device memory: the count of the last Run's or Queue's streaks, once its work is done
  /// (null when there were no drops).
  const int32_t* device_count() const;
  /// copies the last Run's or Queue's streaks to *out (resized to size(); Finish first).
  /// @throws as Finish.
  void Download(std::vector<StreakPod>* out);
  /// wall-clock milliseconds of the last Run (uploads, kernels, the count's read-back) or Queue
  /// (uploads and the kernels' queuing, no wait).
  double run_ms() const { return run_ms_; }
  /// the part of run_ms before the kernels were queued: the staging copies and the transfers'
  /// queuing.
  double stage_ms() const { return stage_ms_; }
  /// device milliseconds of the last finished Queue (CUDA events on its stream; 0 before one):
  /// the inputs' transfer (from its queuing to its end, after any work queued before it on the
  /// stream), and the decision, compaction and the counts' copy back after it (benchmarks).
  double device_upload_ms() const { return device_upload_ms_; }
  /// bytes the last Queue sent to the device: all its inputs, or without the drops' velocities
  /// and radii when they equal the previous Queue's (same sets and sizes: a rain drop keeps
  /// both from frame to frame) and the device still holds those.
  size_t upload_bytes() const { return upload_bytes_; }
  double device_cull_ms() const { return device_cull_ms_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  int count_ = 0;
  int culled_ = 0;
  int bound_ = 0;
  double run_ms_ = 0;
  double stage_ms_ = 0;
  double device_upload_ms_ = 0;
  size_t upload_bytes_ = 0;
  double device_cull_ms_ = 0;
};

}  // namespace penumbra::cuda

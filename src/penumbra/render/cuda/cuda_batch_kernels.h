#pragma once
// the device side of batch rendering (cuda_batch_renderer.h), behind a plain-struct interface
// (no CUDA headers here): one kernel renders every camera of a batch, each in its own world,
// into one device buffer laid out as BatchLayout says; the copy back to the host runs on a
// second stream, ordered after that kernel by an event, so it overlaps the next batch's
// kernel. implemented in cuda_batch_kernels.cu; every function throws penumbra::Error naming
// the CUDA call and its message when the runtime reports an error.

#include <cstdint>
#include <functional>

#include "penumbra/render/bvh/bvh_types.h"
#include "penumbra/render/cuda/batch_layout.h"

namespace penumbra::cuda {

/// where a batch's images go after its kernel.
enum class BatchCopy {
  kPinned,  ///< copied back into page-locked host memory, asynchronously (the default)
  kNone,    ///< left on the device for a consumer on the GPU (device-pointer API)
};

/// the streams, events and per-slot buffers of batch rendering (BatchTickets::kSlots slots).
class BatchDevice {
 public:
  /// allocates each slot's device buffer (and host buffer, unless kNone) of
  /// layout.capacity_bytes() bytes, two streams and the events.
  /// @throws Error if the CUDA runtime fails (no device, out of memory).
  BatchDevice(const BatchLayout& layout, BatchCopy copy);
  ~BatchDevice();
  BatchDevice(const BatchDevice&) = delete;
  BatchDevice& operator=(const BatchDevice&) = delete;

  /// blocks until every kernel submitted so far has finished (their copies may still run):
  /// call before a world's device arrays change (DeviceScene::Sync).
  void WaitForKernels();
  /// more work of a batch, enqueued on the kernel stream (a cudaStream_t, as void*) after the
  /// ground-truth kernel and before the batch's end event, writing into the slot's device
  /// buffer (`buffer`): the realtime rgb and its depth (RealtimeBatch).
  using MoreWork = std::function<void(void* stream, uint8_t* buffer)>;
  /// renders `cameras[0 .. count)` (host array, checked by BatchLayout::Check) of the worlds
  /// `views[0 .. num_views)` (host array of device-pointer SceneViews) into `slot`'s device
  /// buffer, after that slot's previous copy back: the ground-truth kernel (the planes other
  /// than rgb; with rgb, depth is `more`'s), then `more` (if set); then starts the copy back
  /// (unless kNone). returns at once.
  void Submit(int slot, const SceneView* views, int num_views, const BatchCamera* cameras,
              int count, const MoreWork& more = {});
  /// copies `n` floats of ray tables (host array; camera_rays.h's, one batch's, end to end) to
  /// `slot`'s table buffer on the kernel stream, ordered before the slot's next Submit and after
  /// every kernel submitted so far (the buffer grows as needed); returns the buffer's device
  /// address, for the batch's cameras' PinholeCamera::xy and rows. the host array may change
  /// once it returns.
  const float* UploadCameraTables(int slot, const float* tables, int64_t n);
  /// copies `bytes` bytes of host memory `src` (pageable: staged before the call returns, so it
  /// may change once it returns) to device address `dst` (inside a slot's buffer) on `stream`
  /// (MoreWork's): the images of the cameras a batch renders alone (BatchRenderer: worlds with
  /// particles or media) put into its buffer after its kernels, before its end event.
  void CopyToDevice(void* stream, uint8_t* dst, const void* src, int64_t bytes);
  /// blocks until `slot`'s last batch is on the host (kNone: its kernel finished); returns
  /// the host buffer (null for kNone).
  const uint8_t* Wait(int slot);
  /// `slot`'s device buffer.
  const uint8_t* device_buffer(int slot) const;
  /// `slot`'s host buffer (null for kNone).
  const uint8_t* host_buffer(int slot) const;
  /// the cudaEvent_t recorded after `slot`'s last kernel (for cudaStreamWaitEvent).
  void* kernel_event(int slot) const;
  /// the cudaStream_t the kernels run on (work enqueued on it runs after the batch just
  /// submitted and before the next one).
  void* stream() const;
  /// milliseconds `slot`'s last kernel took (CUDA events; call after Wait(slot)).
  double kernel_ms(int slot) const;

 private:
  struct Impl;
  Impl* impl_;
};

/// measured copy rates from device memory to host memory, GB/s (1e9 bytes/s).
struct CopyRates {
  double pinned_gbps = 0;    ///< into page-locked memory (cudaMallocHost)
  double pageable_gbps = 0;  ///< into ordinary memory (new[])
};

/// times `repeats` device-to-host copies of `bytes` bytes into pinned and into pageable host
/// memory (one warm-up each; CUDA events around the copies).
/// @throws Error if the CUDA runtime fails.
CopyRates MeasureCopyRates(int64_t bytes, int repeats);

}  // namespace penumbra::cuda

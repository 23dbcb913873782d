#pragma once
// the CUDA backend's runtime helpers for its .cu files: error checks, checked kernel launches,
// a growing device buffer, a growing page-locked host buffer, the host's copies of page-locked
// outputs into the caller's images and event timing. includes the CUDA runtime header: only .cu
// files include this.

#include <cuda_runtime.h>

#include <algorithm>
#include <cstddef>
#include <cstring>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/cuda/cuda_kernels.h"

namespace penumbra::cuda {

/// throws Error("CUDA backend: <what>: <message>") when `e` is not cudaSuccess.
inline void Check(cudaError_t e, const char* what) {
  if (e != cudaSuccess)
    throw Error(std::string("CUDA backend: ") + what + ": " + cudaGetErrorString(e));
}

/// queues kernel<<<grid, block, shared_bytes, stream>>>(args...) and checks the launch
/// (Check, naming `name`).
template <typename... Params, typename... Args>
void LaunchKernel(const char* name, void (*kernel)(Params...), dim3 grid, dim3 block,
                  size_t shared_bytes, cudaStream_t stream, const Args&... args) {
  kernel<<<grid, block, shared_bytes, stream>>>(args...);
  Check(cudaGetLastError(), name);
}

/// memory that grows (never shrinks) to the bytes asked for, allocated and freed by `Memory`
/// (DeviceMemory or PinnedMemory).
template <class Memory>
struct GrowingBuffer {
  void* p = nullptr;
  size_t bytes = 0;
  GrowingBuffer() = default;
  GrowingBuffer(const GrowingBuffer&) = delete;
  GrowingBuffer& operator=(const GrowingBuffer&) = delete;
  void Reserve(size_t n) {
    if (n <= bytes) return;
    if (p) Memory::Free(p);
    p = nullptr;
    bytes = 0;
    Check(Memory::Allocate(&p, n), Memory::kAllocate);
    bytes = n;
  }
  template <typename T>
  T* as() const {
    return static_cast<T*>(p);
  }
  ~GrowingBuffer() {
    if (p) Memory::Free(p);
  }
};

/// device memory (cudaMalloc).
struct DeviceMemory {
  static constexpr const char* kAllocate = "cudaMalloc";
  static cudaError_t Allocate(void** p, size_t n) { return cudaMalloc(p, n); }
  static void Free(void* p) { cudaFree(p); }
};

/// page-locked host memory (cudaMallocHost).
struct PinnedMemory {
  static constexpr const char* kAllocate = "cudaMallocHost";
  static cudaError_t Allocate(void** p, size_t n) { return cudaMallocHost(p, n); }
  static void Free(void* p) { cudaFreeHost(p); }
};

/// a device buffer that grows (never shrinks) to the bytes asked for.
struct Buffer : GrowingBuffer<DeviceMemory> {
  /// copies n host bytes in on stream s (asynchronous for pinned memory).
  void Upload(const void* src, size_t n, cudaStream_t s) {
    Reserve(n > 0 ? n : 1);
    if (n > 0) Check(cudaMemcpyAsync(p, src, n, cudaMemcpyHostToDevice, s), "cudaMemcpyAsync");
  }
  /// copies n bytes out to the host on stream s.
  void Download(void* dst, size_t n, cudaStream_t s) const {
    if (n > 0) Check(cudaMemcpyAsync(dst, p, n, cudaMemcpyDeviceToHost, s), "cudaMemcpyAsync");
  }
};

/// page-locked host memory that grows (never shrinks).
using PinnedBuffer = GrowingBuffer<PinnedMemory>;

/// one host copy of ParallelCopy.
struct HostCopy {
  void* dst;
  const void* src;
  size_t n;
  cudaEvent_t ready = nullptr;  ///< src is complete once this event passed (null: now)
};

/// the copies, in chunks of `chunk` bytes (at least 4 KiB), in one loop through `parallel`
/// (serially if it is empty, or if the copies hold at most `serial_bytes` bytes: a small frame's
/// copies cost less than waking a pool); a chunk waits for its copy's `ready` event before it
/// is copied.
inline void ParallelCopy(const ParallelFn& parallel, const std::vector<HostCopy>& copies,
                         size_t chunk, size_t serial_bytes = 0) {
  const size_t kChunk = std::max<size_t>(chunk, 4096);
  struct Chunk {
    char* dst;
    const char* src;
    size_t n;
    cudaEvent_t ready;
  };
  std::vector<Chunk> chunks;
  for (const HostCopy& c : copies)
    for (size_t a = 0; a < c.n; a += kChunk)
      chunks.push_back({static_cast<char*>(c.dst) + a, static_cast<const char*>(c.src) + a,
                        std::min(kChunk, c.n - a), c.ready});
  // chunks are taken in order: a thread waits for its chunk's source only
  auto copy = [&](int64_t i) {
    if (chunks[i].ready) Check(cudaEventSynchronize(chunks[i].ready), "copying an output");
    std::memcpy(chunks[i].dst, chunks[i].src, chunks[i].n);
  };
  size_t bytes = 0;
  for (const HostCopy& c : copies) bytes += c.n;
  const int64_t count = static_cast<int64_t>(chunks.size());
  if (parallel && count > 1 && bytes > serial_bytes)
    parallel(count, copy);
  else
    for (int64_t i = 0; i < count; ++i) copy(i);
}

/// the mean device time (ms) of one of `count` runs of `launch` (a callable that queues work on
/// stream s), from CUDA events recorded on s before the first run and after the last (the
/// caller warms up first where the first launch of a kernel costs more). 0 for count <= 0.
/// @throws Error when an event call fails or the work fails.
template <typename Launch>
double TimeOnStream(cudaStream_t s, int count, Launch&& launch) {
  if (count <= 0) return 0.0;
  struct Events {
    cudaEvent_t start = nullptr, stop = nullptr;
    ~Events() {
      if (start) cudaEventDestroy(start);
      if (stop) cudaEventDestroy(stop);
    }
  } e;
  Check(cudaEventCreate(&e.start), "cudaEventCreate");
  Check(cudaEventCreate(&e.stop), "cudaEventCreate");
  Check(cudaEventRecord(e.start, s), "cudaEventRecord");
  for (int k = 0; k < count; ++k) launch();
  Check(cudaGetLastError(), "timed launches");
  Check(cudaEventRecord(e.stop, s), "cudaEventRecord");
  Check(cudaEventSynchronize(e.stop), "timed work");
  float ms = 0;
  Check(cudaEventElapsedTime(&ms, e.start, e.stop), "cudaEventElapsedTime");
  return static_cast<double>(ms) / count;
}

}  // namespace penumbra::cuda

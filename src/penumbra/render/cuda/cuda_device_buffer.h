#pragma once
// the CUDA backend's runtime helpers for its .cu files: error checks, a growing device buffer
// and event timing. includes the CUDA runtime header: only .cu files include this.

#include <cuda_runtime.h>

#include <cstddef>
#include <string>

#include "penumbra/core/error.h"

namespace penumbra::cuda {

/// throws Error("CUDA backend: <what>: <message>") when `e` is not cudaSuccess.
inline void Check(cudaError_t e, const char* what) {
  if (e != cudaSuccess)
    throw Error(std::string("CUDA backend: ") + what + ": " + cudaGetErrorString(e));
}

/// a device buffer that grows (never shrinks) to the bytes asked for.
struct Buffer {
  void* p = nullptr;
  size_t bytes = 0;
  Buffer() = default;
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
  void Reserve(size_t n) {
    if (n <= bytes) return;
    if (p) cudaFree(p);
    p = nullptr;
    bytes = 0;
    Check(cudaMalloc(&p, n), "cudaMalloc");
    bytes = n;
  }
  /// copies n host bytes in on stream s (asynchronous for pinned memory).
  void Upload(const void* src, size_t n, cudaStream_t s) {
    Reserve(n > 0 ? n : 1);
    if (n > 0) Check(cudaMemcpyAsync(p, src, n, cudaMemcpyHostToDevice, s), "cudaMemcpyAsync");
  }
  /// copies n bytes out to the host on stream s.
  void Download(void* dst, size_t n, cudaStream_t s) const {
    if (n > 0) Check(cudaMemcpyAsync(dst, p, n, cudaMemcpyDeviceToHost, s), "cudaMemcpyAsync");
  }
  template <typename T>
  T* as() const {
    return static_cast<T*>(p);
  }
  ~Buffer() {
    if (p) cudaFree(p);
  }
};

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

#pragma once
// the CUDA backend's runtime helpers for its .cu files: error checks and a growing device
// buffer. includes the CUDA runtime header: only .cu files include this.

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

}  // namespace penumbra::cuda

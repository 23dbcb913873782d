// the device side of batch rendering (cuda_batch_kernels.h). the pixel's ray and ground truth
// are primary_pixel.h's PB_HOST_DEVICE functions, the traversal bvh_traversal.h's: no formula
// here that the host does not run too. no atomics: every pixel is written by one thread, so a
// batch's images are the same bits run to run.

#include <cuda_runtime.h>

#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/cuda/cuda_batch_kernels.h"
#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/transport/primary_pixel.h"
#include "penumbra/render/transport/realtime.h"

namespace penumbra::cuda {
namespace {

void CheckBatch(cudaError_t e, const char* what) {
  if (e != cudaSuccess)
    throw Error(std::string("CUDA batch rendering: ") + what + ": " + cudaGetErrorString(e));
}

// one thread per pixel of every camera: block (8, 8), grid z = the camera; the pixel's ray is
// CudaRenderer's PrimaryKernel's (PrimaryRay: with the camera's ray tables where it has them).
__global__ void BatchPrimaryKernel(const SceneView* views, const BatchCamera* cameras, int width,
                                   int height, PixelTruthPlanes out) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= width || v >= height) return;
  const int k = blockIdx.z;
  const BatchCamera& b = cameras[k];
  const PinholeCamera& c = b.camera;
  const F3 axes_W[3] = {c.ex, c.ey, c.ez};
  out.Write(TracePixelTruth(views[b.world], PrimaryRay(c, u, v), out.normal_O ? axes_W : nullptr),
            static_cast<int64_t>(k) * width * height + static_cast<int64_t>(v) * width + u);
}

}  // namespace

struct BatchDevice::Impl {
  explicit Impl(const BatchLayout& l) : layout(l) {}
  BatchLayout layout;
  BatchCopy copy = BatchCopy::kPinned;
  cudaStream_t compute = nullptr, copier = nullptr;
  uint8_t* device[BatchTickets::kSlots] = {};
  uint8_t* host[BatchTickets::kSlots] = {};
  BatchCamera* cameras[BatchTickets::kSlots] = {};
  SceneView* views[BatchTickets::kSlots] = {};
  int64_t views_capacity[BatchTickets::kSlots] = {};
  float* tables[BatchTickets::kSlots] = {};
  int64_t tables_capacity[BatchTickets::kSlots] = {};

  // *p holds at least n elements afterwards: a new buffer once the slot's earlier kernels, which
  // may read the old one, are done
  template <typename T>
  void Grow(T** p, int64_t* capacity, int64_t n, const char* what) {
    if (n <= *capacity) return;
    CheckBatch(cudaStreamSynchronize(compute), "waiting for the batch kernels");
    if (*p) cudaFree(*p);
    *p = nullptr;
    *capacity = 0;
    CheckBatch(cudaMalloc(reinterpret_cast<void**>(p), sizeof(T) * n), what);
    *capacity = n;
  }
  cudaEvent_t started[BatchTickets::kSlots] = {}, done[BatchTickets::kSlots] = {},
              copied[BatchTickets::kSlots] = {};
  bool pending_copy[BatchTickets::kSlots] = {};
  bool used[BatchTickets::kSlots] = {};

  void Release() {
    for (int s = 0; s < BatchTickets::kSlots; ++s) {
      if (device[s]) cudaFree(device[s]);
      if (cameras[s]) cudaFree(cameras[s]);
      if (views[s]) cudaFree(views[s]);
      if (tables[s]) cudaFree(tables[s]);
      if (host[s]) cudaFreeHost(host[s]);
      for (cudaEvent_t e : {started[s], done[s], copied[s]})
        if (e) cudaEventDestroy(e);
    }
    if (compute) cudaStreamDestroy(compute);
    if (copier) cudaStreamDestroy(copier);
  }
};

BatchDevice::BatchDevice(const BatchLayout& layout, BatchCopy copy) : impl_(new Impl(layout)) {
  InitRuntime();
  Impl& m = *impl_;
  m.copy = copy;
  try {
    CheckBatch(cudaStreamCreateWithFlags(&m.compute, cudaStreamNonBlocking), "cudaStreamCreate");
    CheckBatch(cudaStreamCreateWithFlags(&m.copier, cudaStreamNonBlocking), "cudaStreamCreate");
    const size_t bytes = static_cast<size_t>(layout.capacity_bytes());
    for (int s = 0; s < BatchTickets::kSlots; ++s) {
      CheckBatch(cudaMalloc(reinterpret_cast<void**>(&m.device[s]), bytes), "cudaMalloc (images)");
      CheckBatch(cudaMalloc(reinterpret_cast<void**>(&m.cameras[s]),
                            sizeof(BatchCamera) * layout.max_cameras()),
                 "cudaMalloc (cameras)");
      if (copy == BatchCopy::kPinned)
        CheckBatch(cudaMallocHost(reinterpret_cast<void**>(&m.host[s]), bytes),
                   "cudaMallocHost (pinned images)");
      CheckBatch(cudaEventCreate(&m.started[s]), "cudaEventCreate");
      CheckBatch(cudaEventCreate(&m.done[s]), "cudaEventCreate");
      CheckBatch(cudaEventCreateWithFlags(&m.copied[s], cudaEventDisableTiming), "cudaEventCreate");
    }
  } catch (...) {
    m.Release();
    delete impl_;
    throw;
  }
}

BatchDevice::~BatchDevice() {
  cudaStreamSynchronize(impl_->compute);
  cudaStreamSynchronize(impl_->copier);
  impl_->Release();
  delete impl_;
}

void BatchDevice::WaitForKernels() {
  CheckBatch(cudaStreamSynchronize(impl_->compute), "waiting for the batch kernels");
}

void BatchDevice::Submit(int slot, const SceneView* views, int num_views,
                         const BatchCamera* cameras, int count, const MoreWork& more) {
  Impl& m = *impl_;
  const BatchLayout& l = m.layout;
  // the slot's device buffer is free once its previous copy back has run
  if (m.pending_copy[slot])
    CheckBatch(cudaStreamWaitEvent(m.compute, m.copied[slot], 0), "cudaStreamWaitEvent");
  m.Grow(&m.views[slot], &m.views_capacity[slot], num_views, "cudaMalloc (worlds)");
  // from pageable memory: the call returns once the source is staged, so the host arrays may
  // change after it; the kernel below is ordered after the copies on the same stream
  CheckBatch(cudaMemcpyAsync(m.views[slot], views, sizeof(SceneView) * num_views,
                             cudaMemcpyHostToDevice, m.compute),
             "copying the worlds");
  CheckBatch(cudaMemcpyAsync(m.cameras[slot], cameras, sizeof(BatchCamera) * count,
                             cudaMemcpyHostToDevice, m.compute),
             "copying the cameras");
  uint8_t* base = m.device[slot];
  const auto plane = [&](BatchPlane p) -> void* {
    return l.has(p) ? base + l.plane_offset(p, count) : nullptr;
  };
  PixelTruthPlanes out;
  // with rgb the depth is the realtime path's (`more`)
  out.depth = l.outputs().rgb ? nullptr : static_cast<float*>(plane(BatchPlane::kDepth));
  out.geom_id = static_cast<int32_t*>(plane(BatchPlane::kSegmentation));
  out.body_id = static_cast<int32_t*>(plane(BatchPlane::kInstance));
  out.semantic = static_cast<int32_t*>(plane(BatchPlane::kSemantic));
  out.range = static_cast<float*>(plane(BatchPlane::kRange));
  out.normal_O = static_cast<float*>(plane(BatchPlane::kNormal));
  const dim3 block(8, 8);
  const dim3 grid((l.width() + 7) / 8, (l.height() + 7) / 8, count);
  CheckBatch(cudaEventRecord(m.started[slot], m.compute), "cudaEventRecord");
  if (out.any()) {
    BatchPrimaryKernel<<<grid, block, 0, m.compute>>>(m.views[slot], m.cameras[slot], l.width(),
                                                      l.height(), out);
    CheckBatch(cudaGetLastError(), "BatchPrimaryKernel launch");
  }
  if (more) more(m.compute, base);
  CheckBatch(cudaEventRecord(m.done[slot], m.compute), "cudaEventRecord");
  m.used[slot] = true;
  if (m.copy == BatchCopy::kNone) return;
  // the copy back on its own stream, after this kernel: it overlaps the next batch's kernel
  CheckBatch(cudaStreamWaitEvent(m.copier, m.done[slot], 0), "cudaStreamWaitEvent");
  CheckBatch(cudaMemcpyAsync(m.host[slot], base, static_cast<size_t>(l.bytes(count)),
                             cudaMemcpyDeviceToHost, m.copier),
             "copying the images back");
  CheckBatch(cudaEventRecord(m.copied[slot], m.copier), "cudaEventRecord");
  m.pending_copy[slot] = true;
}

const float* BatchDevice::UploadCameraTables(int slot, const float* tables, int64_t n) {
  Impl& m = *impl_;
  m.Grow(&m.tables[slot], &m.tables_capacity[slot], n, "cudaMalloc (camera ray tables)");
  // from pageable memory, as the cameras: staged before the call returns, ordered on the stream
  if (n > 0)
    CheckBatch(cudaMemcpyAsync(m.tables[slot], tables, sizeof(float) * n, cudaMemcpyHostToDevice,
                               m.compute),
               "copying the camera ray tables");
  return m.tables[slot];
}

void BatchDevice::CopyToDevice(void* stream, uint8_t* dst, const void* src, int64_t bytes) {
  if (bytes <= 0) return;
  CheckBatch(cudaMemcpyAsync(dst, src, static_cast<size_t>(bytes), cudaMemcpyHostToDevice,
                             static_cast<cudaStream_t>(stream)),
             "copying a camera's images rendered alone");
}

const uint8_t* BatchDevice::Wait(int slot) {
  Impl& m = *impl_;
  if (!m.used[slot]) return m.host[slot];
  if (m.copy == BatchCopy::kNone) {
    CheckBatch(cudaEventSynchronize(m.done[slot]), "BatchPrimaryKernel");
    return nullptr;
  }
  CheckBatch(cudaEventSynchronize(m.copied[slot]), "copying the images back");
  return m.host[slot];
}

const uint8_t* BatchDevice::device_buffer(int slot) const { return impl_->device[slot]; }
const uint8_t* BatchDevice::host_buffer(int slot) const { return impl_->host[slot]; }
void* BatchDevice::kernel_event(int slot) const { return impl_->done[slot]; }
void* BatchDevice::stream() const { return impl_->compute; }

double BatchDevice::kernel_ms(int slot) const {
  float ms = 0;
  CheckBatch(cudaEventElapsedTime(&ms, impl_->started[slot], impl_->done[slot]),
             "cudaEventElapsedTime");
  return ms;
}

CopyRates MeasureCopyRates(int64_t bytes, int repeats) {
  CopyRates r;
  void* dev = nullptr;
  void* pinned = nullptr;
  std::vector<uint8_t> pageable(static_cast<size_t>(bytes));
  cudaStream_t s = nullptr;
  cudaEvent_t a = nullptr, b = nullptr;
  const auto release = [&] {
    if (dev) cudaFree(dev);
    if (pinned) cudaFreeHost(pinned);
    if (a) cudaEventDestroy(a);
    if (b) cudaEventDestroy(b);
    if (s) cudaStreamDestroy(s);
  };
  try {
    CheckBatch(cudaMalloc(&dev, bytes), "cudaMalloc");
    CheckBatch(cudaMemset(dev, 1, bytes), "cudaMemset");
    CheckBatch(cudaMallocHost(&pinned, bytes), "cudaMallocHost");
    CheckBatch(cudaStreamCreate(&s), "cudaStreamCreate");
    CheckBatch(cudaEventCreate(&a), "cudaEventCreate");
    CheckBatch(cudaEventCreate(&b), "cudaEventCreate");
    const auto rate = [&](void* host) {
      CheckBatch(cudaMemcpyAsync(host, dev, bytes, cudaMemcpyDeviceToHost, s), "warm-up copy");
      CheckBatch(cudaEventRecord(a, s), "cudaEventRecord");
      for (int i = 0; i < repeats; ++i)
        CheckBatch(cudaMemcpyAsync(host, dev, bytes, cudaMemcpyDeviceToHost, s), "timed copy");
      CheckBatch(cudaEventRecord(b, s), "cudaEventRecord");
      CheckBatch(cudaEventSynchronize(b), "timed copies");
      float ms = 0;
      CheckBatch(cudaEventElapsedTime(&ms, a, b), "cudaEventElapsedTime");
      return ms > 0 ? static_cast<double>(bytes) * repeats / (ms * 1e-3) / 1e9 : 0.0;
    };
    r.pinned_gbps = rate(pinned);
    r.pageable_gbps = rate(pageable.data());
  } catch (...) {
    release();
    throw;
  }
  release();
  return r;
}

}  // namespace penumbra::cuda

// the CUDA backend's device code (cuda_kernels.h): the kernels run bvh_traversal.h, the same
// PB_HOST_DEVICE functions the CPU tests run.

#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/core/exp_rn.h"
#include "penumbra/render/bvh/bvh_traversal.h"
#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/geometry/analytic_shape_math.h"
#include "penumbra/render/transport/primary_pixel.h"
#include "penumbra/render/transport/realtime.h"

namespace penumbra::cuda {
namespace {

__global__ void TraceKernel(SceneView s, const TraceRay* rays, int64_t n, TraceHit* hits) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  TraceHit h;
  TraceClosest(s, rays[i], &h);
  hits[i] = h;
}

__global__ void OccludedKernel(SceneView s, const TraceRay* rays, int64_t n, uint8_t* occ) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  occ[i] = TraceOccluded(s, rays[i]) ? 1 : 0;
}

// one thread per pixel: primary_pixel.h's TracePixelTruth, as the batch kernel.
__global__ void PrimaryKernel(SceneView s, PinholeCamera c, PixelTruthPlanes out) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= c.width || v >= c.height) return;
  const F3 axes_W[3] = {c.ex, c.ey, c.ez};
  out.Write(TracePixelTruth(s, PrimaryRay(c, u, v), out.normal_O ? axes_W : nullptr),
            static_cast<int64_t>(v) * c.width + u);
}

__global__ void ExpRnKernel(const float* x, float* y, int64_t n) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i < n) y[i] = ExpRn(x[i]);
}

}  // namespace

void InitRuntime() {
  static std::once_flag once;
  std::call_once(once, [] {
    const bool set = std::getenv("CUDA_MODULE_LOADING") == nullptr;
    if (set) setenv("CUDA_MODULE_LOADING", "EAGER", 1);
    // the runtime and the driver read the mode when they start; the context made here loads
    // every module (cudaFree(nullptr): the usual way to make the primary context)
    int count = 0;
    if (cudaGetDeviceCount(&count) == cudaSuccess && count > 0) cudaFree(nullptr);
    cudaGetLastError();  // no device: the error is ProbeDevice's to report
    if (set) unsetenv("CUDA_MODULE_LOADING");
  });
}

bool ProbeDevice(std::string* name, std::string* why) {
  InitRuntime();
  int count = 0;
  const cudaError_t e = cudaGetDeviceCount(&count);
  if (e != cudaSuccess) {
    if (why) *why = cudaGetErrorString(e);
    cudaGetLastError();  // clear the sticky error
    return false;
  }
  if (count < 1) {
    if (why) *why = "no CUDA device";
    return false;
  }
  cudaDeviceProp prop;
  if (cudaGetDeviceProperties(&prop, 0) != cudaSuccess) {
    if (why) *why = "cudaGetDeviceProperties failed";
    return false;
  }
  if (name) *name = prop.name;
  return true;
}

struct DeviceScene::Impl {
  cudaStream_t stream = nullptr;
  Buffer nodes, prims, triangles, shading, analytics, blases, records, instances;
  Buffer rays, hits, out[6];
  // RenderPrimary's pinned copies: the staging buffers, band k's images staged, and the stage
  // events (timing)
  PinnedBuffer pin_out[6];
  cudaEvent_t band_staged[kPrimaryBands] = {};
  cudaEvent_t primary_start = nullptr, primary_traced = nullptr, primary_copied = nullptr;
  PrimaryTimes primary_times;
  Buffer camera_xy, camera_rows;
  int64_t camera_xy_version = -1;
  int64_t geometry_version = -1;
  SceneView view;
  // the bytes of the instances and the top level the device holds (Sync uploads them only when
  // they change), and Sync's staging of the next ones
  std::vector<uint8_t> uploaded_instances, staged_instances;
};

void ExpRnOnDevice(const float* x, float* y, int64_t n) {
  if (n <= 0) return;
  Buffer dx, dy;
  dx.Upload(x, n * sizeof(float), nullptr);
  dy.Reserve(n * sizeof(float));
  const int block = 256;
  LaunchKernel("ExpRnKernel launch", ExpRnKernel, static_cast<unsigned>((n + block - 1) / block),
               block, 0, 0, dx.as<float>(), dy.as<float>(), n);
  dy.Download(y, n * sizeof(float), nullptr);
  Check(cudaDeviceSynchronize(), "ExpRnKernel");
}

DeviceScene::DeviceScene() : impl_(new Impl) {
  InitRuntime();
  try {
    // the highest priority: the realtime frame's side stream (the mirror layer's, of the lowest
    // priority) runs below it
    int least = 0, greatest = 0;
    Check(cudaDeviceGetStreamPriorityRange(&least, &greatest), "cudaDeviceGetStreamPriorityRange");
    Check(cudaStreamCreateWithPriority(&impl_->stream, cudaStreamDefault, greatest),
          "cudaStreamCreate");
  } catch (...) {
    delete impl_;
    throw;
  }
}

void DeviceScene::UploadCameraRays(const float* xy, int64_t xy_floats, int64_t xy_version,
                                   const float* rows, int64_t row_floats, const float** xy_device,
                                   const float** rows_device) {
  Impl& m = *impl_;
  if (xy_floats > 0 && xy_version != m.camera_xy_version) {
    m.camera_xy.Upload(xy, sizeof(float) * xy_floats, m.stream);
    m.camera_xy_version = xy_version;
  }
  if (row_floats > 0) m.camera_rows.Upload(rows, sizeof(float) * row_floats, m.stream);
  *xy_device = xy_floats > 0 ? m.camera_xy.as<const float>() : nullptr;
  *rows_device = row_floats > 0 ? m.camera_rows.as<const float>() : nullptr;
}

const SceneView& DeviceScene::device_view() const { return impl_->view; }
void* DeviceScene::stream() const { return impl_->stream; }

DeviceScene::~DeviceScene() {
  Impl& m = *impl_;
  for (cudaEvent_t e : m.band_staged)
    if (e) cudaEventDestroy(e);
  for (cudaEvent_t e : {m.primary_start, m.primary_traced, m.primary_copied})
    if (e) cudaEventDestroy(e);
  if (m.stream) cudaStreamDestroy(m.stream);
  delete impl_;
}

const PrimaryTimes& DeviceScene::last_primary_times() const { return impl_->primary_times; }

void DeviceScene::Sync(const SceneView& v, const Sizes& n, int64_t geometry_version, bool wait) {
  Impl& m = *impl_;
  if (geometry_version != m.geometry_version) {
    m.nodes.Upload(v.nodes, n.nodes * sizeof(BvhWideNode), m.stream);
    m.prims.Upload(v.prims, n.prims * sizeof(PrimRef), m.stream);
    m.triangles.Upload(v.triangles, n.triangles * sizeof(Triangle), m.stream);
    m.analytics.Upload(v.analytics, n.analytics * sizeof(AnalyticPrim), m.stream);
    m.blases.Upload(v.blases, n.blases * sizeof(Blas), m.stream);
    m.records.Upload(v.records, n.records * sizeof(Record), m.stream);
    if (n.shading > 0) m.shading.Upload(v.shading, n.shading * sizeof(TriangleShading), m.stream);
    m.geometry_version = geometry_version;
  }
  // the instances' transforms and the top level over their boxes, in one array and one copy
  // (the instances, then the top level's nodes, 64-aligned as an Instance is 128 bytes, then its
  // leaves' instance indices): only when their bytes changed (a frame of static bodies uploads
  // nothing)
  static_assert(sizeof(Instance) % alignof(BvhWideNode) == 0, "the top level's nodes stay aligned");
  const size_t instance_bytes = static_cast<size_t>(v.num_instances) * sizeof(Instance);
  const bool tlas = v.tlas_instances != nullptr;
  const size_t tlas_node_bytes =
      tlas ? static_cast<size_t>(v.tlas.num_nodes) * sizeof(BvhWideNode) : 0;
  const size_t tlas_index_bytes = tlas ? static_cast<size_t>(v.num_instances) * sizeof(int32_t) : 0;
  m.staged_instances.resize(instance_bytes + tlas_node_bytes + tlas_index_bytes);
  uint8_t* staged = m.staged_instances.data();
  if (instance_bytes > 0) std::memcpy(staged, v.instances, instance_bytes);
  if (tlas_node_bytes > 0) std::memcpy(staged + instance_bytes, v.tlas_nodes, tlas_node_bytes);
  if (tlas_index_bytes > 0)
    std::memcpy(staged + instance_bytes + tlas_node_bytes, v.tlas_instances, tlas_index_bytes);
  if (m.instances.p == nullptr || m.uploaded_instances != m.staged_instances) {
    m.instances.Upload(staged, m.staged_instances.size(), m.stream);
    m.uploaded_instances = m.staged_instances;
  }
  m.view.nodes = static_cast<const BvhWideNode*>(m.nodes.p);
  m.view.prims = static_cast<const PrimRef*>(m.prims.p);
  m.view.triangles = static_cast<const Triangle*>(m.triangles.p);
  m.view.analytics = static_cast<const AnalyticPrim*>(m.analytics.p);
  m.view.blases = static_cast<const Blas*>(m.blases.p);
  m.view.records = static_cast<const Record*>(m.records.p);
  m.view.shading = n.shading > 0 ? static_cast<const TriangleShading*>(m.shading.p) : nullptr;
  m.view.instances = static_cast<const Instance*>(m.instances.p);
  m.view.num_instances = v.num_instances;
  const uint8_t* device_instances = static_cast<const uint8_t*>(m.instances.p);
  m.view.tlas_nodes = tlas_node_bytes > 0
                          ? reinterpret_cast<const BvhWideNode*>(device_instances + instance_bytes)
                          : nullptr;
  m.view.tlas_instances =
      tlas ? reinterpret_cast<const int32_t*>(device_instances + instance_bytes + tlas_node_bytes)
           : nullptr;
  m.view.tlas = v.tlas;
  if (wait) Check(cudaStreamSynchronize(m.stream), "uploading the scene");
}

void DeviceScene::Trace(const TraceRay* rays, int64_t n, TraceHit* hits) {
  if (n <= 0) return;
  Impl& m = *impl_;
  m.rays.Upload(rays, n * sizeof(TraceRay), m.stream);
  m.hits.Reserve(n * sizeof(TraceHit));
  const int block = 128;
  LaunchKernel("TraceKernel launch", TraceKernel, static_cast<unsigned>((n + block - 1) / block),
               block, 0, m.stream, m.view, static_cast<const TraceRay*>(m.rays.p), n,
               static_cast<TraceHit*>(m.hits.p));
  Check(cudaMemcpyAsync(hits, m.hits.p, n * sizeof(TraceHit), cudaMemcpyDeviceToHost, m.stream),
        "copying hits back");
  Check(cudaStreamSynchronize(m.stream), "TraceKernel");
}

void DeviceScene::Occluded(const TraceRay* rays, int64_t n, uint8_t* occluded) {
  if (n <= 0) return;
  Impl& m = *impl_;
  m.rays.Upload(rays, n * sizeof(TraceRay), m.stream);
  m.hits.Reserve(n);
  const int block = 128;
  LaunchKernel("OccludedKernel launch", OccludedKernel,
               static_cast<unsigned>((n + block - 1) / block), block, 0, m.stream, m.view,
               static_cast<const TraceRay*>(m.rays.p), n, static_cast<uint8_t*>(m.hits.p));
  Check(cudaMemcpyAsync(occluded, m.hits.p, n, cudaMemcpyDeviceToHost, m.stream),
        "copying occlusion back");
  Check(cudaStreamSynchronize(m.stream), "OccludedKernel");
}

namespace {

PixelTruthPlanes Reserve(Buffer* out, int64_t pixels, const PrimaryOutputs& want) {
  PixelTruthPlanes d;
  auto take = [&](int k, bool on, size_t bytes) -> void* {
    if (!on) return nullptr;
    out[k].Reserve(bytes);
    return out[k].p;
  };
  d.depth = static_cast<float*>(take(0, want.depth, pixels * 4));
  d.geom_id = static_cast<int32_t*>(take(1, want.geom_id, pixels * 4));
  d.range = static_cast<float*>(take(2, want.range, pixels * 4));
  d.normal_O = static_cast<float*>(take(3, want.normal_O, pixels * 12));
  d.body_id = static_cast<int32_t*>(take(4, want.body_id, pixels * 4));
  d.semantic = static_cast<int32_t*>(take(5, want.semantic, pixels * 4));
  return d;
}

}  // namespace

void DeviceScene::RenderPrimary(const PinholeCamera& c, const PrimaryOutputs& want,
                                const ParallelFn& parallel) {
  Impl& m = *impl_;
  const auto t0 = std::chrono::steady_clock::now();
  const int64_t pixels = static_cast<int64_t>(c.width) * c.height;
  if (pixels <= 0) return;
  if (!m.primary_start) {
    for (cudaEvent_t& e : m.band_staged)
      Check(cudaEventCreateWithFlags(&e, cudaEventDisableTiming), "cudaEventCreate");
    for (cudaEvent_t* e : {&m.primary_start, &m.primary_traced, &m.primary_copied})
      Check(cudaEventCreate(e), "cudaEventCreate");
  }
  const PixelTruthPlanes d = Reserve(m.out, pixels, want);
  // the planes: the caller's buffer, the device's, bytes a pixel (pin_out[p]: the staging)
  struct Plane {
    void* host;
    void* dev;
    size_t px;
  };
  const Plane planes[6] = {{want.depth, d.depth, 4},     {want.geom_id, d.geom_id, 4},
                           {want.range, d.range, 4},     {want.normal_O, d.normal_O, 12},
                           {want.body_id, d.body_id, 4}, {want.semantic, d.semantic, 4}};
  for (int p = 0; p < 6; ++p)
    if (planes[p].host) m.pin_out[p].Reserve(planes[p].px * pixels);
  // the kernel over the whole frame (bands of it would each end on their slowest rays); the
  // images go back in bands of rows, band k behind its event, so that the host copies band
  // k into the caller's buffers while band k + 1 comes back (a small frame in one band)
  size_t frame_bytes = 0;
  for (const Plane& p : planes)
    if (p.host) frame_bytes += p.px * pixels;
  const int bands = frame_bytes <= kPrimarySerialBytes ? 1 : kPrimaryBands;
  const int band_rows = (c.height + bands - 1) / bands;
  const dim3 block(8, 8);
  Check(cudaEventRecord(m.primary_start, m.stream), "cudaEventRecord");
  LaunchKernel("PrimaryKernel launch", PrimaryKernel, dim3((c.width + 7) / 8, (c.height + 7) / 8),
               block, 0, m.stream, m.view, c, d);
  Check(cudaEventRecord(m.primary_traced, m.stream), "cudaEventRecord");
  {
    std::vector<HostCopy> copies;
    for (int k = 0; k < bands; ++k) {
      const int r0 = std::min(c.height, k * band_rows);
      const int r1 = std::min(c.height, (k + 1) * band_rows);
      if (r1 <= r0) continue;
      const size_t first = static_cast<size_t>(r0) * c.width;
      const size_t count = static_cast<size_t>(r1 - r0) * c.width;
      for (int p = 0; p < 6; ++p) {
        if (!planes[p].host) continue;
        const size_t off = first * planes[p].px, bytes = count * planes[p].px;
        char* staged = m.pin_out[p].as<char>() + off;
        Check(cudaMemcpyAsync(staged, static_cast<const char*>(planes[p].dev) + off, bytes,
                              cudaMemcpyDeviceToHost, m.stream),
              "copying an image back");
        copies.push_back(
            {static_cast<char*>(planes[p].host) + off, staged, bytes, m.band_staged[k]});
      }
      Check(cudaEventRecord(m.band_staged[k], m.stream), "cudaEventRecord");
    }
    Check(cudaEventRecord(m.primary_copied, m.stream), "cudaEventRecord");
    ParallelCopy(parallel, copies, size_t{256} << 10, kPrimarySerialBytes);
  }
  Check(cudaStreamSynchronize(m.stream), "PrimaryKernel");
  float kernel_ms = 0, copies_ms = 0;
  Check(cudaEventElapsedTime(&kernel_ms, m.primary_start, m.primary_traced),
        "cudaEventElapsedTime");
  Check(cudaEventElapsedTime(&copies_ms, m.primary_start, m.primary_copied),
        "cudaEventElapsedTime");
  m.primary_times.kernel = kernel_ms;
  m.primary_times.copies = copies_ms;
  m.primary_times.total =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

double DeviceScene::TimePrimary(const PinholeCamera& c, int count, bool depth_and_seg_only) {
  Impl& m = *impl_;
  const int64_t pixels = static_cast<int64_t>(c.width) * c.height;
  PrimaryOutputs want;
  float f = 0;
  int32_t i = 0;
  want.depth = &f;
  want.geom_id = &i;
  if (!depth_and_seg_only) {
    want.range = &f;
    want.normal_O = &f;
    want.body_id = &i;
    want.semantic = &i;
  }
  const PixelTruthPlanes d = Reserve(m.out, pixels, want);
  const dim3 block(8, 8);
  const dim3 grid((c.width + 7) / 8, (c.height + 7) / 8);
  PrimaryKernel<<<grid, block, 0, m.stream>>>(m.view, c, d);  // warm-up
  return TimeOnStream(m.stream, count,
                      [&] { PrimaryKernel<<<grid, block, 0, m.stream>>>(m.view, c, d); });
}

}  // namespace penumbra::cuda

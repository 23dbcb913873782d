// the CUDA backend's device code (cuda_kernels.h): the kernels run bvh_traversal.h, the same
// PB_HOST_DEVICE functions the CPU tests run.

#include <cuda_runtime.h>

#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/analytic_shape_math.h"
#include "penumbra/render/cuda/bvh_traversal.h"
#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/cuda/cuda_kernels.h"
#include "penumbra/render/cuda/primary_pixel.h"
#include "penumbra/render/cuda/realtime_shading.h"

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

}  // namespace

bool ProbeDevice(std::string* name, std::string* why) {
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
  Buffer camera_xy, camera_rows;
  int64_t camera_xy_version = -1;
  int64_t geometry_version = -1;
  SceneView view;
  // the bytes of the instances the device holds (Sync uploads them only when they change)
  std::vector<uint8_t> uploaded_instances;
};

DeviceScene::DeviceScene() : impl_(new Impl) {
  try {
    Check(cudaStreamCreate(&impl_->stream), "cudaStreamCreate");
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
  if (impl_->stream) cudaStreamDestroy(impl_->stream);
  delete impl_;
}

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
  // the instances' transforms: only when their bytes changed (a frame of static bodies
  // uploads nothing)
  const size_t instance_bytes = static_cast<size_t>(v.num_instances) * sizeof(Instance);
  const auto* instances = reinterpret_cast<const uint8_t*>(v.instances);
  if (m.instances.p == nullptr || m.uploaded_instances.size() != instance_bytes ||
      (instance_bytes > 0 &&
       std::memcmp(m.uploaded_instances.data(), instances, instance_bytes) != 0)) {
    m.instances.Upload(v.instances, instance_bytes, m.stream);
    m.uploaded_instances.assign(instances, instances + instance_bytes);
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
  if (wait) Check(cudaStreamSynchronize(m.stream), "uploading the scene");
}

void DeviceScene::Trace(const TraceRay* rays, int64_t n, TraceHit* hits) {
  if (n <= 0) return;
  Impl& m = *impl_;
  m.rays.Upload(rays, n * sizeof(TraceRay), m.stream);
  m.hits.Reserve(n * sizeof(TraceHit));
  const int block = 128;
  TraceKernel<<<static_cast<unsigned>((n + block - 1) / block), block, 0, m.stream>>>(
      m.view, static_cast<const TraceRay*>(m.rays.p), n, static_cast<TraceHit*>(m.hits.p));
  Check(cudaGetLastError(), "TraceKernel launch");
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
  OccludedKernel<<<static_cast<unsigned>((n + block - 1) / block), block, 0, m.stream>>>(
      m.view, static_cast<const TraceRay*>(m.rays.p), n, static_cast<uint8_t*>(m.hits.p));
  Check(cudaGetLastError(), "OccludedKernel launch");
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

void DeviceScene::RenderPrimary(const PinholeCamera& c, const PrimaryOutputs& want) {
  Impl& m = *impl_;
  const int64_t pixels = static_cast<int64_t>(c.width) * c.height;
  if (pixels <= 0) return;
  const PixelTruthPlanes d = Reserve(m.out, pixels, want);
  const dim3 block(8, 8);
  const dim3 grid((c.width + 7) / 8, (c.height + 7) / 8);
  PrimaryKernel<<<grid, block, 0, m.stream>>>(m.view, c, d);
  Check(cudaGetLastError(), "PrimaryKernel launch");
  auto back = [&](void* host, const void* dev, size_t bytes) {
    if (host)
      Check(cudaMemcpyAsync(host, dev, bytes, cudaMemcpyDeviceToHost, m.stream),
            "copying an image back");
  };
  back(want.depth, d.depth, pixels * 4);
  back(want.geom_id, d.geom_id, pixels * 4);
  back(want.range, d.range, pixels * 4);
  back(want.normal_O, d.normal_O, pixels * 12);
  back(want.body_id, d.body_id, pixels * 4);
  back(want.semantic, d.semantic, pixels * 4);
  Check(cudaStreamSynchronize(m.stream), "PrimaryKernel");
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

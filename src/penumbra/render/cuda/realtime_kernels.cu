// the realtime tier's kernels (cuda_realtime.h): each runs the PB_HOST_DEVICE per-pixel
// functions of realtime_shading.h, which RenderRealtimeOnHost runs on the CPU.

#include <cuda_runtime.h>

#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/cuda/cuda_realtime.h"
#include "penumbra/render/cuda/realtime_shading.h"

namespace penumbra::cuda {
namespace {

__global__ void GeometryKernel(RealtimeFrameView f, PixelGeometry* geometry, float* depth) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= f.camera.width || v >= f.camera.height) return;
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  float t;
  geometry[i] = PrimaryGeometry(f, u, v, &t);
  depth[i] = t;
}

__global__ void ShadeKernel(RealtimeFrameView f, Float3* radiance) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= f.camera.width || v >= f.camera.height) return;
  radiance[static_cast<int64_t>(v) * f.camera.width + u] = ShadeRealtimePixel(f, u, v);
}

// the shared visibility of lights with an extent (realtime_shading.h), one kernel per step:
// each reads its neighbours' results of the step before.
__global__ void VisibilityRaysKernel(RealtimeFrameView f) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= f.camera.width || v >= f.camera.height) return;
  SharedVisibilityRays(f, u, v);
}

__global__ void VisibilityFractionKernel(RealtimeFrameView f) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= f.camera.width || v >= f.camera.height) return;
  SharedVisibilityFraction(f, u, v);
}

__global__ void VisibilityResolveKernel(RealtimeFrameView f, Float3* radiance) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= f.camera.width || v >= f.camera.height) return;
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  radiance[i] = SharedVisibilityResolve(f, u, v, radiance[i]);
}

__global__ void RowSumKernel(const Float3* radiance, int width, int height, double* rows) {
  const int v = blockIdx.x * blockDim.x + threadIdx.x;
  if (v >= height) return;
  rows[v] = RowLogLuminance(radiance, width, v, 1e-4);
}

struct Exposure {
  float e[3];
};

__global__ void DevelopKernel(const Float3* radiance, int64_t n, Exposure exposure, int filmic,
                              const uint8_t* lut, uint8_t* rgb) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  DevelopPixel(radiance[i], exposure.e, filmic != 0, lut, rgb + 3 * i);
}

}  // namespace

struct DeviceRealtime::Impl {
  Buffer materials, textures, texels, decode, lut, geoms, lights;
  Buffer geometry, depth, sky, radiance, rows, rgb;
  // the shared visibility's buffers (RealtimeFrameView)
  Buffer window, area_c, area_vis, area_visible, area_rays, area_own, area_fraction;
  std::vector<PixelGeometry> host_geometry;
  std::vector<Float3> host_sky;
  std::vector<Float3> host_radiance;
  std::vector<double> host_rows;
  // the last frame, for TimeKernels.
  RealtimeFrameView frame;
  Exposure exposure{{1, 1, 1}};
  int filmic = 1;
  bool rendered = false;
};

DeviceRealtime::DeviceRealtime() : impl_(new Impl) {}
DeviceRealtime::~DeviceRealtime() { delete impl_; }

void DeviceRealtime::Upload(const RealtimeStatic& d) {
  Impl& m = *impl_;
  m.materials.Upload(d.materials, sizeof(MaterialPod) * d.num_materials, nullptr);
  m.textures.Upload(d.textures, sizeof(TexturePod) * d.num_textures, nullptr);
  m.texels.Upload(d.texels, static_cast<size_t>(d.num_texel_bytes), nullptr);
  m.decode.Upload(d.srgb_decode, sizeof(float) * 256, nullptr);
  m.lut.Upload(d.oetf_lut, kFilmLutSize, nullptr);
  Check(cudaDeviceSynchronize(), "uploading the realtime scene");
}

double DeviceRealtime::Render(DeviceScene* scene, const RealtimeFrameView& host_frame,
                              int64_t num_geoms, bool filmic, const SkyFn& sky,
                              const ExposureFn& exposure, const RealtimeOutputs& out) {
  Impl& m = *impl_;
  cudaStream_t stream = static_cast<cudaStream_t>(scene->stream());
  const PinholeCamera& c = host_frame.camera;
  const int W = c.width, H = c.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  m.geoms.Upload(host_frame.geoms, sizeof(GeomPod) * num_geoms, stream);
  m.lights.Upload(host_frame.lights, sizeof(LightPod) * host_frame.num_lights, stream);
  m.geometry.Reserve(sizeof(PixelGeometry) * n);
  m.depth.Reserve(sizeof(float) * n);
  m.sky.Reserve(sizeof(Float3) * n);
  m.radiance.Reserve(sizeof(Float3) * n);
  m.rows.Reserve(sizeof(double) * H);
  m.rgb.Reserve(3 * n);
  const int64_t nl = n * (host_frame.num_lights > 0 ? host_frame.num_lights : 1);
  m.window.Reserve(sizeof(uint32_t) * n);
  m.area_c.Reserve(sizeof(Float3) * nl);
  m.area_vis.Reserve(sizeof(int8_t) * nl);
  m.area_visible.Reserve(sizeof(float) * nl);
  m.area_rays.Reserve(sizeof(float) * nl);
  m.area_own.Reserve(sizeof(uint8_t) * nl);
  m.area_fraction.Reserve(sizeof(float) * nl);
  // the frame with the device copies
  RealtimeFrameView f = host_frame;
  f.scene = scene->device_view();
  f.materials = m.materials.as<MaterialPod>();
  f.textures = m.textures.as<TexturePod>();
  f.texels = m.texels.as<uint8_t>();
  f.srgb_decode = m.decode.as<float>();
  f.geoms = m.geoms.as<GeomPod>();
  f.lights = m.lights.as<LightPod>();
  f.sky_term = m.sky.as<Float3>();
  f.geometry = m.geometry.as<PixelGeometry>();
  f.window = m.window.as<uint32_t>();
  f.area_c = m.area_c.as<Float3>();
  f.area_vis = m.area_vis.as<int8_t>();
  f.area_visible = m.area_visible.as<float>();
  f.area_rays = m.area_rays.as<float>();
  f.area_own = m.area_own.as<uint8_t>();
  f.area_fraction = m.area_fraction.as<float>();
  // (1) primary geometry (materials and normal maps included) and depth
  const dim3 block(16, 8);
  const dim3 grid((W + block.x - 1) / block.x, (H + block.y - 1) / block.y);
  GeometryKernel<<<grid, block, 0, stream>>>(f, m.geometry.as<PixelGeometry>(),
                                             m.depth.as<float>());
  Check(cudaGetLastError(), "GeometryKernel");
  m.host_geometry.resize(n);
  m.geometry.Download(m.host_geometry.data(), sizeof(PixelGeometry) * n, stream);
  if (out.depth) m.depth.Download(out.depth, sizeof(float) * n, stream);
  Check(cudaStreamSynchronize(stream), "GeometryKernel");
  // (2) the sky terms on the host
  m.host_sky.resize(n);
  sky(m.host_geometry.data(), n, m.host_sky.data());
  m.sky.Upload(m.host_sky.data(), sizeof(Float3) * n, stream);
  // (3) shading
  ShadeKernel<<<grid, block, 0, stream>>>(f, m.radiance.as<Float3>());
  Check(cudaGetLastError(), "ShadeKernel");
  VisibilityRaysKernel<<<grid, block, 0, stream>>>(f);
  Check(cudaGetLastError(), "VisibilityRaysKernel");
  VisibilityFractionKernel<<<grid, block, 0, stream>>>(f);
  Check(cudaGetLastError(), "VisibilityFractionKernel");
  VisibilityResolveKernel<<<grid, block, 0, stream>>>(f, m.radiance.as<Float3>());
  Check(cudaGetLastError(), "VisibilityResolveKernel");
  // (4) exposure from the rows' log-luminance sums
  RowSumKernel<<<(H + 127) / 128, 128, 0, stream>>>(m.radiance.as<Float3>(), W, H,
                                                    m.rows.as<double>());
  Check(cudaGetLastError(), "RowSumKernel");
  m.host_rows.resize(H);
  m.rows.Download(m.host_rows.data(), sizeof(double) * H, stream);
  Check(cudaStreamSynchronize(stream), "ShadeKernel");
  Exposure e;
  const double ev100 = exposure(m.host_rows, e.e);
  // (5) film
  DevelopKernel<<<static_cast<unsigned>((n + 255) / 256), 256, 0, stream>>>(
      m.radiance.as<Float3>(), n, e, filmic ? 1 : 0, m.lut.as<uint8_t>(), m.rgb.as<uint8_t>());
  Check(cudaGetLastError(), "DevelopKernel");
  if (out.rgb) m.rgb.Download(out.rgb, 3 * n, stream);
  if (out.radiance) m.radiance.Download(out.radiance, sizeof(Float3) * n, stream);
  Check(cudaStreamSynchronize(stream), "DevelopKernel");
  m.frame = f;
  m.exposure = e;
  m.filmic = filmic ? 1 : 0;
  m.rendered = true;
  return ev100;
}

double DeviceRealtime::TimeKernels(DeviceScene* scene, int count) {
  Impl& m = *impl_;
  if (!m.rendered || count < 1) return 0;
  cudaStream_t stream = static_cast<cudaStream_t>(scene->stream());
  const RealtimeFrameView& f = m.frame;
  const int W = f.camera.width, H = f.camera.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const dim3 block(16, 8);
  const dim3 grid((W + block.x - 1) / block.x, (H + block.y - 1) / block.y);
  cudaEvent_t start, stop;
  Check(cudaEventCreate(&start), "cudaEventCreate");
  Check(cudaEventCreate(&stop), "cudaEventCreate");
  Check(cudaEventRecord(start, stream), "cudaEventRecord");
  for (int k = 0; k < count; ++k) {
    GeometryKernel<<<grid, block, 0, stream>>>(f, m.geometry.as<PixelGeometry>(),
                                               m.depth.as<float>());
    ShadeKernel<<<grid, block, 0, stream>>>(f, m.radiance.as<Float3>());
    VisibilityRaysKernel<<<grid, block, 0, stream>>>(f);
    VisibilityFractionKernel<<<grid, block, 0, stream>>>(f);
    VisibilityResolveKernel<<<grid, block, 0, stream>>>(f, m.radiance.as<Float3>());
    RowSumKernel<<<(H + 127) / 128, 128, 0, stream>>>(m.radiance.as<Float3>(), W, H,
                                                      m.rows.as<double>());
    DevelopKernel<<<static_cast<unsigned>((n + 255) / 256), 256, 0, stream>>>(
        m.radiance.as<Float3>(), n, m.exposure, m.filmic, m.lut.as<uint8_t>(), m.rgb.as<uint8_t>());
  }
  Check(cudaGetLastError(), "realtime kernels");
  Check(cudaEventRecord(stop, stream), "cudaEventRecord");
  Check(cudaEventSynchronize(stop), "cudaEventSynchronize");
  float ms = 0;
  Check(cudaEventElapsedTime(&ms, start, stop), "cudaEventElapsedTime");
  cudaEventDestroy(start);
  cudaEventDestroy(stop);
  return static_cast<double>(ms) / count;
}

}  // namespace penumbra::cuda

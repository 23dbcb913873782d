// the realtime tier's kernels (cuda_realtime.h): each runs the PB_HOST_DEVICE per-pixel
// functions of realtime_shading.h, which RenderRealtimeOnHost runs on the CPU.

#include <cuda_runtime.h>

#include <algorithm>
#include <chrono>
#include <cstring>
#include <string>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/render/cuda/cuda_device_buffer.h"
#include "penumbra/render/cuda/cuda_realtime.h"
#include "penumbra/render/cuda/realtime_shading.h"

namespace penumbra::cuda {
namespace {

constexpr unsigned kFullWarp = 0xffffffffu;

__global__ void GeometryKernel(RealtimeFrameView f, PixelGeometry* geometry, float* depth,
                               TraceHit* hits) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = blockIdx.y * blockDim.y + threadIdx.y;
  if (u >= f.camera.width || v >= f.camera.height) return;
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  float t;
  geometry[i] = PrimaryGeometry(f, u, v, &t, hits ? &hits[i] : nullptr);
  depth[i] = t;
}

// the lanes of a warp share the lattice points of each of their pixels in a penumbra: for each
// such pixel (in lane order) every lane traces the points kLightPenumbraRays + lane,
// + lane + 32, ..., and the integer counts are summed over the warp (the same counts as the
// serial loop, in any order). every lane of the warp must call it, once per light.
struct WarpPenumbraRefiner {
  __device__ void operator()(const SceneView& s, const LightPod& l, bool need,
                             const PenumbraQuery& q, int* rays, int* visible) const {
    const int lane = static_cast<int>((threadIdx.y * blockDim.x + threadIdx.x) & 31u);
    unsigned pending = __ballot_sync(kFullWarp, need);
    while (pending != 0) {
      const int leader = __ffs(pending) - 1;
      pending &= pending - 1;
      PenumbraQuery lq;
      lq.p.x = __shfl_sync(kFullWarp, q.p.x, leader);
      lq.p.y = __shfl_sync(kFullWarp, q.p.y, leader);
      lq.p.z = __shfl_sync(kFullWarp, q.p.z, leader);
      lq.ng.x = __shfl_sync(kFullWarp, q.ng.x, leader);
      lq.ng.y = __shfl_sync(kFullWarp, q.ng.y, leader);
      lq.ng.z = __shfl_sync(kFullWarp, q.ng.z, leader);
      lq.origin.x = __shfl_sync(kFullWarp, q.origin.x, leader);
      lq.origin.y = __shfl_sync(kFullWarp, q.origin.y, leader);
      lq.origin.z = __shfl_sync(kFullWarp, q.origin.z, leader);
      lq.first = __shfl_sync(kFullWarp, q.first, leader);
      int r = 0, vis = 0;
      CountLatticeVisibility(s, l, lq, kLightPenumbraRays + lane, kLightStrata * kLightPenumbraRays,
                             32, &r, &vis);
      r = __reduce_add_sync(kFullWarp, r);
      vis = __reduce_add_sync(kFullWarp, vis);
      if (lane == leader) *rays += r, *visible += vis;
    }
  }
};

// kReuse: the primary hit from GeometryKernel; kWarp: WarpPenumbraRefiner (every thread of a
// warp stays to the end, those outside the image too).
// rows [v0, v1) of the image.
template <bool kReuse, bool kWarp>
__global__ void ShadeKernel(RealtimeFrameView f, const TraceHit* hits, Float3* radiance, int v0,
                            int v1) {
  const int u = blockIdx.x * blockDim.x + threadIdx.x;
  const int v = v0 + blockIdx.y * blockDim.y + threadIdx.y;
  const bool active = u < f.camera.width && v < v1;
  if (!kWarp && !active) return;
  const int64_t i = static_cast<int64_t>(v) * f.camera.width + u;
  const TraceRay r = PrimaryRay(f.camera, u, v);
  TraceHit h;
  if (active) {
    if (kReuse)
      h = hits[i];
    else
      TraceClosest(f.scene, r, &h);
  }
  Float3 L;
  if (kWarp)
    L = ShadeRealtimeHit(f, u, v, r, h, active, WarpPenumbraRefiner());
  else
    L = ShadeRealtimeHit(f, u, v, r, h, true, SerialPenumbraRefiner());
  if (active) radiance[i] = L;
}

__global__ void RowSumKernel(const Float3* radiance, int width, int height, double* rows) {
  const int v = blockIdx.x * blockDim.x + threadIdx.x;
  if (v >= height) return;
  rows[v] = RowLogLuminance(radiance, width, v, 1e-4);
}

// one warp per row: lane k sums columns k, k + 32, ... in order, then a fixed butterfly.
__global__ void RowSumWarpKernel(const Float3* radiance, int width, int height, double* rows) {
  const int lane = threadIdx.x & 31;
  const int v = blockIdx.x * (blockDim.x / 32) + threadIdx.x / 32;
  if (v >= height) return;  // whole warps leave together
  double sum = 0;
  for (int u = lane; u < width; u += 32) {
    const Float3& c = radiance[static_cast<int64_t>(v) * width + u];
    const float rgb[3] = {c.x, c.y, c.z};
    sum += LogLuminanceTerm(rgb, 1e-4);
  }
  for (int offset = 16; offset > 0; offset /= 2) sum += __shfl_xor_sync(kFullWarp, sum, offset);
  if (lane == 0) rows[v] = sum;
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

// page-locked host memory that grows (never shrinks).
struct PinnedBuffer {
  void* p = nullptr;
  size_t bytes = 0;
  PinnedBuffer() = default;
  PinnedBuffer(const PinnedBuffer&) = delete;
  PinnedBuffer& operator=(const PinnedBuffer&) = delete;
  void Reserve(size_t n) {
    if (n <= bytes) return;
    if (p) cudaFreeHost(p);
    p = nullptr;
    bytes = 0;
    Check(cudaMallocHost(&p, n), "cudaMallocHost (realtime frame)");
    bytes = n;
  }
  template <typename T>
  T* as() const {
    return static_cast<T*>(p);
  }
  ~PinnedBuffer() {
    if (p) cudaFreeHost(p);
  }
};

using Clock = std::chrono::steady_clock;
double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// the grid of the per-pixel kernels (whole warps of 16 x 2 pixels).
const dim3 kPixelBlock(16, 8);
dim3 PixelGrid(int W, int H) {
  return dim3((W + kPixelBlock.x - 1) / kPixelBlock.x, (H + kPixelBlock.y - 1) / kPixelBlock.y);
}

}  // namespace

struct DeviceRealtime::Impl {
  Buffer materials, textures, texels, decode, lut, geoms, lights;
  Buffer geometry, depth, sky, radiance, rows, rgb, hits;
  // pinned: the round trip of the geometry and sky terms, the row sums and the outputs
  PinnedBuffer pin_geometry, pin_sky, pin_rows, pin_rgb, pin_radiance, pin_depth;
  std::vector<PixelGeometry> host_geometry;
  std::vector<Float3> host_sky;
  std::vector<double> host_rows;
  cudaStream_t copy_stream = nullptr;
  cudaEvent_t geometry_done = nullptr, shade_done = nullptr;
  cudaEvent_t band_ready[kMaxRealtimeBands] = {};
  RealtimeKernelOptions options;
  RealtimeStageTimes times;
  // the last frame, for TimeKernels.
  RealtimeFrameView frame;
  Exposure exposure{{1, 1, 1}};
  int filmic = 1;
  bool rendered = false;

  // launches the shading kernel of rows [v0, v1) of frame f on `stream` as `o` says.
  void LaunchShade(const RealtimeFrameView& f, const RealtimeKernelOptions& o, int v0, int v1,
                   cudaStream_t stream) {
    if (v1 <= v0) return;
    const dim3 grid = PixelGrid(f.camera.width, v1 - v0);
    TraceHit* h = o.reuse_hit ? hits.as<TraceHit>() : nullptr;
    Float3* L = radiance.as<Float3>();
    if (o.reuse_hit && o.warp_penumbra)
      ShadeKernel<true, true><<<grid, kPixelBlock, 0, stream>>>(f, h, L, v0, v1);
    else if (o.reuse_hit)
      ShadeKernel<true, false><<<grid, kPixelBlock, 0, stream>>>(f, h, L, v0, v1);
    else if (o.warp_penumbra)
      ShadeKernel<false, true><<<grid, kPixelBlock, 0, stream>>>(f, h, L, v0, v1);
    else
      ShadeKernel<false, false><<<grid, kPixelBlock, 0, stream>>>(f, h, L, v0, v1);
    Check(cudaGetLastError(), "ShadeKernel");
  }
  // launches the row-sum kernel of frame f on `stream` as `o` says.
  void LaunchRows(const RealtimeFrameView& f, const RealtimeKernelOptions& o, cudaStream_t stream) {
    const int W = f.camera.width, H = f.camera.height;
    if (o.rows_per_warp)
      RowSumWarpKernel<<<(H + 3) / 4, 128, 0, stream>>>(radiance.as<Float3>(), W, H,
                                                        rows.as<double>());
    else
      RowSumKernel<<<(H + 127) / 128, 128, 0, stream>>>(radiance.as<Float3>(), W, H,
                                                        rows.as<double>());
    Check(cudaGetLastError(), "RowSumKernel");
  }
  // the shading and row-sum kernels of the whole frame.
  void LaunchShading(const RealtimeFrameView& f, const RealtimeKernelOptions& o,
                     cudaStream_t stream) {
    LaunchShade(f, o, 0, f.camera.height, stream);
    LaunchRows(f, o, stream);
  }
  void LaunchGeometry(const RealtimeFrameView& f, const RealtimeKernelOptions& o,
                      cudaStream_t stream) {
    GeometryKernel<<<PixelGrid(f.camera.width, f.camera.height), kPixelBlock, 0, stream>>>(
        f, geometry.as<PixelGeometry>(), depth.as<float>(),
        o.reuse_hit ? hits.as<TraceHit>() : nullptr);
    Check(cudaGetLastError(), "GeometryKernel");
  }
  void LaunchFilm(int64_t n, const Exposure& e, int film, cudaStream_t stream) {
    DevelopKernel<<<static_cast<unsigned>((n + 255) / 256), 256, 0, stream>>>(
        radiance.as<Float3>(), n, e, film, lut.as<uint8_t>(), rgb.as<uint8_t>());
    Check(cudaGetLastError(), "DevelopKernel");
  }
  ~Impl() {
    if (copy_stream) cudaStreamDestroy(copy_stream);
    if (geometry_done) cudaEventDestroy(geometry_done);
    if (shade_done) cudaEventDestroy(shade_done);
    for (cudaEvent_t e : band_ready)
      if (e) cudaEventDestroy(e);
  }
};

DeviceRealtime::DeviceRealtime() : impl_(new Impl) {}
DeviceRealtime::~DeviceRealtime() { delete impl_; }

void DeviceRealtime::set_options(const RealtimeKernelOptions& options) { impl_->options = options; }
const RealtimeKernelOptions& DeviceRealtime::options() const { return impl_->options; }
const RealtimeStageTimes& DeviceRealtime::last_stage_times() const { return impl_->times; }

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
  const RealtimeKernelOptions o = m.options;
  const auto t0 = Clock::now();
  cudaStream_t stream = static_cast<cudaStream_t>(scene->stream());
  if (!m.copy_stream) {
    Check(cudaStreamCreateWithFlags(&m.copy_stream, cudaStreamNonBlocking), "cudaStreamCreate");
    Check(cudaEventCreateWithFlags(&m.geometry_done, cudaEventDisableTiming), "cudaEventCreate");
    Check(cudaEventCreateWithFlags(&m.shade_done, cudaEventDisableTiming), "cudaEventCreate");
    for (cudaEvent_t& e : m.band_ready)
      Check(cudaEventCreateWithFlags(&e, cudaEventDisableTiming), "cudaEventCreate");
  }
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
  if (o.reuse_hit) m.hits.Reserve(sizeof(TraceHit) * n);
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
  // host buffers of the round trips and outputs
  PixelGeometry* host_geometry;
  Float3* host_sky;
  double* host_rows;
  if (o.pinned) {
    m.pin_geometry.Reserve(sizeof(PixelGeometry) * n);
    m.pin_sky.Reserve(sizeof(Float3) * n);
    m.pin_rows.Reserve(sizeof(double) * H);
    host_geometry = m.pin_geometry.as<PixelGeometry>();
    host_sky = m.pin_sky.as<Float3>();
    host_rows = m.pin_rows.as<double>();
    if (out.rgb) m.pin_rgb.Reserve(3 * n);
    if (out.radiance) m.pin_radiance.Reserve(sizeof(Float3) * n);
    if (out.depth) m.pin_depth.Reserve(sizeof(float) * n);
  } else {
    m.host_geometry.resize(n);
    m.host_sky.resize(n);
    m.host_rows.resize(H);
    host_geometry = m.host_geometry.data();
    host_sky = m.host_sky.data();
    host_rows = m.host_rows.data();
  }
  // bands of whole blocks of rows: the host computes band b + 1's sky terms while the GPU
  // shades band b (pinned memory only: pageable copies block the host)
  const int bands = o.pinned ? std::max(1, std::min(o.bands, kMaxRealtimeBands)) : 1;
  const int band_rows = static_cast<int>((H + bands * static_cast<int>(kPixelBlock.y) - 1) /
                                         (bands * static_cast<int>(kPixelBlock.y)) * kPixelBlock.y);
  // (1) primary geometry (materials and normal maps included) and depth; pinned: the geometry
  // goes back band by band and the depth after it, on the copy stream
  m.LaunchGeometry(f, o, stream);
  double sky_ms = 0;
  auto t1 = Clock::now();
  if (o.pinned) {
    Check(cudaEventRecord(m.geometry_done, stream), "cudaEventRecord");
    Check(cudaStreamWaitEvent(m.copy_stream, m.geometry_done, 0), "cudaStreamWaitEvent");
    for (int b = 0; b < bands; ++b) {
      const int64_t v0 = std::min<int64_t>(H, static_cast<int64_t>(b) * band_rows);
      const int64_t v1 = std::min<int64_t>(H, v0 + band_rows);
      Check(cudaMemcpyAsync(host_geometry + v0 * W, m.geometry.as<PixelGeometry>() + v0 * W,
                            sizeof(PixelGeometry) * (v1 - v0) * W, cudaMemcpyDeviceToHost,
                            m.copy_stream),
            "cudaMemcpyAsync");
      Check(cudaEventRecord(m.band_ready[b], m.copy_stream), "cudaEventRecord");
    }
    if (out.depth) m.depth.Download(m.pin_depth.p, sizeof(float) * n, m.copy_stream);
    // (2) each band's sky terms on the host, then (3) its shading
    for (int b = 0; b < bands; ++b) {
      const int64_t v0 = std::min<int64_t>(H, static_cast<int64_t>(b) * band_rows);
      const int64_t v1 = std::min<int64_t>(H, v0 + band_rows);
      Check(cudaEventSynchronize(m.band_ready[b]), "GeometryKernel");
      if (b == 0) t1 = Clock::now();
      const auto ts = Clock::now();
      sky(host_geometry + v0 * W, (v1 - v0) * W, host_sky + v0 * W);
      sky_ms += MsSince(ts);
      Check(cudaMemcpyAsync(m.sky.as<Float3>() + v0 * W, host_sky + v0 * W,
                            sizeof(Float3) * (v1 - v0) * W, cudaMemcpyHostToDevice, stream),
            "cudaMemcpyAsync");
      m.LaunchShade(f, o, static_cast<int>(v0), static_cast<int>(v1), stream);
    }
  } else {
    m.geometry.Download(host_geometry, sizeof(PixelGeometry) * n, stream);
    if (out.depth) m.depth.Download(out.depth, sizeof(float) * n, stream);
    Check(cudaStreamSynchronize(stream), "GeometryKernel");
    t1 = Clock::now();
    // (2) the sky terms on the host
    const auto ts = Clock::now();
    sky(host_geometry, n, host_sky);
    sky_ms = MsSince(ts);
    m.sky.Upload(host_sky, sizeof(Float3) * n, stream);
    // (3) shading
    m.LaunchShade(f, o, 0, H, stream);
  }
  // (4) the rows' log-luminance sums
  m.LaunchRows(f, o, stream);
  m.rows.Download(host_rows, sizeof(double) * H, stream);
  Check(cudaStreamSynchronize(stream), "ShadeKernel");
  const auto t3 = Clock::now();
  if (o.pinned) m.host_rows.assign(host_rows, host_rows + H);
  Exposure e;
  const double ev100 = exposure(m.host_rows, e.e);
  // (5) film; pinned: the radiance goes back on the copy stream while the film kernel runs
  if (out.radiance && o.pinned)
    m.radiance.Download(m.pin_radiance.p, sizeof(Float3) * n, m.copy_stream);
  m.LaunchFilm(n, e, filmic ? 1 : 0, stream);
  if (o.pinned) {
    if (out.rgb) m.rgb.Download(m.pin_rgb.p, 3 * n, stream);
    Check(cudaStreamSynchronize(stream), "DevelopKernel");
    Check(cudaStreamSynchronize(m.copy_stream), "copying the realtime outputs");
    if (out.rgb) std::memcpy(out.rgb, m.pin_rgb.p, 3 * n);
    if (out.radiance) std::memcpy(out.radiance, m.pin_radiance.p, sizeof(Float3) * n);
    if (out.depth) std::memcpy(out.depth, m.pin_depth.p, sizeof(float) * n);
  } else {
    if (out.rgb) m.rgb.Download(out.rgb, 3 * n, stream);
    if (out.radiance) m.radiance.Download(out.radiance, sizeof(Float3) * n, stream);
    Check(cudaStreamSynchronize(stream), "DevelopKernel");
  }
  // geometry: until the first band's geometry is on the host; sky: the host's sky terms;
  // shade: the rest until the row sums are back (the bands' waits and shading that the sky
  // terms did not hide)
  m.times.geometry = std::chrono::duration<double, std::milli>(t1 - t0).count();
  m.times.sky = sky_ms;
  m.times.shade = std::chrono::duration<double, std::milli>(t3 - t1).count() - sky_ms;
  m.times.film = MsSince(t3);
  m.times.total = MsSince(t0);
  m.frame = f;
  m.exposure = e;
  m.filmic = filmic ? 1 : 0;
  m.rendered = true;
  return ev100;
}

double DeviceRealtime::TimeKernels(DeviceScene* scene, int count) {
  return TimeKernels(scene, count, impl_->options);
}

double DeviceRealtime::TimeKernels(DeviceScene* scene, int count,
                                   const RealtimeKernelOptions& options) {
  Impl& m = *impl_;
  if (!m.rendered || count < 1) return 0;
  cudaStream_t stream = static_cast<cudaStream_t>(scene->stream());
  const RealtimeFrameView& f = m.frame;
  const int64_t n = static_cast<int64_t>(f.camera.width) * f.camera.height;
  if (options.reuse_hit) m.hits.Reserve(sizeof(TraceHit) * n);
  // one untimed run (first launch of a kernel variant)
  m.LaunchGeometry(f, options, stream);
  m.LaunchShading(f, options, stream);
  m.LaunchFilm(n, m.exposure, m.filmic, stream);
  Check(cudaStreamSynchronize(stream), "realtime kernels");
  cudaEvent_t start, stop;
  Check(cudaEventCreate(&start), "cudaEventCreate");
  Check(cudaEventCreate(&stop), "cudaEventCreate");
  Check(cudaEventRecord(start, stream), "cudaEventRecord");
  for (int k = 0; k < count; ++k) {
    m.LaunchGeometry(f, options, stream);
    m.LaunchShading(f, options, stream);
    m.LaunchFilm(n, m.exposure, m.filmic, stream);
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

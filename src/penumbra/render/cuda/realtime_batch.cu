// RealtimeBatch (cuda_realtime.h): the realtime tier's kernels (realtime_kernels.cuh) over a
// batch of cameras of the same size, camera k in the grids' z.

#include <string>
#include <vector>

#include "penumbra/render/cuda/realtime_kernels.cuh"

namespace penumbra::cuda {
namespace {

// the stage events of RealtimeBatch: start, then the end of each RealtimeBatchTimes stage
constexpr int kBatchStages = 8;

}  // namespace

struct RealtimeBatch::Impl : realtime::PixelBuffers {
  int width = 0, height = 0, max_cameras = 0, lights = 1, slots = 0;
  bool mirror = false;
  Buffer frames, film, exposure, depth, rows;
  std::vector<RealtimeFrameView> host_frames;
  std::vector<std::vector<cudaEvent_t>> events;  // [slot][kBatchStages + 1]
  ~Impl() {
    for (auto& slot : events)
      for (cudaEvent_t e : slot)
        if (e) cudaEventDestroy(e);
  }
};

RealtimeBatch::RealtimeBatch(int width, int height, int max_cameras, int max_lights, bool mirror,
                             int slots)
    : impl_(new Impl) {
  Impl& m = *impl_;
  try {
    if (width < 1 || height < 1 || height > kMaxDeviceExposureRows || max_cameras < 1 ||
        max_cameras > 65535 || max_lights < 0 || slots < 1)
      throw Error("RealtimeBatch: " + std::to_string(width) + "x" + std::to_string(height) + ", " +
                  std::to_string(max_cameras) + " cameras, " + std::to_string(max_lights) +
                  " lights, " + std::to_string(slots) +
                  " slots; expected a size >= 1x1 with at most " +
                  std::to_string(kMaxDeviceExposureRows) +
                  " rows, 1 to 65535 cameras, lights >= 0, slots >= 1");
    m.width = width;
    m.height = height;
    m.max_cameras = max_cameras;
    m.lights = max_lights > 0 ? max_lights : 1;
    m.mirror = mirror;
    m.slots = slots;
    const size_t n = static_cast<size_t>(width) * height * max_cameras;
    const size_t nl = n * m.lights;
    m.frames.Reserve(sizeof(RealtimeFrameView) * max_cameras);
    m.film.Reserve(sizeof(RealtimeBatchFilm) * max_cameras);
    m.exposure.Reserve(sizeof(realtime::DeviceExposure) * max_cameras);
    m.depth.Reserve(sizeof(float) * n);
    m.rows.Reserve(sizeof(double) * height * max_cameras);
    m.Reserve(n, nl, mirror);
    m.events.assign(slots, std::vector<cudaEvent_t>(kBatchStages + 1, nullptr));
    for (auto& slot : m.events)
      for (cudaEvent_t& e : slot) Check(cudaEventCreate(&e), "cudaEventCreate");
  } catch (...) {
    delete impl_;
    throw;
  }
}

RealtimeBatch::~RealtimeBatch() { delete impl_; }

void RealtimeBatch::Launch(const RealtimeFrameView* frames, const RealtimeBatchFilm* film,
                           int count, float* depth, uint8_t* rgb, int slot, void* stream_ptr) {
  Impl& m = *impl_;
  if (count < 1 || count > m.max_cameras || slot < 0 || slot >= m.slots)
    throw Error("RealtimeBatch::Launch: " + std::to_string(count) + " cameras, slot " +
                std::to_string(slot) + "; expected 1 to " + std::to_string(m.max_cameras) +
                " cameras and a slot in [0, " + std::to_string(m.slots) + ")");
  cudaStream_t stream = static_cast<cudaStream_t>(stream_ptr);
  const int W = m.width, H = m.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int64_t nl = n * m.lights;
  // each camera's frame with its part of the per-pixel arrays
  m.host_frames.assign(frames, frames + count);
  for (int k = 0; k < count; ++k) {
    RealtimeFrameView& f = m.host_frames[k];
    if (f.camera.width != W || f.camera.height != H || f.num_lights > m.lights ||
        (f.any_mirror != 0 && !m.mirror))
      throw Error("RealtimeBatch::Launch: camera " + std::to_string(k) + ": " +
                  std::to_string(f.camera.width) + "x" + std::to_string(f.camera.height) + ", " +
                  std::to_string(f.num_lights) + " lights" +
                  (f.any_mirror != 0 ? ", a mirror layer" : "") + "; expected " +
                  std::to_string(W) + "x" + std::to_string(H) + ", at most " +
                  std::to_string(m.lights) + " lights" + (m.mirror ? "" : ", no mirror layer"));
    m.Point(&f, k * n, k * nl, m.mirror);
  }
  // from pageable memory: staged before the call returns
  m.frames.Upload(m.host_frames.data(), sizeof(RealtimeFrameView) * count, stream);
  m.film.Upload(film, sizeof(RealtimeBatchFilm) * count, stream);
  using namespace realtime;
  const BatchFrames fr{m.frames.as<RealtimeFrameView>()};
  cudaEvent_t* ev = m.events[slot].data();
  const auto stage = [&](int i) { Check(cudaEventRecord(ev[i], stream), "cudaEventRecord"); };
  const dim3 grid = PixelGrid(W, H, count);
  Float3* L = m.radiance.as<Float3>();
  stage(0);
  LaunchGeometry(fr, grid, m.geometry.as<PixelGeometry>(), depth ? depth : m.depth.as<float>(),
                 m.surfaces.as<SurfaceTerms>(), stream);
  if (m.mirror) LaunchMirrorTrace(fr, grid, stream);
  stage(1);
  LaunchSkyQuads(fr, PixelGrid((W + 1) / 2, (H + 1) / 2, count), m.sky.as<Float3>(), stream);
  if (m.mirror) LaunchMirrorSky(fr, grid, m.mirror_sky.as<Float3>(), stream);
  stage(2);
  // batches hold no media (BatchRenderer::UpdateWorld refuses them); the shadow rays apart
  // where the batch fits one wave of the shading kernel (QueueShadowRays), as a frame's
  if (QueueShadowRays(n * count, m.lights)) {
    const ShadowRayQueue q = m.ShadowQueue(n * count, m.lights);
    LaunchBatchShade(fr, W, H, count, m.surfaces.as<SurfaceTerms>(), L, &q, stream);
  } else {
    LaunchBatchShade(fr, W, H, count, m.surfaces.as<SurfaceTerms>(), L, nullptr, stream);
  }
  stage(3);
  // the shared visibility as a frame's, the queue's chunks of kBatchPenumbraChunkRays rays
  m.PenumbraRays(fr, W, H, m.lights, nl, count, kBatchPenumbraChunkRays, stream);
  LaunchVisibilityTiles(fr, W, 0, H, count, /*mirror=*/false, L, stream);
  stage(4);
  if (m.mirror) {
    LaunchMirrorShade(fr, grid, stream);
    LaunchMirrorBlend(fr, grid, L, stream);
  }
  stage(5);
  LaunchRowSums(L, W, H, count, m.rows.as<double>(), stream);
  stage(6);
  // the exposures on the device, one block a camera
  LaunchBatchExposure(m.rows.as<double>(), H, n, count, m.film.as<RealtimeBatchFilm>(),
                      m.exposure.as<DeviceExposure>(), stream);
  stage(7);
  if (rgb)
    LaunchBatchDevelop(L, n, count, m.film.as<RealtimeBatchFilm>(), m.exposure.as<DeviceExposure>(),
                       rgb, stream);
  stage(8);
}

RealtimeBatchTimes RealtimeBatch::times(int slot) const {
  const Impl& m = *impl_;
  RealtimeBatchTimes t;
  if (slot < 0 || slot >= m.slots) return t;
  double ms[kBatchStages] = {};
  for (int i = 0; i < kBatchStages; ++i) {
    float x = 0;
    Check(cudaEventElapsedTime(&x, m.events[slot][i], m.events[slot][i + 1]),
          "cudaEventElapsedTime");
    ms[i] = x;
  }
  t.geometry = ms[0];
  t.sky = ms[1];
  t.shade = ms[2];
  t.visibility = ms[3];
  t.mirror = ms[4];
  t.row_sums = ms[5];
  t.exposure = ms[6];
  t.film = ms[7];
  for (double x : ms) t.total += x;
  return t;
}

}  // namespace penumbra::cuda

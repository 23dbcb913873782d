// DeviceRealtime (cuda_realtime.h): one realtime frame's kernels (realtime_kernels.cuh) on the
// scene's stream, its uploads and its copies back.

#include <chrono>
#include <cstring>
#include <string>
#include <vector>

#include "penumbra/render/cuda/realtime_kernels.cuh"

namespace penumbra::cuda {
namespace {

using realtime::OneFrame;

using Clock = std::chrono::steady_clock;
double MsSince(Clock::time_point t) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
}

// the radiance goes back in this many bands of rows, each copied into the frame's image while
// the next one comes back
constexpr int kOutputBands = 2;
// the host's copies of the outputs into the frame's images: chunks of this many bytes over
// RealtimeOutputs::parallel; a loop of copies of at most kSerialCopyBytes (a small frame's) runs
// on the calling thread alone (waking the pool costs more than such copies)
constexpr size_t kCopyChunkBytes = size_t{256} << 10;
constexpr size_t kSerialCopyBytes = size_t{512} << 10;

}  // namespace

struct DeviceRealtime::Impl : realtime::PixelBuffers {
  Buffer materials, textures, texels, decode, lut, geoms, lights;
  // rgb: the frame's tail, one device buffer copied back at once with the device's exposure: the
  // rgb (3 n bytes), then, 16-byte aligned, the row sums (H doubles) and the device's exposure
  // (TailRows, rows, exposure_out); pin_rgb holds its copy
  Buffer depth, rgb;
  double* rows = nullptr;
  realtime::DeviceExposure* exposure_out = nullptr;
  // the frame's media and particle streaks
  realtime::MediaStreakBuffers extras;
  // the sky's and the sky volume's arrays (UploadSky), their pods with these pointers, and the
  // sky volume's pod on the device (the media's)
  Buffer sky_irradiance, skybox, volume_sh, volume_cells, volume_depth, volume_pod;
  SkyModelPod device_sky;
  SkyVolumePod device_volume;
  bool sky_uploaded = false;
  // the stage times (CUDA events with timing): start, geometry, sky terms, row sums, film (the
  // device's exposure), the tail on the host, the radiance on the host
  cudaEvent_t stage[7] = {};
  // page-locked: the row sums (frames too tall for the device's exposure), the outputs, and the
  // staging of the posed geoms and lights
  PinnedBuffer pin_rows, pin_rgb, pin_radiance, pin_depth, pin_geoms, pin_lights;
  // the bytes of the geoms and lights the device holds (uploaded only when they change);
  // `uploaded` false when they are not known (DeviceFrame uploaded others)
  std::vector<uint8_t> uploaded_geoms, uploaded_lights;
  bool uploaded = false;
  RealtimeExposureChecks checks;
  std::vector<double> host_rows;
  // the outputs' copies back; the mirror layer's kernels' stream (the device's lowest
  // priority, below the frame's stream, so its blocks take the SMs the frame's own kernels
  // leave), the event it forks at (the primary geometry traced) and the one it joins at (the
  // mirrored radiance shaded)
  cudaStream_t copy_stream = nullptr, side_stream = nullptr;
  cudaEvent_t mirror_fork = nullptr, mirror_join = nullptr;
  cudaEvent_t resolved_band[kOutputBands] = {};  // band k of the radiance is final
  cudaEvent_t radiance_band[kOutputBands] = {};  // band k of the radiance is in its pinned buffer
  cudaEvent_t geometry_done = nullptr;
  cudaEvent_t depth_copied = nullptr;  // the depth is in its pinned buffer
  cudaEvent_t rgb_copied = nullptr;    // the tail is in its pinned buffer
  RealtimeStageTimes times;
  // the last frame, for TimeKernels
  RealtimeFrameView frame;
  float exposure[3] = {1, 1, 1};
  RealtimeFilm film;
  int filmic = 1;
  bool rendered = false;

  // the tail's layout (rgb above): the row sums' offset, and its bytes
  static size_t TailRows(int64_t n) { return (static_cast<size_t>(3 * n) + 15) / 16 * 16; }
  static size_t TailBytes(int64_t n, int H) {
    return TailRows(n) + sizeof(double) * H + sizeof(realtime::DeviceExposure);
  }
  // the tail for frames of n pixels and H rows on the device (rows and exposure_out into it)
  void ReserveTail(int64_t n, int H) {
    rgb.Reserve(TailBytes(n, H));
    rows = reinterpret_cast<double*>(rgb.as<char>() + TailRows(n));
    exposure_out = reinterpret_cast<realtime::DeviceExposure*>(rows + H);
  }
  // the streams and events, made by the first frame
  void MakeStreams() {
    if (copy_stream) return;
    const auto event = [](cudaEvent_t* e) {
      Check(cudaEventCreateWithFlags(e, cudaEventDisableTiming), "cudaEventCreate");
    };
    Check(cudaStreamCreateWithFlags(&copy_stream, cudaStreamNonBlocking), "cudaStreamCreate");
    int least = 0, greatest = 0;
    Check(cudaDeviceGetStreamPriorityRange(&least, &greatest), "cudaDeviceGetStreamPriorityRange");
    Check(cudaStreamCreateWithPriority(&side_stream, cudaStreamNonBlocking, least),
          "cudaStreamCreate");
    for (cudaEvent_t* e : {&geometry_done, &depth_copied, &rgb_copied, &mirror_fork, &mirror_join})
      event(e);
    for (cudaEvent_t& e : resolved_band) event(&e);
    for (cudaEvent_t& e : radiance_band) event(&e);
    for (cudaEvent_t& e : stage) Check(cudaEventCreate(&e), "cudaEventCreate");
  }

  // the posed geoms and lights of `f` (host arrays, num_geoms geoms) to the device on `stream`
  // through page-locked staging, asynchronous (the last frame's copies are done: it ended with a
  // synchronisation), only when their bytes differ from the last upload's
  void UploadPosed(const RealtimeFrameView& f, int64_t num_geoms, cudaStream_t stream) {
    const size_t geom_bytes = sizeof(GeomPod) * num_geoms;
    const size_t light_bytes = sizeof(LightPod) * f.num_lights;
    const auto* g = reinterpret_cast<const uint8_t*>(f.geoms);
    const auto* l = reinterpret_cast<const uint8_t*>(f.lights);
    const auto same = [](const std::vector<uint8_t>& a, const uint8_t* b, size_t n) {
      return a.size() == n && (n == 0 || std::memcmp(a.data(), b, n) == 0);
    };
    if (uploaded && same(uploaded_geoms, g, geom_bytes) && same(uploaded_lights, l, light_bytes))
      return;
    pin_geoms.Reserve(geom_bytes > 0 ? geom_bytes : 1);
    pin_lights.Reserve(light_bytes > 0 ? light_bytes : 1);
    if (geom_bytes > 0) std::memcpy(pin_geoms.p, f.geoms, geom_bytes);
    if (light_bytes > 0) std::memcpy(pin_lights.p, f.lights, light_bytes);
    geoms.Upload(pin_geoms.p, geom_bytes, stream);
    lights.Upload(pin_lights.p, light_bytes, stream);
    uploaded_geoms.assign(g, g + geom_bytes);
    uploaded_lights.assign(l, l + light_bytes);
    uploaded = true;
  }

  // whether frame f's mirror layer runs on the side stream: it forks after the geometry kernel
  // and joins before the mirror blend, so its kernels run beside the sky quads, the shading and
  // the shared visibility (which neither read nor write their arrays: the same bits)
  bool ForkMirror(const RealtimeFrameView& f) const {
    return sky_uploaded && side_stream != nullptr && f.any_mirror != 0;
  }
  // the geometry kernel of frame f on `stream`, then its mirrored rays (on the side stream)
  void LaunchGeometry(const RealtimeFrameView& f, cudaStream_t stream) {
    const dim3 grid = realtime::PixelGrid(f.camera.width, f.camera.height);
    realtime::LaunchGeometry(OneFrame{f}, grid, geometry.as<PixelGeometry>(), depth.as<float>(),
                             surfaces.as<SurfaceTerms>(), stream);
    if (f.any_mirror == 0) return;
    cudaStream_t s = stream;
    if (ForkMirror(f)) {
      s = side_stream;
      Check(cudaEventRecord(mirror_fork, stream), "cudaEventRecord");
      Check(cudaStreamWaitEvent(s, mirror_fork, 0), "cudaStreamWaitEvent");
    }
    realtime::LaunchMirrorTrace(OneFrame{f}, grid, s);
  }
  // the sky terms of frame f (its geometry and mirrored rays traced) on `stream`; with the
  // side stream, the mirrored rays' sky terms and shading there, which then joins
  void LaunchSky(const RealtimeFrameView& f, cudaStream_t stream) {
    const int W = f.camera.width, H = f.camera.height;
    realtime::LaunchSkyQuads(OneFrame{f}, realtime::PixelGrid((W + 1) / 2, (H + 1) / 2),
                             sky.as<Float3>(), stream);
    if (f.any_mirror == 0) return;
    const bool fork = ForkMirror(f);
    cudaStream_t s = fork ? side_stream : stream;
    realtime::LaunchMirrorSky(OneFrame{f}, realtime::PixelGrid(W, H), mirror_sky.as<Float3>(), s);
    if (fork) {
      realtime::LaunchMirrorShade(OneFrame{f}, realtime::PixelGrid(W, H), s);
      Check(cudaEventRecord(mirror_join, s), "cudaEventRecord");
    }
  }
  // row k of the radiance's kOutputBands bands of rows of a frame H rows high: whole shadow
  // tiles (the visibility's tile kernel resolves a tile at a time)
  static int OutputBandRow(int H, int k) {
    const int rows = (H + kOutputBands - 1) / kOutputBands;
    const int tiles = (rows + kShadowTileSize - 1) / kShadowTileSize;
    return std::min(H, k * tiles * kShadowTileSize);
  }
  // the shading kernel of frame f on `stream`, its shadow rays apart where QueueShadowRays
  // holds (the same bits)
  void LaunchShade(const RealtimeFrameView& f, cudaStream_t stream) {
    const int64_t n = static_cast<int64_t>(f.camera.width) * f.camera.height;
    realtime::ShadowRayQueue q;
    const bool queue = realtime::QueueShadowRays(n, f.num_lights);
    if (queue) q = ShadowQueue(n, f.num_lights);
    realtime::LaunchFrameShade(f, surfaces.as<SurfaceTerms>(), radiance.as<Float3>(),
                               queue ? &q : nullptr, 0, f.camera.height, stream);
  }
  // the kernels after the shading kernel: the shared visibility with the mirror layer's blend
  // (the mirrored radiance shaded before it), launched in kOutputBands bands of rows, each
  // band's copy back behind its own event (without view passes, which change the radiance
  // after it: then one band), the view passes, the row sums.
  void LaunchAfterShade(const RealtimeFrameView& f, cudaStream_t stream) {
    const int W = f.camera.width, H = f.camera.height;
    const OneFrame fr{f};
    PenumbraRays(fr, W, H, f.num_lights, static_cast<int64_t>(W) * H * f.num_lights, 1,
                 realtime::kFramePenumbraChunkRays, stream);
    const bool mirror = f.any_mirror != 0;
    const bool fork = ForkMirror(f);
    if (mirror && !fork) realtime::LaunchMirrorShade(fr, realtime::PixelGrid(W, H), stream);
    if (fork) Check(cudaStreamWaitEvent(stream, mirror_join, 0), "cudaStreamWaitEvent");
    const bool after = realtime::HasViewPasses(f);
    const int bands = after ? 1 : kOutputBands;
    for (int k = 0; k < bands; ++k) {
      const int r0 = after ? 0 : OutputBandRow(H, k), r1 = after ? H : OutputBandRow(H, k + 1);
      realtime::LaunchVisibilityTiles(fr, W, r0, r1, 1, mirror, radiance.as<Float3>(), stream);
      if (!after) Check(cudaEventRecord(resolved_band[k], stream), "cudaEventRecord");
    }
    realtime::LaunchViewPasses(f, depth.as<float>(), radiance.as<Float3>(), stream);
    if (after)
      for (cudaEvent_t& e : resolved_band) Check(cudaEventRecord(e, stream), "cudaEventRecord");
    realtime::LaunchRowSums(radiance.as<Float3>(), W, H, 1, rows, stream);
  }
  // f's scene-wide arrays: the device copies of Upload, UploadSky and the posed geoms and lights
  void WithDeviceArrays(RealtimeFrameView* f) const {
    f->materials = materials.as<MaterialPod>();
    f->textures = textures.as<TexturePod>();
    f->texels = texels.as<uint8_t>();
    f->srgb_decode = decode.as<float>();
    f->geoms = geoms.as<GeomPod>();
    f->lights = lights.as<LightPod>();
    if (sky_uploaded) {
      f->sky = device_sky;
      f->volume = device_volume;
    }
  }
  ~Impl() {
    if (copy_stream) cudaStreamDestroy(copy_stream);
    if (side_stream) cudaStreamDestroy(side_stream);
    for (cudaEvent_t e : {geometry_done, depth_copied, rgb_copied, mirror_fork, mirror_join})
      if (e) cudaEventDestroy(e);
    for (cudaEvent_t e : resolved_band)
      if (e) cudaEventDestroy(e);
    for (cudaEvent_t e : radiance_band)
      if (e) cudaEventDestroy(e);
    for (cudaEvent_t e : stage)
      if (e) cudaEventDestroy(e);
  }
};

DeviceRealtime::DeviceRealtime() : impl_(new Impl) {}
DeviceRealtime::~DeviceRealtime() { delete impl_; }

const RealtimeStageTimes& DeviceRealtime::last_stage_times() const { return impl_->times; }
const RealtimeExposureChecks& DeviceRealtime::exposure_checks() const { return impl_->checks; }

bool DeviceRealtime::DownloadStreakKeys(std::vector<unsigned long long>* out) const {
  const Impl& m = *impl_;
  const StreakSplatView& sp = m.frame.splat;
  if (!m.rendered || sp.streaks.num <= 0) return false;
  Check(cudaDeviceSynchronize(), "DownloadStreakKeys");
  out->assign(static_cast<size_t>(m.frame.camera.width) * m.frame.camera.height, 0);
  Check(cudaMemcpy(out->data(), sp.nearest, sizeof(unsigned long long) * out->size(),
                   cudaMemcpyDeviceToHost),
        "DownloadStreakKeys");
  return true;
}

bool DeviceRealtime::DownloadGridVolumes(GridVolumeArrays* out) const {
  return impl_->extras.DownloadGridVolumes(out);
}

void DeviceRealtime::Upload(const RealtimeStatic& d) {
  Impl& m = *impl_;
  m.materials.Upload(d.materials, sizeof(MaterialPod) * d.num_materials, nullptr);
  m.textures.Upload(d.textures, sizeof(TexturePod) * d.num_textures, nullptr);
  m.texels.Upload(d.texels, static_cast<size_t>(d.num_texel_bytes), nullptr);
  m.decode.Upload(d.srgb_decode, sizeof(float) * 256, nullptr);
  m.lut.Upload(d.oetf_lut, kFilmLutSize, nullptr);
  Check(cudaDeviceSynchronize(), "uploading the realtime scene");
}

void DeviceRealtime::UploadSky(const RealtimeSky& d) {
  Impl& m = *impl_;
  SkyModelPod sky = d.sky;
  m.sky_irradiance.Upload(d.sky.irradiance, sizeof(float) * 3 * kSkyIrrSide * kSkyIrrSide, nullptr);
  sky.irradiance = m.sky_irradiance.as<float>();
  if (d.sky.skybox != nullptr) {
    const size_t w = static_cast<size_t>(d.sky.skybox_width);
    m.skybox.Upload(d.sky.skybox, 6 * w * w * 3, nullptr);
    sky.skybox = m.skybox.as<uint8_t>();
    sky.srgb_decode = m.decode.as<float>();
  }
  SkyVolumePod v = d.volume;
  if (!v.empty() && d.num_probes > 0) {
    const size_t n = static_cast<size_t>(d.num_probes);
    m.volume_sh.Upload(d.volume.sh, sizeof(float) * kSkyShStride * n, nullptr);
    m.volume_cells.Upload(d.volume.cell_pos, sizeof(float) * 24 * n, nullptr);
    m.volume_depth.Upload(d.volume.depth_q, static_cast<size_t>(kSkyNumTexels) * n, nullptr);
    v.sh = m.volume_sh.as<float>();
    v.cell_pos = m.volume_cells.as<float>();
    v.depth_q = m.volume_depth.as<uint8_t>();
  } else {
    v = SkyVolumePod();
  }
  if (!v.empty()) m.volume_pod.Upload(&v, sizeof(SkyVolumePod), nullptr);
  Check(cudaDeviceSynchronize(), "uploading the realtime sky");
  m.device_sky = sky;
  m.device_volume = v;
  m.sky_uploaded = true;
}

RealtimeFrameView DeviceRealtime::DeviceFrame(const RealtimeFrameView& host_frame,
                                              int64_t num_geoms) {
  Impl& m = *impl_;
  m.uploaded = false;  // Render's next frame uploads its own
  m.geoms.Upload(host_frame.geoms, sizeof(GeomPod) * num_geoms, nullptr);
  m.lights.Upload(host_frame.lights, sizeof(LightPod) * host_frame.num_lights, nullptr);
  Check(cudaStreamSynchronize(nullptr), "uploading the realtime geoms and lights");
  RealtimeFrameView f = host_frame;
  m.WithDeviceArrays(&f);
  return f;
}

const uint8_t* DeviceRealtime::device_lut() const { return impl_->lut.as<uint8_t>(); }

double DeviceRealtime::Render(DeviceScene* scene, const RealtimeFrameView& host_frame,
                              int64_t num_geoms, const RealtimeFilm& film,
                              const ExposureFn& exposure, const RealtimeOutputs& out,
                              const StreaksFn& streaks) {
  Impl& m = *impl_;
  const auto t0 = Clock::now();
  cudaStream_t stream = static_cast<cudaStream_t>(scene->stream());
  m.MakeStreams();
  if (!m.sky_uploaded) throw Error("DeviceRealtime::Render: no UploadSky before the frame");
  Check(cudaEventRecord(m.stage[0], stream), "cudaEventRecord");
  const PinholeCamera& c = host_frame.camera;
  const int W = c.width, H = c.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  const int filmic = film.filmic ? 1 : 0;
  // the exposure on the device: the film kernel follows the row sums without the host
  const bool device_exposure = H <= kMaxDeviceExposureRows;
  m.UploadPosed(host_frame, num_geoms, stream);
  const RealtimeOutputs::ParallelFn& parallel = out.parallel;
  m.depth.Reserve(sizeof(float) * n);
  m.ReserveTail(n, H);
  const int64_t nl = n * (host_frame.num_lights > 0 ? host_frame.num_lights : 1);
  const bool mirror = host_frame.any_mirror != 0;
  m.PixelBuffers::Reserve(n, nl, mirror);
  // the frame with the device copies
  RealtimeFrameView f = host_frame;
  f.scene = scene->device_view();
  m.WithDeviceArrays(&f);
  m.Point(&f, 0, 0, mirror);
  // the particle streaks: the frame's now (the streaks, culled on the host or the device, and
  // their splat, first), or late (`streaks`: none until the shading is queued)
  m.extras.QueueStreaks(streaks ? RealtimeFrameView() : host_frame, &f, n, /*staged=*/false,
                        stream);
  if (f.has_media != 0) {
    const SkyVolumePod* volume =
        m.device_volume.empty() ? nullptr : m.volume_pod.as<SkyVolumePod>();
    m.extras.UploadMedia(host_frame.media, volume, &f.media, stream);
    m.extras.BuildMedia(host_frame.media, &f, stream);
  }
  // the outputs' page-locked buffers; with the device's exposure the row sums come back in the
  // tail's copy
  m.pin_rgb.Reserve(Impl::TailBytes(n, H));
  double* host_rows;
  if (device_exposure) {
    host_rows = reinterpret_cast<double*>(m.pin_rgb.as<char>() + Impl::TailRows(n));
  } else {
    m.pin_rows.Reserve(sizeof(double) * H);
    host_rows = m.pin_rows.as<double>();
  }
  if (out.radiance) m.pin_radiance.Reserve(sizeof(Float3) * n);
  if (out.depth) m.pin_depth.Reserve(sizeof(float) * n);
  // (1) primary geometry (materials and normal maps included) and depth; (2) the sky-term
  // kernels; the depth goes back on the copy stream
  m.LaunchGeometry(f, stream);
  Check(cudaEventRecord(m.stage[1], stream), "cudaEventRecord");
  m.LaunchSky(f, stream);
  Check(cudaEventRecord(m.stage[2], stream), "cudaEventRecord");
  Check(cudaEventRecord(m.geometry_done, stream), "cudaEventRecord");
  Check(cudaStreamWaitEvent(m.copy_stream, m.geometry_done, 0), "cudaStreamWaitEvent");
  if (out.depth) {
    m.depth.Download(m.pin_depth.p, sizeof(float) * n, m.copy_stream);
    Check(cudaEventRecord(m.depth_copied, m.copy_stream), "cudaEventRecord");
  }
  // (3) the shading kernel
  m.LaunchShade(f, stream);
  if (streaks) {
    // the late streaks: made on the host while the GPU runs the kernels queued so far (none of
    // which reads them), then uploaded (staged: the stream is busy) and splatted before the
    // kernels that draw them (the media's view pass or the splat's apply kernel); on a throw
    // the queued work is waited for (the next frame reuses its pinned buffers)
    RealtimeFrameView late;
    try {
      streaks(&late);
    } catch (...) {
      cudaDeviceSynchronize();
      throw;
    }
    m.extras.QueueStreaks(late, &f, n, /*staged=*/true, stream);
  }
  // the shared visibility, the mirror layer and (4) the rows' log-luminance sums
  m.LaunchAfterShade(f, stream);
  // the radiance goes back on the copy stream in bands of rows, each as soon as it is resolved
  // (the row sums still running) and behind an event, so that the host copies band k into the
  // frame's image while band k + 1 comes back
  auto out_row = [&](int k) { return Impl::OutputBandRow(H, k); };
  if (out.radiance) {
    for (int k = 0; k < kOutputBands; ++k) {
      const size_t off = static_cast<size_t>(out_row(k)) * W;
      const size_t count = static_cast<size_t>(out_row(k + 1) - out_row(k)) * W;
      Check(cudaStreamWaitEvent(m.copy_stream, m.resolved_band[k], 0), "cudaStreamWaitEvent");
      if (count > 0)
        Check(cudaMemcpyAsync(m.pin_radiance.as<Float3>() + off, m.radiance.as<Float3>() + off,
                              sizeof(Float3) * count, cudaMemcpyDeviceToHost, m.copy_stream),
              "cudaMemcpyAsync");
      Check(cudaEventRecord(m.radiance_band[k], m.copy_stream), "cudaEventRecord");
    }
    Check(cudaEventRecord(m.stage[6], m.copy_stream), "cudaEventRecord");
  }
  if (device_exposure) {
    // (5) the exposure and the film on the device, the row sums, the device's exposure and the
    // rgb back on the same stream: the host waits once, at the end
    Check(cudaEventRecord(m.stage[3], stream), "cudaEventRecord");
    realtime::LaunchExposure(m.rows, H, n, film.exposure, film.white_balance_gains, m.exposure_out,
                             stream);
    realtime::LaunchDevelop(m.radiance.as<Float3>(), n, m.exposure_out, filmic, m.lut.as<uint8_t>(),
                            m.rgb.as<uint8_t>(), stream);
    Check(cudaEventRecord(m.stage[4], stream), "cudaEventRecord");
    // the rgb, the row sums and the device's exposure: one copy (the rows' part alone without
    // the rgb)
    const size_t from = out.rgb ? 0 : Impl::TailRows(n);
    Check(cudaMemcpyAsync(m.pin_rgb.as<char>() + from, m.rgb.as<char>() + from,
                          Impl::TailBytes(n, H) - from, cudaMemcpyDeviceToHost, stream),
          "cudaMemcpyAsync");
    Check(cudaEventRecord(m.rgb_copied, stream), "cudaEventRecord");
    Check(cudaEventRecord(m.stage[5], stream), "cudaEventRecord");
  } else {
    Check(cudaMemcpyAsync(host_rows, m.rows, sizeof(double) * H, cudaMemcpyDeviceToHost, stream),
          "cudaMemcpyAsync");
    Check(cudaEventRecord(m.stage[3], stream), "cudaEventRecord");
  }
  m.times.launched = MsSince(t0);
  // the depth into the frame's image while the GPU shades
  if (out.depth) {
    Check(cudaEventSynchronize(m.depth_copied), "copying the realtime depth");
    ParallelCopy(parallel, {{out.depth, m.pin_depth.p, sizeof(float) * n}}, kCopyChunkBytes,
                 kSerialCopyBytes);
  }
  float e[3];
  double ev100 = 0;
  const auto tc = Clock::now();
  if (device_exposure) {
    // the radiance bands and the rgb in one loop over the host's threads, each chunk as soon as
    // its band or the rgb is back (the radiance while the row sums, exposure and film run);
    // then the host's exposure from the same row sums: where the device's differs, the film
    // again with the host's, and its rgb copied over the device exposure's
    std::vector<HostCopy> copies;
    if (out.radiance)
      for (int k = 0; k < kOutputBands; ++k) {
        const size_t off = static_cast<size_t>(out_row(k)) * W;
        const size_t count = static_cast<size_t>(out_row(k + 1) - out_row(k)) * W;
        copies.push_back({out.radiance + 3 * off, m.pin_radiance.as<Float3>() + off,
                          sizeof(Float3) * count, m.radiance_band[k]});
      }
    if (out.rgb) copies.push_back({out.rgb, m.pin_rgb.p, static_cast<size_t>(3 * n), m.rgb_copied});
    ParallelCopy(parallel, copies, kCopyChunkBytes, kSerialCopyBytes);
    Check(cudaStreamSynchronize(stream), "DevelopKernel");
    m.host_rows.assign(host_rows, host_rows + H);
    ev100 = exposure(m.host_rows, e);
    const auto& d = *reinterpret_cast<const realtime::DeviceExposure*>(host_rows + H);
    ++m.checks.frames;
    if (std::memcmp(&d.ev100, &ev100, sizeof(double)) != 0) ++m.checks.ev100_differs;
    if (std::memcmp(d.e, e, sizeof(e)) != 0) {
      ++m.checks.redeveloped;
      realtime::LaunchDevelop(m.radiance.as<Float3>(), n, e, filmic, m.lut.as<uint8_t>(),
                              m.rgb.as<uint8_t>(), stream);
      if (out.rgb) m.rgb.Download(m.pin_rgb.p, 3 * n, stream);
      Check(cudaStreamSynchronize(stream), "DevelopKernel");
      if (out.rgb)
        ParallelCopy(parallel, {{out.rgb, m.pin_rgb.p, static_cast<size_t>(3 * n)}},
                     kCopyChunkBytes, kSerialCopyBytes);
    }
    Check(cudaStreamSynchronize(m.copy_stream), "copying the realtime outputs");
  } else {
    // a frame too tall for the device's exposure: the row sums on the host, then (5) the film,
    // the radiance into the frame's image while it runs, then the rgb
    Check(cudaStreamSynchronize(stream), "ShadeKernel");
    m.host_rows.assign(host_rows, host_rows + H);
    ev100 = exposure(m.host_rows, e);
    realtime::LaunchDevelop(m.radiance.as<Float3>(), n, e, filmic, m.lut.as<uint8_t>(),
                            m.rgb.as<uint8_t>(), stream);
    if (out.rgb) m.rgb.Download(m.pin_rgb.p, 3 * n, stream);
    if (out.radiance)
      for (int k = 0; k < kOutputBands; ++k) {
        Check(cudaEventSynchronize(m.radiance_band[k]), "copying the realtime radiance");
        const size_t off = static_cast<size_t>(out_row(k)) * W;
        const size_t count = static_cast<size_t>(out_row(k + 1) - out_row(k)) * W;
        ParallelCopy(
            parallel,
            {{out.radiance + 3 * off, m.pin_radiance.as<Float3>() + off, sizeof(Float3) * count}},
            kCopyChunkBytes, kSerialCopyBytes);
      }
    Check(cudaStreamSynchronize(m.copy_stream), "copying the realtime outputs");
    Check(cudaStreamSynchronize(stream), "DevelopKernel");
    if (out.rgb)
      ParallelCopy(parallel, {{out.rgb, m.pin_rgb.p, static_cast<size_t>(3 * n)}}, kCopyChunkBytes,
                   kSerialCopyBytes);
  }
  m.times.outputs = MsSince(tc);
  m.times.total = MsSince(t0);
  float ms[3] = {0, 0, 0};
  for (int k = 0; k < 3; ++k)
    Check(cudaEventElapsedTime(&ms[k], m.stage[k], m.stage[k + 1]), "cudaEventElapsedTime");
  m.times.geometry = ms[0];
  m.times.sky = ms[1];
  m.times.shade = ms[2];
  m.times.film = m.times.total - (m.times.geometry + m.times.sky + m.times.shade);
  // the device's end of the kernels and of the copies back (with the device's exposure)
  m.times.kernels_end = m.times.copies_end = 0;
  if (device_exposure) {
    float end = 0;
    Check(cudaEventElapsedTime(&end, m.stage[0], m.stage[4]), "cudaEventElapsedTime");
    m.times.kernels_end = end;
    Check(cudaEventElapsedTime(&end, m.stage[0], m.stage[5]), "cudaEventElapsedTime");
    m.times.copies_end = end;
    if (out.radiance) {
      Check(cudaEventElapsedTime(&end, m.stage[0], m.stage[6]), "cudaEventElapsedTime");
      m.times.copies_end = std::max<double>(m.times.copies_end, end);
    }
  }
  m.frame = f;
  std::memcpy(m.exposure, e, sizeof(e));
  m.film = film;
  m.filmic = filmic;
  m.rendered = true;
  return ev100;
}

double DeviceRealtime::TimeKernels(DeviceScene* scene, int count) {
  Impl& m = *impl_;
  if (!m.rendered || count < 1) return 0;
  cudaStream_t stream = static_cast<cudaStream_t>(scene->stream());
  const RealtimeFrameView& f = m.frame;
  const int64_t n = static_cast<int64_t>(f.camera.width) * f.camera.height;
  // the exposure as Render makes it: on the device (its kernel, then the film reading it) or
  // the host's of the last Render
  const int H = f.camera.height;
  const auto film = [&] {
    if (H <= kMaxDeviceExposureRows) {
      realtime::LaunchExposure(m.rows, H, n, m.film.exposure, m.film.white_balance_gains,
                               m.exposure_out, stream);
      realtime::LaunchDevelop(m.radiance.as<Float3>(), n, m.exposure_out, m.filmic,
                              m.lut.as<uint8_t>(), m.rgb.as<uint8_t>(), stream);
    } else {
      realtime::LaunchDevelop(m.radiance.as<Float3>(), n, m.exposure, m.filmic, m.lut.as<uint8_t>(),
                              m.rgb.as<uint8_t>(), stream);
    }
  };
  const auto frame = [&] {
    realtime::LaunchStreakSplat(f, stream);
    m.LaunchGeometry(f, stream);
    m.LaunchSky(f, stream);
    m.LaunchShade(f, stream);
    m.LaunchAfterShade(f, stream);
    film();
  };
  // one untimed run (the first launch of a kernel costs more)
  frame();
  Check(cudaStreamSynchronize(stream), "realtime kernels");
  return TimeOnStream(stream, count, frame);
}

}  // namespace penumbra::cuda

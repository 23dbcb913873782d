#include "penumbra/render/cuda/cuda_renderer.h"

#include <chrono>
#include <cmath>

#include "penumbra/render/camera/camera.h"
#include "penumbra/render/cuda/cuda_ray_query.h"
#include "penumbra/render/cuda/realtime_host.h"
#include "penumbra/render/frame/bvh_ray_query.h"
#include "penumbra/render/light/emitter_sampler.h"
#include "penumbra/scene/texture_image.h"

namespace penumbra::cuda {
namespace {

template <typename T>
T* Shape(Image<T>* img, bool want, int w, int h, int c) {
  if (!want) {
    *img = Image<T>();
    return nullptr;
  }
  if (img->width != w || img->height != h || img->channels != c) *img = Image<T>(w, h, c);
  return img->data.data();
}

}  // namespace

CudaRenderer::CudaRenderer(const SceneDescription& scene) : CudaRenderer(scene, RenderSettings()) {}

CudaRenderer::CudaRenderer(const SceneDescription& scene, const RenderSettings& settings,
                           RayQueryFactory statics_query)
    : scene_(scene) {
  // the pool first: the BVHs (the scene's and the statics' maps') are built over it
  pool_ = std::make_unique<ThreadPool>(settings.threads);
  bvh_ = std::make_unique<BvhScene>(scene_, pool_.get());
  device_ = std::make_unique<DeviceScene>();
  SyncDevice(*bvh_, device_.get());
  // the statics' maps trace on the host (MakeRenderer's renderer through Embree, as the CPU
  // backend's): their rays on the GPU made the first frame shorter, but a second device copy of
  // the geometry made every later frame's kernels 2-7 % slower ("A new renderer's first frame"
  // in docs/journal/2026-11-26-gpu-speed.md)
  realtime_ = std::make_unique<RealtimeFrameData>(
      scene_, settings, statics_query ? std::move(statics_query) : BvhRayQueryFactory(pool_.get()));
  device_realtime_ = std::make_unique<DeviceRealtime>();
  device_path_ = std::make_unique<DevicePath>();
  if (settings.tier == RenderSettings::Tier::kPathtraced) {
    emitters_ = std::make_unique<EmitterSampler>(scene_);
    emitter_host_ = std::make_unique<PathEmitterHost>(*emitters_);
    if (settings.denoise) denoiser_ = std::make_unique<Denoiser>();
  }
  SetDeviceDropCuller();
}

CudaRenderer::~CudaRenderer() = default;

std::vector<DropSet> DropSetsOf(const EffectsFrame& fx) {
  std::vector<DropSet> sets(fx.particles.size());
  for (size_t s = 0; s < sets.size(); ++s) {
    const ParticleSet& ps = fx.particles[s];
    sets[s].p = ps.position_W.empty() ? nullptr : ps.position_W.data()->data();
    sets[s].v = ps.velocity_W.empty() ? nullptr : ps.velocity_W.data()->data();
    sets[s].r = ps.radius_m.data();
    sets[s].n = static_cast<int64_t>(ps.position_W.size());
  }
  return sets;
}

void CudaRenderer::SetDeviceDropCuller() {
  realtime_->set_device_drop_culler([this](const EffectsFrame& fx, const StreakCullSetup& setup) {
    // made at the first frame with drops (its stream and buffers)
    if (!drop_cull_) drop_cull_ = std::make_unique<DeviceStreakCull>();
    const std::vector<DropSet> sets = DropSetsOf(fx);
    // queued only: the frame's stream waits for it on the device, the host does not (its
    // counts are read once the frame is done: FinishDropCulling)
    drop_cull_->Queue(sets.data(), static_cast<int32_t>(sets.size()), setup.frame,
                      setup.sets.data(), HostParallel(), device_->stream());
    cull_queued_ = true;
    RealtimeFrameData::DeviceStreakList list;
    list.streaks = drop_cull_->device_streaks();
    list.bound = drop_cull_->bound();
    list.count = drop_cull_->device_count();
    list.download = [this](std::vector<StreakPod>* out) { drop_cull_->Download(out); };
    return list;
  });
}

void CudaRenderer::FinishDropCulling() {
  if (!cull_queued_) return;
  cull_queued_ = false;
  drop_cull_->Finish();
  realtime_->FinishDeviceCulling(drop_cull_->culled());
}

PinholeCamera CudaRenderer::PinholeOf(const CameraView& view) { return PinholeCameraOf(view); }

ParallelFn CudaRenderer::HostParallel() {
  return [this](int64_t count, const std::function<void(int64_t)>& body) {
    ParallelForOrSerial(pool_.get(), count, body);
  };
}

void CudaRenderer::Render(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                          const CameraView& view, RenderedFrame* out) {
  const auto t0 = std::chrono::steady_clock::now();
  CheckRenderInputs(scene_.bodies.size(), snapshot, view);
  bvh_->Update(snapshot);
  // the frame's kernels run on the device scene's stream, after the copies: no wait here
  SyncDevice(*bvh_, device_.get(), /*wait=*/false);
  // a camera with lens distortion or motion: its ray tables on the device (camera_rays.h)
  camera_rays_.Prepare(view, pool_.get());
  const float *xy = nullptr, *rows = nullptr;
  device_->UploadCameraRays(camera_rays_.xy().data(),
                            static_cast<int64_t>(camera_rays_.xy().size()),
                            camera_rays_.xy_version(), camera_rays_.rows().data(),
                            static_cast<int64_t>(camera_rays_.rows().size()), &xy, &rows);
  const PinholeCamera c = camera_rays_.Point(PinholeOf(view), xy, rows);
  const CameraOutputs& want = view.outputs;
  const int W = c.width, H = c.height;
  out->ev100 = 0;
  if (want[ImageKind::kRgb] && realtime_->settings().tier == RenderSettings::Tier::kPathtraced) {
    RenderPathtraced(snapshot, effects, view, c, t0, out);
  } else if (want[ImageKind::kRgb]) {
    RenderRgb(snapshot, effects, view, c, t0, out);
  } else {
    out->radiance = ImageF();
    out->rgb = ImageU8();
  }
  PrimaryOutputs o;
  // with rgb, depth comes from the realtime path's primary rays
  o.depth =
      want[ImageKind::kRgb] ? nullptr : Shape(&out->depth_m, want[ImageKind::kDepth], W, H, 1);
  o.geom_id = Shape(&out->geom_id, want[ImageKind::kSegmentation], W, H, 1);
  o.range = Shape(&out->range_m, want[ImageKind::kRange], W, H, 1);
  o.normal_O = Shape(&out->normal_O, want[ImageKind::kNormals], W, H, 3);
  o.body_id = Shape(&out->body_id, want[ImageKind::kInstanceSegmentation], W, H, 1);
  o.semantic = Shape(&out->semantic_class, want[ImageKind::kSemanticSegmentation], W, H, 1);
  if (o.depth || o.geom_id || o.range || o.normal_O || o.body_id || o.semantic)
    device_->RenderPrimary(c, o, HostParallel());
  out->rays = static_cast<int64_t>(W) * H;
  out->stopped = false;
  ++gpu_frames_;
}

void CudaRenderer::RenderRgb(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                             const CameraView& view, const PinholeCamera& camera,
                             std::chrono::steady_clock::time_point t0, RenderedFrame* out) {
  // the camera's ray tables were Prepared by Render (camera_rays_): not computed again; the
  // media volumes' shadow rays on the GPU, over the BVH Render posed
  if (!media_query_) media_query_ = std::make_unique<CudaRayQuery>(*bvh_, device_.get());
  // late streaks: the drops culled while the GPU traces and shades
  const bool late = effects != nullptr && !effects->empty() && !effects->particles.empty();
  late_streaks_ms_ = late_streaks_start_ms_ = 0;
  cull_queued_ = false;
  realtime_->Prepare(snapshot, view, pool_.get(), effects, &camera_rays_, media_query_.get(),
                     /*streaks=*/!late);
  UploadRealtime();
  const PinholeCamera& c = realtime_->camera();
  const int W = c.width, H = c.height;
  const int64_t n = static_cast<int64_t>(W) * H;
  float* radiance = Shape(&out->radiance, radiance_output_ && view.want_radiance, W, H, 3);
  Shape(&out->rgb, true, W, H, 3);
  RealtimeOutputs o;
  o.radiance = radiance;
  o.rgb = out->rgb.data.data();
  o.depth = Shape(&out->depth_m, view.outputs[ImageKind::kDepth], W, H, 1);
  o.parallel = HostParallel();
  RealtimeFrameView frame = realtime_->View(device_->device_view(), nullptr);
  // the camera's ray tables: the device copies, not Prepare's host arrays
  frame.camera.xy = camera.xy;
  frame.camera.rows = camera.rows;
  // the film's tone map and exposure (the device's, checked against the host's Ev100 below)
  RealtimeFilm film;
  film.filmic = realtime_->film().filmic();
  film.exposure = realtime_->film().exposure_pod();
  for (int k = 0; k < 3; ++k) film.white_balance_gains[k] = view.white_balance_gains[k];
  prepare_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  out->ev100 = device_realtime_->Render(
      device_.get(), frame, static_cast<int64_t>(realtime_->geoms().size()), film,
      [&](const std::vector<double>& rows, float exposure[3]) {
        return realtime_->Ev100(rows, n, exposure);
      },
      o, late ? LateStreaks(snapshot, effects, view, t0) : DeviceRealtime::StreaksFn());
  // the device culling's counts, read back with the frame's outputs: the culled rain, or the
  // host culling's ConfigError for a non-finite drop, before this frame is returned
  FinishDropCulling();
}

DeviceRealtime::StreaksFn CudaRenderer::LateStreaks(const WorldSnapshot& snapshot,
                                                    const EffectsFrame* effects,
                                                    const CameraView& view,
                                                    std::chrono::steady_clock::time_point t0) {
  return [this, &snapshot, effects, &view, t0](RealtimeFrameView* f) {
    const auto ts = std::chrono::steady_clock::now();
    late_streaks_start_ms_ = std::chrono::duration<double, std::milli>(ts - t0).count();
    const Camera camera(view.X_WO, view.intrinsics, view.motion);
    realtime_->PrepareStreaks(snapshot, effects, camera, view, pool_.get());
    realtime_->StreakFields(f);
    late_streaks_ms_ =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - ts).count();
  };
}

void CudaRenderer::UploadRealtime() {
  if (!realtime_uploaded_) {
    RealtimeStatic st;
    st.materials = realtime_->materials().data();
    st.num_materials = static_cast<int64_t>(realtime_->materials().size());
    st.textures = realtime_->textures().data();
    st.num_textures = static_cast<int64_t>(realtime_->textures().size());
    st.texels = realtime_->texels().data();
    st.num_texel_bytes = static_cast<int64_t>(realtime_->texels().size());
    st.srgb_decode = SrgbDecodeTable();
    st.oetf_lut = realtime_->film().oetf_lut().data();
    device_realtime_->Upload(st);
    realtime_uploaded_ = true;
  }
  // the sky volume is built on the first frame and rebuilt or relit when the static bodies or
  // the sky change: its device copy follows
  if (!sky_uploaded_ || realtime_->sky_generation() != sky_generation_) {
    device_realtime_->UploadSky(SkyDataOf(*realtime_));
    sky_generation_ = realtime_->sky_generation();
    sky_uploaded_ = true;
  }
}

void CudaRenderer::RenderPathtraced(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                                    const CameraView& view, const PinholeCamera& camera,
                                    std::chrono::steady_clock::time_point t0, RenderedFrame* out) {
  // the camera's ray tables were Prepared by Render (camera_rays_): not computed again. the
  // media are the paths' own (path_media_), not the realtime tier's volumes
  realtime_->Prepare(snapshot, view, pool_.get(), EffectsWithoutMedia(effects, &path_effects_),
                     &camera_rays_);
  path_media_.Build(effects != nullptr && !effects->empty() ? effects : nullptr);
  UploadRealtime();
  // the frame sky's sampling tables, again when the sky changes (the effects' sun or scale)
  if (sampling_sky_ != &realtime_->frame_sky() || sampling_generation_ != sky_generation_) {
    sampling_sky_ = &realtime_->frame_sky();
    sampling_generation_ = sky_generation_;
    sky_sampling_ = device_path_->UploadSkySampling(realtime_->frame_sky().sampling_pod());
  }
  RealtimeFrameView host_frame = realtime_->View(device_->device_view(), nullptr);
  // the camera's ray tables: the device copies, not Prepare's host arrays
  host_frame.camera.xy = camera.xy;
  host_frame.camera.rows = camera.rows;
  const RealtimeFrameView frame =
      device_realtime_->DeviceFrame(host_frame, static_cast<int64_t>(realtime_->geoms().size()));
  PathFrameView pf = PathView(*realtime_, frame, sky_sampling_);
  // the emissive geoms: their tables once, their poses every frame
  if (!emitters_->empty()) {
    if (!emitters_uploaded_) device_path_->UploadEmitters(emitter_host_->View());
    emitters_uploaded_ = true;
    emitter_host_->SetPoses(*emitters_, snapshot.X_WB);
    pf.emitters = device_path_->UploadEmitterPoses(emitter_host_->poses.data());
  }
  if (!path_media_.empty()) pf.media = device_path_->UploadMedia(path_media_.View());
  // the particle streaks of Prepare (pathtraced: their BVH for the paths) every frame
  pf.streaks = device_path_->UploadStreaks(realtime_->path_streaks().View());
  prepare_ms_ =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  device_path_->Render(device_.get(), pf, &path_buffers_);
  FinishPathFrame(*realtime_, path_buffers_, denoiser_.get(), view.white_balance_gains,
                  view.outputs[ImageKind::kDepth], pool_.get(), out);
  if (!radiance_output_) out->radiance = ImageF();
}

}  // namespace penumbra::cuda

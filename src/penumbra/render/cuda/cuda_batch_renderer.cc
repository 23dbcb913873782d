#include "penumbra/render/cuda/cuda_batch_renderer.h"

#include <fmt/format.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <utility>

#include "penumbra/core/error.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/cuda/cuda_ray_query.h"
#include "penumbra/render/cuda/cuda_renderer.h"
#include "penumbra/render/cuda/realtime_host.h"
#include "penumbra/render/frame/bvh_ray_query.h"

namespace penumbra::cuda {
namespace {

// the renderers' identities (BatchCamera::tables_owner): a camera's tables are its renderer's
uint64_t NextRendererId() {
  static std::atomic<uint64_t> next{1};
  return next.fetch_add(1);
}

}  // namespace

BatchRenderer::BatchRenderer(const BatchConfig& config)
    : layout_(config.width, config.height, config.max_cameras, config.outputs),
      device_(std::make_unique<BatchDevice>(layout_, config.copy)),
      counts_(BatchTickets::kSlots, 0),
      alone_count_(BatchTickets::kSlots, 0),
      alone_ms_(BatchTickets::kSlots, 0),
      statics_query_(config.statics_query),
      id_(NextRendererId()) {}

BatchRenderer::~BatchRenderer() {
  // the kernels and the exposures' host functions read the worlds and the realtime buffers
  try {
    device_->WaitForKernels();
  } catch (const Error&) {
    // a failed device: nothing left to wait for
  }
}

int BatchRenderer::AddWorld(const SceneDescription& scene, const RenderSettings& settings) {
  auto w = std::make_unique<World>();
  w->scene = scene;
  w->settings = settings;
  // the host's pool (the first world's threads) also builds the worlds' BVHs
  if (!pool_) pool_ = std::make_unique<ThreadPool>(settings.threads);
  w->bvh = std::make_unique<BvhScene>(w->scene, pool_.get());
  w->device = std::make_unique<DeviceScene>();
  SyncDevice(*w->bvh, w->device.get());
  if (layout_.outputs().rgb) {
    // the scene-constant arrays, as CudaRenderer uploads them
    w->realtime = std::make_unique<RealtimeFrameData>(
        w->scene, settings, statics_query_ ? statics_query_ : BvhRayQueryFactory(pool_.get()));
    w->device_realtime = std::make_unique<DeviceRealtime>();
    const RealtimeFrameData& d = *w->realtime;
    RealtimeStatic st;
    st.materials = d.materials().data();
    st.num_materials = static_cast<int64_t>(d.materials().size());
    st.textures = d.textures().data();
    st.num_textures = static_cast<int64_t>(d.textures().size());
    st.texels = d.texels().data();
    st.num_texel_bytes = static_cast<int64_t>(d.texels().size());
    st.srgb_decode = SrgbDecodeTable();
    st.oetf_lut = d.film().oetf_lut().data();
    w->device_realtime->Upload(st);
  }
  views_.push_back(w->device->device_view());
  worlds_.push_back(std::move(w));
  return static_cast<int>(worlds_.size()) - 1;
}

void BatchRenderer::UpdateWorld(int world, const WorldSnapshot& snapshot,
                                const EffectsFrame* effects) {
  if (world < 0 || world >= num_worlds())
    throw Error(
        fmt::format("batch rendering: world {}; expected a world in [0, {})", world, num_worlds()));
  World& w = *worlds_[world];
  w.bvh->Update(snapshot);
  // the submitted kernels read this world's transforms (and, after a rebuild, its arrays)
  device_->WaitForKernels();
  SyncDevice(*w.bvh, w.device.get());
  views_[world] = w.device->device_view();
  if (!w.realtime) return;
  // the ground truth does not see effects; with particles or media each camera needs its own
  // streaks and froxels: the world's cameras are rendered alone (RenderAlone) from this frame
  w.alone = PerCameraEffects(effects);
  if (w.alone) {
    if (!w.single) {
      RenderSettings settings = w.settings;
      settings.tier = RenderSettings::Tier::kRealtime;
      w.single = std::make_unique<CudaRenderer>(w.scene, settings, statics_query_);
      w.single->set_radiance_output(false);
    }
    w.snapshot = snapshot;
    w.effects = *effects;
  }
  w.realtime->PoseWorld(snapshot, pool_.get(), effects);
  if (!w.sky_uploaded || w.realtime->sky_generation() != w.sky_generation) {
    w.device_realtime->UploadSky(SkyDataOf(*w.realtime));
    w.sky_generation = w.realtime->sky_generation();
    w.sky_uploaded = true;
  }
  w.frame = w.device_realtime->DeviceFrame(w.realtime->View(views_[world], nullptr),
                                           static_cast<int64_t>(w.realtime->geoms().size()));
  w.posed = true;
}

void BatchRenderer::LaunchRgb(std::span<const BatchCamera> cameras, int slot, void* stream,
                              uint8_t* buffer) {
  const int count = static_cast<int>(cameras.size());
  frames_.resize(count);
  films_.resize(count);
  for (int k = 0; k < count; ++k) {
    const BatchCamera& c = cameras[k];
    const World& w = *worlds_[c.world];
    RealtimeFrameView& f = frames_[k];
    f = w.frame;
    f.camera = c.camera;
    f.spread_rad = c.spread_rad;
    f.frame_key = w.realtime->FrameKey(c.camera_index, c.frame_index);
    RealtimeBatchFilm& film = films_[k];
    film.exposure = w.realtime->film().exposure_pod();
    for (int ch = 0; ch < 3; ++ch) film.white_balance_gains[ch] = c.white_balance[ch];
    film.filmic = w.realtime->film().filmic() ? 1 : 0;
    film.lut = w.device_realtime->device_lut();
  }
  float* depth =
      layout_.has(BatchPlane::kDepth)
          ? reinterpret_cast<float*>(buffer + layout_.plane_offset(BatchPlane::kDepth, count))
          : nullptr;
  uint8_t* rgb = buffer + layout_.plane_offset(BatchPlane::kRgb, count);
  realtime_->Launch(frames_.data(), films_.data(), count, depth, rgb, slot, stream);
}

void BatchRenderer::CheckAloneViews(std::span<const BatchCamera> cameras) const {
  for (size_t k = 0; k < cameras.size(); ++k) {
    const BatchCamera& c = cameras[k];
    if (!worlds_[c.world]->alone) continue;
    if (c.view_table < 0 || c.tables_owner != id_ ||
        c.view_table >= static_cast<int>(camera_views_.size()) ||
        c.rows_generation != rows_generation_)
      throw Error(fmt::format(
          "batch rendering: camera {}: world {} has particles or media (rendered camera by "
          "camera) and the camera no view of this renderer's; expected a BatchCamera of this "
          "renderer's CameraOf, made again after the CameraOf calls that followed a Submit",
          k, c.world));
  }
}

void BatchRenderer::RenderAlone(std::span<const BatchCamera> cameras, int slot, void* stream,
                                uint8_t* buffer) {
  const auto t0 = std::chrono::steady_clock::now();
  const int count = static_cast<int>(cameras.size());
  const bool depth = layout_.has(BatchPlane::kDepth);
  const int64_t pixels = layout_.pixels();
  // every such camera rendered first, then their copies queued: a copy from pageable memory
  // may wait for the batch's kernels before it, the renders need not
  std::vector<int> alone;
  for (int k = 0; k < count; ++k) {
    World& w = *worlds_[cameras[k].world];
    if (!w.alone) continue;
    if (alone_frames_.size() <= alone.size()) alone_frames_.emplace_back();
    // the camera's view, asking for what the batch keeps of the realtime path (rgb, its depth)
    CameraView view = camera_views_[cameras[k].view_table];
    view.outputs = CameraOutputs::None();
    view.outputs[ImageKind::kRgb] = true;
    view.outputs[ImageKind::kDepth] = depth;
    w.single->Render(w.snapshot, &w.effects, view, &alone_frames_[alone.size()]);
    alone.push_back(k);
  }
  for (size_t i = 0; i < alone.size(); ++i) {
    const RenderedFrame& f = alone_frames_[i];
    device_->CopyToDevice(stream, buffer + layout_.image_offset(BatchPlane::kRgb, count, alone[i]),
                          f.rgb.data.data(), 3 * pixels);
    if (depth)
      device_->CopyToDevice(stream,
                            buffer + layout_.image_offset(BatchPlane::kDepth, count, alone[i]),
                            f.depth_m.data.data(), 4 * pixels);
  }
  alone_count_[slot] = static_cast<int>(alone.size());
  alone_ms_[slot] =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
}

int64_t BatchRenderer::Submit(std::span<const BatchCamera> cameras) {
  const int count = static_cast<int>(std::min<size_t>(cameras.size(), 1 << 30));
  layout_.Check(cameras.data(), count, num_worlds());
  const std::span<const BatchCamera> batch = cameras.first(count);
  BatchDevice::MoreWork rgb;
  if (layout_.outputs().rgb) {
    for (int k = 0; k < count; ++k)
      if (!worlds_[batch[k].world]->posed)
        throw Error(fmt::format(
            "batch rendering: camera {}: world {} has no pose yet; expected UpdateWorld before "
            "its first rgb batch",
            k, batch[k].world));
    // the stages' buffers fit the most lights and the mirror layer of the worlds
    int lights = 0;
    bool mirror = false;
    for (const auto& w : worlds_) {
      lights = std::max(lights, static_cast<int>(w->realtime->lights().size()));
      mirror = mirror || w->realtime->any_mirror();
    }
    if (!realtime_ || lights > realtime_lights_ || (mirror && !realtime_mirror_)) {
      device_->WaitForKernels();
      realtime_.reset();
      realtime_ =
          std::make_unique<RealtimeBatch>(layout_.width(), layout_.height(), layout_.max_cameras(),
                                          lights, mirror, BatchTickets::kSlots);
      realtime_lights_ = lights;
      realtime_mirror_ = mirror;
    }
    CheckAloneViews(batch);
  }
  for (int k = 0; k < count; ++k) {
    const BatchCamera& c = batch[k];
    if (c.xy_table < 0 && c.rows_table < 0) continue;
    if (c.tables_owner != id_)
      throw Error(fmt::format(
          "batch rendering: camera {}: ray tables of another BatchRenderer; expected the "
          "CameraOf of the renderer that renders it (cameras with lens distortion or motion)",
          k));
    if (c.xy_table >= static_cast<int>(xy_tables_.size()) ||
        c.rows_table >= static_cast<int>(rows_tables_.size()) ||
        (c.rows_table >= 0 && c.rows_generation != rows_generation_))
      throw Error(fmt::format(
          "batch rendering: camera {}: row tables of an earlier frame; expected a moving "
          "camera's CameraOf again after the CameraOf calls that followed a Submit",
          k));
  }
  const int64_t t = tickets_.Take();
  const int slot = BatchTickets::SlotOf(t);
  counts_[slot] = count;
  alone_count_[slot] = 0;
  alone_ms_[slot] = 0;
  const std::span<const BatchCamera> submitted = WithRayTables(batch, slot);
  // the cameras rendered alone while the batch's kernels run, then put over their places
  if (layout_.outputs().rgb)
    rgb = [this, submitted, slot](void* stream, uint8_t* buffer) {
      LaunchRgb(submitted, slot, stream, buffer);
      RenderAlone(submitted, slot, stream, buffer);
    };
  device_->Submit(slot, views_.data(), num_worlds(), submitted.data(), count, rgb);
  submitted_since_rows_ = true;
  return t;
}

std::span<const BatchCamera> BatchRenderer::WithRayTables(std::span<const BatchCamera> batch,
                                                          int slot) {
  bool any = false;
  for (const BatchCamera& c : batch) any = any || c.xy_table >= 0 || c.rows_table >= 0;
  if (!any) return batch;
  // each xy table used once, then each camera's rows, end to end
  table_floats_.clear();
  std::vector<int64_t> xy_at(xy_tables_.size(), -1);
  std::vector<int64_t> rows_at(batch.size(), -1);
  for (size_t k = 0; k < batch.size(); ++k) {
    const BatchCamera& c = batch[k];
    if (c.xy_table >= 0 && xy_at[c.xy_table] < 0) {
      xy_at[c.xy_table] = static_cast<int64_t>(table_floats_.size());
      const std::vector<float>& xy = xy_tables_[c.xy_table].xy;
      table_floats_.insert(table_floats_.end(), xy.begin(), xy.end());
    }
    if (c.rows_table >= 0) {
      rows_at[k] = static_cast<int64_t>(table_floats_.size());
      const std::vector<float>& rows = rows_tables_[c.rows_table];
      table_floats_.insert(table_floats_.end(), rows.begin(), rows.end());
    }
  }
  const float* d = device_->UploadCameraTables(slot, table_floats_.data(),
                                               static_cast<int64_t>(table_floats_.size()));
  patched_.assign(batch.begin(), batch.end());
  for (size_t k = 0; k < batch.size(); ++k) {
    BatchCamera& c = patched_[k];
    if (c.xy_table >= 0) c.camera.xy = d + xy_at[c.xy_table];
    if (rows_at[k] >= 0) c.camera.rows = d + rows_at[k];
  }
  return patched_;
}

int BatchRenderer::CheckedSlot(int64_t ticket) const {
  if (!tickets_.Readable(ticket))
    throw Error(fmt::format(
        "batch rendering: ticket {}; expected one of the last {} submitted (of {}): a batch's "
        "images are overwritten when the batch {} later is submitted",
        ticket, BatchTickets::kSlots, tickets_.taken(), BatchTickets::kSlots));
  return BatchTickets::SlotOf(ticket);
}

BatchImages BatchRenderer::Wait(int64_t ticket) {
  const int slot = CheckedSlot(ticket);
  return BatchImages{device_->Wait(slot), &layout_, counts_[slot]};
}

BatchImages BatchRenderer::DeviceImages(int64_t ticket) const {
  const int slot = CheckedSlot(ticket);
  return BatchImages{device_->device_buffer(slot), &layout_, counts_[slot], true};
}

void* BatchRenderer::ready_event(int64_t ticket) const {
  return device_->kernel_event(CheckedSlot(ticket));
}

double BatchRenderer::kernel_ms(int64_t ticket) const {
  return device_->kernel_ms(CheckedSlot(ticket));
}

double BatchRenderer::alone_ms(int64_t ticket) const { return alone_ms_[CheckedSlot(ticket)]; }

int BatchRenderer::alone_cameras(int64_t ticket) const { return alone_count_[CheckedSlot(ticket)]; }

RealtimeBatchTimes BatchRenderer::stage_ms(int64_t ticket) const {
  const int slot = CheckedSlot(ticket);
  if (!realtime_) throw Error("batch rendering: stage times of a batch without rgb");
  return realtime_->times(slot);
}

BatchCamera BatchRenderer::CameraOf(int world, const CameraView& view) {
  BatchCamera b;
  b.world = world;
  b.camera_index = view.camera_index;
  b.frame_index = view.frame_index;
  b.spread_rad = Camera(view.X_WO, view.intrinsics, view.motion).pixel_spread_rad();
  for (int c = 0; c < 3; ++c) b.white_balance[c] = view.white_balance_gains[c];
  b.camera = CudaRenderer::PinholeOf(view);
  // the first camera after a Submit starts a new frame's row tables and views
  if (submitted_since_rows_) {
    rows_tables_.clear();
    camera_views_.clear();
    ++rows_generation_;
    submitted_since_rows_ = false;
  }
  b.tables_owner = id_;
  b.rows_generation = rows_generation_;
  b.view_table = static_cast<int32_t>(camera_views_.size());
  camera_views_.push_back(view);
  if (!view.intrinsics.has_distortion() && !view.motion.moving()) return b;
  ray_tables_.Prepare(view, pool_.get());
  if (view.intrinsics.has_distortion()) {
    const auto same = [&](const XyTable& t) {
      return SameIntrinsics(t.intrinsics, view.intrinsics);
    };
    auto it = std::find_if(xy_tables_.begin(), xy_tables_.end(), same);
    if (it == xy_tables_.end()) {
      xy_tables_.push_back({view.intrinsics, ray_tables_.xy()});
      it = xy_tables_.end() - 1;
    }
    b.xy_table = static_cast<int32_t>(it - xy_tables_.begin());
  }
  if (view.motion.moving()) {
    rows_tables_.push_back(ray_tables_.rows());
    b.rows_table = static_cast<int32_t>(rows_tables_.size() - 1);
  }
  return b;
}

}  // namespace penumbra::cuda

#include "penumbra/render/cuda/cuda_batch_renderer.h"

#include <fmt/format.h>

#include <algorithm>

#include "penumbra/core/error.h"
#include "penumbra/render/cuda/cuda_ray_query.h"
#include "penumbra/render/cuda/cuda_renderer.h"

namespace penumbra::cuda {

BatchRenderer::BatchRenderer(const BatchConfig& config)
    : layout_(config.width, config.height, config.max_cameras, config.outputs),
      device_(std::make_unique<BatchDevice>(layout_, config.copy)),
      counts_(BatchTickets::kSlots, 0) {}

BatchRenderer::~BatchRenderer() = default;

int BatchRenderer::AddWorld(const SceneDescription& scene) {
  auto w = std::make_unique<World>();
  w->scene = scene;
  w->bvh = std::make_unique<BvhScene>(w->scene);
  w->device = std::make_unique<DeviceScene>();
  SyncDevice(*w->bvh, w->device.get());
  views_.push_back(w->device->device_view());
  worlds_.push_back(std::move(w));
  return static_cast<int>(worlds_.size()) - 1;
}

void BatchRenderer::UpdateWorld(int world, const WorldSnapshot& snapshot) {
  if (world < 0 || world >= num_worlds())
    throw Error(
        fmt::format("batch rendering: world {}; expected a world in [0, {})", world, num_worlds()));
  World& w = *worlds_[world];
  w.bvh->Update(snapshot);
  // the submitted kernels read this world's transforms (and, after a rebuild, its arrays)
  device_->WaitForKernels();
  SyncDevice(*w.bvh, w.device.get());
  views_[world] = w.device->device_view();
}

int64_t BatchRenderer::Submit(std::span<const BatchCamera> cameras) {
  const int count = static_cast<int>(std::min<size_t>(cameras.size(), 1 << 30));
  layout_.Check(cameras.data(), count, num_worlds());
  const int64_t t = tickets_.Take();
  const int slot = BatchTickets::SlotOf(t);
  counts_[slot] = count;
  device_->Submit(slot, views_.data(), num_worlds(), cameras.data(), count);
  return t;
}

void BatchRenderer::CheckTicket(int64_t ticket) const {
  if (!tickets_.Readable(ticket))
    throw Error(fmt::format(
        "batch rendering: ticket {}; expected one of the last {} submitted (of {}): a batch's "
        "images are overwritten when the batch {} later is submitted",
        ticket, BatchTickets::kSlots, tickets_.taken(), BatchTickets::kSlots));
}

BatchImages BatchRenderer::Wait(int64_t ticket) {
  CheckTicket(ticket);
  const int slot = BatchTickets::SlotOf(ticket);
  BatchImages img;
  img.base = device_->Wait(slot);
  img.layout = &layout_;
  img.cameras = counts_[slot];
  return img;
}

BatchImages BatchRenderer::DeviceImages(int64_t ticket) const {
  CheckTicket(ticket);
  const int slot = BatchTickets::SlotOf(ticket);
  BatchImages img;
  img.base = device_->device_buffer(slot);
  img.layout = &layout_;
  img.cameras = counts_[slot];
  img.on_device = true;
  return img;
}

void* BatchRenderer::ready_event(int64_t ticket) const {
  CheckTicket(ticket);
  return device_->kernel_event(BatchTickets::SlotOf(ticket));
}

double BatchRenderer::kernel_ms(int64_t ticket) const {
  CheckTicket(ticket);
  return device_->kernel_ms(BatchTickets::SlotOf(ticket));
}

BatchCamera BatchRenderer::CameraOf(int world, const CameraView& view) {
  if (view.intrinsics.has_distortion() || view.motion.moving())
    throw Error(
        "batch rendering: a camera with lens distortion or motion; expected a pinhole camera "
        "(distortion and motion are not on the GPU yet, docs/gpu.md)");
  BatchCamera b;
  b.world = world;
  b.camera = CudaRenderer::PinholeOf(view);
  return b;
}

}  // namespace penumbra::cuda

#include "penumbra/sinks/frame_buffer_pool.h"

#include <utility>

namespace penumbra {

void FrameBufferPool::Return(CameraFrame&& frame) noexcept {
  try {
    // images only: the pose and times are the next frame's to set
    CameraFrame images = TakeImages(&frame);
    std::lock_guard<std::mutex> lock(mu_);
    std::vector<CameraFrame>& list = kept_[frame.camera];
    if (static_cast<int>(list.size()) < max_per_camera_) list.push_back(std::move(images));
  } catch (...) {
    // out of memory for the name or the list: the images are freed
  }
}

void FrameBufferPool::Take(const std::string& camera, CameraImages* out) {
  CameraFrame images;
  {
    std::lock_guard<std::mutex> lock(mu_);
    auto it = kept_.find(camera);
    if (it == kept_.end() || it->second.empty()) return;
    images = std::move(it->second.back());
    it->second.pop_back();
  }
  out->rgb = std::move(images.rgb);
  out->depth_m = std::move(images.depth_m);
  out->truth.geom_id = std::move(images.geom_id);
  out->truth.range_m = std::move(images.range_m);
  out->truth.normal_O = std::move(images.normal_O);
  out->truth.body_id = std::move(images.body_id);
  out->truth.semantic_class = std::move(images.semantic_class);
}

int FrameBufferPool::kept(const std::string& camera) const {
  std::lock_guard<std::mutex> lock(mu_);
  auto it = kept_.find(camera);
  return it == kept_.end() ? 0 : static_cast<int>(it->second.size());
}

}  // namespace penumbra

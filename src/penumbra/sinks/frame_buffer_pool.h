#pragma once
// image buffers of written camera frames, handed back by the frame writer and reused by the next
// frame of the same camera. a fresh 640x480 frame's images cost 0.5-0.6 ms of allocation,
// zero-fill and page faults (measured beside the CUDA backend on an H100, where a frame renders
// in about 1 ms); a reused buffer of the right shape is overwritten in place by the renderer and
// the camera model, which write every pixel of every image they produce.
#include <map>
#include <mutex>
#include <string>
#include <vector>

#include "penumbra/output/camera_frame.h"
#include "penumbra/sensors/camera_imager.h"

namespace penumbra {

/// a per-camera store of the output images of frames that were written (CameraFrame's rgb,
/// depth_m and ground-truth images), bounded per camera. thread-safe: the frame writer's threads
/// return frames while the render thread takes them.
class FrameBufferPool {
 public:
  /// @param max_per_camera  frames kept per camera (>= 0); more returned frames are freed.
  explicit FrameBufferPool(int max_per_camera = 2) : max_per_camera_(max_per_camera) {}

  /// keeps `frame`'s images for its camera (`frame.camera`) while fewer than max_per_camera are
  /// kept, else frees them. never throws (a failed allocation of the list frees the frame).
  void Return(CameraFrame&& frame) noexcept;

  /// moves the images of one kept frame of `camera` into `out`: rgb and depth_m into out's,
  /// geom_id, range_m, normal_O, body_id and semantic_class into out->truth's (whatever they
  /// held is replaced). `out` is unchanged when none is kept. the moved images keep their last
  /// frame's pixels: the caller must overwrite every pixel it keeps (Renderer::Render and
  /// CameraImager::Capture do).
  void Take(const std::string& camera, CameraImages* out);

  /// frames kept for `camera` now.
  int kept(const std::string& camera) const;

 private:
  int max_per_camera_;
  mutable std::mutex mu_;
  std::map<std::string, std::vector<CameraFrame>> kept_;
};

}  // namespace penumbra

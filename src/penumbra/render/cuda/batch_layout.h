#pragma once
// the host-side bookkeeping of batch rendering (cuda_batch_renderer.h): which images a batch
// renders, where each camera's image of each output lies in the batch's one buffer, the checks
// of a batch's cameras, and the ring of buffer slots that lets a batch's copy back overlap the
// next batch's kernel. plain C++ (no CUDA): built and tested on every machine; C++17, as
// cuda_batch_kernels.cu includes it.

#include <array>
#include <cstdint>

#include "penumbra/render/cuda/cuda_kernels.h"

namespace penumbra {
struct EffectsFrame;
}  // namespace penumbra

namespace penumbra::cuda {

/// whether `effects` (null: none) hold what a batch's rgb kernels do not draw: particles (rain,
/// snow, sparks), homogeneous media (fog, haze, dust) or grid media (smoke, fire, VDB), whose
/// streaks and froxels each camera needs of its own. a batch with rgb renders the rgb and depth
/// of such a world's cameras through the single-frame pipeline (BatchRenderer: the world's
/// CudaRenderer), camera by camera; lighting-only effects stay in the batch's kernels.
bool PerCameraEffects(const EffectsFrame* effects);

/// the images a batch renders: the ground truth of the pixel-centre ray, each one 4-byte value
/// per pixel: depth and range float metres, segmentation (MuJoCo geom id), instance (body id)
/// and semantic class int32, as RenderedFrame's depth_m, geom_id, body_id, semantic_class and
/// range_m; normals, 3 floats a pixel (the unit geometric normal facing the camera in the
/// camera's optical frame, 0 0 0 = miss, as RenderedFrame::normal_O); and the realtime tier's
/// rgb, 3 bytes a pixel (sRGB, as RenderedFrame::rgb), whose depth is then the realtime path's
/// (the same as CudaRenderer's with rgb on).
struct BatchOutputs {
  bool depth = true;
  bool segmentation = true;
  bool instance_segmentation = false;
  bool semantic_segmentation = false;
  bool range = false;
  bool normals = false;
  bool rgb = false;
};

/// one camera of a batch: the world it looks at (the index BatchRenderer::AddWorld returned)
/// and its pinhole camera (CudaRenderer::PinholeOf); its width and height must be the batch's.
/// the rgb's per-pixel random numbers are keyed by camera_index and frame_index (as
/// CameraView's), its texture filtering's ray cones start at spread_rad
/// (Camera::pixel_spread_rad) and its exposure is multiplied by white_balance (linear rgb
/// gains, CameraView::white_balance_gains); BatchRenderer::CameraOf fills all of them. a camera
/// with lens distortion or motion (rolling shutter) also names the ray tables
/// (render/cuda/camera_rays.h) its renderer keeps for it: camera.xy and camera.rows stay null
/// here and Submit points them to the tables' device copies.
struct BatchCamera {
  int32_t world = 0;
  int32_t camera_index = 0;            ///< CameraView::camera_index
  int64_t frame_index = 0;             ///< CameraView::frame_index
  float spread_rad = 0;                ///< Camera::pixel_spread_rad, radians
  float white_balance[3] = {1, 1, 1};  ///< CameraView::white_balance_gains
  PinholeCamera camera;
  /// the renderer's undistortion table of this camera's intrinsics (-1: no lens distortion).
  int32_t xy_table = -1;
  /// the renderer's per-row poses of this moving camera (-1: the camera does not move).
  int32_t rows_table = -1;
  /// the renderer whose tables xy_table, rows_table and view_table index (0: none).
  uint64_t tables_owner = 0;
  /// the generation of the renderer's row tables that rows_table indexes (and view_table).
  int64_t rows_generation = 0;
  /// the renderer's copy of this camera's CameraView (BatchRenderer::CameraOf; -1: none): the
  /// rgb of a camera whose world has particles or media is rendered from it alone.
  int32_t view_table = -1;
};

/// the planes of a batch's buffer, in buffer order.
enum class BatchPlane { kDepth = 0, kSegmentation, kInstance, kSemantic, kRange, kNormal, kRgb };
inline constexpr int kBatchPlaneCount = 7;

/// bytes per pixel of plane p: 3 for rgb, 12 for normals (3 floats), else 4.
inline constexpr int BatchPlaneBytes(BatchPlane p) {
  return p == BatchPlane::kRgb ? 3 : p == BatchPlane::kNormal ? 12 : 4;
}

/// where a batch's images lie in its one buffer: the planes that are on (BatchOutputs), in
/// BatchPlane order, each `cameras` x height x width values of BatchPlaneBytes bytes,
/// camera-major then row-major (camera k's pixel (u, v) at k * width * height + v * width + u;
/// rgb last, so every 4-byte plane stays 4-byte aligned). a batch of k cameras uses the first
/// bytes(k) bytes, so it is copied back in one transfer.
class BatchLayout {
 public:
  /// @throws Error if width or height is not in [1, 16384], max_cameras not in [1, 65535] (the
  ///         kernel's grid z), or no output is on.
  BatchLayout(int width, int height, int max_cameras, const BatchOutputs& outputs);

  int width() const { return width_; }
  int height() const { return height_; }
  int max_cameras() const { return max_cameras_; }
  const BatchOutputs& outputs() const { return outputs_; }
  /// pixels of one camera's image.
  int64_t pixels() const { return static_cast<int64_t>(width_) * height_; }
  /// true if plane p is on.
  bool has(BatchPlane p) const { return index_[static_cast<int>(p)] >= 0; }
  /// the planes that are on.
  int planes() const { return planes_; }
  /// byte offset of plane p (on) in the buffer of a batch of `cameras` cameras.
  int64_t plane_offset(BatchPlane p, int cameras) const;
  /// byte offset of camera k's image of plane p in the buffer of a batch of `cameras`.
  int64_t image_offset(BatchPlane p, int cameras, int k) const {
    return plane_offset(p, cameras) + BatchPlaneBytes(p) * pixels() * k;
  }
  /// bytes of the images of a batch of `cameras` cameras.
  int64_t bytes(int cameras) const { return pixel_bytes_ * pixels() * cameras; }
  /// bytes of the largest batch (each slot's buffer).
  int64_t capacity_bytes() const { return bytes(max_cameras_); }

  /// checks a batch cameras[0 .. count): 1 to max_cameras cameras, each of a world in [0,
  /// num_worlds), the batch's width and height, finite pose and intrinsics, inv_fx and inv_fy > 0,
  /// camera.xy and camera.rows null.
  /// @throws Error naming the camera's index and the field.
  void Check(const BatchCamera* cameras, int count, int num_worlds) const;

 private:
  int width_, height_, max_cameras_;
  BatchOutputs outputs_;
  std::array<int, kBatchPlaneCount> index_{};   // position among the planes that are on, -1 off
  std::array<int, kBatchPlaneCount> before_{};  // bytes per pixel of the planes before p
  int planes_ = 0;
  int pixel_bytes_ = 0;  // bytes per pixel of all planes
};

/// the ring of kSlots buffer slots batches rotate through: ticket t (the t-th batch
/// submitted, from 0) renders into slot t % kSlots, so batch t + 1's kernel runs while batch t
/// is copied back; batch t's images stay readable until batch t + kSlots is submitted.
class BatchTickets {
 public:
  static constexpr int kSlots = 2;
  /// takes the next ticket.
  int64_t Take() { return next_++; }
  /// the slot of ticket t.
  static int SlotOf(int64_t t) { return static_cast<int>(t % kSlots); }
  /// tickets taken so far.
  int64_t taken() const { return next_; }
  /// true if ticket t was taken and its slot not reused since (its images are readable).
  bool Readable(int64_t t) const { return t >= 0 && t < next_ && t >= next_ - kSlots; }

 private:
  int64_t next_ = 0;
};

}  // namespace penumbra::cuda

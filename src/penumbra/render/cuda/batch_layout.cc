#include "penumbra/render/cuda/batch_layout.h"

#include <fmt/format.h>

#include <cmath>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/scene/effects_frame.h"

namespace penumbra::cuda {
namespace {

bool Finite3(const F3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

bool PerCameraEffects(const EffectsFrame* effects) {
  return effects != nullptr &&
         (!effects->particles.empty() || !effects->homogeneous_media.empty() ||
          !effects->grid_media.empty());
}

BatchLayout::BatchLayout(int width, int height, int max_cameras, const BatchOutputs& outputs)
    : width_(width), height_(height), max_cameras_(max_cameras), outputs_(outputs) {
  if (width < 1 || width > 16384 || height < 1 || height > 16384)
    throw Error(
        fmt::format("batch rendering: image size {}x{}; expected width and height in "
                    "[1, 16384]",
                    width, height));
  if (max_cameras < 1 || max_cameras > 65535)
    throw Error(
        fmt::format("batch rendering: {} cameras per batch; expected 1 to 65535", max_cameras));
  const bool on[kBatchPlaneCount] = {outputs.depth,
                                     outputs.segmentation,
                                     outputs.instance_segmentation,
                                     outputs.semantic_segmentation,
                                     outputs.range,
                                     outputs.normals,
                                     outputs.rgb};
  for (int p = 0; p < kBatchPlaneCount; ++p) {
    before_[p] = pixel_bytes_;
    index_[p] = on[p] ? planes_++ : -1;
    if (on[p]) pixel_bytes_ += BatchPlaneBytes(static_cast<BatchPlane>(p));
  }
  if (planes_ == 0)
    throw Error(
        "batch rendering: no output; expected at least one of depth, segmentation, "
        "instance_segmentation, semantic_segmentation, range, normals, rgb");
}

int64_t BatchLayout::plane_offset(BatchPlane p, int cameras) const {
  if (index_[static_cast<int>(p)] < 0)
    throw Error("batch rendering: plane not rendered by this batch");
  return static_cast<int64_t>(before_[static_cast<int>(p)]) * pixels() * cameras;
}

void BatchLayout::Check(const BatchCamera* cameras, int count, int num_worlds) const {
  if (count < 1 || count > max_cameras_)
    throw Error(fmt::format("batch rendering: {} cameras; expected 1 to {} (max_cameras)", count,
                            max_cameras_));
  for (int k = 0; k < count; ++k) {
    const BatchCamera& b = cameras[k];
    const PinholeCamera& c = b.camera;
    const auto bad = [&](const std::string& what) {
      return Error(fmt::format("batch rendering: camera {}: {}", k, what));
    };
    if (b.world < 0 || b.world >= num_worlds)
      throw bad(fmt::format("world {}; expected a world in [0, {})", b.world, num_worlds));
    if (c.width != width_ || c.height != height_)
      throw bad(fmt::format("size {}x{}; expected the batch's {}x{}", c.width, c.height, width_,
                            height_));
    if (!Finite3(c.o) || !Finite3(c.ex) || !Finite3(c.ey) || !Finite3(c.ez))
      throw bad("a pose that is not finite; expected finite o, ex, ey, ez");
    if (!std::isfinite(c.cx) || !std::isfinite(c.cy) || !std::isfinite(c.near) || c.near < 0 ||
        !(c.inv_fx > 0) || !(c.inv_fy > 0) || !std::isfinite(c.inv_fx) || !std::isfinite(c.inv_fy))
      throw bad("intrinsics; expected finite cx, cy, near >= 0 and finite inv_fx, inv_fy > 0");
    if (c.xy || c.rows)
      throw bad(
          "ray table pointers set; expected null (BatchRenderer::CameraOf names the tables of a "
          "camera with lens distortion or motion, and Submit points to them)");
  }
}

}  // namespace penumbra::cuda

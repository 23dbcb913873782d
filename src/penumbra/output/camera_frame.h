#pragma once
// one rendered frame of one camera, as handed to the output writers.

#include <cstdint>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/core/image.h"
#include "penumbra/core/pose.h"
#include "penumbra/scene/image_kind.h"

namespace penumbra {

/// images and pose of one camera at one instant. images that the camera does not
/// output are left empty.
struct CameraFrame {
  std::string camera;   ///< camera name, may contain '/' (e.g. "rover/head")
  int64_t index = 0;    ///< per-camera frame counter, 0-based; names the files (NNNNNN.png)
  int64_t step = -1;    ///< physics step of the capture (start of the exposure); -1 = unknown
  double time_sec = 0;  ///< simulation time of the frame
  Pose X_WO = Pose::Identity();  ///< optical frame (OpenCV: x right, y down, z forward) in world
  ImageU8 rgb;                   ///< (H x W x 3) uint8 sRGB
  ImageF depth_m;    ///< (H x W x 1) float z-depth along the optical axis in m, 0 = no hit
  ImageI32 geom_id;  ///< (H x W x 1) MuJoCo geom id of the first hit, -1 = background
  /// ground truth from the pixel-centre rays (render/renderer.h RenderedFrame):
  ImageF range_m;    ///< (H x W x 1) distance optical centre -> hit along the ray, m; 0 = no hit
  ImageF normal_O;   ///< (H x W x 3) unit normal facing the camera, optical frame; 0 = no hit
  ImageI32 body_id;  ///< (H x W x 1) body index of the hit, -1 = background
  ImageI32 semantic_class;  ///< (H x W x 1) semantic class id of the hit, 0 = none
};

/// moves `frame`'s images (rgb, depth_m and the ground-truth images) into a new frame of the same
/// camera, leaving `frame` with empty images (width and height 0) and its name, index, step,
/// time and pose.
inline CameraFrame TakeImages(CameraFrame* frame) {
  CameraFrame images;
  images.camera = frame->camera;
  images.rgb = std::exchange(frame->rgb, {});
  images.depth_m = std::exchange(frame->depth_m, {});
  images.geom_id = std::exchange(frame->geom_id, {});
  images.range_m = std::exchange(frame->range_m, {});
  images.normal_O = std::exchange(frame->normal_O, {});
  images.body_id = std::exchange(frame->body_id, {});
  images.semantic_class = std::exchange(frame->semantic_class, {});
  return images;
}

/// calls `fn(image)` with the frame's image of `kind` (scene/image_kind.h): an ImageU8 (rgb), an
/// ImageF (depth_m, range_m, normal_O) or an ImageI32 (geom_id, body_id, semantic_class); returns
/// what fn returns (the same type for every image type).
template <typename F>
decltype(auto) WithImage(const CameraFrame& f, ImageKind kind, F&& fn) {
  switch (kind) {
    case ImageKind::kRgb:
      return fn(f.rgb);
    case ImageKind::kDepth:
      return fn(f.depth_m);
    case ImageKind::kSegmentation:
      return fn(f.geom_id);
    case ImageKind::kRange:
      return fn(f.range_m);
    case ImageKind::kNormals:
      return fn(f.normal_O);
    case ImageKind::kInstanceSegmentation:
      return fn(f.body_id);
    case ImageKind::kSemanticSegmentation:
      break;
  }
  return fn(f.semantic_class);
}

/// receives each image file a camera writer wrote: the frame (camera, index, step, time), the
/// output kind ("rgb", "depth", "segmentation", ...) and the PNG bytes (the file's content).
/// called on the frame writer's threads, possibly several at once.
using CameraImageCallback = std::function<void(const CameraFrame& frame, const std::string& kind,
                                               const std::vector<uint8_t>& png)>;

}  // namespace penumbra

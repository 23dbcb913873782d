#pragma once
// per-pixel ground-truth images of a camera (range, normals, instance and semantic ids), written
// from the pixel-centre camera ray and its first hit, like depth and geom-id segmentation: exact,
// never blended. used by the Embree renderer's primary-ray pass.

#include "penumbra/core/image.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/ray.h"
#include "penumbra/scene/scene_description.h"

namespace penumbra {

struct RenderedFrame;

/// the requested ground-truth images of one frame (null = not requested).
struct GroundTruthImages {
  ImageF* range_m = nullptr;           ///< (H x W x 1) |hit - origin| in m, 0 = no hit
  ImageF* normal_O = nullptr;          ///< (H x W x 3) unit normal facing the camera, optical frame
  ImageI32* body_id = nullptr;         ///< (H x W x 1) body index, -1 = background
  ImageI32* semantic_class = nullptr;  ///< (H x W x 1) Geom::semantic_class, 0 = background
  bool any = false;
};

/// sizes (W x H) the images of `out` that `want` requests and clears the others.
GroundTruthImages PrepareGroundTruth(const CameraOutputs& want, int W, int H, RenderedFrame* out);

/// writes pixel (u, v) of every requested image from the pixel-centre `ray` and its `hit`.
/// normals are rotated into the optical frame of the camera at row v (rolling shutter aware).
void WriteGroundTruth(const GroundTruthImages& img, const Camera& camera,
                      const SceneDescription& scene, const Ray& ray, bool did_hit,
                      const SurfaceHit& hit, int u, int v);

}  // namespace penumbra

#include "penumbra/render/camera/camera_ground_truth.h"

#include "penumbra/render/renderer.h"

namespace penumbra {
namespace {

template <typename T>
Image<T>* Prepare(bool want, int w, int h, int c, Image<T>* img) {
  if (!want) {
    *img = Image<T>();
    return nullptr;
  }
  if (img->width != w || img->height != h || img->channels != c) *img = Image<T>(w, h, c);
  return img;
}

}  // namespace

GroundTruthImages PrepareGroundTruth(const CameraOutputs& want, int W, int H, RenderedFrame* out) {
  GroundTruthImages g;
  g.range_m = Prepare(want[ImageKind::kRange], W, H, 1, &out->range_m);
  g.normal_O = Prepare(want[ImageKind::kNormals], W, H, 3, &out->normal_O);
  g.body_id = Prepare(want[ImageKind::kInstanceSegmentation], W, H, 1, &out->body_id);
  g.semantic_class = Prepare(want[ImageKind::kSemanticSegmentation], W, H, 1, &out->semantic_class);
  g.any = g.range_m || g.normal_O || g.body_id || g.semantic_class;
  return g;
}

void WriteGroundTruth(const GroundTruthImages& img, const Camera& camera,
                      const SceneDescription& scene, const Ray& ray, bool did_hit,
                      const SurfaceHit& hit, int u, int v) {
  if (img.range_m) *img.range_m->at(u, v) = did_hit ? hit.t * ray.d.norm() : 0.0f;
  if (img.normal_O) {
    float* n = img.normal_O->at(u, v);
    if (did_hit) {
      const Eigen::Matrix3f R_OW = camera.PoseAtRow(v).linear().transpose().cast<float>();
      const Eigen::Vector3f n_O = R_OW * hit.ng_W;
      n[0] = n_O.x();
      n[1] = n_O.y();
      n[2] = n_O.z();
    } else {
      n[0] = n[1] = n[2] = 0.0f;
    }
  }
  const Geom* g = did_hit && hit.geom >= 0 ? &scene.geoms[hit.geom] : nullptr;
  if (img.body_id) *img.body_id->at(u, v) = g ? g->body : -1;
  if (img.semantic_class) *img.semantic_class->at(u, v) = g ? g->semantic_class : 0;
}

}  // namespace penumbra

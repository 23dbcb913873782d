#include "penumbra/render/cuda/cuda_renderer.h"

#include <spdlog/spdlog.h>

#include <cmath>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/camera.h"
#include "penumbra/render/cuda/cuda_ray_query.h"

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

F3 ToF3(const Eigen::Vector3f& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

CudaRenderer::CudaRenderer(const SceneDescription& scene, std::unique_ptr<Renderer> cpu)
    : scene_(scene), cpu_(std::move(cpu)) {
  if (!cpu_) throw Error("CudaRenderer: no CPU renderer for the frames the GPU cannot render");
  bvh_ = std::make_unique<BvhScene>(scene_);
  device_ = std::make_unique<DeviceScene>();
  SyncDevice(*bvh_, device_.get());
}

bool CudaRenderer::OnGpu(const EffectsFrame* effects, const CameraView& view) {
  return !view.outputs.rgb && (effects == nullptr || effects->empty()) &&
         !view.intrinsics.has_distortion() && !view.motion.moving();
}

PinholeCamera CudaRenderer::PinholeOf(const CameraView& view) {
  const Camera camera(view.X_WO, view.intrinsics, view.motion);
  const Camera::PinholeTerms t = camera.pinhole_terms();
  PinholeCamera c;
  c.o = ToF3(t.o_W);
  c.ex = ToF3(t.ex_W);
  c.ey = ToF3(t.ey_W);
  c.ez = ToF3(t.ez_W);
  c.cx = t.cx;
  c.cy = t.cy;
  c.inv_fx = t.inv_fx;
  c.inv_fy = t.inv_fy;
  c.near = static_cast<float>(view.near_m);
  c.width = camera.width();
  c.height = camera.height();
  return c;
}

void CudaRenderer::Render(const WorldSnapshot& snapshot, const EffectsFrame* effects,
                          const CameraView& view, RenderedFrame* out) {
  if (!OnGpu(effects, view)) {
    if (!told_cpu_) {
      spdlog::info(
          "renderer: cuda backend: rgb, effects, lens distortion and camera motion are not on "
          "the GPU yet; such frames are rendered by the CPU renderer (docs/gpu.md)");
      told_cpu_ = true;
    }
    ++cpu_frames_;
    cpu_->Render(snapshot, effects, view, out);
    return;
  }
  CheckRenderInputs(scene_.bodies.size(), snapshot, view);
  bvh_->Update(snapshot);
  SyncDevice(*bvh_, device_.get());
  const PinholeCamera c = PinholeOf(view);
  const CameraOutputs& want = view.outputs;
  const int W = c.width, H = c.height;
  out->radiance = ImageF();
  out->rgb = ImageU8();
  PrimaryOutputs o;
  o.depth = Shape(&out->depth_m, want.depth, W, H, 1);
  o.geom_id = Shape(&out->geom_id, want.segmentation, W, H, 1);
  o.range = Shape(&out->range_m, want.range, W, H, 1);
  o.normal_O = Shape(&out->normal_O, want.normals, W, H, 3);
  o.body_id = Shape(&out->body_id, want.instance_segmentation, W, H, 1);
  o.semantic = Shape(&out->semantic_class, want.semantic_segmentation, W, H, 1);
  device_->RenderPrimary(c, o);
  out->ev100 = 0;
  out->rays = static_cast<int64_t>(W) * H;
  out->stopped = false;
  ++gpu_frames_;
}

}  // namespace penumbra::cuda

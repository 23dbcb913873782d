#include "penumbra/render/frame/path_frame.h"

#include <algorithm>
#include <memory>

namespace penumbra::cuda {

const EffectsFrame* EffectsWithoutMedia(const EffectsFrame* effects, EffectsFrame* storage) {
  if (effects == nullptr || (effects->homogeneous_media.empty() && effects->grid_media.empty()))
    return effects;
  *storage = *effects;
  storage->homogeneous_media.clear();
  storage->grid_media.clear();
  return storage->empty() ? nullptr : storage;
}

PathEmitterHost::PathEmitterHost(const EmitterSampler& sampler) : pick_cdf(&sampler.pick_cdf()) {
  for (int k = 0; k < sampler.size(); ++k) {
    pods.push_back(sampler.pod(k));
    const Eigen::Vector3f& le = sampler.Le(k);
    Le.push_back(Float3{le.x(), le.y(), le.z()});
  }
  emitter_of_geom.assign(sampler.emitter_of_geom().begin(), sampler.emitter_of_geom().end());
}

void PathEmitterHost::SetPoses(const EmitterSampler& sampler, const std::vector<Pose>& X_WB) {
  poses.resize(12 * pods.size());
  for (int k = 0; k < sampler.size(); ++k) {
    const Pose X = sampler.EmitterPose(X_WB, k);
    double* o = poses.data() + 12 * k;
    for (int r = 0; r < 3; ++r) {
      for (int c = 0; c < 3; ++c) o[3 * r + c] = X.linear()(r, c);
      o[9 + r] = X.translation()[r];
    }
  }
}

PathEmitters PathEmitterHost::View() const {
  PathEmitters e;
  e.num = static_cast<int32_t>(pods.size());
  if (e.num == 0) return e;
  e.pods = pods.data();
  e.Le = Le.data();
  e.pick_cdf = pick_cdf->data();
  e.emitter_of_geom = emitter_of_geom.data();
  e.num_geoms = static_cast<int32_t>(emitter_of_geom.size());
  e.poses = poses.empty() ? nullptr : poses.data();
  return e;
}

PathFrameView PathView(const RealtimeFrameData& data, const RealtimeFrameView& frame,
                       const SkySamplingPod& sky_sampling) {
  PathFrameView pf;
  pf.rt = frame;
  pf.sky_sampling = sky_sampling;
  // the sky lights the scene where its irradiance up or down is > 0 (a sky of no light is not
  // sampled)
  const SkyModel& sky = data.frame_sky();
  const Eigen::Vector3f up = sky.Irradiance({0, 0, 1});
  const Eigen::Vector3f down = sky.Irradiance({0, 0, -1});
  pf.sky_active = up.maxCoeff() > 0 || down.maxCoeff() > 0 ? 1 : 0;
  pf.spp = std::max(1, data.settings().samples_per_pixel);
  pf.max_bounces = std::max(1, data.settings().max_bounces);
  return pf;
}

namespace {

// a W x H x c image of the n = W H Float3 values (c = 3) or floats (c = 1).
void ToImage(const std::vector<Float3>& v, int W, int H, ImageF* img) {
  if (img->width != W || img->height != H || img->channels != 3) *img = ImageF(W, H, 3);
  for (size_t i = 0; i < v.size(); ++i) {
    img->data[3 * i] = v[i].x;
    img->data[3 * i + 1] = v[i].y;
    img->data[3 * i + 2] = v[i].z;
  }
}

}  // namespace

void FinishPathFrame(const RealtimeFrameData& data, const PathBuffers& b, const Denoiser* denoiser,
                     const Eigen::Vector3f& white_balance_gains, bool want_depth, ThreadPool* pool,
                     RenderedFrame* out) {
  const PinholeCamera& c = data.camera();
  const int W = c.width, H = c.height;
  ToImage(b.radiance, W, H, &out->radiance);
  ImageF depth(W, H, 1);
  std::copy(b.depth.begin(), b.depth.end(), depth.data.begin());
  if (denoiser != nullptr) {
    ImageF albedo, normal, denoised;
    ToImage(b.albedo, W, H, &albedo);
    ToImage(b.normal, W, H, &normal);
    DenoiserGuides guides;
    guides.albedo = &albedo;
    guides.normal = &normal;
    guides.depth = &depth;
    denoiser->Denoise(out->radiance, guides, pool, &denoised);
    std::swap(out->radiance, denoised);
  }
  out->ev100 = data.film().Ev100(out->radiance, pool);
  data.film().Develop(out->radiance, out->ev100, pool, &out->rgb, white_balance_gains);
  if (want_depth) {
    out->depth_m = std::move(depth);
  } else {
    out->depth_m = ImageF();
  }
}

}  // namespace penumbra::cuda

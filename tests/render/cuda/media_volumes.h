#pragma once
// the realtime media's light volumes (render/media/media_realtime.h) of a bundled effects world at
// 1 s built over another RayQuery than the CPU renderer's Embree RayScene (the CUDA backend's
// BvhRayQuery on the host, CudaRayQuery on the GPU), compared with Embree's: the world light
// volume's visibility entries and the camera rays' media terms (media_volumes_test.cc,
// media_volumes_gpu_test.cc).

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include "penumbra/core/thread_pool.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/media/media_realtime.h"
#include "penumbra/render/media/media_scene.h"
#include "realtime_parity.h"

namespace penumbra::media_volumes {

struct Compared {
  size_t entries = 0;  ///< visibility entries of the world light volume (cells x lights)
  int lit = 0;         ///< of them > 0 over Embree
  int differ = 0;      ///< of them that differ between the two queries
  double max_dT = 0, max_dL = 0, max_L = 0;  ///< view rays to 20 m (every 3rd pixel)
};

/// builds world `file`'s (under worlds/) media volumes at 1 s for its first camera at 96x72
/// over Embree and over the query `make` builds, and compares them. `ok` is false (and the
/// result empty) if the world's effects frame has no homogeneous medium.
template <typename MakeQuery>
Compared CompareWithEmbree(const std::string& file, const MakeQuery& make, bool* ok) {
  const std::unique_ptr<Session> session = realtime_parity::LoadSimulatedAt(file, 1.0);
  const SceneDescription& scene = session->scene();
  const WorldSnapshot snap = session->sim().Snapshot();
  constexpr int W = 96, H = 72;
  const CameraView view = realtime_parity::RgbDepthView(scene, snap, W, H);
  const std::shared_ptr<const EffectsFrame> fx =
      session->effects().Evaluate(snap, view.X_WO.translation());
  Compared c;
  *ok = fx && !fx->homogeneous_media.empty();
  if (!*ok) return c;
  MediaScene media;
  media.Build(fx.get());
  LightSampler lights(scene);
  lights.Update(snap, fx.get());
  RayScene embree(scene);
  embree.Update(snap);
  const std::unique_ptr<RayQuery> other = make(scene);
  other->Update(snap);
  const Camera camera(view.X_WO, view.intrinsics);
  const Eigen::Vector3f centre = scene.center_W.cast<float>();
  const Eigen::Vector3f sky = Eigen::Vector3f::Constant(0.5f);
  ThreadPool pool(2);
  RealtimeMedia a, b;
  a.Build(media, lights, embree, camera, 77, centre, scene.extent_m, sky, nullptr, &pool);
  b.Build(media, lights, *other, camera, 77, centre, scene.extent_m, sky, nullptr, &pool);
  const std::vector<float>& va = a.light_volume_visibility();
  const std::vector<float>& vb = b.light_volume_visibility();
  c.entries = va.size();
  if (vb.size() != va.size()) {
    c.differ = static_cast<int>(va.size() + vb.size());
    return c;
  }
  for (size_t i = 0; i < va.size(); ++i) {
    c.differ += va[i] != vb[i] ? 1 : 0;
    c.lit += va[i] > 0 ? 1 : 0;
  }
  for (int v = 0; v < H; v += 3) {
    for (int u = 0; u < W; u += 3) {
      const Ray r = camera.GenerateRay(static_cast<float>(u), static_cast<float>(v));
      const Eigen::Vector3f d = r.d.normalized();
      const MediaSegment sa = a.IntegrateView(lights, r.o, d, 20.0f, u, v);
      const MediaSegment sb = b.IntegrateView(lights, r.o, d, 20.0f, u, v);
      c.max_dT = std::max(c.max_dT, static_cast<double>((sa.T - sb.T).cwiseAbs().maxCoeff()));
      c.max_dL =
          std::max(c.max_dL, static_cast<double>((sa.L_add - sb.L_add).cwiseAbs().maxCoeff()));
      c.max_L = std::max(c.max_L, static_cast<double>(sa.L_add.maxCoeff()));
    }
  }
  return c;
}

}  // namespace penumbra::media_volumes

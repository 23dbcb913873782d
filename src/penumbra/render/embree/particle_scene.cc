#include "penumbra/render/embree/particle_scene.h"

#include <embree3/rtcore.h>

#include "penumbra/core/error.h"

namespace penumbra {

struct ParticleScene::Impl {
  RTCDevice device = nullptr;
  RTCScene scene = nullptr;
  ~Impl() {
    if (scene) rtcReleaseScene(scene);
    if (device) rtcReleaseDevice(device);
  }
};

ParticleScene::ParticleScene() : impl_(std::make_unique<Impl>()) {}

ParticleScene::~ParticleScene() = default;

void ParticleScene::Build(const EffectsFrame* fx, const Camera& camera, double exposure_time_sec,
                          StreakRays rays, ThreadPool* pool, const MediaScene* media,
                          const ShelterMap* shelter) {
  if (impl_->scene) {
    rtcReleaseScene(impl_->scene);
    impl_->scene = nullptr;
  }
  ParticleStreaks::Build(fx, camera, exposure_time_sec, rays, pool, media, shelter);
  if (count_ == 0 || rays == StreakRays::kPixelCentres) return;
  if (!impl_->device) {
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device) throw Error("ParticleScene: cannot create the Embree device");
  }
  RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
  auto* verts = static_cast<float*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 2 * count_));
  auto* index = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned), count_));
  for (int n = 0; n < count_; ++n) {
    for (int e = 0; e < 2; ++e)
      for (int k = 0; k < 4; ++k) verts[8 * n + 4 * e + k] = ends_[2 * n + e][k];
    index[n] = static_cast<unsigned>(2 * n);
  }
  rtcCommitGeometry(geom);
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_LOW);
  rtcAttachGeometry(impl_->scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(impl_->scene);
}

bool ParticleScene::Intersect(const Ray& ray, float tmax, ParticleHit* hit) const {
  if (count_ == 0) return false;
  // a ray Embree would reject misses the particles (RayScene logs such rays)
  if (!IsTraceableRay(ray.o.x(), ray.o.y(), ray.o.z(), ray.d.x(), ray.d.y(), ray.d.z(), ray.tmin,
                      tmax))
    return false;
  RTCIntersectContext ctx;
  rtcInitIntersectContext(&ctx);
  RTCRayHit rh;
  rh.ray.org_x = ray.o.x(), rh.ray.org_y = ray.o.y(), rh.ray.org_z = ray.o.z();
  rh.ray.dir_x = ray.d.x(), rh.ray.dir_y = ray.d.y(), rh.ray.dir_z = ray.d.z();
  rh.ray.tnear = ray.tmin;
  rh.ray.tfar = tmax;
  rh.ray.time = 0;
  rh.ray.mask = 0xFFFFFFFFu;
  rh.ray.id = 0;
  rh.ray.flags = 0;
  rh.hit.geomID = RTC_INVALID_GEOMETRY_ID;
  rh.hit.instID[0] = RTC_INVALID_GEOMETRY_ID;
  rtcIntersect1(impl_->scene, &ctx, &rh);
  if (rh.hit.geomID == RTC_INVALID_GEOMETRY_ID) return false;
  const unsigned prim = rh.hit.primID;
  hit->t = rh.ray.tfar;
  Eigen::Vector3f n(rh.hit.Ng_x, rh.hit.Ng_y, rh.hit.Ng_z);
  const float nn = n.norm();
  n = nn > 0 ? Eigen::Vector3f(n / nn) : Eigen::Vector3f(-ray.d.normalized());
  if (n.dot(ray.d) > 0) n = -n;
  hit->ng_W = n;
  hit->alpha = alpha_[prim];
  hit->prim = static_cast<int>(prim);
  hit->set = set_[prim];
  hit->kind = fx_->particles[hit->set].kind;
  return true;
}

}  // namespace penumbra

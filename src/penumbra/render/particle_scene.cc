#include "penumbra/render/particle_scene.h"

#include <embree3/rtcore.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/media_common.h"

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

void ParticleScene::Build(const EffectsFrame* fx, const Camera& camera, double exposure_time_sec) {
  fx_ = fx;
  count_ = 0;
  alpha_.clear();
  set_.clear();
  if (impl_->scene) {
    rtcReleaseScene(impl_->scene);
    impl_->scene = nullptr;
  }
  if (fx == nullptr) return;
  size_t total = 0;
  for (size_t s = 0; s < fx->particles.size(); ++s) {
    const ParticleSet& ps = fx->particles[s];
    const std::string key = "effects.particles[" + std::to_string(s) + "]";
    if (ps.velocity_W.size() != ps.position_W.size() || ps.radius_m.size() != ps.position_W.size())
      throw ConfigError("", 0, key,
                        "expected position_W, velocity_W and radius_m of equal length (got " +
                            std::to_string(ps.position_W.size()) + ", " +
                            std::to_string(ps.velocity_W.size()) + ", " +
                            std::to_string(ps.radius_m.size()) + ")");
    for (size_t i = 0; i < ps.position_W.size(); ++i) {
      if (!ps.position_W[i].allFinite() || !ps.velocity_W[i].allFinite() ||
          !std::isfinite(ps.radius_m[i]))
        throw ConfigError("", 0, key, "particle " + std::to_string(i) + " has a non-finite value");
      if (ps.radius_m[i] > 0) ++total;
    }
  }
  if (total == 0) return;
  if (!impl_->device) {
    impl_->device = rtcNewDevice(nullptr);
    if (!impl_->device) throw Error("ParticleScene: cannot create the Embree device");
  }
  const float T = static_cast<float>(std::max(0.0, exposure_time_sec));
  const Eigen::Vector3f cam_o = camera.X_WO().translation().cast<float>();
  const float fx_px = static_cast<float>(camera.intrinsics().fx);

  RTCGeometry geom = rtcNewGeometry(impl_->device, RTC_GEOMETRY_TYPE_ROUND_LINEAR_CURVE);
  auto* verts = static_cast<float*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_VERTEX, 0, RTC_FORMAT_FLOAT4, 4 * sizeof(float), 2 * total));
  auto* index = static_cast<unsigned*>(rtcSetNewGeometryBuffer(
      geom, RTC_BUFFER_TYPE_INDEX, 0, RTC_FORMAT_UINT, sizeof(unsigned), total));
  alpha_.reserve(total);
  set_.reserve(total);
  size_t n = 0;
  for (size_t s = 0; s < fx->particles.size(); ++s) {
    const ParticleSet& ps = fx->particles[s];
    for (size_t i = 0; i < ps.position_W.size(); ++i) {
      const Eigen::Vector3f& p = ps.position_W[i];
      const Eigen::Vector3f& v = ps.velocity_W[i];
      const float r = ps.radius_m[i];
      if (!(r > 0)) continue;
      Eigen::Vector3f q = p + T * v;
      // a still particle: a capsule of negligible length (Embree needs two distinct ends).
      if (!((q - p).norm() > 1e-3f * r)) q = p + Eigen::Vector3f(1e-3f * r, 0, 0);
      const float len = T * v.norm();  // the motion, not the widened capsule
      // widen to half a pixel at the streak's nearest distance to the camera.
      const Eigen::Vector3f seg = q - p;
      const float l2 = seg.squaredNorm();
      const float w = l2 > 0 ? std::clamp((cam_o - p).dot(seg) / l2, 0.0f, 1.0f) : 0.0f;
      const float dist = (p + w * seg - cam_o).norm();
      const float r_wide = std::max(r, 0.5f * dist / fx_px);
      const float alpha = std::min(1.0f, 2 * r / (len + 2 * r)) * (r / r_wide);
      float* vp = verts + 8 * n;
      vp[0] = p.x(), vp[1] = p.y(), vp[2] = p.z(), vp[3] = r_wide;
      vp[4] = q.x(), vp[5] = q.y(), vp[6] = q.z(), vp[7] = r_wide;
      index[n] = static_cast<unsigned>(2 * n);
      alpha_.push_back(alpha);
      set_.push_back(static_cast<int>(s));
      ++n;
    }
  }
  rtcCommitGeometry(geom);
  impl_->scene = rtcNewScene(impl_->device);
  rtcSetSceneBuildQuality(impl_->scene, RTC_BUILD_QUALITY_LOW);
  rtcAttachGeometry(impl_->scene, geom);
  rtcReleaseGeometry(geom);
  rtcCommitScene(impl_->scene);
  count_ = static_cast<int>(n);
}

bool ParticleScene::Intersect(const Ray& ray, float tmax, ParticleHit* hit) const {
  if (count_ == 0) return false;
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
  hit->set = set_[prim];
  hit->kind = fx_->particles[hit->set].kind;
  return true;
}

Eigen::Vector3f ParticleScene::Shade(const ParticleHit& hit, const Eigen::Vector3f& p_W,
                                     const LightSampler& lights,
                                     const Eigen::Vector3f& sky_ambient) const {
  const ParticleSet& ps = fx_->particles[hit.set];
  if (hit.kind == ParticleKind::kSpark) return ps.emission;
  Eigen::Vector3f E = Eigen::Vector3f::Zero();
  for (int j = 0; j < lights.size(); ++j) {
    LightSample ls;
    if (!lights.Sample(j, p_W, 0.5f, 0.5f, &ls)) continue;
    if (hit.kind == ParticleKind::kSnow) {
      E += ls.E * (std::max(0.0f, hit.ng_W.dot(ls.wi)) * 0.318309886f);
    } else {
      E += ls.E * kInv4Pi;
    }
  }
  return ps.color.cwiseProduct(sky_ambient + E) + ps.emission;
}

}  // namespace penumbra

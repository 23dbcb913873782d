#include "penumbra/render/particles/particle_streaks.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "penumbra/core/error.h"
#include "penumbra/render/particles/particle_math.h"
#include "penumbra/render/ray.h"

namespace penumbra {

StreakMotion StreakMotionOf(const Camera& camera) {
  StreakMotion out;
  if (!camera.motion().moving()) return out;
  // row v is seen from the pose slerped / lerped at a = (time_sec + line_time_sec v) / end_sec
  // (camera.h): from o(a), turned by |a| theta from X_WO (theta the rotation from X_WO to
  // X_WO_end); turn and shift are the largest |a| over the rows (v in [-0.5, height]: the
  // pathtraced tier's jittered samples reach the image's edge) times theta and times the
  // translation (1 % and 1e-6 to spare).
  const CameraMotion& m = camera.motion();
  const CameraIntrinsics& k = camera.intrinsics();
  const double a_max = std::max(std::abs(m.time_sec - 0.5 * m.line_time_sec),
                                std::abs(m.time_sec + m.line_time_sec * k.height)) /
                       m.end_sec;
  const Eigen::Quaterniond q0(camera.X_WO().linear()), q1(m.X_WO_end.linear());
  const double theta =
      2.0 * std::acos(std::min(1.0, std::abs(q0.normalized().dot(q1.normalized()))));
  const double move = (m.X_WO_end.translation() - camera.X_WO().translation()).norm();
  out.turn = static_cast<float>(1.01 * a_max * theta + 1e-6);
  out.shift = static_cast<float>(1.01 * a_max * move + 1e-6);
  // the image's corner pixel centres
  double t2 = 0;
  for (const double u : {0.0, k.width - 1.0})
    for (const double v : {0.0, k.height - 1.0}) {
      const double x = (u - k.cx) / k.fx, y = (v - k.cy) / k.fy;
      t2 = std::max(t2, x * x + y * y);
    }
  out.tan_max = static_cast<float>(1.001 * std::sqrt(t2));
  return out;
}

void StreakRowPoses(const Camera& camera, std::vector<double>* rows) {
  const int H = camera.height();
  rows->resize(12 * static_cast<size_t>(H));
  for (int v = 0; v < H; ++v) {
    const Pose X = camera.PoseAtRow(v);
    double* r = &(*rows)[12 * static_cast<size_t>(v)];
    for (int i = 0; i < 3; ++i) {
      for (int j = 0; j < 3; ++j) r[3 * i + j] = X.linear()(i, j);
      r[9 + i] = X.translation()(i);
    }
  }
}

void StreakCullSetupOf(const EffectsFrame& fx, const Camera& camera, double exposure_time_sec,
                       StreakRays rays, const MediaScene* media, const ShelterMap* shelter,
                       StreakCullSetup* out) {
  StreakCullFrame& f = out->frame;
  f = StreakCullFrame();
  const Eigen::Vector3f cam_o = camera.X_WO().translation().cast<float>();
  f.cam_o = Float3{cam_o.x(), cam_o.y(), cam_o.z()};
  f.T = static_cast<float>(std::max(0.0, exposure_time_sec));
  f.fx_px = static_cast<float>(camera.intrinsics().fx);
  f.four_fx2 = 4.0f * f.fx_px * f.fx_px;
  f.pixel_hits = rays == StreakRays::kPixelCentres ? 1 : 0;
  // realtime: the optical-frame depth of a point (as BuildPixelHits computes it), to drop the
  // streaks that lie wholly behind the camera's near plane before any other work (BuildPixelHits
  // would give them an empty pixel box: it clips at kStreakNear + radius >= kStreakNear).
  const Pose X_OW = camera.X_WO().inverse();
  const Eigen::Matrix3f R_OW = X_OW.linear().cast<float>();
  f.depth_row = Float3{R_OW(2, 0), R_OW(2, 1), R_OW(2, 2)};
  f.depth_offset = X_OW.translation().cast<float>().z();
  // a camera's rays through a lens without distortion: the outward unit normals (world) of the
  // four side planes of the pyramid of the pixel-centre rays widened by half a pixel (at the
  // pose X_WO), which holds every ray through the image (pixel samples jittered within their
  // pixel too), to skip the drops no such ray can meet (StreakCullOutside).
  f.frustum = rays != StreakRays::kAny && !camera.intrinsics().has_distortion() ? 1 : 0;
  if (f.frustum != 0) {
    const CameraIntrinsics& k = camera.intrinsics();
    const double l = (-0.5 - k.cx) / k.fx, rt = (k.width - 0.5 - k.cx) / k.fx;
    const double tp = (-0.5 - k.cy) / k.fy, bt = (k.height - 0.5 - k.cy) / k.fy;
    // optical frame: x right, y down, z forward; outside the left side where x < l z, etc.
    const Eigen::Vector3d side_O[4] = {{-1, 0, l}, {1, 0, -rt}, {0, -1, tp}, {0, 1, -bt}};
    for (int i = 0; i < 4; ++i) {
      const Eigen::Vector3f n = (camera.X_WO().linear() * side_O[i].normalized()).cast<float>();
      f.side_W[i] = Float3{n.x(), n.y(), n.z()};
    }
    // a moving camera: the planes move by at most turn |x - cam_o| + shift at a point x
    // (StreakMotionOf).
    if (camera.motion().moving()) {
      const StreakMotion m = StreakMotionOf(camera);
      f.moving = 1;
      f.turn = m.turn;
      f.shift = m.shift;
    }
  }
  // the rain culling's media: per homogeneous medium what does not depend on the streak
  out->media.clear();
  if (media != nullptr)
    for (const AnalyticMedium& m : media->analytic()) {
      const bool cam_in = !m.bounded || ((cam_o.array() >= m.box_min.array()).all() &&
                                         (cam_o.array() <= m.box_max.array()).all());
      StreakCullMedium c;
      c.bounded = m.bounded ? 1 : 0;
      c.cam_in = cam_in ? 1 : 0;
      c.sigma_t_min = m.sigma_t.minCoeff();
      c.cam_density = m.Density(cam_o.z());
      c.falloff = m.falloff;
      c.base = m.base;
      c.box_min = Float3{m.box_min.x(), m.box_min.y(), m.box_min.z()};
      c.box_max = Float3{m.box_max.x(), m.box_max.y(), m.box_max.z()};
      out->media.push_back(c);
    }
  f.media = out->media.empty() ? nullptr : out->media.data();
  f.num_media = static_cast<int32_t>(out->media.size());
  if (shelter != nullptr) f.shelter = shelter->pod();
  out->sets.resize(fx.particles.size());
  for (size_t s = 0; s < fx.particles.size(); ++s) {
    const ParticleSet& ps = fx.particles[s];
    out->sets[s].rain = ps.kind == ParticleKind::kRain ? 1 : 0;
    out->sets[s].sheltered = shelter != nullptr && ShelterApplies(ps) ? 1 : 0;
  }
}

void ParticleStreaks::Build(const EffectsFrame* fx, const Camera& camera, double exposure_time_sec,
                            StreakRays rays, ThreadPool* pool, const MediaScene* media,
                            const ShelterMap* shelter) {
  fx_ = fx;
  count_ = 0;
  culled_ = 0;
  alpha_.clear();
  set_.clear();
  ends_.clear();
  rain_radiance_.clear();
  visible_.clear();
  pixel_hits_built_ = false;
  if (fx == nullptr) return;
  for (size_t s = 0; s < fx->particles.size(); ++s) {
    const ParticleSet& ps = fx->particles[s];
    if (ps.velocity_W.size() != ps.position_W.size() || ps.radius_m.size() != ps.position_W.size())
      throw ConfigError("", 0, "effects.particles[" + std::to_string(s) + "]",
                        "expected position_W, velocity_W and radius_m of equal length (got " +
                            std::to_string(ps.position_W.size()) + ", " +
                            std::to_string(ps.velocity_W.size()) + ", " +
                            std::to_string(ps.radius_m.size()) + ")");
  }
  // every drop's check for finite values, streak and cull flag in parallel chunks (each drop
  // only reads its own input), each chunk keeping its drawn streaks in (set, index) order in its
  // own buffers (reused between frames), which are then concatenated in chunk order, so the
  // output (and the first non-finite particle reported) does not depend on the thread count.
  std::vector<size_t> first(fx->particles.size() + 1, 0);
  for (size_t s = 0; s < fx->particles.size(); ++s)
    first[s + 1] = first[s] + fx->particles[s].position_W.size();
  const size_t n_all = first.back();
  // the frame's inputs of the shared decision (render/particles/streak_cull_math.h, which the CUDA
  // backend's device culling calls too); without host culling the caller decides the drops
  StreakCullSetupOf(*fx, camera, exposure_time_sec, rays, media, shelter, &cull_);
  if (n_all == 0 || !host_culling_) return;
  const bool pixel_hits = rays == StreakRays::kPixelCentres;
  // one drop: nothing (radius <= 0; sheltered; realtime: wholly behind the near plane or
  // outside the image), culled (counted) or a streak appended to `out`.
  auto drop = [&](size_t s, size_t i, DropChunk* out) {
    const ParticleSet& ps = fx->particles[s];
    const Eigen::Vector3f& p = ps.position_W[i];
    const Eigen::Vector3f& v = ps.velocity_W[i];
    StreakCullOut o;
    const int32_t verdict = StreakCullDrop(cull_.frame, cull_.sets[s], Float3{p.x(), p.y(), p.z()},
                                           Float3{v.x(), v.y(), v.z()}, ps.radius_m[i], &o);
    if (verdict == kStreakCulled) ++out->culled;
    if (verdict != kStreakDrawn) return;
    out->alpha.push_back(o.alpha);
    out->set.push_back(static_cast<int>(s));
    out->ends.emplace_back(p.x(), p.y(), p.z(), o.r_wide);
    out->ends.emplace_back(o.q.x, o.q.y, o.q.z, o.r_wide);
  };
  constexpr size_t kDropChunk = 4096;
  const size_t drop_chunks = (n_all + kDropChunk - 1) / kDropChunk;
  if (drop_chunks_.size() < drop_chunks) drop_chunks_.resize(drop_chunks);
  auto drop_chunk = [&](int64_t c) {
    DropChunk& out = drop_chunks_[c];
    out.alpha.clear();
    out.set.clear();
    out.ends.clear();
    out.culled = 0;
    out.bad = n_all;
    const size_t g0 = static_cast<size_t>(c) * kDropChunk;
    const size_t g1 = std::min(n_all, g0 + kDropChunk);
    size_t s =
        static_cast<size_t>(std::upper_bound(first.begin(), first.end(), g0) - first.begin()) - 1;
    for (size_t g = g0; g < g1; ++g) {
      while (g >= first[s + 1]) ++s;
      const ParticleSet& ps = fx->particles[s];
      const size_t i = g - first[s];
      if (!ps.position_W[i].allFinite() || !ps.velocity_W[i].allFinite() ||
          !std::isfinite(ps.radius_m[i])) {
        out.bad = g;  // its first non-finite particle
        return;
      }
      drop(s, i, &out);
    }
  };
  ParallelForOrSerial(pool, static_cast<int64_t>(drop_chunks), drop_chunk);
  for (size_t c = 0; c < drop_chunks; ++c) {
    const size_t g = drop_chunks_[c].bad;
    if (g == n_all) continue;
    const size_t s =
        static_cast<size_t>(std::upper_bound(first.begin(), first.end(), g) - first.begin()) - 1;
    throw NonFiniteParticleError(s, g - first[s]);
  }
  size_t total = 0;
  for (size_t c = 0; c < drop_chunks; ++c) {
    total += drop_chunks_[c].alpha.size();
    culled_ += drop_chunks_[c].culled;
  }
  alpha_.reserve(total);
  set_.reserve(total);
  ends_.reserve(2 * total);
  for (size_t c = 0; c < drop_chunks; ++c) {
    const DropChunk& dc = drop_chunks_[c];
    alpha_.insert(alpha_.end(), dc.alpha.begin(), dc.alpha.end());
    set_.insert(set_.end(), dc.set.begin(), dc.set.end());
    ends_.insert(ends_.end(), dc.ends.begin(), dc.ends.end());
  }
  count_ = static_cast<int>(alpha_.size());
  if (count_ == 0) return;
  if (pixel_hits && host_splat_) BuildPixelHits(camera, pool);
}

namespace {

Float3 StreakF3(const Eigen::Vector3f& v) { return Float3{v.x(), v.y(), v.z()}; }

}  // namespace

void ParticleStreaks::BuildPixelHits(const Camera& camera, ThreadPool* pool) {
  const int W = camera.width(), H = camera.height();
  pixel_w_ = W;
  // (filled band by band below, in parallel)
  pixel_.resize(static_cast<size_t>(W) * H);
  pixel_hits_built_ = true;
  const CameraIntrinsics& k = camera.intrinsics();
  const Pose X_OW = camera.X_WO().inverse();
  const Eigen::Matrix<float, 3, 3, Eigen::RowMajor> R_OW = X_OW.linear().cast<float>();
  const Float3 p_OW = StreakF3(X_OW.translation().cast<float>());
  // pixel box and projected segment of every streak (the shared ProjectStreak of
  // render/particles/particle_math.h, which the CUDA backend's splat calls too), in parallel chunks
  // (empty box when behind the camera or outside the image).
  // a moving camera: the boxes widened by the rows' motion (WidenStreakForMotion), and each
  // row's columns taken in that row's own pose (StreakRowColumnsAtPose over StreakRowPoses),
  // as the CUDA backend's splat (SplatStreakRow) takes them.
  const StreakMotion motion = StreakMotionOf(camera);
  const bool moving = motion.moving();
  if (moving) StreakRowPoses(camera, &row_poses_);
  std::vector<StreakProjection> box(count_);
  auto project = [&](int n) {
    const Float3 ao = StreakToOptical(R_OW.data(), p_OW, StreakF3(ends_[2 * n].head<3>()));
    const Float3 bo = StreakToOptical(R_OW.data(), p_OW, StreakF3(ends_[2 * n + 1].head<3>()));
    box[n] = ProjectStreak(ao, bo, ends_[2 * n].w(), k.fx, k.fy, k.cx, k.cy, W, H);
    if (moving) box[n] = WidenStreakForMotion(box[n], motion, k.fx, k.fy, W, H);
  };
  constexpr int kChunk = 4096;
  const int chunks = (count_ + kChunk - 1) / kChunk;
  auto chunk = [&](int64_t c) {
    const int n1 = std::min(count_, static_cast<int>(c + 1) * kChunk);
    for (int n = static_cast<int>(c) * kChunk; n < n1; ++n) project(n);
  };
  ParallelForOrSerial(pool, chunks, chunk);
  // bands of rows in parallel; within a band streaks in index order (nearest wins, ties keep
  // the lower index), so the result does not depend on the thread count.
  constexpr int kBand = 16;
  const int bands = (H + kBand - 1) / kBand;
  // the streaks of every band, in index order; streaks outside the image are culled.
  std::vector<std::vector<int>> in_band(bands);
  visible_.assign(count_, 0);
  for (int n = 0; n < count_; ++n) {
    const StreakProjection& bx = box[n];
    if (bx.empty()) continue;
    visible_[n] = 1;
    for (int bi = bx.v0 / kBand; bi <= bx.v1 / kBand; ++bi) in_band[bi].push_back(n);
  }
  const Eigen::Vector3f o_shared = camera.GenerateRay(0.0f, 0.0f).o;
  auto band = [&](int64_t bi) {
    const int r0 = static_cast<int>(bi) * kBand, r1 = std::min(H - 1, r0 + kBand - 1);
    const size_t p0 = static_cast<size_t>(r0) * W, p1 = static_cast<size_t>(r1 + 1) * W;
    std::fill(pixel_.begin() + p0, pixel_.begin() + p1, PixelStreak());
    for (int n : in_band[bi]) {
      const StreakProjection& bx = box[n];
      const int v0 = std::max(bx.v0, r0), v1 = std::min(bx.v1, r1);
      if (v0 > v1 || bx.u0 > bx.u1) continue;
      const Eigen::Vector3f a = ends_[2 * n].head<3>(), b = ends_[2 * n + 1].head<3>();
      const float r = ends_[2 * n].w();
      // the origin-dependent terms once per streak for the camera centre (every pixel's ray
      // origin unless the camera moves during the exposure: then per pixel).
      const CapsuleOrigin shared =
          MakeCapsuleOrigin(StreakF3(o_shared), StreakF3(a), StreakF3(b), r);
      for (int v = v0; v <= v1; ++v) {
        // the columns within rp of the projected segment's part near this row.
        int c0, c1;
        if (moving)
          StreakRowColumnsAtPose(&row_poses_[12 * static_cast<size_t>(v)], StreakF3(a), StreakF3(b),
                                 r, k.fx, k.fy, k.cx, k.cy, W, H, v, &c0, &c1);
        else
          StreakRowColumns(bx, v, &c0, &c1);
        for (int u = c0; u <= c1; ++u) {
          const Ray ray = camera.GenerateRay(static_cast<float>(u), static_cast<float>(v));
          const Float3 d = StreakF3(ray.d);
          const float t_ray =
              ray.o == o_shared
                  ? IntersectCapsuleRay(shared, d)
                  : IntersectCapsuleRay(
                        MakeCapsuleOrigin(StreakF3(ray.o), StreakF3(a), StreakF3(b), r), d);
          if (!(t_ray > 0)) continue;
          const size_t at = static_cast<size_t>(v) * W + u;
          if (t_ray < pixel_[at].t) pixel_[at] = PixelStreak{t_ray, n};
        }
      }
    }
  };
  ParallelForOrSerial(pool, bands, band);
}

bool ParticleStreaks::PixelHit(const Ray& ray, int u, int v, float tmax, ParticleHit* hit) const {
  if (!pixel_hits_built_) return false;
  const size_t at = static_cast<size_t>(v) * pixel_w_ + u;
  const PixelStreak px = pixel_[at];
  const int n = px.prim;
  if (n < 0 || !(px.t <= tmax)) return false;
  hit->t = px.t;
  const Eigen::Vector3f a = ends_[2 * n].head<3>(), b = ends_[2 * n + 1].head<3>();
  const Eigen::Vector3f p = ray.o + hit->t * ray.d;
  const Float3 nrm = CapsuleNormal(StreakF3(p), StreakF3(a), StreakF3(b), StreakF3(ray.d));
  hit->ng_W = Eigen::Vector3f(nrm.x, nrm.y, nrm.z);
  hit->alpha = alpha_[n];
  hit->prim = n;
  hit->set = set_[n];
  hit->kind = fx_->particles[hit->set].kind;
  return true;
}

void ParticleStreaks::PrecomputeRain(const LightSampler& lights, const Eigen::Vector3f& sky_ambient,
                                     const SkyIrradianceVolume* sky_volume, ThreadPool* pool) {
  rain_radiance_.clear();
  sky_volume_ = sky_volume;
  bool any = false;
  const bool culled = !visible_.empty();  // realtime: only streaks in the image are drawn
  for (int n = 0; n < count_ && !any; ++n)
    any = fx_->particles[set_[n]].kind == ParticleKind::kRain;
  if (!any) return;
  std::vector<Eigen::Vector3f> L(count_, Eigen::Vector3f::Zero());
  auto one = [&](int64_t n) {
    if (fx_->particles[set_[n]].kind != ParticleKind::kRain || (culled && !visible_[n])) return;
    ParticleHit h;
    h.kind = ParticleKind::kRain;
    h.set = set_[n];
    h.prim = -1;
    const Eigen::Vector3f c = 0.5f * (ends_[2 * n].head<3>() + ends_[2 * n + 1].head<3>());
    L[n] = Shade(h, c, lights, sky_ambient);
  };
  // chunks of streaks per task (one task per streak costs more in scheduling than shading).
  constexpr int kChunk = 1024;
  const int chunks = (count_ + kChunk - 1) / kChunk;
  auto chunk = [&](int64_t c) {
    const int64_t n1 = std::min<int64_t>(count_, (c + 1) * kChunk);
    for (int64_t n = c * kChunk; n < n1; ++n) one(n);
  };
  ParallelForOrSerial(pool, chunks, chunk);
  rain_radiance_ = std::move(L);
}

StreakSetPod ParticleStreaks::SetPod(int set) const {
  const ParticleSet& ps = fx_->particles[set];
  StreakSetPod pod;
  pod.kind = ps.kind == ParticleKind::kSpark  ? StreakKind::kSpark
             : ps.kind == ParticleKind::kSnow ? StreakKind::kSnow
                                              : StreakKind::kRain;
  pod.color = StreakF3(ps.color);
  pod.emission = StreakF3(ps.emission);
  return pod;
}

Eigen::Vector3f ParticleStreaks::Shade(const ParticleHit& hit, const Eigen::Vector3f& p_W,
                                       const LightSampler& lights,
                                       const Eigen::Vector3f& sky_ambient) const {
  // the shared ShadeStreak (render/particles/particle_math.h), with the hit's kind
  StreakSetPod set = SetPod(hit.set);
  set.kind = hit.kind == ParticleKind::kSpark  ? StreakKind::kSpark
             : hit.kind == ParticleKind::kSnow ? StreakKind::kSnow
                                               : StreakKind::kRain;
  Float3 rain;
  const bool precomputed = hit.kind == ParticleKind::kRain && hit.prim >= 0 &&
                           hit.prim < static_cast<int>(rain_radiance_.size());
  if (precomputed) rain = StreakF3(rain_radiance_[hit.prim]);
  const Float3 L = ShadeStreak(set, precomputed ? &rain : nullptr, StreakF3(p_W),
                               StreakF3(hit.ng_W), lights.pods().data(), lights.size(),
                               sky_volume_ != nullptr ? sky_volume_->pod() : SkyVolumePod(),
                               StreakF3(sky_ambient));
  return Eigen::Vector3f(L.x, L.y, L.z);
}

}  // namespace penumbra

// the drops' shared culling decision (render/particles/streak_cull_math.h's StreakCullDrop),
// which ParticleStreaks::Build and the CUDA backend's device culling (cuda_streak_cull.h) call,
// on the CPU (no GPU needed): on every drop of the rain and snow frames at 1 s, 640x480, of the
// rain frame in fog (realtime_parity::AddRainFog: a height fog and a box of haze, rain culled as
// invisible) and of the rain frame seen by a turning rolling-shutter camera, it decides as Build's
// per-drop code did before the move (kept below as the reference, in its Eigen expressions): the
// same verdict and the same bits of the streak's end, widened radius and coverage; Build's streaks
// are the drawn drops in (set, index) order and its culled count theirs. the bits depend on the
// rounding forms (a distance summed (x + y) + z instead of Eigen's x + (y + z) changes some widened
// radii), so the comparison can fail. RealtimeFrameData's device drop culler
// (set_device_drop_culler: PrepareStreaks hands the decision's inputs to it and the splat reads
// the streaks where it made them, their count there too) fed by a host run of
// StreakCullDrop with an in-order compaction, as the device's kernels do, in host memory, gives
// the host culling's frame to the bit (rgb, radiance, depth, EV100), though its list holds more
// places than streaks.

#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <functional>
#include <memory>
#include <numeric>
#include <string>
#include <vector>

#include "host_path.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/cuda/realtime_host.h"
#include "penumbra/render/particles/streak_cull_math.h"
#include "realtime_parity.h"

namespace penumbra {
namespace {

Eigen::Vector3f E(const Float3& f) { return Eigen::Vector3f(f.x, f.y, f.z); }

// ParticleStreaks::Build's `drop` lambda (with its `outside` and RainInvisible) written
// independently in Eigen, over the frame's decision inputs: the reference.
int32_t ReferenceDrop(const StreakCullSetup& c, const Camera& camera, size_t s,
                      const Eigen::Vector3f& p, const Eigen::Vector3f& v, float r,
                      StreakCullOut* out) {
  const StreakCullFrame& f = c.frame;
  const Eigen::Vector3f cam_o = camera.X_WO().translation().cast<float>();
  const float T = f.T, fx_px = f.fx_px, four_fx2 = 4.0f * fx_px * fx_px;
  const Pose X_OW = camera.X_WO().inverse();
  const Eigen::Matrix3f R_OW = X_OW.linear().cast<float>();
  const Eigen::Vector3f p_OW = X_OW.translation().cast<float>();
  auto depth = [&](const Eigen::Vector3f& x) { return (R_OW * x + p_OW).z(); };
  auto outside = [&](const Eigen::Vector3f& a, const Eigen::Vector3f& b, float rr) {
    const Eigen::Vector3f dp = a - cam_o, dq = b - cam_o;
    const float D2 = std::max(dp.squaredNorm(), dq.squaredNorm());
    if (f.moving == 0) {
      for (const Float3& n3 : f.side_W) {
        const Eigen::Vector3f n = E(n3);
        const float sd = std::min(n.dot(dp), n.dot(dq));
        if (sd > 1.001f * rr && four_fx2 * sd * sd > 1.002f * D2) return true;
      }
      return false;
    }
    const float D = std::sqrt(D2);
    const float R = 1.001f * std::max(rr, 0.5f * D / fx_px);
    const float margin = R + f.turn * (D + R) + f.shift;
    for (const Float3& n3 : f.side_W)
      if (std::min(E(n3).dot(dp), E(n3).dot(dq)) > margin) return true;
    return false;
  };
  auto invisible = [&](float alpha, const Eigen::Vector3f& p_W) {
    if (alpha < kRainCullContrast) return true;
    if (c.media.empty()) return false;
    const float dist = (p_W - cam_o).norm();
    float tau = 0;
    for (const StreakCullMedium& m : c.media) {
      if (m.bounded != 0 && !(m.cam_in != 0 && (p_W.array() >= E(m.box_min).array()).all() &&
                              (p_W.array() <= E(m.box_max).array()).all()))
        continue;
      tau += m.sigma_t_min * dist *
             std::min(m.cam_density, MediumHeightDensity(m.falloff, m.base, p_W.z()));
    }
    return alpha * std::exp(-tau) < kRainCullContrast;
  };
  if (!(r > 0)) return kStreakNone;
  if (c.sets[s].sheltered != 0 && ShelterSheltered(f.shelter, Float3{p.x(), p.y(), p.z()}))
    return kStreakNone;
  Eigen::Vector3f q = p + T * v;
  if (!((q - p).norm() > 1e-3f * r)) q = p + Eigen::Vector3f(1e-3f * r, 0, 0);
  if (f.pixel_hits != 0 && depth(p) < kStreakNear && depth(q) < kStreakNear) return kStreakNone;
  if (f.frustum != 0 && outside(p, q, r)) return kStreakNone;
  const float len = T * v.norm();
  const Eigen::Vector3f seg = q - p;
  const float l2 = seg.squaredNorm();
  const float w = l2 > 0 ? std::clamp((cam_o - p).dot(seg) / l2, 0.0f, 1.0f) : 0.0f;
  const float dist = (p + w * seg - cam_o).norm();
  const float r_wide = std::max(r, 0.5f * dist / fx_px);
  const float alpha = std::min(1.0f, 2 * r / (len + 2 * r)) * (r / r_wide);
  if (f.pixel_hits != 0 && c.sets[s].rain != 0 && invisible(alpha, p + w * seg))
    return kStreakCulled;
  out->q = Float3{q.x(), q.y(), q.z()};
  out->r_wide = r_wide;
  out->alpha = alpha;
  return kStreakDrawn;
}

uint32_t Bits(float x) {
  uint32_t u;
  std::memcpy(&u, &x, 4);
  return u;
}

struct CullCase {
  const char* file;
  bool rolling;
  bool fog;  // realtime_parity::AddRainFog
};

// every drop of the frame: the shared decision against the reference and Build's streaks.
TEST(StreakCullShared, DecidesEveryDropAsBuildDidBefore) {
  int64_t fog_free_culled = -1;  // rain's culled drops without the fog
  for (const CullCase& k :
       {CullCase{"effects/rain.yaml", false, false}, CullCase{"effects/snow.yaml", false, false},
        CullCase{"effects/rain.yaml", false, true}, CullCase{"effects/rain.yaml", true, false}}) {
    SCOPED_TRACE(std::string(k.file) + (k.rolling ? " rolling shutter" : "") +
                 (k.fog ? " in fog" : ""));
    auto [session, snap, view, loaded] = realtime_parity::LoadFrameAt(k.file, 1.0, 640, 480);
    ASSERT_TRUE(loaded && !loaded->particles.empty());
    auto fx = std::make_shared<EffectsFrame>(*loaded);
    if (k.fog) realtime_parity::AddRainFog(fx.get());
    if (k.rolling) realtime_parity::AddRollingShutter(&view);
    host_path::HostPath path(session->scene(), snap);
    cuda::RealtimeFrameData& data = path.data();
    data.Prepare(snap, view, &path.pool(), fx.get());
    const ParticleStreaks& built = data.particles();
    const StreakCullSetup& setup = built.cull_setup();
    const Camera camera(view.X_WO, view.intrinsics, view.motion);
    EXPECT_EQ(setup.frame.moving != 0, k.rolling);
    EXPECT_EQ(setup.media.size(), k.fog ? 2u : 0u);
    int64_t counts[3] = {0, 0, 0}, mismatched = 0, sum_form_differs = 0;
    std::vector<float> alpha;
    std::vector<int> set;
    std::vector<Eigen::Vector4f> ends;
    for (size_t s = 0; s < fx->particles.size(); ++s) {
      const ParticleSet& ps = fx->particles[s];
      for (size_t i = 0; i < ps.position_W.size(); ++i) {
        const Eigen::Vector3f& p = ps.position_W[i];
        const Eigen::Vector3f& v = ps.velocity_W[i];
        StreakCullOut a, b;
        const int32_t va = StreakCullDrop(setup.frame, setup.sets[s], Float3{p.x(), p.y(), p.z()},
                                          Float3{v.x(), v.y(), v.z()}, ps.radius_m[i], &a);
        const int32_t vb = ReferenceDrop(setup, camera, s, p, v, ps.radius_m[i], &b);
        ++counts[va];
        bool same = va == vb;
        if (same && va == kStreakDrawn) {
          same = Bits(a.q.x) == Bits(b.q.x) && Bits(a.q.y) == Bits(b.q.y) &&
                 Bits(a.q.z) == Bits(b.q.z) && Bits(a.r_wide) == Bits(b.r_wide) &&
                 Bits(a.alpha) == Bits(b.alpha);
          alpha.push_back(a.alpha);
          set.push_back(static_cast<int>(s));
          ends.emplace_back(p.x(), p.y(), p.z(), a.r_wide);
          ends.emplace_back(a.q.x, a.q.y, a.q.z, a.r_wide);
          // the camera distance of p summed (x + y) + z: another rounding form
          const Eigen::Vector3f d = p - camera.X_WO().translation().cast<float>();
          const float other = std::sqrt((d.x() * d.x() + d.y() * d.y()) + d.z() * d.z());
          sum_form_differs += Bits(other) != Bits(d.norm()) ? 1 : 0;
        }
        mismatched += same ? 0 : 1;
      }
    }
    std::printf(
        "%s%s%s: %lld drops: %lld none, %lld culled, %lld drawn; %lld differ from the "
        "reference; %lld drawn drops' distance differs summed (x + y) + z\n",
        k.file, k.rolling ? " (rolling shutter)" : "", k.fog ? " (in fog)" : "",
        static_cast<long long>(counts[0] + counts[1] + counts[2]),
        static_cast<long long>(counts[0]), static_cast<long long>(counts[1]),
        static_cast<long long>(counts[2]), static_cast<long long>(mismatched),
        static_cast<long long>(sum_form_differs));
    EXPECT_EQ(mismatched, 0);
    EXPECT_GT(counts[kStreakDrawn], 0);
    EXPECT_GT(counts[kStreakNone], 0);
    EXPECT_GT(sum_form_differs, 0);
    if (k.fog) {
      EXPECT_GT(counts[kStreakCulled], fog_free_culled);
    } else if (std::string(k.file) == "effects/rain.yaml" && !k.rolling) {
      fog_free_culled = counts[kStreakCulled];
    }
    // Build's streaks: the drawn drops in order
    EXPECT_EQ(built.culled(), counts[kStreakCulled]);
    ASSERT_EQ(built.size(), static_cast<int>(alpha.size()));
    EXPECT_EQ(built.set_of(), set);
    EXPECT_EQ(std::memcmp(built.alpha().data(), alpha.data(), sizeof(float) * alpha.size()), 0);
    EXPECT_EQ(std::memcmp(built.ends().data(), ends.data(), sizeof(Eigen::Vector4f) * ends.size()),
              0);
  }
}

// the drops of `fx` culled on the host as the device's kernels cull them: StreakCullDrop over
// every drop, the kept ones compacted in (set, index) order into *pods, the culled rain counted
// into *culled.
void CullOnHost(const EffectsFrame& fx, const StreakCullSetup& setup,
                std::vector<cuda::StreakPod>* pods, int* culled) {
  pods->clear();
  *culled = 0;
  for (size_t s = 0; s < fx.particles.size(); ++s) {
    const ParticleSet& ps = fx.particles[s];
    for (size_t i = 0; i < ps.position_W.size(); ++i) {
      const Eigen::Vector3f& p = ps.position_W[i];
      const Eigen::Vector3f& v = ps.velocity_W[i];
      StreakCullOut o;
      const int32_t verdict =
          StreakCullDrop(setup.frame, setup.sets[s], Float3{p.x(), p.y(), p.z()},
                         Float3{v.x(), v.y(), v.z()}, ps.radius_m[i], &o);
      *culled += verdict == kStreakCulled ? 1 : 0;
      if (verdict != kStreakDrawn) continue;
      cuda::StreakPod pod;
      pod.a[0] = p.x(), pod.a[1] = p.y(), pod.a[2] = p.z();
      pod.b[0] = o.q.x, pod.b[1] = o.q.y, pod.b[2] = o.q.z;
      pod.r = o.r_wide;
      pod.alpha = o.alpha;
      pod.prim = static_cast<int32_t>(pods->size());
      pod.set = static_cast<int32_t>(s);
      pods->push_back(pod);
    }
  }
}

// rain at 1 s, 160x120 (the turning rolling shutter of AddRollingShutter where `rolling`) on the
// host path, and its frame with the host's culling: the splat's StreakPods and the culled rain.
// path refers to w's snapshot: kept behind a pointer.
struct HostCulledRain {
  realtime_parity::WorldFrame w;
  std::unique_ptr<host_path::HostPath> path;
  RenderedFrame frame;
  std::vector<cuda::StreakPod> pods;
  int culled = 0;
};

std::unique_ptr<HostCulledRain> RenderHostCulledRain(bool rolling) {
  auto r = std::make_unique<HostCulledRain>();
  r->w = realtime_parity::LoadFrameAt("effects/rain.yaml", 1.0, 160, 120);
  if (rolling) realtime_parity::AddRollingShutter(&r->w.view);
  r->path = std::make_unique<host_path::HostPath>(r->w.session->scene(), r->w.snap);
  cuda::RealtimeFrameData& data = r->path->data();
  EXPECT_FALSE(data.has_drop_culler());
  r->frame = r->path->Render(r->w.view, r->w.fx.get());
  const cuda::PathStreaks list = data.splat_streaks().View();
  r->pods.assign(list.streaks, list.streaks + list.num);
  r->culled = data.streaks_culled();
  return r;
}

// the streaks left where the culler made them (RealtimeFrameData::set_device_drop_culler:
// the CUDA backend's, with device memory): a culler that returns a list of
// `bound` places (the device's: every drop's; here twice the streaks and one) of which only the
// first *count are streaks, the rest other (wider, opaque) streaks, and its culled rain after
// the frame (FinishDeviceCulling). here its
// memory is the host's, which RenderRealtimeOnHost reads: the frame is the host culling's to the
// bit (rgb, radiance, depth, EV100), splat_streaks() copies the streaks once (download) and they
// are the host culling's StreakPods byte for byte, streaks_culled() is the host's once reported.
// a list whose count is its bound (the reader drawing every place) changes the frame: the count
// is what bounds the splat (SplatStreakCount), so the comparison can fail.
TEST(StreakCullShared, DeviceStreakListGivesTheHostCullingsBits) {
  for (bool rolling : {false, true}) {
    SCOPED_TRACE(rolling ? "rolling shutter" : "still");
    // the host culling's frame, splat list and culled rain, and the world frame it renders
    const std::unique_ptr<HostCulledRain> rain = RenderHostCulledRain(rolling);
    const auto& [w, path, host, host_pods, host_culled] = *rain;
    const CameraView& view = w.view;
    const EffectsFrame* fx = w.fx.get();
    cuda::RealtimeFrameData& data = path->data();
    ASSERT_GT(host_pods.size(), 0u);
    ASSERT_GT(host_culled, 0);
    // the culler's "device" memory: bound places, count streaks
    std::vector<cuda::StreakPod> places;
    int32_t count = 0;
    int culled = 0, downloads = 0;
    const auto culler = [&](bool count_is_bound) {
      return [&, count_is_bound](const EffectsFrame& frame, const StreakCullSetup& setup) {
        CullOnHost(frame, setup, &places, &culled);
        count = static_cast<int32_t>(places.size());
        for (int32_t k = 0; k <= count && count > 0; ++k) {
          cuda::StreakPod other = places[k % count];
          other.r *= 3;
          other.alpha = 1;
          places.push_back(other);
        }
        if (count_is_bound) count = static_cast<int32_t>(places.size());
        cuda::RealtimeFrameData::DeviceStreakList list;
        list.streaks = places.data();
        list.bound = static_cast<int32_t>(places.size());
        list.count = &count;
        list.download = [&](std::vector<cuda::StreakPod>* out) {
          ++downloads;
          out->assign(places.begin(), places.begin() + count);
        };
        return list;
      };
    };
    data.set_device_drop_culler(culler(false));
    EXPECT_TRUE(data.has_drop_culler());
    const RenderedFrame kept = path->Render(view, fx);
    EXPECT_FALSE(data.particles().host_culling());
    EXPECT_EQ(data.particles().size(), 0);
    EXPECT_GT(static_cast<int32_t>(places.size()), count);
    EXPECT_EQ(data.streaks_culled(), 0);
    data.FinishDeviceCulling(culled);
    EXPECT_EQ(data.streaks_culled(), host_culled);
    EXPECT_EQ(downloads, 0);
    const cuda::PathStreaks list = data.splat_streaks().View();
    data.splat_streaks();
    EXPECT_EQ(downloads, 1);
    ASSERT_EQ(static_cast<size_t>(list.num), host_pods.size());
    EXPECT_EQ(std::memcmp(list.streaks, host_pods.data(), sizeof(cuda::StreakPod) * list.num), 0);
    EXPECT_EQ(kept.rgb.data, host.rgb.data);
    EXPECT_EQ(kept.radiance.data, host.radiance.data);
    EXPECT_EQ(kept.depth_m.data, host.depth_m.data);
    EXPECT_EQ(std::memcmp(&kept.ev100, &host.ev100, sizeof(double)), 0);
    // every place drawn: other streaks, another frame
    data.set_device_drop_culler(culler(true));
    const RenderedFrame all = path->Render(view, fx);
    ASSERT_EQ(all.radiance.data.size(), host.radiance.data.size());
    const size_t differ = std::inner_product(all.radiance.data.begin(), all.radiance.data.end(),
                                             host.radiance.data.begin(), size_t{0}, std::plus<>(),
                                             std::not_equal_to<>());
    std::printf(
        "rain 160x120%s: %zu streaks of %zu places, %d rain culled; every place drawn: "
        "%zu radiance values differ\n",
        rolling ? ", rolling shutter" : "", host_pods.size(), places.size(), host_culled, differ);
    EXPECT_GT(differ, 0u);
    data.set_device_drop_culler(cuda::RealtimeFrameData::DeviceDropCuller());
    EXPECT_FALSE(data.has_drop_culler());
    const RenderedFrame again = path->Render(view, fx);
    EXPECT_TRUE(data.particles().host_culling());
    EXPECT_EQ(again.radiance.data, host.radiance.data);
  }
}

}  // namespace
}  // namespace penumbra

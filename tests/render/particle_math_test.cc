// the shared streak functions of render/particle_math.h (the ray-capsule test, the capsule's
// normal, the streak's radiance ShadeStreak) against the Eigen code that ParticleStreaks ran
// before they moved there (restated below as it was), bit for bit on many random inputs: the
// CPU backend's particle images did not change, and the CUDA backend's paths (path_streaks.h)
// compute what the CPU computes.

#include "penumbra/render/particle_math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/render/camera.h"
#include "penumbra/render/light_sampler.h"
#include "penumbra/render/particle_streaks.h"

namespace penumbra {
namespace {

// ---- the code before the move (render/particle_streaks.cc at main 6da4288), restated ----

struct OldCapsuleOrigin {
  Eigen::Vector3f ba, oa, ob;
  float baba, baoa, qc, sc_a, sc_b;
  OldCapsuleOrigin(const Eigen::Vector3f& o, const Eigen::Vector3f& a, const Eigen::Vector3f& b,
                   float r)
      : ba(b - a), oa(o - a), ob(o - b) {
    baba = ba.dot(ba);
    baoa = ba.dot(oa);
    const float oaoa = oa.dot(oa);
    qc = baba * oaoa - baoa * baoa - r * r * baba;
    sc_a = oa.dot(oa) - r * r;
    sc_b = ob.dot(ob) - r * r;
  }
};

float OldIntersectCapsule(const OldCapsuleOrigin& c, const Eigen::Vector3f& d) {
  const float bard = c.ba.dot(d), rdoa = d.dot(c.oa);
  const float qa = c.baba - bard * bard;
  const float qb = c.baba * rdoa - c.baoa * bard;
  float h = qb * qb - qa * c.qc;
  float y;
  if (qa > 1e-12f) {
    if (h < 0) return -1.0f;
    const float t = (-qb - std::sqrt(h)) / qa;
    y = c.baoa + t * bard;
    if (y > 0 && y < c.baba) return t > 0 ? t : -1.0f;
  } else {
    y = bard > 0 ? -1.0f : c.baba + 1.0f;
  }
  const bool at_a = y <= 0;
  const float sb = d.dot(at_a ? c.oa : c.ob), sc = at_a ? c.sc_a : c.sc_b;
  h = sb * sb - sc;
  if (h <= 0) return -1.0f;
  const float t = -sb - std::sqrt(h);
  return t > 0 ? t : -1.0f;
}

// ParticleStreaks::PixelHit's normal at p for a ray of direction d
Eigen::Vector3f OldNormal(const Eigen::Vector3f& p, const Eigen::Vector3f& a,
                          const Eigen::Vector3f& b, const Eigen::Vector3f& d) {
  const Eigen::Vector3f ba = b - a;
  const float w = std::clamp((p - a).dot(ba) / std::max(ba.squaredNorm(), 1e-20f), 0.0f, 1.0f);
  Eigen::Vector3f nrm = p - (a + w * ba);
  const float nn = nrm.norm();
  nrm = nn > 0 ? Eigen::Vector3f(nrm / nn) : Eigen::Vector3f(-d.normalized());
  if (nrm.dot(d) > 0) nrm = -nrm;
  return nrm;
}

// ParticleStreaks::Shade without a sky volume (rain: its precomputed radiance where given)
Eigen::Vector3f OldShade(ParticleKind kind, const ParticleSet& ps, const Eigen::Vector3f* rain,
                         const Eigen::Vector3f& p_W, const Eigen::Vector3f& ng_W,
                         const LightSampler& lights, const Eigen::Vector3f& sky_ambient) {
  if (kind == ParticleKind::kSpark) return ps.emission;
  if (kind == ParticleKind::kRain && rain != nullptr) return *rain;
  Eigen::Vector3f E = Eigen::Vector3f::Zero();
  for (int j = 0; j < lights.size(); ++j) {
    LightSample ls;
    if (!lights.Sample(j, p_W, 0.5f, 0.5f, &ls)) continue;
    if (kind == ParticleKind::kSnow) {
      E += ls.E * (std::max(0.0f, ng_W.dot(ls.wi)) * 0.318309886f);
    } else {
      E += ls.E * kInv4Pi;
    }
  }
  const Eigen::Vector3f sky = sky_ambient;
  return ps.color.cwiseProduct(sky + E) + ps.emission;
}

// ---- helpers ----

Float3 AsFloat3(const Eigen::Vector3f& v) { return Float3{v.x(), v.y(), v.z()}; }

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }
bool SameBits(const Float3& a, const Eigen::Vector3f& b) {
  return SameBits(a.x, b.x()) && SameBits(a.y, b.y()) && SameBits(a.z, b.z());
}

Eigen::Vector3f RandomIn(Rng* rng, float lo, float hi) {
  return Eigen::Vector3f(lo + (hi - lo) * rng->Uniform(), lo + (hi - lo) * rng->Uniform(),
                         lo + (hi - lo) * rng->Uniform());
}

Eigen::Vector3f RandomUnit(Rng* rng) {
  while (true) {
    const Eigen::Vector3f v = RandomIn(rng, -1, 1);
    const float n = v.norm();
    if (n > 0.1f && n <= 1) return v / n;
  }
}

// ---- tests ----

// random capsules (lengths from 0 to 1 m, radii 0.1 mm to 5 cm) and rays from random origins
// aimed at a random point near each capsule, so that about half hit (body and end caps);
// directions unit (as the splat and the paths pass them).
TEST(ParticleMathTest, CapsuleTestAndNormalEqualTheOldCodeBitForBit) {
  Rng rng(20261127);
  int hits = 0, caps = 0, shared_origin = 0;
  constexpr int kCases = 200000;
  for (int i = 0; i < kCases; ++i) {
    const Eigen::Vector3f a = RandomIn(&rng, -3, 3);
    // a tenth of the capsules are still particles (a 1e-3 r long segment, as Build makes them)
    const float r = 1e-4f + 0.05f * rng.Uniform() * rng.Uniform();
    const Eigen::Vector3f b = i % 10 == 0 ? Eigen::Vector3f(a + Eigen::Vector3f(1e-3f * r, 0, 0))
                                          : Eigen::Vector3f(a + RandomIn(&rng, -0.5f, 0.5f));
    const Eigen::Vector3f o = RandomIn(&rng, -8, 8);
    const Eigen::Vector3f aim = a + rng.Uniform() * (b - a) + RandomIn(&rng, -2 * r, 2 * r);
    const Eigen::Vector3f d = (aim - o).normalized();
    const OldCapsuleOrigin old(o, a, b, r);
    const CapsuleOrigin now = MakeCapsuleOrigin(AsFloat3(o), AsFloat3(a), AsFloat3(b), r);
    ASSERT_TRUE(SameBits(now.qc, old.qc) && SameBits(now.sc_a, old.sc_a) &&
                SameBits(now.sc_b, old.sc_b) && SameBits(now.baoa, old.baoa))
        << "case " << i;
    const float t_old = OldIntersectCapsule(old, d);
    const float t_now = IntersectCapsule(now, AsFloat3(d));
    ASSERT_TRUE(SameBits(t_now, t_old)) << "case " << i << ": " << t_now << " vs " << t_old;
    if (!(t_old > 0)) continue;
    ++hits;
    const Eigen::Vector3f p = o + t_old * d;
    const float w = (p - a).dot(b - a) / std::max((b - a).squaredNorm(), 1e-20f);
    if (w <= 0 || w >= 1) ++caps;
    // the normal for the unit direction and for a longer one (the splat's rays are not unit)
    for (const Eigen::Vector3f& dd : {d, Eigen::Vector3f(2.5f * d)}) {
      const Float3 n = CapsuleNormal(AsFloat3(p), AsFloat3(a), AsFloat3(b), AsFloat3(dd));
      ASSERT_TRUE(SameBits(n, OldNormal(p, a, b, dd))) << "case " << i;
    }
    // a point on the axis: the normal is -d normalised
    const Float3 n_axis = CapsuleNormal(AsFloat3(a), AsFloat3(a), AsFloat3(b), AsFloat3(d));
    ASSERT_TRUE(SameBits(n_axis, OldNormal(a, a, b, d)));
    shared_origin += SameBits(t_now, IntersectCapsule(now, AsFloat3(d))) ? 1 : 0;
  }
  std::printf("%d capsule cases: %d hits (%d on an end cap)\n", kCases, hits, caps);
  EXPECT_GT(hits, kCases / 4);
  EXPECT_GT(caps, kCases / 50);
  EXPECT_EQ(shared_origin, hits);
}

// ParticleStreaks::Shade (now ShadeStreak over the LightSampler's pods) against the old Eigen
// code for rain (precomputed and not), snow and sparks under a sun with an angular radius, a
// point light, a spot light and a lamp sphere, at random points and normals; and every rain
// streak's precomputed radiance (PrecomputeRain, which calls Shade) equals the old code's at the
// streak's centre.
TEST(ParticleMathTest, ShadeEqualsTheOldCodeBitForBit) {
  SceneDescription s;
  s.bodies.push_back({"world", -1, true});
  Light sun;
  sun.type = Light::Type::kDirectional;
  sun.direction_B = {-0.5f, 0.4f, -0.7f};
  sun.intensity = 52500;
  sun.color = {1.0f, 0.96f, 0.9f};
  sun.angular_radius_deg = 0.2665f;
  Light point;
  point.type = Light::Type::kPoint;
  point.position_B = {1, 2, 3};
  point.intensity = 300;
  Light spot;
  spot.type = Light::Type::kSpot;
  spot.position_B = {0, 0, 4};
  spot.direction_B = {0, 0.2f, -1};
  spot.intensity = 900;
  spot.spot_inner_deg = 20;
  spot.spot_outer_deg = 45;
  Light lamp = point;
  lamp.position_B = {-2, 1, 2.5f};
  lamp.radius_m = 0.1f;
  s.lights = {sun, point, spot, lamp};
  LightSampler lights(s);
  WorldSnapshot snap;
  snap.X_WB.assign(1, Pose::Identity());
  lights.Update(snap);

  Rng rng(7);
  EffectsFrame fx;
  const ParticleKind kinds[3] = {ParticleKind::kRain, ParticleKind::kSnow, ParticleKind::kSpark};
  for (ParticleKind kind : kinds) {
    ParticleSet ps;
    ps.kind = kind;
    ps.color = RandomIn(&rng, 0.5f, 1.0f);
    ps.emission = kind == ParticleKind::kSpark ? RandomIn(&rng, 10, 50) : RandomIn(&rng, 0, 0.1f);
    for (int i = 0; i < 300; ++i) {
      ps.position_W.push_back(RandomIn(&rng, -4, 4));
      ps.velocity_W.push_back(RandomIn(&rng, -5, 5));
      ps.radius_m.push_back(0.001f);
    }
    fx.particles.push_back(ps);
  }
  CameraIntrinsics k = CameraIntrinsics::FromFovy(64, 48, 60);
  const Camera camera(Pose::Identity(), k);
  ParticleStreaks streaks;
  streaks.Build(&fx, camera, 0.01, StreakRays::kAny);
  ASSERT_EQ(streaks.size(), 900);
  const Eigen::Vector3f sky_ambient(2100, 2300, 2900);
  streaks.PrecomputeRain(lights, sky_ambient, nullptr, nullptr);
  ASSERT_EQ(static_cast<int>(streaks.rain_radiance().size()), streaks.size());
  for (int n = 0; n < streaks.size(); ++n) {
    const int set = streaks.set_of()[n];
    const Eigen::Vector3f c =
        0.5f * (streaks.ends()[2 * n].head<3>() + streaks.ends()[2 * n + 1].head<3>());
    const ParticleKind kind = fx.particles[set].kind;
    const Eigen::Vector3f want = kind == ParticleKind::kRain
                                     ? OldShade(kind, fx.particles[set], nullptr, c,
                                                Eigen::Vector3f(0, 0, 1), lights, sky_ambient)
                                     : Eigen::Vector3f::Zero();
    const Eigen::Vector3f& got = streaks.rain_radiance()[n];
    ASSERT_TRUE(SameBits(AsFloat3(got), want)) << "streak " << n;
  }
  int lit = 0;
  for (int i = 0; i < 100000; ++i) {
    ParticleHit hit;
    hit.prim = static_cast<int>(rng.Uniform() * (streaks.size() + 20)) - 10;  // some out of range
    hit.set = std::clamp(hit.prim, 0, streaks.size() - 1);
    hit.set = streaks.set_of()[hit.set];
    hit.kind = fx.particles[hit.set].kind;
    hit.ng_W = RandomUnit(&rng);
    const Eigen::Vector3f p = RandomIn(&rng, -6, 6);
    const bool pre = hit.kind == ParticleKind::kRain && hit.prim >= 0 && hit.prim < streaks.size();
    const Eigen::Vector3f want = OldShade(hit.kind, fx.particles[hit.set],
                                          pre ? &streaks.rain_radiance()[hit.prim] : nullptr, p,
                                          hit.ng_W, lights, sky_ambient);
    const Eigen::Vector3f got = streaks.Shade(hit, p, lights, sky_ambient);
    ASSERT_TRUE(SameBits(AsFloat3(got), want)) << "case " << i;
    // the shared function called directly (as the paths call it)
    const StreakSetPod set = streaks.SetPod(hit.set);
    const Float3 rain = pre ? AsFloat3(streaks.rain_radiance()[hit.prim]) : Float3{};
    const Float3 direct =
        ShadeStreak(set, pre ? &rain : nullptr, AsFloat3(p), AsFloat3(hit.ng_W),
                    lights.pods().data(), lights.size(), SkyVolumePod(), AsFloat3(sky_ambient));
    ASSERT_TRUE(SameBits(direct, want)) << "case " << i;
    if (hit.kind == ParticleKind::kSnow &&
        (want - fx.particles[hit.set].color.cwiseProduct(sky_ambient) -
         fx.particles[hit.set].emission)
                .maxCoeff() > 0)
      ++lit;
  }
  EXPECT_GT(lit, 1000);  // snow lit by the lights, not only the sky
}

}  // namespace
}  // namespace penumbra

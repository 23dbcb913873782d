// the shared streak functions of render/particles/particle_math.h (the ray-capsule test, the
// capsule's normal, the streak's radiance ShadeStreak) against the Eigen code that ParticleStreaks
// ran before they moved there (restated below as it was), bit for bit on many random inputs: the
// CPU backend's particle images did not change, and the CUDA backend's paths (path_streaks.h)
// compute what the CPU computes.

#include "penumbra/render/particles/particle_math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "penumbra/core/rng.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/particles/particle_streaks.h"

namespace penumbra {
namespace {

// ---- the code before the move (render/particles/particle_streaks.cc at main 6da4288), restated
// ----

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

// ---- the realtime splat's projection before it moved to particle_math.h, as
// ParticleStreaks::BuildPixelHits ran it at main 58c0de3 ----

struct OldProjection {
  bool empty = true;
  Eigen::Vector4i box{0, -1, 0, -1};
  float ua = 0, va = 0, ub = 0, vb = 0, rp = 0;
};

OldProjection OldProject(const Eigen::Matrix3f& R_OW, const Eigen::Vector3f& p_OW,
                         const CameraIntrinsics& k, const Eigen::Vector3f& a,
                         const Eigen::Vector3f& b, float r) {
  OldProjection out;
  const int W = k.width, H = k.height;
  constexpr float kNear = 0.01f;
  Eigen::Vector3f ao = R_OW * a + p_OW;
  Eigen::Vector3f bo = R_OW * b + p_OW;
  const float zmin = kNear + r;
  if (ao.z() < zmin && bo.z() < zmin) return out;
  if (ao.z() < zmin) ao = bo + (ao - bo) * ((bo.z() - zmin) / (bo.z() - ao.z()));
  if (bo.z() < zmin) bo = ao + (bo - ao) * ((ao.z() - zmin) / (ao.z() - bo.z()));
  const float z_near = std::min(ao.z(), bo.z()) - r;
  const float rp = static_cast<float>(std::max(k.fx, k.fy)) * r / std::max(z_near, kNear) + 1.0f;
  const float ua = static_cast<float>(k.fx * ao.x() / ao.z() + k.cx);
  const float va = static_cast<float>(k.fy * ao.y() / ao.z() + k.cy);
  const float ub = static_cast<float>(k.fx * bo.x() / bo.z() + k.cx);
  const float vb = static_cast<float>(k.fy * bo.y() / bo.z() + k.cy);
  out = OldProjection{
      false,
      Eigen::Vector4i(std::max(0, static_cast<int>(std::floor(std::min(ua, ub) - rp))),
                      std::min(W - 1, static_cast<int>(std::ceil(std::max(ua, ub) + rp))),
                      std::max(0, static_cast<int>(std::floor(std::min(va, vb) - rp))),
                      std::min(H - 1, static_cast<int>(std::ceil(std::max(va, vb) + rp)))),
      ua,
      va,
      ub,
      vb,
      rp};
  return out;
}

void OldRowColumns(const OldProjection& p, int v, int* c0, int* c1) {
  const float du = p.ub - p.ua, dv = p.vb - p.va;
  float s0 = 0, s1 = 1;
  if (std::abs(dv) > 1e-6f) {
    s0 = std::clamp((v - p.rp - p.va) / dv, 0.0f, 1.0f);
    s1 = std::clamp((v + p.rp - p.va) / dv, 0.0f, 1.0f);
    if (s0 > s1) std::swap(s0, s1);
  }
  const float ul = std::min(p.ua + s0 * du, p.ua + s1 * du) - p.rp;
  const float uh = std::max(p.ua + s0 * du, p.ua + s1 * du) + p.rp;
  *c0 = std::max(p.box[0], static_cast<int>(std::floor(ul)));
  *c1 = std::min(p.box[1], static_cast<int>(std::ceil(uh)));
}

// the realtime splat's projection (StreakToOptical, ProjectStreak, StreakRowColumns) and pixel
// test (IntersectCapsuleRay), now shared by ParticleStreaks::BuildPixelHits and the CUDA
// backend's splat kernel, against the code before the move, bit for bit: random pinhole cameras
// (640x480 and 160x120, random poses) and streaks around them (in front, behind, crossing the
// near plane, off the image; lengths up to 1 m, radii 0.1 mm to 5 cm), every row of every box,
// and the pixel-centre rays of the first row's columns.
TEST(ParticleMathTest, SplatProjectionEqualsTheOldCodeBitForBit) {
  Rng rng(20261127);
  int boxes = 0, clipped = 0, rows = 0, hits = 0;
  constexpr int kCases = 100000;
  for (int i = 0; i < kCases; ++i) {
    CameraIntrinsics k = i % 2 == 0 ? CameraIntrinsics::FromFovy(640, 480, 40 + 40 * rng.Uniform())
                                    : CameraIntrinsics::FromFovy(160, 120, 60);
    k.cx += rng.Uniform() - 0.5;
    const Eigen::Vector3d axis = RandomUnit(&rng).cast<double>();
    Pose X_WO = Pose::Identity();
    X_WO.linear() = Eigen::AngleAxisd(3 * rng.Uniform(), axis).toRotationMatrix();
    X_WO.translation() = RandomIn(&rng, -5, 5).cast<double>();
    const Camera camera(X_WO, k);
    const Pose X_OW = X_WO.inverse();
    const Eigen::Matrix3f R_OW = X_OW.linear().cast<float>();
    const Eigen::Matrix<float, 3, 3, Eigen::RowMajor> R_row = R_OW;
    const Eigen::Vector3f p_OW = X_OW.translation().cast<float>();
    // a streak in the optical frame (z from -1 to 10 m), then in the world
    const Eigen::Vector3f a_O(4 * (rng.Uniform() - 0.5f), 3 * (rng.Uniform() - 0.5f),
                              -1 + 11 * rng.Uniform() * rng.Uniform());
    const Eigen::Vector3f b_O = a_O + RandomIn(&rng, -0.5f, 0.5f);
    const float r = 1e-4f + 0.05f * rng.Uniform() * rng.Uniform();
    const Eigen::Vector3f a = (X_WO * a_O.cast<double>()).cast<float>();
    const Eigen::Vector3f b = (X_WO * b_O.cast<double>()).cast<float>();
    const Float3 ao = StreakToOptical(R_row.data(), AsFloat3(p_OW), AsFloat3(a));
    ASSERT_TRUE(SameBits(ao, R_OW * a + p_OW)) << "case " << i;
    const Float3 bo = StreakToOptical(R_row.data(), AsFloat3(p_OW), AsFloat3(b));
    const StreakProjection now =
        ProjectStreak(ao, bo, r, k.fx, k.fy, k.cx, k.cy, k.width, k.height);
    const OldProjection old = OldProject(R_OW, p_OW, k, a, b, r);
    if (old.empty) {
      ASSERT_TRUE(now.empty()) << "case " << i;
      continue;
    }
    ASSERT_TRUE(SameBits(now.ua, old.ua) && SameBits(now.va, old.va) && SameBits(now.ub, old.ub) &&
                SameBits(now.vb, old.vb) && SameBits(now.rp, old.rp))
        << "case " << i;
    ASSERT_EQ(now.u0, old.box[0]) << "case " << i;
    ASSERT_EQ(now.u1, old.box[1]) << "case " << i;
    ASSERT_EQ(now.v0, old.box[2]) << "case " << i;
    ASSERT_EQ(now.v1, old.box[3]) << "case " << i;
    if (now.empty()) continue;
    ++boxes;
    clipped += (a_O.z() < 0.01f + r) != (b_O.z() < 0.01f + r) ? 1 : 0;
    for (int v = now.v0; v <= now.v1; ++v) {
      int c0, c1, o0, o1;
      StreakRowColumns(now, v, &c0, &c1);
      OldRowColumns(old, v, &o0, &o1);
      ASSERT_EQ(c0, o0) << "case " << i << " row " << v;
      ASSERT_EQ(c1, o1) << "case " << i << " row " << v;
      ++rows;
      if (v != now.v0) continue;
      // the pixel test: t / |d| of the unit ray, as BuildPixelHits computed it
      const CapsuleOrigin c =
          MakeCapsuleOrigin(AsFloat3(camera.GenerateRay(0, 0).o), AsFloat3(a), AsFloat3(b), r);
      for (int u = c0; u <= c1; ++u) {
        const Ray ray = camera.GenerateRay(static_cast<float>(u), static_cast<float>(v));
        const float len = ray.d.norm();
        const float t = IntersectCapsule(c, AsFloat3(ray.d / len));
        const float want = t > 0 ? t / len : -1.0f;
        ASSERT_TRUE(SameBits(IntersectCapsuleRay(c, AsFloat3(ray.d)), want)) << "case " << i;
        hits += t > 0 ? 1 : 0;
      }
    }
  }
  std::printf(
      "%d projection cases: %d boxes in the image (%d clipped at the near plane), %d rows, "
      "%d pixel hits\n",
      kCases, boxes, clipped, rows, hits);
  EXPECT_GT(boxes, kCases / 4);
  EXPECT_GT(clipped, 100);
  EXPECT_GT(hits, 1000);
}

// the splat's StreakKey: the smallest key is the nearest t, ties the lower index; its parts come
// back unchanged.
TEST(ParticleMathTest, StreakKeyOrdersByTThenIndex) {
  EXPECT_LT(StreakKey(0.5f, 7), StreakKey(0.75f, 3));
  EXPECT_LT(StreakKey(1e-30f, 100), StreakKey(2e-30f, 0));
  EXPECT_LT(StreakKey(3.0f, 2), StreakKey(3.0f, 5));
  EXPECT_LT(StreakKey(1e30f, 0x7ffffffe), kNoStreakKey);
  EXPECT_EQ(StreakKeyT(StreakKey(1.25f, 123456)), 1.25f);
  EXPECT_EQ(StreakKeyIndex(StreakKey(1.25f, 123456)), 123456);
}

}  // namespace
}  // namespace penumbra

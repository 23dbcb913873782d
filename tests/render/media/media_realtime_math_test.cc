// the realtime media's shared per-pixel formulas (render/media/media_realtime_math.h): the CPU's
// SSE restatement of the world light volume's lookup against the shared CellLightsLookup, the
// froxel lookups of the device's record type (Rgb4) against the CPU's (Eigen::Array4f), a
// frame's view segments and light transmittances over RealtimeMedia::HostView against the CPU's
// IntegrateView and surface loop (homogeneous media, grids, both), the grids' light volumes and
// froxels that Build makes with media_build_math.h against the former Eigen code's, and
// RayQuery's batched
// occlusion (its default through closest hits and Embree's rtcOccluded1) that the light volumes
// trace their shadow rays with.

#include "penumbra/render/media/media_realtime_math.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/camera/camera.h"
#include "penumbra/render/embree/ray_scene.h"
#include "penumbra/render/light/light_sampler.h"
#include "penumbra/render/media/media_common.h"
#include "penumbra/render/media/media_realtime.h"
#include "penumbra/render/media/media_scene.h"
#include "penumbra/render/sky/sky_irradiance_volume.h"
#include "penumbra/render/sky/sky_model.h"
#include "render/media_test_util.h"

namespace penumbra::testing {
namespace {

bool SameBits(float a, float b) { return std::memcmp(&a, &b, sizeof(float)) == 0; }

// a floor, a wall and a pillar under five point lights (a stride of 8 lights per cell).
SceneDescription LitRoom() {
  SceneDescription s = EmptyScene();
  const int m = AddMaterial(&s, Eigen::Vector3f::Constant(0.5f));
  AddGeom(&s, GeomShape::kBox, {6, 6, 0.05}, Translation(0, 0, -0.05), 0, m);
  AddGeom(&s, GeomShape::kBox, {0.1, 6, 2}, Translation(3, 0, 2), 0, m);
  AddGeom(&s, GeomShape::kBox, {0.3, 0.3, 1.5}, Translation(0.5, 0.5, 1.5), 0, m);
  for (int i = 0; i < 5; ++i) {
    Light l;
    l.type = Light::Type::kPoint;
    l.position_B = {-2.0 + i, -1.0 + 0.5 * i, 2.5};
    l.intensity = 100;
    s.lights.push_back(l);
  }
  return s;
}

TEST(MediaRealtimeMathTest, SseLightVolumeLookupIsTheSharedOneBitForBit) {
  const SceneDescription s = LitRoom();
  EffectsFrame fx;
  HomogeneousMedium fog = Fog(0.2f, 0.9f, 0.3f);
  fog.height_falloff_per_m = 0.3f;
  fx.homogeneous_media.push_back(fog);
  const WorldSnapshot snap = IdentitySnapshot(s);
  LightSampler lights(s);
  lights.Update(snap);
  RayScene rays(s);
  rays.Update(snap);
  const CameraView view = MakeView(CameraLookingAlongX({-3, 0, 1.2}), 96, 72, 60.0);
  const Camera camera(view.X_WO, view.intrinsics);
  MediaScene media;
  media.Build(&fx);
  RealtimeMedia rm;
  rm.Build(media, lights, rays, camera, 99, Eigen::Vector3f(0, 0, 2), 4.0,
           Eigen::Vector3f::Constant(0.3f), nullptr, nullptr);
  const CellLightsPod& pod = rm.light_volume_pod();
  ASSERT_EQ(pod.stride, 8);
  ASSERT_FALSE(rm.light_volume_visibility().empty());
  Rng rng(7);
  int inside = 0, outside = 0, occluded_entries = 0;
  for (int i = 0; i < 20000; ++i) {
    // points over and beyond the volume's box, and some on its faces and cell centres.
    Eigen::Vector3f p(-5 + 10 * rng.Uniform(), -5 + 10 * rng.Uniform(), -1 + 8 * rng.Uniform());
    if (i % 10 == 0) p.x() = pod.lo[0];
    if (i % 10 == 1) p.z() = pod.hi[2];
    float sse_t[kMaxVolumeLights], shared_t[kMaxVolumeLights];
    float sse_v[kMaxVolumeLights], shared_v[kMaxVolumeLights];
    const bool in_sse = rm.LightTransmittances(p, sse_t);
    const bool in_shared =
        CellLightsLookup(pod, rm.light_volume_transmittance().data(), p.data(), shared_t);
    ASSERT_EQ(in_sse, in_shared) << i;
    ASSERT_EQ(rm.LightVisibilities(p, sse_v),
              CellLightsLookup(pod, rm.light_volume_visibility().data(), p.data(), shared_v));
    if (!in_sse) {
      ++outside;
      continue;
    }
    ++inside;
    for (int j = 0; j < pod.stride; ++j) {
      ASSERT_TRUE(SameBits(sse_t[j], shared_t[j])) << i << " light " << j;
      ASSERT_TRUE(SameBits(sse_v[j], shared_v[j])) << i << " light " << j;
      occluded_entries += j < 5 && shared_v[j] < shared_t[j] ? 1 : 0;
    }
  }
  EXPECT_GT(inside, 2000);
  EXPECT_GT(outside, 2000);
  EXPECT_GT(occluded_entries, 100);  // the pillar and the wall shadow some of the lights
}

bool SameF3(const Eigen::Vector3f& a, const Float3& b) {
  return SameBits(a.x(), b.x) && SameBits(a.y(), b.y) && SameBits(a.z(), b.z);
}

// what CheckViewAgainstCpu compared.
struct ViewCounts {
  int segments = 0, lit = 0, quad_pixels = 0, located = 0, closed = 0;
  int grid_shadowed = 0;  // closed-form transmittances a grid's light volume lowered
};

// MediaViewSegment (per pixel, and with MediaPrepareQuad's shared quad lookups) and
// MediaLightTransmittance over rm.HostView against the CPU's IntegrateView (without and with
// PrepareQuad's MediaQuad) and its surface loop's transmittance, bit for bit: the view rays of
// the W x H `camera` (every other pixel, the border and beyond) to four distances, every 2x2
// quad with surfaces at varying distances and sky quads, 4,000 surface points x every light.
ViewCounts CheckViewAgainstCpu(const RealtimeMedia& rm, const LightSampler& lights,
                               const Camera& camera, int W, int H) {
  ViewCounts n;
  RealtimeMediaHostArrays arrays;
  const RealtimeMediaView mv = rm.HostView(&arrays);
  const float inf = std::numeric_limits<float>::infinity();
  for (int v = -1; v <= H; v += 2) {  // the image's border rows and columns and beyond
    for (int u = -1; u <= W; u += 2) {
      const Ray r = camera.GenerateRay(static_cast<float>(u), static_cast<float>(v));
      const Eigen::Vector3f d = r.d.normalized();
      for (const float t_end : {inf, 25.0f, 3.7f, 0.2f}) {
        const MediaSegment cpu = rm.IntegrateView(lights, r.o, d, t_end, u, v);
        Float3 T, L;
        MediaViewSegment(mv, u, v, r.o.data(), d.data(), t_end, &T, &L);
        EXPECT_TRUE(SameF3(cpu.T, T)) << u << " " << v << " " << t_end;
        EXPECT_TRUE(SameF3(cpu.L_add, L)) << u << " " << v << " " << t_end;
        if (!SameF3(cpu.T, T) || !SameF3(cpu.L_add, L)) return n;
        ++n.segments;
        n.lit += cpu.L_add.maxCoeff() > 0 ? 1 : 0;
      }
    }
  }
  // 2x2 quads sharing their lookups (the realtime integrator's MediaQuads): surfaces at
  // distances that vary over the image, and sky quads.
  for (int v0 = 0; v0 < H; v0 += 2) {
    for (int u0 = 0; u0 < W; u0 += 2) {
      const bool sky_quad = (u0 / 2 + v0 / 2) % 5 == 0;
      Eigen::Vector3f o[4], d[4];
      float t[4];
      Eigen::Vector3f d_sum = Eigen::Vector3f::Zero();
      for (int c = 0; c < 4; ++c) {
        const Ray r =
            camera.GenerateRay(static_cast<float>(u0 + (c & 1)), static_cast<float>(v0 + (c >> 1)));
        o[c] = r.o;
        d[c] = r.d.normalized();
        d_sum += d[c];
        t[c] = sky_quad ? inf : 2.0f + 0.1f * (u0 + (c & 1)) + 0.05f * (v0 + (c >> 1));
      }
      const float t_c = sky_quad ? inf : 0.25f * (t[0] + t[1] + t[2] + t[3]);
      const Eigen::Vector3f d_c = d_sum.normalized();
      MediaQuad cpu_q;
      rm.PrepareQuad(u0, v0, t_c, o[0], d_c, &cpu_q);
      MediaQuadShared q;
      MediaPrepareQuad(mv, u0, v0, t_c, o[0].data(), d_c.data(), &q);
      for (int c = 0; c < 4; ++c) {
        const int u = u0 + (c & 1), v = v0 + (c >> 1);
        for (const float te :
             {t[c], sky_quad ? 1.0f : 1.01f * t_c, sky_quad ? 3.0f : 0.5f * t[c]}) {
          const MediaSegment cpu = rm.IntegrateView(lights, o[c], d[c], te, u, v, &cpu_q);
          Float3 T, L;
          MediaViewSegment(mv, u, v, o[c].data(), d[c].data(), te, &T, &L, &q);
          EXPECT_TRUE(SameF3(cpu.T, T)) << u << " " << v << " " << te;
          EXPECT_TRUE(SameF3(cpu.L_add, L)) << u << " " << v << " " << te;
          if (!SameF3(cpu.T, T) || !SameF3(cpu.L_add, L)) return n;
          ++n.quad_pixels;
        }
      }
    }
  }
  // surface points: the CPU's loop takes the volume's lookup where it holds the point and the
  // light (LightTransmittances), else LightTransmittance.
  RealtimeMediaView no_grids = mv;
  no_grids.num_grids = 0;
  Rng rng(9);
  for (int i = 0; i < 4000; ++i) {
    const Eigen::Vector3f p(-6 + 12 * rng.Uniform(), -6 + 12 * rng.Uniform(), 4 * rng.Uniform());
    float vol_T[kMaxVolumeLights];
    const bool in = rm.LightTransmittances(p, vol_T);
    for (int j = 0; j < lights.size(); ++j) {
      LightSample ls;
      if (!lights.Sample(j, p, 0.5f, 0.5f, &ls)) continue;
      const Eigen::Vector3f cpu = in && j < rm.num_volume_lights()
                                      ? Eigen::Vector3f::Constant(vol_T[j])
                                      : rm.LightTransmittance(j, p, ls.wi, ls.distance);
      const Float3 shared = MediaLightTransmittance(mv, j, p.data(), ls.wi.data(), ls.distance);
      EXPECT_TRUE(SameF3(cpu, shared)) << i << " light " << j;
      if (!SameF3(cpu, shared)) return n;
      const bool located = in && j < rm.num_volume_lights();
      (located ? n.located : n.closed) += 1;
      if (!located) {
        const Float3 h = MediaLightTransmittance(no_grids, j, p.data(), ls.wi.data(), ls.distance);
        n.grid_shadowed += shared.x < h.x ? 1 : 0;
      }
    }
  }
  return n;
}

// the two view tests' frame of scene s at rest: its lights, Embree scene, sky irradiance
// volume and a 96 x 72 camera at (-3, 0.2, 1.2) looking along +x (70 deg vertical field).
struct LitFrame {
  static constexpr int kWidth = 96, kHeight = 72;
  explicit LitFrame(const SceneDescription& s)
      : snap(IdentitySnapshot(s)),
        lights(s),
        rays(s),
        sky(s.sky),
        pool(2),
        volume([](const SceneDescription& sc) {
          return MakeRayQuery(sc, RenderSettings::Backend::kEmbree);
        }),
        view(MakeView(CameraLookingAlongX({-3, 0.2f, 1.2}), kWidth, kHeight, 70.0)),
        camera(view.X_WO, view.intrinsics) {
    lights.Update(snap);
    rays.Update(snap);
    volume.Update(s, snap, sky, &pool);
  }
  const WorldSnapshot snap;
  LightSampler lights;
  RayScene rays;
  const SkyModel sky;
  ThreadPool pool;
  SkyIrradianceVolume volume;
  const CameraView view;
  const Camera camera;
};

// in the lit room with a sky volume (the sky at the in-scatter median point), non-grey height
// fog and a boxed haze.
TEST(MediaRealtimeMathTest, ViewSegmentAndLightTransmittanceAreTheCpusBitForBit) {
  SceneDescription s = LitRoom();
  Sky sky_desc;
  sky_desc.type = Sky::Type::kDaylight;
  sky_desc.sun_direction_W = Eigen::Vector3d(-0.28, -0.77, 0.57).normalized();
  sky_desc.turbidity = 3;
  sky_desc.zenith_luminance = 8000;
  s.sky = sky_desc;
  EffectsFrame fx;
  HomogeneousMedium fog = Fog(0.15f, 0.9f, 0.4f);
  fog.sigma_t_per_m = Eigen::Vector3f(0.12f, 0.15f, 0.2f);  // not grey
  fog.height_falloff_per_m = 0.4f;
  fog.base_height_m = 0.5f;
  fx.homogeneous_media.push_back(fog);
  HomogeneousMedium haze = Fog(0.3f, 0.7f, 0.0f);
  haze.region = BoxRegion{Eigen::Vector3d(-1, -2, 0), Eigen::Vector3d(2, 2, 1.5)};
  fx.homogeneous_media.push_back(haze);
  LitFrame f(s);
  ASSERT_FALSE(f.volume.empty());
  MediaScene media;
  media.Build(&fx);
  RealtimeMedia rm;
  rm.Build(media, f.lights, f.rays, f.camera, 5, Eigen::Vector3f(0, 0, 2), 4.0,
           Eigen::Vector3f(0.3f, 0.4f, 0.6f), &f.volume, &f.pool);
  RealtimeMediaHostArrays arrays;
  const RealtimeMediaView mv = rm.HostView(&arrays);
  ASSERT_NE(mv.fog_S, nullptr);
  ASSERT_NE(mv.sky_volume, nullptr);
  ASSERT_NE(mv.light_trans, nullptr);
  ASSERT_EQ(mv.grid_records, nullptr);
  const ViewCounts n =
      CheckViewAgainstCpu(rm, f.lights, f.camera, LitFrame::kWidth, LitFrame::kHeight);
  EXPECT_GT(n.segments, 3000);
  EXPECT_GT(n.lit, n.segments / 2);
  EXPECT_GT(n.quad_pixels, 15000);
  EXPECT_GT(n.located, 1000);
  EXPECT_GT(n.closed, 1000);
}

// LitRoom under a daylight sky.
SceneDescription SkyLitRoom() {
  SceneDescription s = LitRoom();
  Sky sky_desc;
  sky_desc.type = Sky::Type::kDaylight;
  sky_desc.sun_direction_W = Eigen::Vector3d(-0.28, -0.77, 0.57).normalized();
  sky_desc.zenith_luminance = 8000;
  s.sky = sky_desc;
  return s;
}

// two grids in LitRoom: a smoke grid with a density ramp turned about z and y, and an emissive
// grid.
EffectsFrame TwoGrids() {
  EffectsFrame grids;
  GridMedium smoke = RampGrid({1, 0.3, 1.2}, {1.2, 0.9, 1.0}, 20, 1.0f, 0.4f, 1.2f, 0.8f);
  smoke.X_WG.linear() = (Eigen::AngleAxisd(0.5, Eigen::Vector3d::UnitZ()) *
                         Eigen::AngleAxisd(0.2, Eigen::Vector3d::UnitY()))
                            .toRotationMatrix();
  grids.grid_media.push_back(smoke);
  GridMedium fire = RampGrid({-0.5, -1.0, 0.6}, {0.4, 0.4, 0.6}, 8, 0.6f, 0.2f, 2.0f, 0.3f);
  auto e = std::make_shared<std::vector<float>>(static_cast<size_t>(8) * 2 * 2 * 3);
  for (size_t i = 0; i < e->size(); ++i) (*e)[i] = 40.0f + 5.0f * static_cast<float>(i % 7);
  fire.emission = e;
  grids.grid_media.push_back(fire);
  return grids;
}

// `fx` with non-grey height fog added.
EffectsFrame WithHeightFog(EffectsFrame fx) {
  HomogeneousMedium fog = Fog(0.15f, 0.9f, 0.4f);
  fog.sigma_t_per_m = Eigen::Vector3f(0.12f, 0.15f, 0.2f);
  fog.height_falloff_per_m = 0.4f;
  fx.homogeneous_media.push_back(fog);
  return fx;
}

// a smoke grid turned about z and y (GridVolume::ToGrid's 3x3 product) with a density ramp and
// an emissive grid (fire), in the lit room: alone (smoke_plume's and fire's case: no homogeneous
// media, no sky volume) and with height fog and a sky volume (adversity_major's: the
// homogeneous in-scatter behind a grid's entry attenuated by it).
TEST(MediaRealtimeMathTest, GridViewSegmentAndLightTransmittanceAreTheCpusBitForBit) {
  SceneDescription s = SkyLitRoom();
  const EffectsFrame grids = TwoGrids();
  LitFrame f(s);
  // ToGrid's product restated: the same bits
  MediaScene probe;
  probe.Build(&grids);
  ASSERT_EQ(probe.grids().size(), 2u);
  RealtimeMedia probe_rm;
  probe_rm.Build(probe, f.lights, f.rays, f.camera, 3, Eigen::Vector3f(0, 0, 2), 4.0,
                 Eigen::Vector3f::Constant(0.3f), nullptr, &f.pool);
  RealtimeMediaHostArrays probe_arrays;
  const RealtimeMediaView pv = probe_rm.HostView(&probe_arrays);
  ASSERT_EQ(pv.num_grids, 2);
  Rng rng(4);
  for (int i = 0; i < 2000; ++i) {
    const Eigen::Vector3f x(-5 + 10 * rng.Uniform(), -5 + 10 * rng.Uniform(), 4 * rng.Uniform());
    float x_G[3], d_G[3];
    GridToFrame(pv.grids[0], x.data(), x_G);
    GridRotate(pv.grids[0], x.data(), d_G);
    const GridVolume& g = probe.grids()[0];
    const Eigen::Vector3f want = g.ToGrid(x), want_d = g.R_GW * x;
    for (int k = 0; k < 3; ++k) {
      ASSERT_TRUE(SameBits(want[k], x_G[k])) << i;
      ASSERT_TRUE(SameBits(want_d[k], d_G[k])) << i;
    }
  }
  for (const bool with_fog : {false, true}) {
    const EffectsFrame fx = with_fog ? WithHeightFog(grids) : grids;
    MediaScene media;
    media.Build(&fx);
    RealtimeMedia rm;
    rm.Build(media, f.lights, f.rays, f.camera, 5, Eigen::Vector3f(0, 0, 2), 4.0,
             Eigen::Vector3f(0.3f, 0.4f, 0.6f), with_fog ? &f.volume : nullptr, &f.pool);
    RealtimeMediaHostArrays arrays;
    const RealtimeMediaView mv = rm.HostView(&arrays);
    ASSERT_NE(mv.grid_records, nullptr);
    ASSERT_EQ(mv.num_grids, 2);
    ASSERT_EQ(mv.fog_S != nullptr, with_fog);
    const ViewCounts n =
        CheckViewAgainstCpu(rm, f.lights, f.camera, LitFrame::kWidth, LitFrame::kHeight);
    std::printf(
        "grids%s: %d segments (%d lit), %d quad pixels, %d + %d light transmittances "
        "(%d lowered by a grid outside the world light volume)\n",
        with_fog ? " and fog" : "", n.segments, n.lit, n.quad_pixels, n.located, n.closed,
        n.grid_shadowed);
    EXPECT_GT(n.segments, 3000);
    EXPECT_GT(n.lit, 300);
    EXPECT_GT(n.quad_pixels, 15000);
    EXPECT_GT(n.located, 1000);
    EXPECT_GT(n.closed, 1000);
    EXPECT_GT(n.grid_shadowed, 20);
  }
}

// froxel records of a few columns with rgb in lanes 0..2, as both record types.
struct Records {
  std::vector<Eigen::Array4f> eigen;
  std::vector<Rgb4> rgb4;
  std::vector<float> inv_log_far;
};
Records MakeRecords(int columns) {
  Records r;
  Rng rng(3);
  for (int c = 0; c < columns; ++c) {
    r.inv_log_far.push_back(1.0f / std::log((2.0f + 60 * rng.Uniform()) / kFogFroxelNear));
    Eigen::Array4f S = Eigen::Array4f::Zero();
    r.eigen.push_back(S);
    r.rgb4.push_back({0, 0, 0, 0});
    for (int k = 0; k < kFogFroxelSlices; ++k) {
      S += Eigen::Array4f(rng.Uniform(), 0.5f * rng.Uniform(), 2 * rng.Uniform(), 0);
      r.eigen.push_back(S);
      r.rgb4.push_back({S[0], S[1], S[2], S[3]});
    }
  }
  return r;
}

bool SameRgb(const Eigen::Array4f& a, const Rgb4& b) {
  return SameBits(a[0], b.x) && SameBits(a[1], b.y) && SameBits(a[2], b.z);
}

// RealtimeMedia's grid light volumes and grid froxels computed with the Eigen code, serial, one
// shadow ray at a time, apart from media_build_math.h's functions: the reference of
// GridVolumesAreTheFormerEigenCodesBitForBit.
struct FormerGridVolumes {
  std::vector<float> T;                 // [grid][light][cell] end to end
  std::vector<Eigen::Vector3f> source;  // [grid][cell] end to end
  std::vector<float> t0, t1, slices_per_m;
  std::vector<Eigen::Array4f> S, Tr;  // [column][boundary]
};
FormerGridVolumes FormerGridBuild(const MediaScene& media, const LightSampler& lights,
                                  const RayQuery& scene, const Camera& camera, uint64_t frame_key,
                                  const Eigen::Vector3f& sky_ambient,
                                  const SkyIrradianceVolume* sky_volume) {
  FormerGridVolumes out;
  const int nl = std::min(lights.size(), kMaxVolumeLights);
  auto sky_at = [&](const Eigen::Vector3f& p) {
    return sky_volume != nullptr ? sky_volume->AmbientRadiance(p, sky_ambient) : sky_ambient;
  };
  auto exp3 = [](const Eigen::Vector3f& x) -> Eigen::Vector3f {
    if (x.x() == x.y() && x.y() == x.z()) return Eigen::Vector3f::Constant(std::exp(x.x()));
    return x.array().exp().matrix();
  };
  struct GridLightRef {
    int r[3];
    Eigen::Vector3f cells_per_m;
    std::vector<Eigen::Vector3f> source;
  };
  std::vector<GridLightRef> gls;
  for (const GridVolume& v : media.grids()) {
    GridLightRef gl;
    const int n[3] = {v.nx, v.ny, v.nz};
    const Eigen::Vector3f size = 2 * v.half;
    const float cell = std::cbrt(size.prod() / kGridLightCells);
    for (int k = 0; k < 3; ++k) {
      gl.r[k] = std::clamp(static_cast<int>(std::ceil(size[k] / cell)), 1, n[k]);
      gl.cells_per_m[k] = gl.r[k] / size[k];
    }
    const float cell_m = (1.0f / gl.cells_per_m.array()).minCoeff();
    const int cells = gl.r[0] * gl.r[1] * gl.r[2];
    std::vector<float> T(static_cast<size_t>(nl) * cells, 1.0f);
    const Eigen::Matrix3f R_WG = v.R_GW.transpose();
    const float sigma = Mean3(v.sigma_t);
    for (int c = 0; c < cells; ++c) {
      const int i = c % gl.r[0], j = (c / gl.r[0]) % gl.r[1], k = c / (gl.r[0] * gl.r[1]);
      const Eigen::Vector3f x_G =
          -v.half + Eigen::Vector3f(i + 0.5f, j + 0.5f, k + 0.5f).cwiseQuotient(gl.cells_per_m);
      const Eigen::Vector3f p = R_WG * (x_G - v.p_GW);
      Eigen::Vector3f src = sky_at(p);
      for (int l = 0; l < nl; ++l) {
        LightSample ls;
        if (!lights.Sample(l, p, 0.5f, 0.5f, &ls)) {
          T[static_cast<size_t>(l) * cells + c] = 0.0f;
          continue;
        }
        float a, b, Tg = 1.0f;
        if (v.Interval(p, ls.wi, 0.0f, ls.distance, &a, &b)) {
          const int steps =
              std::clamp(static_cast<int>(std::ceil((b - a) / cell_m)), 1, kGridLightSteps);
          const float ds = (b - a) / steps;
          const Eigen::Vector3f o_G = v.ToGrid(p), d_G = v.R_GW * ls.wi;
          float tau = 0;
          for (int s = 0; s < steps; ++s) tau += v.DensityAt(o_G + (a + (s + 0.5f) * ds) * d_G);
          Tg = std::exp(-tau * sigma * ds);
        }
        T[static_cast<size_t>(l) * cells + c] = Tg;
        if (!(Tg > 1e-4f)) continue;
        if (ls.cast_shadow) {
          Ray sr;
          sr.o = p;
          sr.d = ls.wi;
          sr.tmax = std::isinf(ls.distance) ? std::numeric_limits<float>::infinity()
                                            : ls.distance * (1.0f - 1e-4f);
          bool blocked = false;
          scene.Occluded(std::span<const Ray>(&sr, 1), std::span<bool>(&blocked, 1));
          if (blocked) continue;
        }
        const float Th =
            media.analytic().empty()
                ? 1.0f
                : std::exp(-Mean3(media.AnalyticOpticalDepth(p, ls.wi, 0, ls.distance)));
        src += ls.E * (Tg * Th * kInv4Pi);
      }
      gl.source.push_back(src);
    }
    out.T.insert(out.T.end(), T.begin(), T.end());
    out.source.insert(out.source.end(), gl.source.begin(), gl.source.end());
    gls.push_back(gl);
  }
  const int W = camera.width(), H = camera.height();
  const int nx = (W + kFroxelBlock - 1) / kFroxelBlock, ny = (H + kFroxelBlock - 1) / kFroxelBlock;
  constexpr int Z = kFroxelSlices;
  const bool analytic = !media.analytic().empty();
  for (int c = 0; c < nx * ny; ++c) {
    const int uc = std::min((c % nx) * kFroxelBlock + kFroxelBlock / 2, W - 1);
    const int vc = std::min((c / nx) * kFroxelBlock + kFroxelBlock / 2, H - 1);
    const Ray r = camera.GenerateRay(static_cast<float>(uc), static_cast<float>(vc));
    const Eigen::Vector3f o = r.o, d = r.d.normalized();
    float a = std::numeric_limits<float>::infinity(), b = -a;
    for (const GridVolume& v : media.grids()) {
      float ga, gb;
      if (!v.Interval(o, d, 0.0f, std::numeric_limits<float>::infinity(), &ga, &gb)) continue;
      a = std::min(a, ga);
      b = std::max(b, gb);
    }
    Eigen::Vector3f S = Eigen::Vector3f::Zero(), T = Eigen::Vector3f::Ones();
    auto put = [&] {
      out.S.emplace_back(S.x(), S.y(), S.z(), 0.0f);
      out.Tr.emplace_back(T.x(), T.y(), T.z(), 0.0f);
    };
    put();
    if (!(a < b)) {
      for (int k = 0; k < Z; ++k) put();
      out.t0.push_back(0), out.t1.push_back(0), out.slices_per_m.push_back(0);
      continue;
    }
    out.t0.push_back(a), out.t1.push_back(b),
        out.slices_per_m.push_back(std::min(Z / (b - a), 1e30f));
    const float jitter = FroxelColumnJitter(frame_key, uc, vc, W, 2);
    const float ds = (b - a) / Z;
    for (int k = 0; k < Z; ++k) {
      const float t = a + (k + jitter) * ds;
      const Eigen::Vector3f p = o + t * d;
      Eigen::Vector3f sig_t = Eigen::Vector3f::Zero(), src = Eigen::Vector3f::Zero();
      for (size_t g = 0; g < media.grids().size(); ++g) {
        const GridVolume& v = media.grids()[g];
        const Eigen::Vector3f x = v.ToGrid(p);
        const float dens = v.DensityAt(x);
        if (dens > 0) {
          const GridLightRef& gl = gls[g];
          const Eigen::Vector3f f =
              (x + v.half).cwiseProduct(gl.cells_per_m) - Eigen::Vector3f::Constant(0.5f);
          sig_t += dens * v.sigma_t;
          src += (dens * v.sigma_s)
                     .cwiseProduct(MediaTrilinear(gl.source.data(), gl.r, f.x(), f.y(), f.z()));
        }
        if (v.emission) src += v.EmissionAt(x);
      }
      if (sig_t.maxCoeff() > 0 || src.maxCoeff() > 0) {
        if (analytic) src = src.cwiseProduct(exp3(-media.AnalyticOpticalDepth(o, d, 0, t)));
        const Eigen::Vector3f step_T = exp3(-sig_t * ds);
        Eigen::Vector3f factor;
        for (int ch = 0; ch < 3; ++ch)
          factor[ch] = sig_t[ch] * ds > 1e-5f ? (1.0f - step_T[ch]) / sig_t[ch] : ds;
        S += T.cwiseProduct(src).cwiseProduct(factor);
        T = T.cwiseProduct(step_T);
      }
      put();
    }
  }
  return out;
}

// the grids' light volumes (transmittances and in-scatter sources) and the grid froxels
// (columns and records) that RealtimeMedia::Build makes with media_build_math.h's shared
// functions against the former Eigen code's (FormerGridBuild), bit for bit: the two grids of
// GridViewSegmentAndLightTransmittanceAreTheCpusBitForBit (one turned about z and y, one
// emissive) in the lit room, alone and with non-grey height fog and the sky volume.
TEST(MediaRealtimeMathTest, GridVolumesAreTheFormerEigenCodesBitForBit) {
  SceneDescription s = SkyLitRoom();
  const EffectsFrame grids = TwoGrids();
  LitFrame f(s);
  for (const bool with_fog : {false, true}) {
    const EffectsFrame fx = with_fog ? WithHeightFog(grids) : grids;
    MediaScene media;
    media.Build(&fx);
    const Eigen::Vector3f ambient(0.3f, 0.4f, 0.6f);
    const SkyIrradianceVolume* volume = with_fog ? &f.volume : nullptr;
    RealtimeMedia rm;
    rm.Build(media, f.lights, f.rays, f.camera, 5, Eigen::Vector3f(0, 0, 2), 4.0, ambient, volume,
             &f.pool);
    RealtimeMediaHostArrays arrays;
    const RealtimeMediaView mv = rm.HostView(&arrays);
    const FormerGridVolumes want =
        FormerGridBuild(media, f.lights, f.rays, f.camera, 5, ambient, volume);
    ASSERT_EQ(mv.num_grids, 2);
    ASSERT_EQ(arrays.grid_light_T.size(), want.T.size());
    int shadowed = 0;
    for (size_t i = 0; i < want.T.size(); ++i) {
      ASSERT_TRUE(SameBits(arrays.grid_light_T[i], want.T[i])) << i;
      shadowed += want.T[i] < 0.9f ? 1 : 0;
    }
    ASSERT_EQ(rm.grid_light_source().size(), want.source.size());
    for (size_t i = 0; i < want.source.size(); ++i) {
      const Float3& got = rm.grid_light_source()[i];
      ASSERT_TRUE(SameBits(got.x, want.source[i].x()) && SameBits(got.y, want.source[i].y()) &&
                  SameBits(got.z, want.source[i].z()))
          << i;
    }
    const size_t columns = want.t0.size();
    ASSERT_EQ(static_cast<size_t>(mv.grid_nx) * mv.grid_ny, columns);
    int met = 0, lit = 0;
    for (size_t c = 0; c < columns; ++c) {
      ASSERT_TRUE(SameBits(mv.grid_t0[c], want.t0[c]) && SameBits(mv.grid_t1[c], want.t1[c]) &&
                  SameBits(mv.grid_slices_per_m[c], want.slices_per_m[c]))
          << c;
      met += want.t0[c] < want.t1[c] ? 1 : 0;
    }
    for (size_t i = 0; i < want.S.size(); ++i) {
      const GridFroxelRecord<Rgb4>& r = mv.grid_records[i];
      ASSERT_TRUE(SameRgb(want.S[i], r.S) && SameRgb(want.Tr[i], r.T)) << i;
      ASSERT_EQ(r.S.w, 0.0f);
      ASSERT_EQ(r.T.w, 0.0f);
      lit += want.S[i][0] > 0 ? 1 : 0;
    }
    std::printf(
        "grids%s: %zu light-volume transmittances (%d below 0.9), %zu sources, %zu columns (%d "
        "meet a grid), %zu records (%d with in-scatter): equal\n",
        with_fog ? " and fog" : "", want.T.size(), shadowed, want.source.size(), columns, met,
        want.S.size(), lit);
    EXPECT_GT(shadowed, 100);
    EXPECT_GT(met, 10);
    EXPECT_GT(lit, 100);
  }
}

TEST(MediaRealtimeMathTest, FogFroxelLookupsOfBothRecordTypesAgreeBitForBit) {
  constexpr int nx = 5, ny = 4, W = nx * kFogFroxelBlock, H = ny * kFogFroxelBlock;
  const Records r = MakeRecords(nx * ny);
  Rng rng(11);
  int quad_hits = 0;
  for (int i = 0; i < 5000; ++i) {
    const float x = W * rng.Uniform(), y = H * rng.Uniform();
    const MediaColumns cb = MediaColumnsAt(x, y, kFogFroxelBlock, nx, ny);
    // distances before the first boundary, inside the slices and beyond the last one.
    const float t = i % 7 == 0 ? 0.2f * rng.Uniform() : 0.1f + 200 * rng.Uniform() * rng.Uniform();
    const Eigen::Array4f a =
        FogFroxelLookup(cb, r.eigen.data(), r.inv_log_far.data(), t, Eigen::Array4f::Zero().eval());
    const Rgb4 b = FogFroxelLookup(cb, r.rgb4.data(), r.inv_log_far.data(), t, Rgb4{});
    ASSERT_TRUE(SameRgb(a, b)) << i;
    if (!(t > kFogFroxelNear)) continue;
    FogQuad<Eigen::Array4f> qa{0, 1, 0, Eigen::Array4f::Zero(), Eigen::Array4f::Zero()};
    FogQuad<Rgb4> qb;
    FogQuadPrepare(cb, r.eigen.data(), r.inv_log_far.data(), t, &qa);
    FogQuadPrepare(cb, r.rgb4.data(), r.inv_log_far.data(), t, &qb);
    ASSERT_TRUE(SameRgb(qa.fS, qb.fS) && SameRgb(qa.fS_dlog, qb.fS_dlog)) << i;
    ASSERT_TRUE(SameBits(qa.lo, qb.lo) && SameBits(qa.hi, qb.hi)) << i;
    for (const float te : {t, 1.01f * t, 0.98f * t}) {
      Eigen::Array4f va;
      Rgb4 vb;
      const bool ha = FogQuadValue(qa, te, &va), hb = FogQuadValue(qb, te, &vb);
      ASSERT_EQ(ha, hb);
      if (ha) {
        ASSERT_TRUE(SameRgb(va, vb)) << i;
      }
      quad_hits += ha ? 1 : 0;
    }
  }
  EXPECT_GT(quad_hits, 1000);
}

// a RayQuery that has closest hits only (RayQuery's default Occluded).
class ClosestHitsOnly final : public RayQuery {
 public:
  explicit ClosestHitsOnly(const RayScene& inner) : inner_(inner) {}
  const SceneDescription& scene() const override { return inner_.scene(); }
  void Update(const WorldSnapshot&) override {}

 private:
  void IntersectBatch(std::span<const Ray> rays, std::span<SurfaceHit> hits,
                      std::span<bool> did_hit) const override {
    inner_.Intersect(rays, hits, did_hit);
  }
  const RayScene& inner_;
};

TEST(MediaRealtimeMathTest, BatchedOcclusionMatchesEmbreesOneRayVerdicts) {
  const SceneDescription s = LitRoom();
  RayScene rays(s);
  rays.Update(IdentitySnapshot(s));
  const ClosestHitsOnly closest(rays);
  Rng rng(5);
  std::vector<Ray> batch(4000);
  for (Ray& r : batch) {
    r.o = Eigen::Vector3f(-4 + 8 * rng.Uniform(), -4 + 8 * rng.Uniform(), 0.1f + 3 * rng.Uniform());
    r.d = Eigen::Vector3f(rng.Uniform() - 0.5f, rng.Uniform() - 0.5f, rng.Uniform() - 0.5f)
              .normalized();
    r.tmax = 0.5f + 6 * rng.Uniform();
  }
  const std::unique_ptr<bool[]> a(new bool[batch.size()]), b(new bool[batch.size()]);
  rays.Occluded(batch, std::span<bool>(a.get(), batch.size()));
  closest.Occluded(batch, std::span<bool>(b.get(), batch.size()));
  int blocked = 0, differ = 0;
  for (size_t i = 0; i < batch.size(); ++i) {
    EXPECT_EQ(a[i], rays.Occluded(batch[i])) << i;  // the batch is rtcOccluded1 ray by ray
    differ += a[i] != b[i] ? 1 : 0;
    blocked += a[i] ? 1 : 0;
  }
  EXPECT_GT(blocked, 400);
  EXPECT_LT(blocked, 3600);
  // closest hits and any-hit traversal agree but for rays that graze an edge (float rounding)
  EXPECT_LE(differ, 4);
  // too few verdicts for the rays
  EXPECT_THROW(rays.Occluded(batch, std::span<bool>(a.get(), 10)), Error);
}

}  // namespace
}  // namespace penumbra::testing

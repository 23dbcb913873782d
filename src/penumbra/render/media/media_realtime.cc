#include "penumbra/render/media/media_realtime.h"

#include <emmintrin.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <limits>
#include <memory>
#include <span>
#include <vector>

#include "penumbra/render/media/media_common.h"

namespace penumbra {
namespace {

constexpr float kInfView = std::numeric_limits<float>::infinity();

using ColumnBilerp = MediaColumns;

// MediaAxisAt at every pixel centre u and every quad centre u + 0.5 of an axis of n pixels
// (so MediaColumnsFrom of two table entries is MediaColumnsAt of the position bit for bit).
void BuildAxisTables(int n, int block, int columns, std::vector<RealtimeMedia::AxisBilerp>* at,
                     std::vector<RealtimeMedia::AxisBilerp>* at_half) {
  at->resize(n);
  at_half->resize(n);
  for (int u = 0; u < n; ++u) {
    (*at)[u] = MediaAxisAt(static_cast<float>(u), block, columns);
    (*at_half)[u] = MediaAxisAt(u + 0.5f, block, columns);
  }
}

// the column layout of froxels `fr` (Froxels or FogFroxels) over a w x h image in square
// blocks of `block` pixels: nx, ny and the axis tables; returns the number of columns.
template <typename F>
int LayOutColumns(int w, int h, int block, F* fr) {
  fr->nx = (w + block - 1) / block;
  fr->ny = (h + block - 1) / block;
  BuildAxisTables(w, block, fr->nx, &fr->ax, &fr->ax_half);
  BuildAxisTables(h, block, fr->ny, &fr->ay, &fr->ay_half);
  return fr->nx * fr->ny;
}

// MediaColumnsAt(u, v) of pixel (u, v) (from the tables inside the image).
template <typename F>
ColumnBilerp PixelColumns(const F& fr, int u, int v, int block) {
  if (u >= 0 && v >= 0 && u < static_cast<int>(fr.ax.size()) && v < static_cast<int>(fr.ay.size()))
    return MediaColumnsFrom(fr.ax[u], fr.ay[v], fr.nx);
  return MediaColumnsAt(static_cast<float>(u), static_cast<float>(v), block, fr.nx, fr.ny);
}

// MediaColumnsAt(u0 + 0.5, v0 + 0.5) of the quad at (u0, v0).
template <typename F>
ColumnBilerp QuadColumns(const F& fr, int u0, int v0, int block) {
  if (u0 >= 0 && v0 >= 0 && u0 < static_cast<int>(fr.ax_half.size()) &&
      v0 < static_cast<int>(fr.ay_half.size()))
    return MediaColumnsFrom(fr.ax_half[u0], fr.ay_half[v0], fr.nx);
  return MediaColumnsAt(u0 + 0.5f, v0 + 0.5f, block, fr.nx, fr.ny);
}

// MediaTrilinear (media_realtime_math.h) at continuous index f.
template <typename T>
T Trilinear(const T* a, const int r[3], const Eigen::Vector3f& f) {
  return MediaTrilinear(a, r, f.x(), f.y(), f.z());
}

// light j's value at p_W of the [light][cell] array `a` over light volume `v` (trilinear between
// the cell centres) in *out; false outside the volume.
bool LightVolumeLookup(const CellLightsPod& v, const float* a, int j, const Eigen::Vector3f& p_W,
                       float* out) {
  using Map3 = Eigen::Map<const Eigen::Vector3f>;
  const Map3 lo(v.lo), hi(v.hi), cells_per_m(v.cells_per_m);
  if (!(p_W.array() >= lo.array()).all() || !(p_W.array() <= hi.array()).all()) return false;
  const Eigen::Vector3f f = (p_W - lo).cwiseProduct(cells_per_m) - Eigen::Vector3f::Constant(0.5f);
  const size_t cells = static_cast<size_t>(v.r[0]) * v.r[1] * v.r[2];
  *out = Trilinear(a + j * cells, v.r, f);
  return true;
}

// e^x per channel; one exponential when the channels are equal (grey media).
Eigen::Vector3f Exp(const Eigen::Vector3f& x) {
  if (x.x() == x.y() && x.y() == x.z()) return Eigen::Vector3f::Constant(std::exp(x.x()));
  return x.array().exp().matrix();
}

// rgb in lanes 0..2 of a 4-lane array (lane 3 = 0), for vectorised lookups.
Eigen::Array4f To4(const Eigen::Vector3f& v) { return Eigen::Array4f(v.x(), v.y(), v.z(), 0.0f); }

// Float3 <-> the CPU's 4-lane and 3-vector forms.
Float3 ToF3(const Eigen::Array4f& a) { return {a[0], a[1], a[2]}; }
Eigen::Vector3f FromF3(const Float3& a) { return {a.x, a.y, a.z}; }

// (*blocked)[i] = query.Occluded(rays[i]) for every i with want[i] == kMediaRayTrace (others
// untouched but sized): the noted rays gathered in order, in batches of kShadowRayBatch
// spread over `pool`.
void TraceShadowRays(const RayQuery& query, const std::vector<Ray>& rays,
                     const std::vector<uint8_t>& want, std::vector<uint8_t>* blocked,
                     ThreadPool* pool) {
  blocked->assign(rays.size(), 0);
  std::vector<size_t> traced;
  for (size_t i = 0; i < want.size(); ++i)
    if (want[i] == kMediaRayTrace) traced.push_back(i);
  const int64_t batches =
      (static_cast<int64_t>(traced.size()) + kShadowRayBatch - 1) / kShadowRayBatch;
  ParallelForOrSerial(pool, batches, [&](int64_t b) {
    const size_t lo = static_cast<size_t>(b) * kShadowRayBatch;
    const size_t n = std::min(traced.size() - lo, static_cast<size_t>(kShadowRayBatch));
    std::vector<Ray> batch(n);
    for (size_t i = 0; i < n; ++i) batch[i] = rays[traced[lo + i]];
    const std::unique_ptr<bool[]> occluded(new bool[n]);
    query.Occluded(batch, std::span<bool>(occluded.get(), n));
    for (size_t i = 0; i < n; ++i) (*blocked)[traced[lo + i]] = occluded[i] ? 1 : 0;
  });
}

}  // namespace

void RealtimeMedia::Build(const MediaScene& media, const LightSampler& lights,
                          const RayQuery& scene, const Camera& camera, uint64_t frame_key,
                          const Eigen::Vector3f& bounds_center_W, double bounds_extent_m,
                          const Eigen::Vector3f& sky_ambient, const SkyIrradianceVolume* sky_volume,
                          ThreadPool* pool, bool device_volumes) {
  using Clock = std::chrono::steady_clock;
  auto ms_since = [](Clock::time_point t) {
    return std::chrono::duration<double, std::milli>(Clock::now() - t).count();
  };
  build_times_ = BuildTimes();
  device_build_ = MediaVolumesToBuild();
  auto stage = Clock::now();
  media_ = &media;
  sky_ambient_ = sky_ambient;
  sky_volume_ = sky_volume != nullptr && !sky_volume->empty() ? sky_volume : nullptr;
  sky_ambient4_ = To4(sky_ambient);
  // the media for the shared per-pixel formulas, with the camera's h(0) per medium
  // (DensityIntegralF), and whether every sigma_t is grey.
  h_cam_oz_ = camera.GenerateRay(0.0f, 0.0f).o.z();
  pods_.clear();
  grey_t_ = true;
  for (const AnalyticMedium& m : media.analytic()) {
    MediumPod pod = PodOf(m);
    const float k = m.falloff, zb = m.base;
    pod.h_cam = std::exp(-k * std::max(0.0f, h_cam_oz_ + 0.0f * 0.0f - zb));
    pod.g = m.g;
    pods_.push_back(pod);
    grey_t_ = grey_t_ && m.sigma_t.x() == m.sigma_t.y() && m.sigma_t.y() == m.sigma_t.z();
  }
  num_lights_ = std::min(lights.size(), kMaxVolumeLights);
  const int nl = num_lights_;
  // the geometric visibility of light l from p takes one shadow ray where the light casts
  // shadows: each volume notes, per cell and light, whether it asks for the light's
  // visibility (kMediaRayLit: no ray, kMediaRayTrace: rays[slot]), then the noted rays are
  // traced in batches
  // (TraceShadowRays) and the cells finished with the verdicts.
  std::vector<Ray> rays;
  std::vector<uint8_t> want, blocked;
  // what slot asks (want), and its shadow ray from p along d to tmax where it traces one
  auto note = [&](size_t slot, uint8_t w, const float p[3], const float d[3], float tmax) {
    want[slot] = w;
    if (w != kMediaRayTrace) return;
    Ray& sr = rays[slot];
    sr.o = Eigen::Vector3f(p[0], p[1], p[2]);
    sr.d = Eigen::Vector3f(d[0], d[1], d[2]);
    sr.tmax = tmax;
  };
  auto seen = [&](size_t slot) {
    return want[slot] == kMediaRayLit || (want[slot] == kMediaRayTrace && blocked[slot] == 0);
  };

  // grid light volumes: per grid its layout, then per cell and light the grid's transmittance
  // and the shadow ray the cell's source asks (GridLightCellLight), the rays traced in batches,
  // and the sources (GridLightCellSky, GridLightCellSource in light order; media_build_math.h).
  grid_light_.assign(media.grids().size(), GridLight());
  grid_media_.clear();
  std::vector<GridLightPod> layouts;
  for (size_t g = 0; g < media.grids().size(); ++g) {
    const GridVolume& v = media.grids()[g];
    GridLight& gl = grid_light_[g];
    const int n[3] = {v.nx, v.ny, v.nz};
    const Eigen::Vector3f size = 2 * v.half;
    const float cell = std::cbrt(size.prod() / kGridLightCells);
    for (int k = 0; k < 3; ++k) {
      gl.r[k] = std::clamp(static_cast<int>(std::ceil(size[k] / cell)), 1, n[k]);
      gl.cells_per_m[k] = gl.r[k] / size[k];
    }
    for (int i = 0; i < 3; ++i) {
      for (int k = 0; k < 3; ++k) gl.pod.R_GW[3 * i + k] = v.R_GW(i, k);
      gl.pod.p_GW[i] = v.p_GW[i];
      gl.pod.half[i] = v.half[i];
      gl.pod.cells_per_m[i] = gl.cells_per_m[i];
      gl.pod.r[i] = gl.r[i];
    }
    grid_media_.push_back(v.pod);
    layouts.push_back(gl.pod);
  }
  GridLightBuild gb;
  gb.grids = grid_media_.data();
  gb.layouts = layouts.data();
  gb.num_grids = static_cast<int>(grid_media_.size());
  gb.lights = lights.pods().data();
  gb.num_lights = nl;
  gb.media = pods_.data();
  gb.num_media = static_cast<int>(pods_.size());
  for (int k = 0; k < 3; ++k) gb.sky_ambient[k] = sky_ambient[k];
  if (sky_volume_ != nullptr) {
    grid_sky_pod_ = sky_volume_->pod();
    gb.sky_volume = &grid_sky_pod_;
  }
  grid_source_.clear();
  if (device_volumes && !grid_media_.empty()) {
    // the layouts only: the grids' arrays go to the device, which builds the volumes
    device_build_.grids = 1;
    device_build_.grid_media = grid_media_.data();
    bool same = held_grid_arrays_.size() == 2 * media.grids().size();
    for (size_t g = 0; same && g < media.grids().size(); ++g)
      same = held_grid_arrays_[2 * g] == media.grids()[g].density &&
             held_grid_arrays_[2 * g + 1] == media.grids()[g].emission;
    if (!same) {
      // a new generation (unique in the process: the arrays held keep their addresses unique)
      static std::atomic<uint64_t> next_generation{1};
      grid_generation_ = next_generation.fetch_add(1);
      held_grid_arrays_.clear();
      for (const GridVolume& v : media.grids()) {
        held_grid_arrays_.push_back(v.density);
        held_grid_arrays_.push_back(v.emission);
      }
    }
    device_build_.grid_generation = grid_generation_;
    device_build_.frame_key = frame_key;
  }
  for (size_t g = 0; g < media.grids().size() && !device_build_.grids; ++g) {
    GridLight& gl = grid_light_[g];
    const int cells = gl.r[0] * gl.r[1] * gl.r[2];
    gl.T.assign(static_cast<size_t>(nl) * cells, 1.0f);
    const size_t src_at = grid_source_.size();
    grid_source_.resize(src_at + cells);
    rays.assign(static_cast<size_t>(cells) * nl, Ray());
    want.assign(static_cast<size_t>(cells) * nl, kMediaRayNone);
    // the grid's transmittance to each light, and the shadow rays of the lit cells.
    ParallelForOrSerial(pool, cells, [&](int64_t c) {
      float p[3];
      GridLightCellCentre(gl.pod, c, p);
      for (int l = 0; l < nl; ++l) {
        float Tg, d[3], tmax;
        const uint8_t w = GridLightCellLight(gb, static_cast<int>(g), p, l, &Tg, d, &tmax);
        gl.T[static_cast<size_t>(l) * cells + c] = Tg;
        note(static_cast<size_t>(c) * nl + l, w, p, d, tmax);
      }
    });
    TraceShadowRays(scene, rays, want, &blocked, pool);
    // the in-scatter source: the sky, and each light the cell sees.
    ParallelForOrSerial(pool, cells, [&](int64_t c) {
      float p[3];
      GridLightCellCentre(gl.pod, c, p);
      Float3 src = GridLightCellSky(gb, p);
      for (int l = 0; l < nl; ++l)
        if (seen(static_cast<size_t>(c) * nl + l))
          src = GridLightCellSource(gb, p, l, gl.T[static_cast<size_t>(l) * cells + c], src);
      grid_source_[src_at + c] = src;
    });
  }

  // every grid's light volume end to end (the shared build functions and HostView read them)
  grid_pods_.clear();
  grid_light_T_.clear();
  // (or, left to a device, their offsets only)
  size_t grid_T_at = 0;
  for (const GridLight& gl : grid_light_) {
    GridLightPod pod = gl.pod;
    pod.offset = grid_T_at;
    grid_T_at += static_cast<size_t>(nl) * gl.r[0] * gl.r[1] * gl.r[2];
    grid_light_T_.insert(grid_light_T_.end(), gl.T.begin(), gl.T.end());
    grid_pods_.push_back(pod);
  }
  build_times_.grid_light = ms_since(stage);
  stage = Clock::now();

  // world light volume: transmittance to every light (all media), and for homogeneous media
  // also times the geometric visibility (their in-scatter).
  vol_ = LightVolume();
  cl_pod_ = CellLightsPod();
  if (nl > 0) {
    Eigen::Vector3f lo = bounds_center_W - Eigen::Vector3f::Constant(bounds_extent_m);
    Eigen::Vector3f hi = bounds_center_W + Eigen::Vector3f::Constant(bounds_extent_m);
    bool all_bounded = true;
    Eigen::Vector3f ulo = Eigen::Vector3f::Constant(kInfView),
                    uhi = Eigen::Vector3f::Constant(-kInfView);
    for (const AnalyticMedium& m : media.analytic()) {
      if (!m.bounded) {
        all_bounded = false;
        break;
      }
      ulo = ulo.cwiseMin(m.box_min);
      uhi = uhi.cwiseMax(m.box_max);
    }
    if (all_bounded && !media.analytic().empty()) {
      lo = lo.cwiseMax(ulo);
      hi = hi.cwiseMin(uhi);
    }
    const Eigen::Vector3f size = hi - lo;
    if ((size.array() > 0).all()) {
      vol_.active = true;
      vol_.with_visibility = !media.analytic().empty();
      const float cell = std::cbrt(size.prod() / kLightVolumeCells);
      for (int k = 0; k < 3; ++k) {
        cl_pod_.lo[k] = lo[k];
        cl_pod_.hi[k] = hi[k];
        cl_pod_.r[k] = std::clamp(static_cast<int>(std::ceil(size[k] / cell)), 1, 128);
        cl_pod_.cells_per_m[k] = cl_pod_.r[k] / size[k];
        vol_.lo4[k] = cl_pod_.lo[k];
        vol_.hi4[k] = cl_pod_.hi[k];
        vol_.cpm4[k] = cl_pod_.cells_per_m[k];
        vol_.rmax4[k] = static_cast<float>(cl_pod_.r[k] - 1);
        vol_.imax4[k] = static_cast<float>(std::max(cl_pod_.r[k] - 2, 0));
      }
      const int cells = cl_pod_.r[0] * cl_pod_.r[1] * cl_pod_.r[2];
      cl_pod_.stride = (nl + 3) / 4 * 4;
      if (device_volumes) {
        device_build_.light_volume = 1;
        device_build_.with_visibility = vol_.with_visibility ? 1 : 0;
      } else {
        LightVolumeBuild b;
        b.layout = cl_pod_;
        b.num_lights = nl;
        b.with_visibility = vol_.with_visibility ? 1 : 0;
        b.lights = lights.pods().data();
        b.media = pods_.data();
        b.num_media = static_cast<int>(pods_.size());
        b.grids = grid_pods_.data();
        b.grid_light_T = grid_light_T_.data();
        b.num_grids = static_cast<int>(grid_pods_.size());
        vol_.trans.assign(static_cast<size_t>(nl) * cells, 1.0f);
        if (vol_.with_visibility) {
          vol_.vis.assign(static_cast<size_t>(nl) * cells, 1.0f);
          rays.assign(static_cast<size_t>(cells) * nl, Ray());
          want.assign(static_cast<size_t>(cells) * nl, kMediaRayNone);
        }
        // per cell and light the transmittance and what its visibility asks
        // (LightVolumeCellLight), the shadow rays gathered
        ParallelForOrSerial(pool, cells, [&](int64_t c) {
          float p[3];
          LightVolumeCellCentre(cl_pod_, c, p);
          for (int l = 0; l < nl; ++l) {
            float T, d[3], tmax;
            const uint8_t w = LightVolumeCellLight(b, p, l, &T, d, &tmax);
            vol_.trans[static_cast<size_t>(l) * cells + c] = T;
            if (!vol_.with_visibility) continue;
            note(static_cast<size_t>(c) * nl + l, w, p, d, tmax);
          }
        });
        // V Th Tgrid: the transmittance where the light is seen, else 0.
        if (vol_.with_visibility) {
          TraceShadowRays(scene, rays, want, &blocked, pool);
          ParallelForOrSerial(pool, cells, [&](int64_t c) {
            for (int l = 0; l < nl; ++l) {
              const size_t at = static_cast<size_t>(l) * cells + c;
              vol_.vis[at] = seen(static_cast<size_t>(c) * nl + l) ? vol_.trans[at] : 0.0f;
            }
          });
        }
        // the same values with the lights of a cell adjacent (LightTransmittances).
        vol_.trans_cl.assign(static_cast<size_t>(cells) * cl_pod_.stride, 0.0f);
        if (vol_.with_visibility)
          vol_.vis_cl.assign(static_cast<size_t>(cells) * cl_pod_.stride, 0.0f);
        for (int l = 0; l < nl; ++l) {
          for (int c = 0; c < cells; ++c) {
            const size_t at = static_cast<size_t>(c) * cl_pod_.stride + l;
            vol_.trans_cl[at] = vol_.trans[static_cast<size_t>(l) * cells + c];
            if (vol_.with_visibility)
              vol_.vis_cl[at] = vol_.vis[static_cast<size_t>(l) * cells + c];
          }
        }
      }
    }
  }
  build_times_.light_volume = ms_since(stage);
  stage = Clock::now();
  BuildFroxels(lights, camera, frame_key, pool, device_build_.grids != 0);
  build_times_.grid_froxels = ms_since(stage);
  stage = Clock::now();
  BuildFogFroxels(lights, camera, frame_key, pool, device_volumes);
  if (device_volumes && !fog_froxels_.inv_log_far.empty()) {
    device_build_.fog = 1;
    device_build_.frame_key = frame_key;
  }
  build_times_.fog_froxels = ms_since(stage);
}

void RealtimeMedia::BuildFroxels(const LightSampler& lights, const Camera& camera,
                                 uint64_t frame_key, ThreadPool* pool, bool device) {
  froxels_ = Froxels();
  const MediaScene& media = *media_;
  if (media.grids().empty()) return;
  const int W = camera.width(), H = camera.height();
  Froxels& fr = froxels_;
  const int columns = LayOutColumns(W, H, kFroxelBlock, &fr);
  constexpr int Z = kFroxelSlices;
  if (device) return;  // the layout only: the columns are the device's
  fr.t0.assign(columns, 0.0f);
  fr.t1.assign(columns, 0.0f);
  fr.slices_per_m.assign(columns, 0.0f);
  fr.records.assign(static_cast<size_t>(columns) * (Z + 1),
                    FroxelRecord{To4(Eigen::Vector3f::Zero()), To4(Eigen::Vector3f::Ones())});
  // the shared column (media_build_math.h) over this frame's arrays
  GridFroxelBuild b;
  b.grids = grid_media_.data();
  b.layouts = grid_pods_.data();
  b.source = grid_source_.data();
  b.num_grids = static_cast<int>(grid_media_.size());
  b.media = pods_.data();
  b.num_media = static_cast<int>(pods_.size());
  static_assert(sizeof(FroxelRecord) == 8 * sizeof(float), "records of 8 floats");
  auto column = [&](int64_t c) {
    int uc, vc;
    MediaColumnCentre(static_cast<int>(c), fr.nx, kFroxelBlock, W, H, &uc, &vc);
    const Ray r = camera.GenerateRay(static_cast<float>(uc), static_cast<float>(vc));
    const Eigen::Vector3f o = r.o, d = r.d.normalized();
    float a, e;
    if (!GridFroxelColumnInterval(b, o.data(), d.data(), &a, &e)) return;
    fr.t0[c] = a;
    fr.t1[c] = e;
    fr.slices_per_m[c] = std::min(Z / (e - a), 1e30f);
    // jitter of the slice samples from the column's centre pixel stream 2.
    const float jitter = FroxelColumnJitter(frame_key, uc, vc, W, 2);
    GridFroxelStep steps[Z];
    for (int k = 0; k < Z; ++k) steps[k] = GridFroxelSlice(b, o.data(), d.data(), a, e, jitter, k);
    GridFroxelRecords(
        steps, reinterpret_cast<float*>(fr.records.data() + static_cast<size_t>(c) * (Z + 1)));
  };
  ParallelForOrSerial(pool, columns, column);
}

float RealtimeMedia::LookupFroxels(int u, int v, float t, Eigen::Array4f* S,
                                   Eigen::Array4f* T) const {
  const Froxels& fr = froxels_;
  return GridFroxelLookup(PixelColumns(fr, u, v, kFroxelBlock), fr.t0.data(), fr.t1.data(),
                          fr.slices_per_m.data(), fr.records.data(), t,
                          Eigen::Array4f::Zero().eval(), Eigen::Array4f(1, 1, 1, 0), S, T);
}

void RealtimeMedia::BuildFogFroxels(const LightSampler& lights, const Camera& camera,
                                    uint64_t frame_key, ThreadPool* pool, bool device) {
  fog_froxels_ = FogFroxels();
  const MediaScene& media = *media_;
  if (media.analytic().empty() || lights.size() == 0) return;
  const int W = camera.width(), H = camera.height();
  FogFroxels& fr = fog_froxels_;
  const int columns = LayOutColumns(W, H, kFogFroxelBlock, &fr);
  constexpr int Z = kFogFroxelSlices;
  fr.inv_log_far.assign(columns, 1.0f / std::log(2.0f));
  if (device) return;  // the layout only: the columns are the device's
  fr.S.assign(static_cast<size_t>(columns) * (Z + 1), Eigen::Array4f::Zero());
  // the shared column (media_build_math.h) over this frame's arrays
  FogFroxelBuild<Eigen::Array4f> b;
  b.media = pods_.data();
  b.num_media = static_cast<int>(pods_.size());
  b.lights = lights.pods().data();
  b.num_lights = lights.size();
  b.num_volume_lights = num_lights_;
  b.vis_layout = cl_pod_;
  b.vis_cl = vol_.with_visibility ? vol_.vis_cl.data() : nullptr;
  b.grids = grid_pods_.data();
  b.grid_light_T = grid_light_T_.data();
  b.num_grids = static_cast<int>(grid_pods_.size());
  const Froxels& gf = froxels_;
  if (!gf.records.empty()) {
    b.grid_t0 = gf.t0.data();
    b.grid_t1 = gf.t1.data();
    b.grid_slices_per_m = gf.slices_per_m.data();
    b.grid_records = gf.records.data();
  }
  const Eigen::Array4f zero = Eigen::Array4f::Zero(), unit(1, 1, 1, 0);
  auto column = [&](int64_t c) {
    int uc, vc;
    MediaColumnCentre(static_cast<int>(c), fr.nx, kFogFroxelBlock, W, H, &uc, &vc);
    const Ray r = camera.GenerateRay(static_cast<float>(uc), static_cast<float>(vc));
    const Eigen::Vector3f o = r.o, d = r.d.normalized();
    const MediaColumns grid_cols =
        gf.records.empty() ? MediaColumns{} : PixelColumns(gf, uc, vc, kFroxelBlock);
    FogFroxelColumn(b, o.data(), d.data(), FroxelColumnJitter(frame_key, uc, vc, W, 3), grid_cols,
                    zero, unit, &fr.inv_log_far[c],
                    reinterpret_cast<float*>(fr.S.data() + static_cast<size_t>(c) * (Z + 1)));
  };
  ParallelForOrSerial(pool, columns, column);
}

Eigen::Array4f RealtimeMedia::LookupFogFroxels(int u, int v, float t) const {
  const FogFroxels& fr = fog_froxels_;
  return FogFroxelLookup(PixelColumns(fr, u, v, kFogFroxelBlock), fr.S.data(),
                         fr.inv_log_far.data(), t, Eigen::Array4f::Zero().eval());
}

RealtimeMediaView RealtimeMedia::HostView(RealtimeMediaHostArrays* arrays) const {
  RealtimeMediaView m;
  m.media = pods_.data();
  m.num_media = static_cast<int>(pods_.size());
  m.camera_height = h_cam_oz_;
  m.grey = grey_t_ ? 1 : 0;
  for (int k = 0; k < 3; ++k) m.sky_ambient[k] = sky_ambient_[k];
  if (sky_volume_ != nullptr) {
    arrays->sky_pod = sky_volume_->pod();
    m.sky_volume = &arrays->sky_pod;
  }
  auto rgb4 = [](const Eigen::Array4f& a) { return Rgb4{a[0], a[1], a[2], a[3]}; };
  const FogFroxels& ff = fog_froxels_;
  arrays->fog_records.clear();
  if (ff.nx > 0) {
    // the layout; the records unless left to a device (device_build().fog)
    arrays->fog_records.resize(ff.S.size());
    for (size_t i = 0; i < ff.S.size(); ++i) arrays->fog_records[i] = rgb4(ff.S[i]);
    m.fog_nx = ff.nx;
    m.fog_ny = ff.ny;
    m.width = static_cast<int>(ff.ax.size());
    m.height = static_cast<int>(ff.ay.size());
    m.fog_S = ff.S.empty() ? nullptr : arrays->fog_records.data();
    m.fog_inv_log_far = ff.S.empty() ? nullptr : ff.inv_log_far.data();
    m.fog_ax = ff.ax.data();
    m.fog_ay = ff.ay.data();
    m.fog_ax_half = ff.ax_half.data();
    m.fog_ay_half = ff.ay_half.data();
  }
  if (vol_.active) {
    m.light_volume = cl_pod_;
    m.light_trans = vol_.trans_cl.empty() ? nullptr : vol_.trans_cl.data();
    m.num_volume_lights = num_lights_;
  }
  const Froxels& fr = froxels_;
  arrays->grid_records.clear();
  if (fr.nx > 0) {
    // the layout; the columns and records unless left to a device (device_build().grids)
    arrays->grid_records.resize(fr.records.size());
    for (size_t i = 0; i < fr.records.size(); ++i)
      arrays->grid_records[i] = {rgb4(fr.records[i].S), rgb4(fr.records[i].T)};
    m.grid_nx = fr.nx;
    m.grid_ny = fr.ny;
    m.width = static_cast<int>(fr.ax.size());
    m.height = static_cast<int>(fr.ay.size());
    if (!fr.records.empty()) {
      m.grid_t0 = fr.t0.data();
      m.grid_t1 = fr.t1.data();
      m.grid_slices_per_m = fr.slices_per_m.data();
      m.grid_records = arrays->grid_records.data();
    }
    m.grid_ax = fr.ax.data();
    m.grid_ay = fr.ay.data();
    m.grid_ax_half = fr.ax_half.data();
    m.grid_ay_half = fr.ay_half.data();
  }
  // the grids' light volumes end to end, each pod's offset where its own starts (Build's)
  arrays->grid_light_T = grid_light_T_;
  arrays->grid_pods = grid_pods_;
  if (!arrays->grid_pods.empty()) {
    m.num_grids = static_cast<int>(arrays->grid_pods.size());
    m.grids = arrays->grid_pods.data();
    m.grid_light_T = arrays->grid_light_T.empty() ? nullptr : arrays->grid_light_T.data();
    m.num_grid_lights = num_lights_;
  }
  return m;
}

Eigen::Vector3f RealtimeMedia::SkyAmbientAt(const Eigen::Vector3f& p_W) const {
  return sky_volume_ != nullptr ? sky_volume_->AmbientRadiance(p_W, sky_ambient_) : sky_ambient_;
}

Eigen::Array4f RealtimeMedia::SkyAlongRay(const Eigen::Vector3f& o, const Eigen::Vector3f& d,
                                          float t_end) const {
  if (sky_volume_ == nullptr) return sky_ambient4_;
  // the in-scatter median point of the medium of largest optical depth (media_realtime_math.h)
  float t_med;
  if (!SkyMedianDistance(pods_.data(), static_cast<int>(pods_.size()), o.data(), d.data(), t_end,
                         &t_med))
    return sky_ambient4_;
  return To4(sky_volume_->AmbientRadiance(o + t_med * d, sky_ambient_));
}

void RealtimeMedia::PrepareQuad(int u0, int v0, float t_c, const Eigen::Vector3f& o,
                                const Eigen::Vector3f& d_c, MediaQuad* quad) const {
  MediaQuad& q = *quad;
  q = MediaQuad();
  if (sky_volume_ != nullptr && !media_->analytic().empty()) {
    q.sky = SkyAlongRay(o, d_c, t_c);
    q.has_sky = true;
  }
  // grid froxels: the columns and weights of the quad's centre, then per column the slice that
  // holds t and the distances where that stays so (media_realtime_math.h).
  const Froxels& fr = froxels_;
  if (!fr.records.empty())
    GridQuadPrepare(QuadColumns(fr, u0, v0, kFroxelBlock), fr.t0.data(), fr.t1.data(),
                    fr.slices_per_m.data(), fr.records.data(), t_c, Eigen::Array4f(1, 1, 1, 0),
                    &q.grid);
  // light in-scatter froxels: the same in log distance (slices are spaced exponentially),
  // beyond the first slice boundary only.
  const FogFroxels& ff = fog_froxels_;
  if (!ff.S.empty() && t_c > kFogFroxelNear)
    FogQuadPrepare(QuadColumns(ff, u0, v0, kFogFroxelBlock), ff.S.data(), ff.inv_log_far.data(),
                   t_c, &q.fog);
}

float RealtimeMedia::QuadFroxels(const MediaQuad& q, int u, int v, float t, Eigen::Array4f* S,
                                 Eigen::Array4f* T) const {
  float t_enter;
  if (GridQuadValue(q.grid, t, Eigen::Array4f::Zero().eval(), Eigen::Array4f(1, 1, 1, 0), S, T,
                    &t_enter) != 0)
    return t_enter;
  return LookupFroxels(u, v, t, S, T);
}

Eigen::Array4f RealtimeMedia::QuadFogFroxels(const MediaQuad& q, int u, int v, float t) const {
  Eigen::Array4f out;
  if (FogQuadValue(q.fog, t, &out)) return out;
  return LookupFogFroxels(u, v, t);
}

float RealtimeMedia::GridLightT(int g, int j, const Eigen::Vector3f& p_W, const Eigen::Vector3f& wi,
                                float dist) const {
  const GridLight& gl = grid_light_[g];
  return GridLightTransmittance(gl.pod, gl.T.data(), num_lights_, j, p_W.data(), wi.data(), dist);
}

float RealtimeMedia::FogVisibility(int j, const Eigen::Vector3f& p_W, const Eigen::Vector3f& wi,
                                   float dist) const {
  float V;
  if (vol_.with_visibility && j < num_lights_ &&
      LightVolumeLookup(cl_pod_, vol_.vis.data(), j, p_W, &V))
    return V;
  float T = std::exp(-Mean3(media_->AnalyticOpticalDepth(p_W, wi, 0, dist)));
  for (size_t g = 0; g < grid_light_.size(); ++g)
    T *= GridLightT(static_cast<int>(g), j, p_W, wi, dist);
  return T;
}

bool RealtimeMedia::LightVisibilities(const Eigen::Vector3f& p_W, float* T) const {
  if (!vol_.with_visibility) return false;
  return CellLightsLookupSse(vol_.vis_cl.data(), p_W, T);
}

bool RealtimeMedia::LightTransmittances(const Eigen::Vector3f& p_W, float* T) const {
  if (!vol_.active) return false;
  return CellLightsLookupSse(vol_.trans_cl.data(), p_W, T);
}

bool RealtimeMedia::CellLightsLookupSse(const float* cl, const Eigen::Vector3f& p_W,
                                        float* T) const {
  // CellLightsLookup of media_realtime_math.h restated in SSE (tested bit for bit against it,
  // tests/render/media/media_realtime_math_test.cc). the three axes in SSE lanes 0..2 (lane 3 is a
  // dummy inside [0, 0]): the same IEEE operations as the scalar form clamp((x - lo) cells_per_m -
  // 0.5, 0, r - 1), i0 = min(trunc(c), max(r - 2, 0)), step = min(i0 + 1, r - 1) - i0, w = c - i0
  // (the clamp's input is never -0 or NaN here, where max/min and std::clamp agree).
  const __m128 x = _mm_set_ps(0.0f, p_W.z(), p_W.y(), p_W.x());
  const __m128 inside = _mm_and_ps(_mm_cmpge_ps(x, _mm_loadu_ps(vol_.lo4.data())),
                                   _mm_cmple_ps(x, _mm_loadu_ps(vol_.hi4.data())));
  if (_mm_movemask_ps(inside) != 0xF) return false;
  const __m128 rmax = _mm_loadu_ps(vol_.rmax4.data());
  __m128 c = _mm_sub_ps(
      _mm_mul_ps(_mm_sub_ps(x, _mm_loadu_ps(vol_.lo4.data())), _mm_loadu_ps(vol_.cpm4.data())),
      _mm_set1_ps(0.5f));
  c = _mm_min_ps(_mm_max_ps(c, _mm_setzero_ps()), rmax);
  const __m128 i0 =
      _mm_min_ps(_mm_cvtepi32_ps(_mm_cvttps_epi32(c)), _mm_loadu_ps(vol_.imax4.data()));
  alignas(16) float wv[4], iv[4], sv[4];
  _mm_store_ps(wv, _mm_sub_ps(c, i0));
  _mm_store_ps(iv, i0);
  const __m128 one = _mm_set1_ps(1.0f);
  _mm_store_ps(sv, _mm_and_ps(_mm_cmple_ps(_mm_add_ps(i0, one), rmax), one));
  int base[3], step[3];
  float w[3];
  for (int k = 0; k < 3; ++k) {
    base[k] = static_cast<int>(iv[k]);
    step[k] = static_cast<int>(sv[k]);
    w[k] = wv[k];
  }
  // the eight corners (+1 along x, y, z for bits 0, 1, 2 of the corner index) and their
  // trilinear weights, summed in corner order; lights adjacent per cell.
  const size_t S = static_cast<size_t>(cl_pod_.stride);
  const CellCorners k = CellLightsCorners(cl_pod_, cl, base, step);
  const size_t ox = k.ox, oy = k.oy, oz = k.oz;
  float wc[8];
  TrilinearCornerWeights(w, wc);
  using A4 = Eigen::Map<const Eigen::Array4f>;
  for (size_t j0 = 0; j0 < S; j0 += 4) {
    const float* c = k.c0 + j0;
    Eigen::Array4f sum = wc[0] * A4(c);
    sum += wc[1] * A4(c + ox);
    sum += wc[2] * A4(c + oy);
    sum += wc[3] * A4(c + ox + oy);
    sum += wc[4] * A4(c + oz);
    sum += wc[5] * A4(c + ox + oz);
    sum += wc[6] * A4(c + oy + oz);
    sum += wc[7] * A4(c + ox + oy + oz);
    Eigen::Map<Eigen::Array4f>(T + j0) = sum;
  }
  return true;
}

Eigen::Vector3f RealtimeMedia::LightTransmittance(int j, const Eigen::Vector3f& p_W,
                                                  const Eigen::Vector3f& wi, float dist) const {
  float T_volume;
  if (vol_.active && j < num_lights_ &&
      LightVolumeLookup(cl_pod_, vol_.trans.data(), j, p_W, &T_volume))
    return Eigen::Vector3f::Constant(T_volume);
  Eigen::Vector3f T = media_->analytic().empty()
                          ? Eigen::Vector3f::Ones()
                          : Exp(-media_->AnalyticOpticalDepth(p_W, wi, 0, dist));
  for (size_t g = 0; g < grid_light_.size(); ++g)
    T *= GridLightT(static_cast<int>(g), j, p_W, wi, dist);
  return T;
}

MediaSegment RealtimeMedia::IntegrateView(const LightSampler& lights, const Eigen::Vector3f& o,
                                          const Eigen::Vector3f& d, float t_end, int u, int v,
                                          const MediaQuad* quad) const {
  const MediaScene& media = *media_;
  const bool analytic = !media.analytic().empty();

  // grids: the froxel volume at the pixel's distance.
  Eigen::Array4f L_add = Eigen::Array4f::Zero(), Tg(1, 1, 1, 0);
  float first_a = kInfView;
  if (!froxels_.records.empty()) {
    const float t = std::min(t_end, 1e30f);
    first_a = quad != nullptr ? QuadFroxels(*quad, u, v, t, &L_add, &Tg)
                              : LookupFroxels(u, v, t, &L_add, &Tg);
  }

  MediaSegment out;
  if (!analytic) {
    out.T = Tg.head<3>().matrix();
    out.L_add = L_add.head<3>().matrix();
    return out;
  }

  // homogeneous media: closed-form transmittance and sky in-scatter (single precision), to the
  // end and, when the ray enters a grid before it, to the grid's entry (media_realtime_math.h).
  const bool to_grid = first_a < t_end;
  Float3 tau_t, tau_s, tau_a;
  HomogeneousViewDepths(pods_.data(), static_cast<int>(pods_.size()), o.data(), d.data(), t_end,
                        to_grid, first_a, h_cam_oz_, &tau_t, &tau_s, &tau_a);
  const Eigen::Array4f sky = sky_volume_ == nullptr             ? sky_ambient4_
                             : quad != nullptr && quad->has_sky ? quad->sky
                                                                : SkyAlongRay(o, d, t_end);
  Float3 T3, L3 = ToF3(L_add);
  MediaViewClosedForm(tau_t, tau_s, tau_a, to_grid, grey_t_, ToF3(Tg), ToF3(sky), &T3, &L3);
  L_add = To4(FromF3(L3));
  // light in-scatter from the froxel columns.
  if (!fog_froxels_.S.empty())
    L_add += quad != nullptr ? QuadFogFroxels(*quad, u, v, t_end) : LookupFogFroxels(u, v, t_end);
  out.T = FromF3(T3);
  out.L_add = L_add.head<3>().matrix();
  return out;
}

}  // namespace penumbra

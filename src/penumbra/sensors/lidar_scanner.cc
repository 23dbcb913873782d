#include "penumbra/sensors/lidar_scanner.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <span>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/sensors/sensor_noise.h"

namespace penumbra {
namespace {

constexpr double kScanPi = 3.14159265358979323846;
constexpr double kBinDeg = 0.5;  // angular bins of beams for the particle lookup
constexpr int kChunk = 256;
constexpr int kSoftSamples = 48;
// beams closer than 2.5 deg are neighbours for the edge test of the mixed returns
const float kCosNeighbour = static_cast<float>(std::cos(2.5 * 3.14159265358979323846 / 180));
constexpr double kSpeedOfLight = 299792458.0;
// Hahner et al. 2021: beta = 0.046 / MOR, sigma_t = ln(20) / MOR
const double kBetaPerSigma = 0.046 / std::log(20.0);

float Luminance(const Eigen::Vector3f& c) {
  return 0.2126f * c.x() + 0.7152f * c.y() + 0.0722f * c.z();
}

// [t0, t1] of the ray o + t d (d unit) inside an axis-aligned box, clipped to [0, r];
// false if the ray misses it.
bool ClipToBox(const Eigen::Vector3d& o, const Eigen::Vector3d& d, const Eigen::Vector3d& lo,
               const Eigen::Vector3d& hi, double r, double* t0, double* t1) {
  double a = 0, b = r;
  for (int k = 0; k < 3; ++k) {
    if (std::abs(d[k]) < 1e-12) {
      if (o[k] < lo[k] || o[k] > hi[k]) return false;
      continue;
    }
    double ta = (lo[k] - o[k]) / d[k], tb = (hi[k] - o[k]) / d[k];
    if (ta > tb) std::swap(ta, tb);
    a = std::max(a, ta);
    b = std::min(b, tb);
  }
  *t0 = a;
  *t1 = b;
  return a < b;
}

// extinction (1/m) and backscatter (1/(m sr)) of the media of one EffectsFrame, channel 0.
class MediaView {
 public:
  explicit MediaView(const EffectsFrame* fx) : fx_(fx) {
    if (fx_)
      for (const GridMedium& g : fx_->grid_media) X_GW_.push_back(g.X_WG.inverse());
  }
  bool empty() const { return !fx_ || (fx_->homogeneous_media.empty() && fx_->grid_media.empty()); }

  // sigma_t and beta at p_W
  void At(const Eigen::Vector3d& p, double* sigma, double* beta) const {
    *sigma = 0;
    *beta = 0;
    for (const HomogeneousMedium& m : fx_->homogeneous_media) {
      if (m.region && ((p.array() < m.region->min_W.array()).any() ||
                       (p.array() > m.region->max_W.array()).any()))
        continue;
      double s = m.sigma_t_per_m[0];
      if (m.height_falloff_per_m > 0)
        s *= std::exp(-m.height_falloff_per_m * std::max(0.0, p.z() - m.base_height_m));
      *sigma += s;
      *beta += s * m.albedo[0] * kBetaPerSigma;
    }
    for (size_t gi = 0; gi < fx_->grid_media.size(); ++gi) {
      const GridMedium& g = fx_->grid_media[gi];
      const double d = GridDensityLocal(g, X_GW_[gi] * p);
      if (d <= 0) continue;
      *sigma += d * g.sigma_t_per_m[0];
      *beta += d * g.sigma_t_per_m[0] * g.albedo[0] * kBetaPerSigma;
    }
  }

  // int_0^r sigma_t(o + s d) ds
  double OpticalDepth(const Eigen::Vector3d& o, const Eigen::Vector3d& d, double r) const {
    double tau = 0;
    for (const HomogeneousMedium& m : fx_->homogeneous_media) {
      double t0 = 0, t1 = r;
      if (m.region && !ClipToBox(o, d, m.region->min_W, m.region->max_W, r, &t0, &t1)) continue;
      if (m.height_falloff_per_m <= 0) {
        tau += m.sigma_t_per_m[0] * (t1 - t0);
        continue;
      }
      // height fog: midpoint rule on 16 steps
      const int n = 16;
      const double h = (t1 - t0) / n;
      for (int i = 0; i < n; ++i) {
        const double z = o.z() + (t0 + (i + 0.5) * h) * d.z();
        tau += m.sigma_t_per_m[0] *
               std::exp(-m.height_falloff_per_m * std::max(0.0, z - m.base_height_m)) * h;
      }
    }
    for (size_t gi = 0; gi < fx_->grid_media.size(); ++gi) {
      const GridMedium& g = fx_->grid_media[gi];
      const Eigen::Vector3d o_G = X_GW_[gi] * o;
      const Eigen::Vector3d d_G = g.X_WG.linear().transpose() * d;
      double t0, t1;
      if (!ClipToBox(o_G, d_G, -g.half_extents_m, g.half_extents_m, r, &t0, &t1)) continue;
      const double voxel = std::min({2 * g.half_extents_m.x() / std::max(g.nx, 1),
                                     2 * g.half_extents_m.y() / std::max(g.ny, 1),
                                     2 * g.half_extents_m.z() / std::max(g.nz, 1)});
      const int n = std::clamp(static_cast<int>(std::ceil((t1 - t0) / voxel)), 1, 128);
      const double h = (t1 - t0) / n;
      double acc = 0;
      for (int i = 0; i < n; ++i) acc += GridDensityLocal(g, o_G + (t0 + (i + 0.5) * h) * d_G);
      tau += acc * h * g.sigma_t_per_m[0];
    }
    return tau;
  }

 private:
  // nearest-voxel density at a point in the grid frame
  static double GridDensityLocal(const GridMedium& g, const Eigen::Vector3d& p) {
    if (!g.density || g.nx <= 0 || g.ny <= 0 || g.nz <= 0) return 0;
    const Eigen::Vector3d u = (p + g.half_extents_m).cwiseQuotient(2 * g.half_extents_m);
    if ((u.array() < 0).any() || (u.array() >= 1).any()) return 0;
    const int i = std::min(g.nx - 1, static_cast<int>(u.x() * g.nx));
    const int j = std::min(g.ny - 1, static_cast<int>(u.y() * g.ny));
    const int k = std::min(g.nz - 1, static_cast<int>(u.z() * g.nz));
    return (*g.density)[(static_cast<size_t>(k) * g.ny + j) * g.nx + i];
  }
  const EffectsFrame* fx_;
  std::vector<Pose> X_GW_;  // inverse grid poses
};

struct ParticleCandidate {
  int beam;
  int set;
  int index;
};

}  // namespace

void LidarConfig::ValidateOrThrow() const {
  const auto bad = [](const std::string& key, double v, const std::string& range) {
    throw Error("lidar: " + key + " = " + std::to_string(v) + " is out of range; expected " +
                range);
  };
  if (pattern.beams.empty()) throw Error("lidar: the scan pattern has no beams");
  if (!(pattern.rate_hz > 0)) bad("rate_hz", pattern.rate_hz, "> 0");
  if (!(pattern.min_range_m >= 0 && pattern.min_range_m < pattern.max_range_m))
    bad("min_range_m", pattern.min_range_m, "[0, max_range_m)");
  if (!(range_noise_stddev_m >= 0 && std::isfinite(range_noise_stddev_m)))
    bad("range_noise_stddev_m", range_noise_stddev_m, ">= 0");
  if (!(dropout_probability >= 0 && dropout_probability <= 1))
    bad("dropout_probability", dropout_probability, "[0, 1]");
  if (!(min_intensity >= 0 && std::isfinite(min_intensity)))
    bad("min_intensity", min_intensity, ">= 0");
  if (!(reference_reflectivity > 0 && reference_reflectivity <= 1))
    bad("reference_reflectivity", reference_reflectivity, "(0, 1]");
  if (!(receiver_noise >= 0 && std::isfinite(receiver_noise)))
    bad("receiver_noise", receiver_noise, ">= 0");
  if (!(pulse_half_power_width_ns > 0 && std::isfinite(pulse_half_power_width_ns)))
    bad("pulse_half_power_width_ns", pulse_half_power_width_ns, "> 0");
  if (!(overlap_start_m >= 0 && overlap_full_m > overlap_start_m))
    bad("overlap_full_m", overlap_full_m, "> overlap_start_m >= 0");
  if (footprint_rays < 0 || footprint_rays > kMaxFootprintRays)
    bad("footprint_rays", footprint_rays, "[0, " + std::to_string(kMaxFootprintRays) + "]");
}

Pose InterpolatePose(const Pose& a, const Pose& b, double s) {
  Pose X = Pose::Identity();
  const Eigen::Quaterniond qa(a.linear()), qb(b.linear());
  X.linear() = qa.slerp(s, qb).toRotationMatrix();
  X.translation() = (1 - s) * a.translation() + s * b.translation();
  return X;
}

LidarScanner::LidarScanner(LidarConfig config, uint64_t stream_seed)
    : config_(std::move(config)), seed_(stream_seed) {
  config_.ValidateOrThrow();
  const LidarPattern& p = config_.pattern;
  p_th_ = config_.reference_reflectivity / kScanPi / (p.max_range_m * p.max_range_m);
  const int n = static_cast<int>(p.beams.size());
  dir_S_.resize(n);
  for (int i = 0; i < n; ++i) p.Direction(i, &dir_S_[i].x(), &dir_S_[i].y(), &dir_S_[i].z());
  // beams bucketed by (azimuth, elevation) for the particle lookup
  n_az_ = static_cast<int>(std::lround(360.0 / kBinDeg));
  n_el_ = static_cast<int>(std::lround(180.0 / kBinDeg));
  std::vector<int> count(static_cast<size_t>(n_az_) * n_el_ + 1, 0);
  std::vector<int> bin(n);
  for (int i = 0; i < n; ++i) {
    const double az = std::atan2(dir_S_[i].y(), dir_S_[i].x()) * 180 / kScanPi + 180;  // [0, 360]
    const double el = std::asin(std::clamp(dir_S_[i].z(), -1.0f, 1.0f)) * 180 / kScanPi + 90;
    const int a = std::min(n_az_ - 1, static_cast<int>(az / kBinDeg));
    const int e = std::min(n_el_ - 1, static_cast<int>(el / kBinDeg));
    bin[i] = a * n_el_ + e;
    ++count[bin[i] + 1];
  }
  el_min_deg_ = 90;
  el_max_deg_ = -90;
  for (int i = 0; i < n; ++i) {
    const double el = std::asin(std::clamp(dir_S_[i].z(), -1.0f, 1.0f)) * 180 / kScanPi;
    el_min_deg_ = std::min(el_min_deg_, el);
    el_max_deg_ = std::max(el_max_deg_, el);
  }
  for (size_t k = 1; k < count.size(); ++k) count[k] += count[k - 1];
  bin_start_ = count;
  bin_beams_.resize(n);
  std::vector<int> fill(count.begin(), count.end() - 1);
  for (int i = 0; i < n; ++i) bin_beams_[fill[bin[i]]++] = i;
}

void LidarScanner::Scan(const RayQuery& scene, const EffectsFrame* effects,
                        const SensorPoseAt& X_WS, int64_t scan_index, LidarScan* out) const {
  const LidarPattern& pat = config_.pattern;
  const SceneDescription& desc = scene.scene();
  const int n = static_cast<int>(pat.beams.size());
  out->points.clear();
  out->rays = n;
  out->medium_returns = 0;
  out->particle_returns = 0;
  const MediaView media(config_.media ? effects : nullptr);
  const bool has_media = config_.media && !media.empty();
  const double tan_half_div = std::tan(0.5 * pat.beam_divergence_rad);
  const double sigma_n = config_.receiver_noise * p_th_;
  const double pulse_len = kSpeedOfLight * config_.pulse_half_power_width_ns * 1e-9 / 2;
  const double r1 = config_.overlap_start_m, r2 = config_.overlap_full_m;
  // the weakest power that can still be detected (receiver noise up to 5 sigma), and the
  // largest backscatter-per-range-squared numerator any return can have (for early exits)
  const double floor_power = std::max(0.0, p_th_ - 5 * sigma_n);
  double beta_max = 0;
  if (has_media) {
    for (const HomogeneousMedium& m : effects->homogeneous_media)
      beta_max += m.sigma_t_per_m[0] * m.albedo[0] * kBetaPerSigma;
    for (const GridMedium& g : effects->grid_media)
      beta_max += g.max_density * g.sigma_t_per_m[0] * g.albedo[0] * kBetaPerSigma;
  }
  const double bound_numerator = std::max(beta_max * pulse_len, 1.0 / kScanPi);

  // particle candidates per beam (CSR by beam), from the scan-start pose
  std::vector<int> cand_start;
  std::vector<ParticleCandidate> cands;
  if (config_.media && effects && !effects->particles.empty()) {
    // the particle's direction in the sensor frame at 3 instants over the scan (the sensor
    // may move and turn while scanning); the candidate bins cover all of them
    constexpr int kKeys = 3;
    const double period = 1.0 / pat.rate_hz;
    Pose X_SW[kKeys];
    for (int k = 0; k < kKeys; ++k) X_SW[k] = X_WS(period * k / (kKeys - 1)).inverse();
    const double pad_deg = 0.1;  // float rounding and the motion between the key poses
    std::vector<double> rho_of_set;
    for (const ParticleSet& ps : effects->particles)
      rho_of_set.push_back(ps.kind == ParticleKind::kRain ? 0.02 : Luminance(ps.color));
    for (int s = 0; s < static_cast<int>(effects->particles.size()); ++s) {
      const ParticleSet& ps = effects->particles[s];
      for (int i = 0; i < static_cast<int>(ps.position_W.size()); ++i) {
        const Eigen::Vector3d p_W = ps.position_W[i].cast<double>();
        const double rp = i < static_cast<int>(ps.radius_m.size()) ? ps.radius_m[i] : 0.0;
        {
          // skip particles too faint to be detected anywhere in the scan: the most they can
          // return (full transmittance) is rho_p / pi min(1, (r_p / r_beam)^2) / R^2
          const double R = std::max((X_SW[0] * p_W).norm() - 1.0, pat.min_range_m);
          const double r_beam = R * tan_half_div;
          const double cover = r_beam > rp ? (rp * rp) / (r_beam * r_beam) : 1.0;
          if (rho_of_set[s] / kScanPi * cover / (R * R) + 5 * sigma_n < p_th_) continue;
        }
        double az_lo = 1e9, az_hi = -1e9, el_lo = 1e9, el_hi = -1e9, ang = 0, az_ref = 0;
        bool in_range = false;
        for (int k = 0; k < kKeys; ++k) {
          const Eigen::Vector3d p_S = X_SW[k] * p_W;
          const double dist = p_S.norm();
          if (dist < pat.min_range_m - rp || dist > pat.max_range_m + rp || dist <= 0) continue;
          in_range = true;
          ang = std::max(
              ang, std::asin(std::min(1.0, (rp + dist * tan_half_div) / dist)) * 180 / kScanPi);
          double az = std::atan2(p_S.y(), p_S.x()) * 180 / kScanPi + 180;
          if (az_lo > az_hi) az_ref = az;
          az = az_ref + std::remainder(az - az_ref, 360.0);  // unwrap around the first key
          const double el = std::asin(std::clamp(p_S.z() / dist, -1.0, 1.0)) * 180 / kScanPi + 90;
          az_lo = std::min(az_lo, az);
          az_hi = std::max(az_hi, az);
          el_lo = std::min(el_lo, el);
          el_hi = std::max(el_hi, el);
        }
        if (!in_range) continue;
        ang += pad_deg;
        // outside the pattern's elevation span: no beam can reach it
        if (el_hi + ang < el_min_deg_ + 90 || el_lo - ang > el_max_deg_ + 90) continue;
        const int e0 = std::max(0, static_cast<int>((el_lo - ang) / kBinDeg));
        const int e1 = std::min(n_el_ - 1, static_cast<int>((el_hi + ang) / kBinDeg));
        const int a0 = static_cast<int>(std::floor((az_lo - ang) / kBinDeg));
        const int a1 =
            std::min(a0 + n_az_ - 1, static_cast<int>(std::floor((az_hi + ang) / kBinDeg)));
        for (int a = a0; a <= a1; ++a) {
          const int aw = ((a % n_az_) + n_az_) % n_az_;
          for (int e = e0; e <= e1; ++e) {
            const int b = aw * n_el_ + e;
            for (int k = bin_start_[b]; k < bin_start_[b + 1]; ++k)
              cands.push_back({bin_beams_[k], s, i});
          }
        }
      }
    }
    // group by beam (counting sort; within a beam, particle order = set, index as collected)
    std::vector<int> count(n + 1, 0);
    for (const ParticleCandidate& c : cands) ++count[c.beam + 1];
    for (int k = 0; k < n; ++k) count[k + 1] += count[k];
    std::vector<ParticleCandidate> sorted(cands.size());
    for (const ParticleCandidate& c : cands) sorted[count[c.beam]++] = c;
    cands.swap(sorted);
  }
  size_t cand_pos = 0;

  std::vector<Ray> rays(kChunk);
  std::vector<SurfaceHit> hits(kChunk);
  bool did_hit[kChunk];
  // the beam's footprint: K more rays on a ring of 0.7 half-divergences around the axis (the
  // rms radius of a uniform disc), traced per chunk
  const int K = pat.beam_divergence_rad > 0 ? config_.footprint_rays : 0;
  const double ring = 0.7 * tan_half_div;
  std::vector<Ray> fp_rays(static_cast<size_t>(kChunk) * K);
  std::vector<SurfaceHit> fp_hits(fp_rays.size());
  std::unique_ptr<bool[]> fp_did_hit(new bool[std::max<size_t>(1, fp_rays.size())]);
  std::vector<int> fp_first(kChunk, -1);  // first footprint ray of each beam, -1 = none
  float last_time = -1;
  Pose X = Pose::Identity();
  for (int start = 0; start < n; start += kChunk) {
    const int m = std::min(kChunk, n - start);
    for (int j = 0; j < m; ++j) {
      const LidarBeam& b = pat.beams[start + j];
      if (b.time_sec != last_time) {
        X = X_WS(b.time_sec);
        last_time = b.time_sec;
      }
      Ray& r = rays[j];
      r.o = X.translation().cast<float>();
      r.d = (X.linear().cast<float>() * dir_S_[start + j]).normalized();
      r.tmin = 0.0f;
      r.tmax = static_cast<float>(pat.max_range_m);
    }
    scene.Intersect(std::span<const Ray>(rays.data(), m), std::span<SurfaceHit>(hits.data(), m),
                    std::span<bool>(did_hit, m));
    int n_fp = 0;
    if (K > 0) {
      // only beams that may straddle an edge trace their footprint: a neighbour (the next beam
      // either way, and the neighbouring column of a spinning sensor, within 2.5 deg) hits and
      // this one does
      // not or the other way round, or its hit lies off this hit's tangent plane by more than
      // 5 cm + 2 % of the range (a plane seen at any angle keeps its neighbours on it)
      const int col = pat.spinning && pat.rings > 0 ? pat.rings : 0;
      for (int j = 0; j < m; ++j) {
        bool edge = false;
        for (const int nb : {j - 1, j + 1, j - col, j + col}) {
          if (nb == j || nb < 0 || nb >= m) continue;
          // a neighbour in the firing order that is not one in angle (a new column) is skipped
          if (dir_S_[start + nb].dot(dir_S_[start + j]) < kCosNeighbour) continue;
          if (did_hit[nb] != did_hit[j]) {
            edge = true;
            break;
          }
          if (!did_hit[j]) continue;
          const double off = std::abs(hits[j].ng_W.dot(hits[nb].p_W - hits[j].p_W));
          if (off > 0.05 + 0.02 * hits[j].t) {
            edge = true;
            break;
          }
        }
        fp_first[j] = -1;
        if (!edge) continue;
        fp_first[j] = n_fp;
        const Eigen::Vector3f d = rays[j].d;
        const Eigen::Vector3f e1 = d.unitOrthogonal(), e2 = d.cross(e1);
        for (int k = 0; k < K; ++k) {
          const float phi = static_cast<float>(2 * kScanPi * (k + 0.5) / K);
          Ray& r = fp_rays[n_fp++];
          r = rays[j];
          r.d = (d + static_cast<float>(ring) * (std::cos(phi) * e1 + std::sin(phi) * e2))
                    .normalized();
        }
      }
      if (n_fp > 0)
        scene.Intersect(std::span<const Ray>(fp_rays.data(), n_fp),
                        std::span<SurfaceHit>(fp_hits.data(), n_fp),
                        std::span<bool>(fp_did_hit.get(), n_fp));
    }
    for (int j = 0; j < m; ++j) {
      const int i = start + j;
      const LidarBeam& beam = pat.beams[i];
      // draws in a fixed order, each only when its model is on (a noise-free beam costs none)
      Rng rng(HashKeys(seed_, static_cast<uint64_t>(scan_index), static_cast<uint64_t>(i)));
      const double u_drop = config_.dropout_probability > 0 ? rng.UniformD() : 1.0;
      const double n_range = config_.range_noise_stddev_m > 0 ? StandardNormal(&rng) : 0.0;
      const double n_hard = sigma_n > 0 ? StandardNormal(&rng) : 0.0;
      const double n_soft = sigma_n > 0 ? StandardNormal(&rng) : 0.0;
      const double n_part = sigma_n > 0 ? StandardNormal(&rng) : 0.0;
      const Ray& ray = rays[j];
      const Eigen::Vector3d o = ray.o.cast<double>(), d = ray.d.cast<double>();

      // candidates: hard target, medium peak, particle; strongest wins
      double best_p = -std::numeric_limits<double>::infinity(), best_r = 0;
      LidarReturnKind best_kind = LidarReturnKind::kSurface;
      const double r_end = did_hit[j] ? hits[j].t : pat.max_range_m;
      // soft target first: P_soft(R) sampled on [R1, R_end], stopping where nothing beyond
      // can reach the detection floor (the most any later return can bring is
      // e^{-2 tau} max(beta_max L, 1 / pi) / R^2)
      double tau_stop = 0, r_stop = r_end, tau_end = -1;
      if (has_media) {
        const double a = std::max(r1, pat.min_range_m), b = r_end;
        if (b > a) {
          const double h = (b - a) / kSoftSamples;
          double tau = media.OpticalDepth(o, d, a);
          double trans = std::exp(-2 * tau);  // T^2 at the start of the current step
          double soft_best = 0, soft_r = 0;
          for (int k = 0; k < kSoftSamples; ++k) {
            const double R = a + (k + 0.5) * h;
            const double bound = trans * bound_numerator / (R * R);
            if (bound < std::max(soft_best, floor_power)) {
              tau_stop = tau;
              r_stop = R;
              break;
            }
            double sigma, beta;
            media.At(o + R * d, &sigma, &beta);
            // T^2 over half a step: e^{-sigma h} (one exp per sample)
            const double half = sigma > 0 ? std::exp(-sigma * h) : 1.0;
            const double trans_mid = trans * half;
            trans = trans_mid * half;
            tau += sigma * h;
            if (beta <= 0) continue;
            const double xi = std::clamp((R - r1) / (r2 - r1), 0.0, 1.0);
            const double ps = beta * pulse_len * xi * trans_mid / (R * R);
            if (ps > soft_best) {
              soft_best = ps;
              soft_r = R;
            }
          }
          if (r_stop == r_end) tau_end = tau;  // marched to the target: its optical depth
          if (soft_best > 0) {
            const double ps = soft_best + sigma_n * n_soft;
            if (ps > best_p) {
              best_p = ps;
              best_r = soft_r;
              best_kind = LidarReturnKind::kMedium;
            }
          }
        }
      }
      // hard target: the power of one ray's surface hit (LiDAR equation, media T^2)
      auto hard_power = [&](const SurfaceHit& h, const Ray& ry, bool main_ray) {
        const double r = h.t;
        const float rho = h.material >= 0 && h.material < static_cast<int>(desc.materials.size())
                              ? Luminance(desc.materials[h.material].base_color)
                              : 0.8f;
        const double cos_t = std::abs(static_cast<double>(h.ng_W.dot(ry.d)));
        double p = rho * cos_t / kScanPi / (r * r);
        if (has_media) {
          // zero if the soft-target march already showed it undetectable; else T^2 from the
          // march's optical depth (exact for uniform media: the initial segment is exact and
          // the midpoint sum of a constant is exact; 48 midpoint samples for height fog and
          // grids), or from OpticalDepth when the march did not run
          if (main_ray && r_stop < r_end && p * std::exp(-2 * tau_stop) < floor_power)
            p = 0;
          else if (main_ray && tau_end >= 0)
            p *= std::exp(-2 * tau_end);
          else
            p *= std::exp(-2 * media.OpticalDepth(ry.o.cast<double>(), ry.d.cast<double>(), r));
        }
        return p;
      };
      double hard_p = 0, hard_r = 0;
      bool hard = false;
      if (K == 0 || fp_first[j] < 0) {
        if (did_hit[j]) {
          hard = true;
          hard_r = hits[j].t;
          hard_p = hard_power(hits[j], ray, true);
        }
      } else {
        // the footprint's returns (equal weights, axis and ring) overlap in time when their
        // ranges differ by less than the pulse length and the receiver sees one pulse: the
        // strongest such group is the return, at its power-weighted mean range (a mixed
        // return between foreground and background on an edge); farther apart they are
        // separate pulses and the stronger group wins
        double ps[kMaxFootprintRays + 1], rs[kMaxFootprintRays + 1];
        int ns = 0;
        if (did_hit[j]) {
          rs[ns] = hits[j].t;
          ps[ns++] = hard_power(hits[j], ray, true);
        }
        for (int k = 0; k < K; ++k) {
          const size_t f = static_cast<size_t>(fp_first[j]) + k;
          if (!fp_did_hit[f]) continue;
          rs[ns] = fp_hits[f].t;
          ps[ns++] = hard_power(fp_hits[f], fp_rays[f], false);
        }
        double best_group = 0;
        for (int a = 0; a < ns; ++a) {
          double sp = 0, spr = 0;
          for (int b = 0; b < ns; ++b) {
            if (std::abs(rs[b] - rs[a]) >= pulse_len) continue;
            sp += ps[b];
            spr += ps[b] * rs[b];
          }
          if (sp > best_group) {
            best_group = sp;
            hard_r = spr / sp;
          }
        }
        if (best_group > 0) {
          hard = true;
          hard_p = best_group / (K + 1);
        }
      }
      if (hard) {
        const double p = hard_p + sigma_n * n_hard;
        if (hard_r >= pat.min_range_m && p > best_p) {
          best_p = p;
          best_r = hard_r;
          best_kind = LidarReturnKind::kSurface;
        }
      }
      if (!cands.empty()) {
        while (cand_pos < cands.size() && cands[cand_pos].beam < i) ++cand_pos;
        double p_best_part = 0, r_part = 0;
        for (size_t c = cand_pos; c < cands.size() && cands[c].beam == i; ++c) {
          const ParticleSet& ps = effects->particles[cands[c].set];
          const Eigen::Vector3d q = ps.position_W[cands[c].index].cast<double>();
          const double rp = cands[c].index < static_cast<int>(ps.radius_m.size())
                                ? ps.radius_m[cands[c].index]
                                : 0.0;
          const double tc = (q - o).dot(d);
          if (tc <= 0) continue;
          const double d2 = (q - o - tc * d).squaredNorm();
          const double r_beam = tc * tan_half_div;
          const double reach = rp + r_beam;
          if (d2 > reach * reach) continue;
          const double R = tc - std::sqrt(std::max(0.0, rp * rp - d2));
          if (R < pat.min_range_m || R >= r_end) continue;
          const double rho = ps.kind == ParticleKind::kRain ? 0.02 : Luminance(ps.color);
          const double cover = r_beam > 0 ? std::min(1.0, (rp * rp) / (r_beam * r_beam)) : 1.0;
          double p = rho / kScanPi * cover / (R * R);
          if (has_media) p *= std::exp(-2 * media.OpticalDepth(o, d, R));
          if (p > p_best_part) {
            p_best_part = p;
            r_part = R;
          }
        }
        if (p_best_part > 0) {
          const double p = p_best_part + sigma_n * n_part;
          if (p > best_p) {
            best_p = p;
            best_r = r_part;
            best_kind = LidarReturnKind::kParticle;
          }
        }
      }
      if (!(best_p >= p_th_)) continue;
      if (u_drop < config_.dropout_probability) continue;
      const double intensity =
          kScanPi * best_p * (config_.intensity_range_normalized ? best_r * best_r : 1.0);
      if (intensity < config_.min_intensity) continue;
      const double range = best_r + config_.range_noise_stddev_m * n_range;
      if (range <= 0) continue;
      LidarPoint pt;
      const Eigen::Vector3f& ds = dir_S_[i];
      pt.x = static_cast<float>(range * ds.x());
      pt.y = static_cast<float>(range * ds.y());
      pt.z = static_cast<float>(range * ds.z());
      pt.intensity = static_cast<float>(intensity);
      pt.ring = static_cast<uint16_t>(beam.ring);
      pt.time = beam.time_sec;
      pt.kind = best_kind;
      pt.beam = i;
      if (best_kind == LidarReturnKind::kMedium) ++out->medium_returns;
      if (best_kind == LidarReturnKind::kParticle) ++out->particle_returns;
      out->points.push_back(pt);
    }
  }
}

}  // namespace penumbra

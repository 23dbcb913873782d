#include "penumbra/sensors/depth_noise.h"

#include <fmt/format.h>

#include <Eigen/Core>
#include <algorithm>
#include <cmath>
#include <complex>
#include <limits>
#include <opencv2/core.hpp>
#include <opencv2/imgproc.hpp>
#include <vector>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/media/media_scene.h"
#include "penumbra/sensors/image_noise.h"

namespace penumbra {
namespace {

// theta^2 / (pi/2 - theta)^2, the angular growth term of Nguyen 2012 and Fankhauser 2015.
double AngleTerm(double theta) {
  const double d = std::max(1e-6, 0.5 * M_PI - theta);
  return theta * theta / (d * d);
}

}  // namespace

double DepthNoiseModel::AxialSigma(double z, double theta, double fx_px) const {
  switch (axial) {
    case Axial::kKinectV1:
      return 0.0012 + 0.0019 * (z - 0.4) * (z - 0.4) + 0.0001 / std::sqrt(z) * AngleTerm(theta);
    case Axial::kKinectV2:
      return 1e-3 * (1.5 - 0.5 * z + 0.3 * z * z + 0.1 * std::pow(z, 1.5) * AngleTerm(theta));
    case Axial::kStereoRms:
      return z * z * stereo_subpixel / (fx_px * stereo_baseline_m);
  }
  return 0;
}

double DepthNoiseModel::LateralSigmaPx(double theta) const {
  return lateral_sigma_px + lateral_theta_coeff * theta / std::max(1e-6, 0.5 * M_PI - theta);
}

double DepthNoiseModel::InvalidBandPx(double z, double fx_px) const {
  if (kind != Kind::kActiveStereo || !invalid_band || !(z > 0)) return 0.0;
  return fx_px * stereo_baseline_m / z;
}

DepthNoiseModel DepthNoisePreset(const DepthNoiseConfig& config, const std::string& key) {
  DepthNoiseModel m;
  m.name = config.preset;
  if (config.preset == "realsense_d435") {
    m.kind = DepthNoiseModel::Kind::kActiveStereo;
    m.axial = DepthNoiseModel::Axial::kStereoRms;
    m.min_range_m = 0.2;
    m.max_range_m = 10.0;
    m.lateral_sigma_px = 0.5;
  } else if (config.preset == "kinect_v1") {
    m.kind = DepthNoiseModel::Kind::kStructuredLight;
    m.axial = DepthNoiseModel::Axial::kKinectV1;
    m.min_range_m = 0.5;
    m.max_range_m = 4.0;
    m.lateral_sigma_px = 0.8;
    m.lateral_theta_coeff = 0.035;
    m.stereo_baseline_m = 0.075;
    m.window_px = 9;
    m.passive_texture = false;
    m.invalid_band = false;
    m.ambient_fraction = 0.04;
    m.projector_luminance_1m = 80;
  } else if (config.preset == "kinect_v2") {
    m.kind = DepthNoiseModel::Kind::kTimeOfFlight;
    m.axial = DepthNoiseModel::Axial::kKinectV2;
    m.min_range_m = 0.5;
    m.max_range_m = 4.5;
    m.lateral_sigma_px = 1.6;
  } else {
    std::string names;
    for (std::string_view n : kDepthNoisePresets)
      names += (names.empty() ? "" : ", ") + std::string(n);
    throw ConfigError(
        "", 0, key + ".preset",
        "unknown depth noise preset '" + config.preset + "'; expected one of: " + names);
  }
  if (config.min_range_m) m.min_range_m = *config.min_range_m;
  if (config.max_range_m) m.max_range_m = *config.max_range_m;
  if (!(m.min_range_m >= 0) || !(m.max_range_m > m.min_range_m) || !std::isfinite(m.max_range_m))
    throw ConfigError("", 0, key + ".max_range_m",
                      "range [" + std::to_string(m.min_range_m) + ", " +
                          std::to_string(m.max_range_m) +
                          "] m; expected 0 <= min_range_m < max_range_m, finite");
  return m;
}

namespace {

// the ray (x, y, 1) of pixel (u, v) in the optical frame.
Eigen::Vector3d PixelRay(const DepthNoiseInputs& in, int u, int v) {
  const Eigen::Vector2d xy = in.camera ? in.camera->Unproject(u, v)
                                       : Eigen::Vector2d((u - in.cx) / in.fx, (v - in.cy) / in.fy);
  return Eigen::Vector3d(xy.x(), xy.y(), 1.0);
}

void CheckInputSize(const ImageF* img, const ImageF& depth, int channels, const char* name) {
  if (!img || img->empty()) return;
  if (img->width != depth.width || img->height != depth.height || img->channels != channels)
    throw Error(fmt::format(
        "ApplyDepthNoise: {} is {} x {} x {}; expected the depth image's {} x {} x {}", name,
        img->width, img->height, img->channels, depth.width, depth.height, channels));
}

// box mean over a w x w window (mirrored borders), in double.
cv::Mat BoxMean(const cv::Mat& m, int w) {
  cv::Mat out;
  cv::boxFilter(m, out, CV_64F, cv::Size(w, w), cv::Point(-1, -1), true, cv::BORDER_REFLECT);
  return out;
}

// per-pixel inputs of every model, flattened (index v * W + u).
struct PixelInputs {
  std::vector<float> cos_theta, rho, transmittance, ray_norm;
  std::vector<uint8_t> specular;
  std::vector<Eigen::Vector3f> normal;  // facing the camera
};

// correlation matcher (active stereo, structured light): 1 where the window finds its match
// and both views see the point (see the header, steps 2-5).
std::vector<uint8_t> MatcherValid(const ImageF& depth_z, const DepthNoiseInputs& in,
                                  const PixelInputs& px, const DepthNoiseModel& model, uint64_t key,
                                  ThreadPool* pool) {
  const int W = depth_z.width, H = depth_z.height;
  const int w = std::max(1, model.window_px | 1);
  cv::Mat A(H, W, CV_64F), S(H, W, CV_64F), V(H, W, CV_64F);
  const bool have_ambient = in.ambient_cd_m2 && !in.ambient_cd_m2->empty();
  ParallelForOrSerial(pool, H, [&](int v) {
    for (int u = 0; u < W; ++u) {
      const size_t i = static_cast<size_t>(v) * W + u;
      const double z = depth_z.data[i];
      const bool hit = z > 0;
      const double t2 = static_cast<double>(px.transmittance[i]) * px.transmittance[i];
      const double rho = px.specular[i] ? 0.0 : px.rho[i];
      const double lum =
          have_ambient ? std::max(0.0f, in.ambient_cd_m2->data[i])
                       : (hit ? model.default_ambient_cd_m2 * rho * px.transmittance[i] : 0.0);
      A.at<double>(v, u) = model.ambient_fraction * lum / model.projector_luminance_1m;
      S.at<double>(v, u) = hit ? rho * px.cos_theta[i] * t2 / (z * z) : 0.0;
      V.at<double>(v, u) = hit ? model.backscatter * (1.0 - t2) : 0.0;
    }
  });
  // white noise on the image padded by the window's half width, so that every window below
  // averages w^2 independent samples (mirrored borders would repeat some)
  const int r = w / 2, PW = W + 2 * r, PH = H + 2 * r;
  cv::Mat noise(PH, PW, CV_64F);
  ParallelForOrSerial(pool, PH, [&](int v) {
    for (int u = 0; u < PW; ++u) {
      Rng rng(HashKeys(key, static_cast<uint64_t>(v) * static_cast<uint64_t>(PW) + u, 7));
      noise.at<double>(v, u) = SampleStandardNormal(&rng);
    }
  });
  // global auto exposure from the frame's mean signal (summed in a fixed order)
  const double p = model.dot_fill;
  double frame_sum = 0.0;
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u)
      frame_sum += A.at<double>(v, u) + p * S.at<double>(v, u) + V.at<double>(v, u);
  const double frame_mean = frame_sum / std::max<double>(1.0, static_cast<double>(W) * H);
  const double gain = model.target_electrons / std::max(frame_mean, model.min_frame_signal);
  const cv::Mat mA = BoxMean(A, w), mA2 = BoxMean(A.mul(A), w), mS = BoxMean(S, w),
                mV = BoxMean(V, w);
  // the window score's fluctuation: white noise averaged over the window, rescaled to unit
  // variance (a box mean of w^2 unit normals has standard deviation 1 / w)
  const cv::Mat jitter = BoxMean(noise, w)(cv::Rect(r, r, W, H)) * static_cast<double>(w);
  cv::Mat matched(H, W, CV_64F);
  const double read2 = model.read_noise_e * model.read_noise_e;
  ParallelForOrSerial(pool, H, [&](int v) {
    for (int u = 0; u < W; ++u) {
      const double a = mA.at<double>(v, u), s = mS.at<double>(v, u);
      const double var_a =
          model.passive_texture ? std::max(0.0, mA2.at<double>(v, u) - a * a) : 0.0;
      const double texture = std::sqrt(var_a + p * (1.0 - p) * s * s);
      const double mean = a + p * s + mV.at<double>(v, u);
      const double snr = gain * texture / std::sqrt(gain * mean + read2);
      matched.at<double>(v, u) =
          snr * std::exp(model.snr_jitter * jitter.at<double>(v, u)) >= model.min_snr ? 1.0 : 0.0;
    }
  });
  // the matcher's consistency filtering: a pixel keeps its match when most of its window did
  const cv::Mat majority = BoxMean(matched, w);
  std::vector<uint8_t> valid(static_cast<size_t>(W) * H, 0);
  for (int v = 0; v < H; ++v)
    for (int u = 0; u < W; ++u)
      valid[static_cast<size_t>(v) * W + u] = majority.at<double>(v, u) > 0.5;
  // occlusion and the left invalid band: the second view (right imager or projector) is at
  // +baseline along optical x; pixel u lands at u - d there
  ParallelForOrSerial(pool, H, [&](int v) {
    double min_xr = std::numeric_limits<double>::infinity();
    for (int u = W - 1; u >= 0; --u) {
      const size_t i = static_cast<size_t>(v) * W + u;
      const double z = depth_z.data[i];
      if (!(z > 0)) continue;
      const double xr = u - in.fx * model.stereo_baseline_m / z;
      if (xr >= min_xr || (model.invalid_band && xr < 0.0)) valid[i] = 0;
      min_xr = std::min(min_xr, xr);
    }
  });
  return valid;
}

// time of flight: each pixel's range after mixing its footprint (flying pixels at depth edges)
// and one-bounce multipath; returns the z-depth the phase gives (0 where there is no return).
std::vector<float> TofDepth(const ImageF& depth_z, const DepthNoiseInputs& in,
                            const PixelInputs& px, const DepthNoiseModel& model, ThreadPool* pool) {
  const int W = depth_z.width, H = depth_z.height;
  constexpr double kC = 299792458.0;
  const double k = 2.0 * M_PI * model.modulation_hz / kC;  // phase per metre of path
  // amplitude of each pixel's own return: rho cos(theta) / r^2
  std::vector<double> amp(static_cast<size_t>(W) * H, 0.0), range(amp.size(), 0.0);
  for (size_t i = 0; i < amp.size(); ++i) {
    const double z = depth_z.data[i];
    if (!(z > 0)) continue;
    range[i] = z * px.ray_norm[i];
    const double rho = px.specular[i] ? 0.0 : px.rho[i];
    amp[i] = rho * px.cos_theta[i] / (range[i] * range[i]);
  }
  // multipath on a patch grid: path-length bias of the return, m of range
  const int stride = std::max(1, static_cast<int>(std::ceil(std::max(W / 48.0, H / 36.0))));
  const int gw = (W + stride - 1) / stride, gh = (H + stride - 1) / stride;
  std::vector<double> bias(static_cast<size_t>(gw) * gh, 0.0);
  if (model.multipath) {
    struct Patch {
      Eigen::Vector3d X, n;
      double r = 0, e = 0, radiance = 0, area = 0;
      bool hit = false;
    };
    std::vector<Patch> patches(bias.size());
    for (int j = 0; j < gh; ++j) {
      for (int i = 0; i < gw; ++i) {
        const int u = std::min(W - 1, i * stride + stride / 2),
                  v = std::min(H - 1, j * stride + stride / 2);
        const size_t q = static_cast<size_t>(v) * W + u;
        Patch& P = patches[static_cast<size_t>(j) * gw + i];
        const double z = depth_z.data[q];
        if (!(z > 0)) continue;
        const Eigen::Vector3d ray = PixelRay(in, u, v);
        P.hit = true;
        P.X = z * ray;
        P.r = P.X.norm();
        P.n = px.normal[q].cast<double>();
        const double c = std::max<double>(1e-3, px.cos_theta[q]);
        P.e = c / (P.r * P.r);  // irradiance from the emitter at the camera
        P.radiance = (px.specular[q] ? 0.0 : px.rho[q]) * P.e / M_PI;
        P.area = stride * stride * z * z / (in.fx * in.fy * ray.norm() * c);
      }
    }
    ParallelForOrSerial(pool, gh, [&](int j) {
      for (int i = 0; i < gw; ++i) {
        const size_t pi = static_cast<size_t>(j) * gw + i;
        const Patch& P = patches[pi];
        if (!P.hit || !(P.e > 0)) continue;
        std::complex<double> sum(P.e, 0.0);  // direct return, path 2 r_p
        for (size_t qi = 0; qi < patches.size(); ++qi) {
          const Patch& Q = patches[qi];
          if (qi == pi || !Q.hit || !(Q.radiance > 0)) continue;
          const Eigen::Vector3d d = P.X - Q.X;
          const double dist2 = d.squaredNorm(), dist = std::sqrt(dist2);
          if (!(dist > 0)) continue;
          const double cq = Q.n.dot(d) / dist, cp = -P.n.dot(d) / dist;
          if (cq <= 1e-6 || cp <= 1e-6) continue;
          // irradiance at p from q (disk form factor, bounded for near patches)
          const double e = Q.radiance * cq * cp * Q.area * M_PI / (M_PI * dist2 + Q.area);
          sum += std::polar(e, k * (Q.r + dist - P.r));
        }
        bias[pi] = 0.5 * std::arg(sum) / k;
      }
    });
  }
  auto bias_at = [&](int u, int v) {
    const double gx = std::clamp((u + 0.5) / stride - 0.5, 0.0, gw - 1.0),
                 gy = std::clamp((v + 0.5) / stride - 0.5, 0.0, gh - 1.0);
    const int x0 = static_cast<int>(gx), y0 = static_cast<int>(gy);
    const int x1 = std::min(gw - 1, x0 + 1), y1 = std::min(gh - 1, y0 + 1);
    const double fx = gx - x0, fy = gy - y0;
    auto b = [&](int x, int y) { return bias[static_cast<size_t>(y) * gw + x]; };
    return (1 - fy) * ((1 - fx) * b(x0, y0) + fx * b(x1, y0)) +
           fy * ((1 - fx) * b(x0, y1) + fx * b(x1, y1));
  };
  std::vector<float> out(amp.size(), 0.0f);
  const double s2 = 2.0 * model.tof_psf_sigma_px * model.tof_psf_sigma_px;
  ParallelForOrSerial(pool, H, [&](int v) {
    for (int u = 0; u < W; ++u) {
      const size_t i = static_cast<size_t>(v) * W + u;
      if (!(range[i] > 0)) continue;
      // the footprint's phasor sum, relative to the pixel's own range
      std::complex<double> sum(0.0, 0.0);
      double total = 0.0;
      for (int dv = -1; dv <= 1; ++dv) {
        for (int du = -1; du <= 1; ++du) {
          const int uu = u + du, vv = v + dv;
          if (uu < 0 || vv < 0 || uu >= W || vv >= H) continue;
          const size_t n = static_cast<size_t>(vv) * W + uu;
          if (!(range[n] > 0)) continue;
          const double wgt =
              (s2 > 0 ? std::exp(-(du * du + dv * dv) / s2) : (du == 0 && dv == 0)) * amp[n];
          sum += std::polar(wgt, 2.0 * k * (range[n] - range[i]));
          total += wgt;
        }
      }
      double r = range[i];
      if (total > 0) r += 0.5 * std::arg(sum) / k;
      r += bias_at(u, v);
      out[i] = static_cast<float>(r / px.ray_norm[i]);
    }
  });
  return out;
}

}  // namespace

void ApplyDepthNoise(const ImageF& depth_z, const DepthNoiseInputs& in,
                     const DepthNoiseModel& model, uint64_t key, ImageF* out, ThreadPool* pool) {
  const int W = depth_z.width, H = depth_z.height;
  CheckInputSize(in.normal_O, depth_z, 3, "normal_O");
  CheckInputSize(in.reflectance, depth_z, 1, "reflectance");
  CheckInputSize(in.transmittance, depth_z, 1, "transmittance");
  CheckInputSize(in.ambient_cd_m2, depth_z, 1, "ambient_cd_m2");
  const size_t N = static_cast<size_t>(W) * H;
  PixelInputs px;
  px.cos_theta.assign(N, 1.0f);
  px.rho.assign(N, 1.0f);
  px.transmittance.assign(N, 1.0f);
  px.ray_norm.assign(N, 1.0f);
  px.specular.assign(N, 0);
  px.normal.assign(N, Eigen::Vector3f(0, 0, -1));
  const bool have_n = in.normal_O && !in.normal_O->empty();
  const bool have_r = in.reflectance && !in.reflectance->empty();
  const bool have_t = in.transmittance && !in.transmittance->empty();
  ParallelForOrSerial(pool, H, [&](int v) {
    for (int u = 0; u < W; ++u) {
      const size_t i = static_cast<size_t>(v) * W + u;
      const Eigen::Vector3d ray = PixelRay(in, u, v);
      px.ray_norm[i] = static_cast<float>(ray.norm());
      if (have_n) {
        const float* n = in.normal_O->at(u, v);
        px.normal[i] = Eigen::Vector3f(n[0], n[1], n[2]);
        px.cos_theta[i] = static_cast<float>(
            std::min(1.0, std::abs(Eigen::Vector3d(n[0], n[1], n[2]).dot(ray)) / ray.norm()));
      } else {
        px.normal[i] = -ray.normalized().cast<float>();
      }
      if (have_r) {
        const float r = *in.reflectance->at(u, v);
        px.specular[i] = r < 0;
        px.rho[i] = std::clamp(r, 0.0f, 1.0f);
      }
      if (have_t) px.transmittance[i] = std::clamp(*in.transmittance->at(u, v), 0.0f, 1.0f);
    }
  });
  const bool matcher = model.kind != DepthNoiseModel::Kind::kTimeOfFlight;
  std::vector<uint8_t> valid;
  std::vector<float> z_meas;
  if (matcher) {
    valid = MatcherValid(depth_z, in, px, model, key, pool);
  } else {
    z_meas = TofDepth(depth_z, in, px, model, pool);
  }
  *out = ImageF(W, H, 1);
  const double cos_max = std::cos(model.max_incidence_deg * M_PI / 180.0);
  ParallelForOrSerial(pool, H, [&](int v) {
    for (int u = 0; u < W; ++u) {
      Rng rng(HashKeys(key, static_cast<uint64_t>(v) * static_cast<uint64_t>(W) + u));
      const size_t i0 = static_cast<size_t>(v) * W + u;
      const double theta = std::acos(std::clamp<double>(px.cos_theta[i0], 0.0, 1.0));
      // lateral: read the depth of a displaced pixel (edges jag; flat surfaces do not change)
      const double sl = model.LateralSigmaPx(theta);
      const int us =
          std::clamp(static_cast<int>(std::lround(u + sl * SampleStandardNormal(&rng))), 0, W - 1);
      const int vs =
          std::clamp(static_cast<int>(std::lround(v + sl * SampleStandardNormal(&rng))), 0, H - 1);
      const double axial_n = SampleStandardNormal(&rng);
      const double drop_u = rng.UniformD();
      const size_t i = static_cast<size_t>(vs) * W + us;
      const double z_true = depth_z.data[i];
      float& o = *out->at(u, v);
      o = 0.0f;
      if (!(z_true > 0) || z_true < model.min_range_m || z_true > model.max_range_m) continue;
      if (px.cos_theta[i] < cos_max || px.specular[i]) continue;
      const double t2 = static_cast<double>(px.transmittance[i]) * px.transmittance[i];
      if (t2 < model.min_round_trip_transmittance) continue;
      double z = z_true;
      if (matcher) {
        if (!valid[i]) continue;
      } else {
        if (px.rho[i] < model.min_reflectance || drop_u >= t2) continue;
        z = z_meas[i];
      }
      const double th = std::acos(std::clamp<double>(px.cos_theta[i], 0.0, 1.0));
      o = static_cast<float>(z + model.AxialSigma(z, th, in.fx) * axial_n);
    }
  });
}

double HomogeneousOpticalDepth(const HomogeneousMedium& medium, const Eigen::Vector3d& a_W,
                               const Eigen::Vector3d& b_W) {
  const double sigma = medium.sigma_t_per_m.cast<double>().mean();
  if (!(sigma > 0)) return 0.0;
  double t0 = 0.0, t1 = 1.0;  // segment parameters inside the region
  const Eigen::Vector3d d = b_W - a_W;
  if (medium.region) {
    for (int i = 0; i < 3; ++i) {
      const double lo = medium.region->min_W[i], hi = medium.region->max_W[i];
      if (std::abs(d[i]) < 1e-15) {
        if (a_W[i] < lo || a_W[i] > hi) return 0.0;
        continue;
      }
      double ta = (lo - a_W[i]) / d[i], tb = (hi - a_W[i]) / d[i];
      if (ta > tb) std::swap(ta, tb);
      t0 = std::max(t0, ta);
      t1 = std::min(t1, tb);
    }
    if (t1 <= t0) return 0.0;
  }
  const double len = d.norm() * (t1 - t0);
  if (medium.height_falloff_per_m <= 0) return sigma * len;
  constexpr int kSteps = 64;
  double sum = 0.0;
  for (int i = 0; i < kSteps; ++i) {
    const double t = t0 + (t1 - t0) * (i + 0.5) / kSteps;
    const double z = a_W.z() + t * d.z();
    sum += std::exp(-medium.height_falloff_per_m * std::max(0.0, z - medium.base_height_m));
  }
  return sigma * len * sum / kSteps;
}

ImageF DepthTransmittance(const ImageF& depth_z, const Camera& camera, const EffectsFrame& effects,
                          uint64_t key, ThreadPool* pool) {
  ImageF t(depth_z.width, depth_z.height, 1, 1.0f);
  if (effects.homogeneous_media.empty() && effects.grid_media.empty()) return t;
  MediaScene media;
  media.Build(&effects);
  if (media.empty()) return t;
  ParallelForOrSerial(pool, depth_z.height, [&](int v) {
    for (int u = 0; u < depth_z.width; ++u) {
      const double z = *depth_z.at(u, v);
      if (!(z > 0)) continue;
      const Ray r = camera.GenerateRay(static_cast<float>(u), static_cast<float>(v));
      const float len = r.d.norm();
      Rng rng(HashKeys(key, static_cast<uint64_t>(v) * static_cast<uint64_t>(depth_z.width) + u));
      const Eigen::Vector3f tr =
          media.Transmittance(r.o, r.d / len, 0.0f, static_cast<float>(z) * len, &rng);
      *t.at(u, v) = std::clamp(tr.mean(), 0.0f, 1.0f);
    }
  });
  return t;
}

}  // namespace penumbra

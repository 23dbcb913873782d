#include "penumbra/sensors/camera_imager.h"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <opencv2/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <opencv2/imgproc.hpp>

#include "penumbra/core/error.h"
#include "penumbra/core/rng.h"
#include "penumbra/render/backends/renderer_factory.h"
#include "penumbra/render/film/white_balance.h"
#include "penumbra/sensors/camera_lens_droplets.h"
#include "penumbra/sensors/image_noise.h"

namespace penumbra {
namespace {

Pose Interpolate(const Pose& a, const Pose& b, double t) {
  Pose X = Pose::Identity();
  X.linear() =
      Eigen::Quaterniond(a.linear()).slerp(t, Eigen::Quaterniond(b.linear())).toRotationMatrix();
  X.translation() = (1.0 - t) * a.translation() + t * b.translation();
  return X;
}

// the world at fraction t between start and end: body poses, MJCF cameras and light positions
// interpolated; everything else (effects, joint state) from start.
WorldSnapshot InterpolateSnapshot(const WorldSnapshot& a, const WorldSnapshot& b, double t) {
  WorldSnapshot s = a;
  s.time_sec = a.time_sec + t * (b.time_sec - a.time_sec);
  for (size_t i = 0; i < s.X_WB.size() && i < b.X_WB.size(); ++i)
    s.X_WB[i] = Interpolate(a.X_WB[i], b.X_WB[i], t);
  for (size_t i = 0; i < s.X_W_mjcam.size() && i < b.X_W_mjcam.size(); ++i)
    s.X_W_mjcam[i] = Interpolate(a.X_W_mjcam[i], b.X_W_mjcam[i], t);
  for (size_t i = 0; i < s.light_position_W.size() && i < b.light_position_W.size(); ++i)
    s.light_position_W[i] = (1.0 - t) * a.light_position_W[i] + t * b.light_position_W[i];
  return s;
}

void RoundTripJpeg(int quality, ImageU8* rgb) {
  cv::Mat img(rgb->height, rgb->width, CV_8UC3, rgb->data.data());
  cv::Mat bgr;
  cv::cvtColor(img, bgr, cv::COLOR_RGB2BGR);
  std::vector<uint8_t> buf;
  cv::imencode(".jpg", bgr, buf, {cv::IMWRITE_JPEG_QUALITY, quality});
  const cv::Mat dec = cv::imdecode(buf, cv::IMREAD_COLOR);
  cv::cvtColor(dec, img, cv::COLOR_BGR2RGB);  // writes into rgb's buffer (same size and type)
}

bool HasOptics(const OpticsConfig& o) {
  return o.vignetting_exponent > 0 || o.psf_sigma_px > 0 || o.lateral_ca_px > 0;
}

// bilinear sample of channel ch of `img` at (x, y) px (pixel centres at integers), clamped to
// the image.
float Bilinear(const ImageF& img, float x, float y, int ch) {
  x = std::clamp(x, 0.0f, static_cast<float>(img.width - 1));
  y = std::clamp(y, 0.0f, static_cast<float>(img.height - 1));
  const int x0 = std::min(static_cast<int>(x), img.width - 2 < 0 ? 0 : img.width - 2);
  const int y0 = std::min(static_cast<int>(y), img.height - 2 < 0 ? 0 : img.height - 2);
  const int x1 = std::min(x0 + 1, img.width - 1), y1 = std::min(y0 + 1, img.height - 1);
  const float fx = x - x0, fy = y - y0;
  const float a = img.at(x0, y0)[ch], b = img.at(x1, y0)[ch];
  const float c = img.at(x0, y1)[ch], d = img.at(x1, y1)[ch];
  return (1 - fy) * ((1 - fx) * a + fx * b) + fy * ((1 - fx) * c + fx * d);
}

// the optics of `o` on `in` ((H x W x 3) radiance) into `out`: vignetting, lateral chromatic
// aberration, then the Gaussian PSF (separable, edges clamped). `tmp` is scratch.
void ApplyOptics(const OpticsConfig& o, const CameraIntrinsics& k, const ImageF& in, ImageF* out,
                 ImageF* tmp, ThreadPool* pool) {
  const int W = in.width, H = in.height;
  if (out->width != W || out->height != H || out->channels != 3) *out = ImageF(W, H, 3);
  if (tmp->width != W || tmp->height != H || tmp->channels != 3) *tmp = ImageF(W, H, 3);
  const double scale = o.reference_width > 0 ? static_cast<double>(W) / o.reference_width : 1.0;
  // lateral CA: relative magnification of red (1 + m) and blue (1 - m) from the corner shift
  const double corner = std::hypot(std::max(k.cx, W - 1 - k.cx), std::max(k.cy, H - 1 - k.cy));
  const float m = corner > 0 ? static_cast<float>(o.lateral_ca_px * scale / corner) : 0.0f;
  const float half_n = static_cast<float>(0.5 * o.vignetting_exponent);
  ParallelForOrSerial(pool, H, [&](int v) {
    const float b = static_cast<float>((v - k.cy) / k.fy);
    float* dst = tmp->at(0, v);
    for (int u = 0; u < W; ++u) {
      const float a = static_cast<float>((u - k.cx) / k.fx);
      const float ri = half_n > 0 ? std::pow(1.0f + a * a + b * b, -half_n) : 1.0f;
      const float* src = in.at(u, v);
      float r = src[0], g = src[1], bl = src[2];
      if (m > 0) {
        const float du = u - static_cast<float>(k.cx), dv = v - static_cast<float>(k.cy);
        r = Bilinear(in, static_cast<float>(k.cx) + du / (1 + m),
                     static_cast<float>(k.cy) + dv / (1 + m), 0);
        bl = Bilinear(in, static_cast<float>(k.cx) + du / (1 - m),
                      static_cast<float>(k.cy) + dv / (1 - m), 2);
      }
      dst[3 * u] = r * ri;
      dst[3 * u + 1] = g * ri;
      dst[3 * u + 2] = bl * ri;
    }
  });
  const double sigma = o.psf_sigma_px * scale;
  if (!(sigma >= 0.05)) {
    std::swap(*out, *tmp);
    return;
  }
  const int radius = std::max(1, static_cast<int>(std::ceil(3 * sigma)));
  std::vector<float> w(2 * radius + 1);
  float sum = 0;
  for (int i = -radius; i <= radius; ++i)
    sum += w[i + radius] = static_cast<float>(std::exp(-0.5 * i * i / (sigma * sigma)));
  for (float& x : w) x /= sum;
  // rows (tmp -> out), then columns (out -> tmp), then swap
  ParallelForOrSerial(pool, H, [&](int v) {
    for (int u = 0; u < W; ++u)
      for (int ch = 0; ch < 3; ++ch) {
        float acc = 0;
        for (int i = -radius; i <= radius; ++i)
          acc += w[i + radius] * tmp->at(std::clamp(u + i, 0, W - 1), v)[ch];
        out->at(u, v)[ch] = acc;
      }
  });
  ParallelForOrSerial(pool, H, [&](int v) {
    for (int u = 0; u < W; ++u)
      for (int ch = 0; ch < 3; ++ch) {
        float acc = 0;
        for (int i = -radius; i <= radius; ++i)
          acc += w[i + radius] * out->at(u, std::clamp(v + i, 0, H - 1))[ch];
        tmp->at(u, v)[ch] = acc;
      }
  });
  std::swap(*out, *tmp);
}

// `k` at a quarter of its size (at least 1 x 1), the same field of view.
CameraIntrinsics QuarterIntrinsics(const CameraIntrinsics& k) {
  CameraIntrinsics q = k;
  q.width = std::max(1, k.width / 4);
  q.height = std::max(1, k.height / 4);
  const double sx = static_cast<double>(q.width) / k.width;
  const double sy = static_cast<double>(q.height) / k.height;
  q.fx = k.fx * sx;
  q.fy = k.fy * sy;
  q.cx = (k.cx + 0.5) * sx - 0.5;
  q.cy = (k.cy + 0.5) * sy - 0.5;
  return q;
}

// the radiance (cd/m^2) of the largest white-balanced channel that a fraction `fraction` of the
// pixels of `img` exceed; 0 for an empty image.
double BrightQuantile(const ImageF& img, const Eigen::Vector3f& wb, double fraction) {
  const size_t n = static_cast<size_t>(img.width) * img.height;
  if (n == 0) return 0;
  std::vector<float> m(n);
  for (size_t i = 0; i < n; ++i) {
    const float* p = &img.data[3 * i];
    const float v = std::max({p[0] * wb[0], p[1] * wb[1], p[2] * wb[2]});
    m[i] = std::isfinite(v) ? v : 0.0f;
  }
  const size_t k = std::min(n - 1, static_cast<size_t>(std::floor((1.0 - fraction) * n)));
  std::nth_element(m.begin(), m.begin() + k, m.end());
  return m[k];
}

}  // namespace

double FilmicWhite() {
  // AcesFilmic(x) = 1: 0.08 x^2 - 0.56 x - 0.14 = 0
  return (0.56 + std::sqrt(0.56 * 0.56 + 4 * 0.08 * 0.14)) / (2 * 0.08);
}

double RowTimeSec(const CameraSensorConfig& c, int height) {
  if (c.rolling_shutter_line_time_sec > 0 || height <= 0) return c.rolling_shutter_line_time_sec;
  return c.rolling_shutter_readout_sec / height;
}

double FrameSpanSec(const CameraSensorConfig& c, int height) {
  const double T = c.auto_exposure.enabled
                       ? std::max(c.exposure_time_sec, c.auto_exposure.max_exposure_time_sec)
                       : c.exposure_time_sec;
  return T + std::max(0, height - 1) * RowTimeSec(c, height);
}

void ValidateCameraSensorOrThrow(const CameraSensorConfig& c, const std::string& key_prefix) {
  auto fail = [&](const std::string& key, const std::string& problem) {
    throw ConfigError("", 0, key_prefix + "." + key, problem);
  };
  if (!(c.exposure_time_sec >= 0) || !std::isfinite(c.exposure_time_sec))
    fail("exposure_time_sec", "got " + std::to_string(c.exposure_time_sec) +
                                  "; expected a finite number >= 0 (seconds)");
  if (c.motion_blur_samples < 1 || c.motion_blur_samples > 64)
    fail("motion_blur_samples",
         "got " + std::to_string(c.motion_blur_samples) + "; expected an integer in [1, 64]");
  if (!(c.rolling_shutter_line_time_sec >= 0) || !std::isfinite(c.rolling_shutter_line_time_sec))
    fail("rolling_shutter_line_time_sec", "expected a finite number >= 0 (seconds per row)");
  if (!(c.auto_exposure_time_constant_sec >= 0) ||
      !std::isfinite(c.auto_exposure_time_constant_sec))
    fail("auto_exposure_time_constant_sec", "expected a finite number >= 0 (seconds)");
  if (c.jpeg_quality < 0 || c.jpeg_quality > 100)
    fail("jpeg_quality", "got " + std::to_string(c.jpeg_quality) +
                             "; expected 0 (lossless) or a JPEG quality in [1, 100]");
  if (c.lens_droplet_count < 0 || c.lens_droplet_count > 1000)
    fail("lens_droplets.count", "expected an integer in [0, 1000]");
  if (c.white_balance.mode == WhiteBalance::Mode::kKelvin &&
      !(c.white_balance.kelvin >= WhiteBalance::kMinKelvin &&
        c.white_balance.kelvin <= WhiteBalance::kMaxKelvin))
    fail("white_balance", "expected a colour temperature in [1667, 25000] K");
  if (c.stereo_baseline_m && (!(*c.stereo_baseline_m > 0) || !std::isfinite(*c.stereo_baseline_m)))
    fail("stereo.baseline_m", "expected a finite baseline > 0 (m)");
  if (!(c.rolling_shutter_readout_sec >= 0 && c.rolling_shutter_readout_sec <= 10))
    fail("rolling_shutter_readout_sec", "expected a number in [0, 10] (seconds)");
  const OpticsConfig& o = c.optics;
  if (!(o.vignetting_exponent >= 0 && o.vignetting_exponent <= 8))
    fail("optics.vignetting_exponent", "expected a number in [0, 8]");
  if (!(o.psf_sigma_px >= 0 && o.psf_sigma_px <= 20))
    fail("optics.psf_sigma_px", "expected a number in [0, 20] (px)");
  if (!(o.lateral_ca_px >= 0 && o.lateral_ca_px <= 20))
    fail("optics.lateral_ca_px", "expected a number in [0, 20] (px)");
  if (o.reference_width < 0 || o.reference_width > 100000)
    fail("optics.reference_width", "expected an integer in [0, 100000] (px)");
  const AutoExposureConfig& a = c.auto_exposure;
  if (a.enabled) {
    if (!(a.f_number > 0 && a.f_number <= 1000))
      fail("auto_exposure.f_number", "expected a number in (0, 1000]");
    if (!(a.min_exposure_time_sec > 0 && a.min_exposure_time_sec <= 60))
      fail("auto_exposure.min_exposure_time_sec", "expected a number in (0, 60] (seconds)");
    if (!(a.max_exposure_time_sec >= a.min_exposure_time_sec && a.max_exposure_time_sec <= 60))
      fail("auto_exposure.max_exposure_time_sec",
           "expected a number in [min_exposure_time_sec, 60] (seconds)");
    if (!(a.max_gain >= 1 && a.max_gain <= 1e6))
      fail("auto_exposure.max_gain", "expected a number in [1, 1e6]");
    if (!(a.saturated_fraction >= 0 && a.saturated_fraction <= 1))
      fail("auto_exposure.saturated_fraction", "expected a number in [0, 1]");
    if (!(a.max_highlight_reduction_ev >= 0 && a.max_highlight_reduction_ev <= 10))
      fail("auto_exposure.max_highlight_reduction_ev", "expected a number in [0, 10] (EV)");
    if (!(a.motion_blur_step_sec >= 0 && a.motion_blur_step_sec <= 60))
      fail("auto_exposure.motion_blur_step_sec", "expected a number in [0, 60] (seconds)");
  }
  ValidateImageNoiseOrThrow(c.noise, key_prefix + ".noise");
  if (!c.depth_noise.preset.empty()) DepthNoisePreset(c.depth_noise, key_prefix + ".depth_noise");
}

CameraImager::CameraImager(const CameraSpec& spec, const CameraSensorConfig& config,
                           const RenderSettings& render_settings, int camera_index,
                           const SceneDescription& scene)
    : spec_(spec),
      config_(config),
      settings_(render_settings),
      film_(render_settings),
      camera_index_(camera_index),
      scene_(scene) {
  const std::string key = "cameras[" + spec.name + "]";
  ValidateCameraSensorOrThrow(config, key);
  if (!config.depth_noise.preset.empty())
    depth_model_ = DepthNoisePreset(config.depth_noise, key + ".depth_noise");
  if (config.noise.enabled || depth_model_ || config.motion_blur_samples > 1 ||
      HasOptics(config.optics) || config.auto_exposure.enabled)
    pool_ = std::make_unique<ThreadPool>(render_settings.threads);
  if (config.white_balance.mode == WhiteBalance::Mode::kDaylight)
    daylight_white_ = DaylightWhite(scene);
}

void CameraImager::Capture(Renderer* renderer, const WorldSnapshot& start,
                           const EffectsFrame* effects, const Pose& X_WO_start,
                           const WorldSnapshot* end, const Pose& X_WO_end, int64_t frame_index,
                           CameraImages* out) {
  const CameraSensorConfig& c = config_;
  const int W = spec_.intrinsics.width, H = spec_.intrinsics.height;
  const AutoExposureConfig& ae_cfg = c.auto_exposure;
  const bool ae = ae_cfg.enabled;
  const bool want_rgb_frame = spec_.outputs[ImageKind::kRgb];
  const bool optics = HasOptics(c.optics);
  // renderer frame indices: sub-frames (and the metering view) of different frames never share
  // one
  const int64_t stride = ae ? c.motion_blur_samples + 1 : 0;
  // auto exposure: this frame's shutter time and gain, metered on a quarter-size view of the
  // capture instant (as a camera's statistics grid), so they depend on this frame alone
  double ae_t = c.exposure_time_sec, ae_g = 1, ae_ev = 0;
  if (ae && want_rgb_frame) {
    CameraView mv;
    mv.X_WO = X_WO_start;
    mv.intrinsics = QuarterIntrinsics(spec_.intrinsics);
    mv.near_m = spec_.near_m;
    mv.frame_index = frame_index * stride + c.motion_blur_samples;
    mv.camera_index = camera_index_;
    mv.exposure_time_sec = c.exposure_time_sec;
    mv.want_radiance = true;
    mv.outputs = CameraOutputs::None();
    mv.outputs[ImageKind::kRgb] = true;
    RenderedFrame meter;
    const auto t0 = std::chrono::steady_clock::now();
    renderer->Render(start, effects, mv, &meter);
    renderer_sec_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    out->stopped = meter.stopped;
    if (out->stopped) return;
    const ImageF* m = &meter.radiance;
    if (optics) {
      ApplyOptics(c.optics, mv.intrinsics, meter.radiance, &meter_optic_, &meter_tmp_, pool_.get());
      m = &meter_optic_;
    }
    ae_ev = film_.Ev100(*m, pool_.get());
    if (settings_.auto_exposure && c.auto_exposure_time_constant_sec > 0 && last_ev_) {
      const double dt = std::max(0.0, start.time_sec - *last_time_);
      ae_ev = ae_ev + (*last_ev_ - ae_ev) * std::exp(-dt / c.auto_exposure_time_constant_sec);
    }
    last_ev_ = ae_ev;
    last_time_ = start.time_sec;
    const Eigen::Vector3f wb = GainsForFrame(c.white_balance, daylight_white_, *m);
    const double k = 100.0 * 1.2 * ae_cfg.f_number * ae_cfg.f_number / c.noise.base_iso;
    const double white = film_.filmic() ? FilmicWhite() : 1.0;
    // the target exposure, raw full scale at the curve's white; highlights protected
    double h = ExposureFromEv100(ae_ev) / white;
    if (settings_.auto_exposure && ae_cfg.saturated_fraction < 1) {
      const double bright = BrightQuantile(*m, wb, ae_cfg.saturated_fraction);
      // the brightest pixels at 80 % of full scale: their noise stays below saturation
      constexpr double kHighlightLevel = 0.8;
      if (bright * h > kHighlightLevel)
        h = std::max(kHighlightLevel / bright, h * std::exp2(-ae_cfg.max_highlight_reduction_ev));
    }
    const double tg = h * k;
    ae_t = std::clamp(tg, ae_cfg.min_exposure_time_sec, ae_cfg.max_exposure_time_sec);
    ae_g = std::clamp(tg / ae_t, 1.0, ae_cfg.max_gain);
  }
  const double T = ae ? ae_t : c.exposure_time_sec;
  const double row_time = RowTimeSec(c, H);
  const bool moving = end != nullptr && end->time_sec > start.time_sec;
  const double span = moving ? end->time_sec - start.time_sec : 0.0;
  int n = moving ? c.motion_blur_samples : 1;
  if (moving && ae && ae_cfg.motion_blur_step_sec > 0)
    n = std::clamp(static_cast<int>(std::ceil(T / ae_cfg.motion_blur_step_sec)), 1,
                   c.motion_blur_samples);
  const int truth_k = n / 2;

  CameraOutputs internal = spec_.outputs;
  // a correlation matcher (stereo, structured light) reads the scene's light: the radiance of
  // the ground-truth sub-frame
  const bool depth_reads_light =
      depth_model_ && depth_model_->kind != DepthNoiseModel::Kind::kTimeOfFlight;
  if (depth_model_) {
    for (ImageKind k : {ImageKind::kDepth, ImageKind::kNormals, ImageKind::kSegmentation})
      internal[k] = true;
    if (depth_reads_light) internal[ImageKind::kRgb] = true;
  }
  const bool want_rgb = spec_.outputs[ImageKind::kRgb];
  if (want_rgb && n > 1) {
    if (accum_.width != W || accum_.height != H || accum_.channels != 3) accum_ = ImageF(W, H, 3);
    std::fill(accum_.data.begin(), accum_.data.end(), 0.0f);
  }
  // gray world (auto white balance) and exposure adaptation read this frame's radiance
  const bool gray_world = c.white_balance.mode == WhiteBalance::Mode::kAuto;
  const bool adapts = settings_.auto_exposure && c.auto_exposure_time_constant_sec > 0;
  // white balance known before the frame (not gray world): the renderer develops with it, so
  // that a frame without sub-frames, noise or adaptation is developed once
  const Eigen::Vector3f wb_before = gray_world
                                        ? Eigen::Vector3f::Ones()
                                        : GainsForFrame(c.white_balance, daylight_white_, ImageF());
  // the camera model reads the radiance for sub-frames, noise, gray world and adaptation;
  // otherwise the renderer's developed rgb is the camera's (set_keep_radiance)
  const bool need_radiance =
      keep_radiance_ || n > 1 || c.noise.enabled || gray_world || adapts || optics || ae;
  truth_view_.reset();
  truth_moving_ = moving;
  RenderedFrame sub;
  for (int k = 0; k < n; ++k) {
    const double s = (k + 0.5) * T / n;
    CameraView view;
    view.X_WO = X_WO_start;
    view.intrinsics = spec_.intrinsics;
    view.near_m = spec_.near_m;
    view.frame_index = frame_index * (ae ? stride : n) + k;
    view.camera_index = camera_index_;
    view.exposure_time_sec = T;
    view.white_balance_gains = wb_before;
    view.want_radiance = (want_rgb && need_radiance) || (k == truth_k && depth_reads_light);
    view.outputs = internal;
    if (k != truth_k) {
      view.outputs = CameraOutputs::None();
      view.outputs[ImageKind::kRgb] = want_rgb;
    }
    if (moving) {
      view.motion.X_WO_end = X_WO_end;
      view.motion.end_sec = span;
      view.motion.time_sec = s;
      view.motion.line_time_sec = row_time;
    }
    // (interp_ keeps the last sub-frame's snapshot: the ground truth's when n = 1, the only
    // case BrightestRadiance renders again)
    const WorldSnapshot* snap = &start;
    if (moving) {
      interp_ = InterpolateSnapshot(start, *end, s / span);
      snap = &interp_;
    }
    RenderedFrame* target = k == truth_k ? &out->truth : &sub;
    const auto t0 = std::chrono::steady_clock::now();
    renderer->Render(*snap, effects, view, target);
    renderer_sec_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    out->stopped = target->stopped;
    if (out->stopped) return;  // unfinished: the auto-exposure state is left as it was
    if (want_rgb && n > 1) {
      const std::vector<float>& r = target->radiance.data;
      for (size_t i = 0; i < r.size(); ++i) accum_.data[i] += r[i];
    }
    if (k == truth_k) {
      truth_view_ = view;
      out->mid_exposure_time_sec = moving ? start.time_sec + s : start.time_sec;
      out->X_WO =
          moving ? Camera(X_WO_start, spec_.intrinsics, view.motion).PoseAtRow(0) : X_WO_start;
    }
  }
  out->time_sec = start.time_sec;

  if (want_rgb) {
    // the mean over the sub-frames; one frame is the renderer's radiance as it is
    if (n > 1) {
      for (float& v : accum_.data) v /= static_cast<float>(n);
      out->radiance = accum_;
    } else if (need_radiance) {
      out->radiance = out->truth.radiance;
    } else {
      out->radiance = ImageF();
    }
    const ImageF& radiance = out->radiance;
    // the light on the sensor: the radiance through the optics
    const ImageF* sensor_in = &radiance;
    if (optics) {
      ApplyOptics(c.optics, spec_.intrinsics, radiance, &optic_, &optic_tmp_, pool_.get());
      sensor_in = &optic_;
    }
    // exposure with adaptation over sim time; one frame's metering is the renderer's (Film::Ev100
    // of this very radiance)
    const bool developed = n == 1 && !out->truth.rgb.empty() && !optics;
    if (!developed && radiance.empty())
      throw Error(fmt::format(
          "camera '{}': frame {}: the renderer gave neither rgb nor radiance; expected the rgb "
          "it was asked for (CameraOutputs rgb)",
          spec_.name, frame_index));
    double ev = ae_ev;
    if (!ae) {
      ev = developed ? out->truth.ev100 : film_.Ev100(*sensor_in, pool_.get());
      if (adapts && last_ev_) {
        const double dt = std::max(0.0, start.time_sec - *last_time_);
        ev = ev + (*last_ev_ - ev) * std::exp(-dt / c.auto_exposure_time_constant_sec);
      }
      last_ev_ = ev;
      last_time_ = start.time_sec;
    }
    out->ev100 = ev;
    // gray world needs this frame's radiance; the other modes' gains were known before it
    const Eigen::Vector3f wb_gains =
        gray_world ? GainsForFrame(c.white_balance, daylight_white_, radiance) : wb_before;
    out->exposure_time_sec = T;
    out->analog_gain = 1;
    const uint64_t noise_key = HashKeys(settings_.seed, camera_index_, frame_index, 1);
    const uint64_t pattern_key = HashKeys(settings_.seed, camera_index_, 5);
    if ((ae || c.noise.enabled) &&
        (exposed_.width != W || exposed_.height != H || exposed_.channels != 3))
      exposed_ = ImageF(W, H, 3);
    if (ae) {
      // exposure per cd/m^2 of shutter time t and gain g: H = t g / k (saturation-based ISO)
      const double k = 100.0 * 1.2 * ae_cfg.f_number * ae_cfg.f_number / c.noise.base_iso;
      const double white = film_.filmic() ? FilmicWhite() : 1.0;
      const double t = ae_t, g = ae_g;
      const double h_used = t * g / k;
      out->exposure_time_sec = t;
      out->analog_gain = g;
      out->ev100 = -std::log2(1.2 * h_used * white);
      const float hf = static_cast<float>(h_used);
      for (size_t i = 0; i < sensor_in->data.size(); ++i)
        exposed_.data[i] = sensor_in->data[i] * hf;
      ImageNoiseConfig sensor = c.noise;
      sensor.iso = sensor.base_iso * g;
      ApplyImageNoise(exposed_, sensor, noise_key, &dn_, pool_.get(), t, pattern_key);
      const float inv_max = static_cast<float>(1.0 / (std::ldexp(1.0, c.noise.adc_bits) - 1.0));
      for (float& v : dn_.data) v *= inv_max;
      film_.Develop(dn_, -std::log2(1.2 * white), pool_.get(), &out->rgb, wb_gains);
    } else if (c.noise.enabled) {
      const float h = static_cast<float>(ExposureFromEv100(ev));
      for (size_t i = 0; i < sensor_in->data.size(); ++i) exposed_.data[i] = sensor_in->data[i] * h;
      ApplyImageNoise(exposed_, c.noise, noise_key, &dn_, pool_.get(), T, pattern_key);
      const float inv_max = static_cast<float>(1.0 / (std::ldexp(1.0, c.noise.adc_bits) - 1.0));
      for (float& v : dn_.data) v *= inv_max;
      film_.Develop(dn_, -std::log2(1.2), pool_.get(), &out->rgb, wb_gains);  // exposure H = 1
    } else if (developed && ev == out->truth.ev100 && wb_gains == wb_before) {
      out->rgb = out->truth.rgb;  // the renderer developed this very radiance at this EV and gains
    } else {
      film_.Develop(*sensor_in, ev, pool_.get(), &out->rgb, wb_gains);
    }
    if (c.lens_droplets) {
      // drops land only while the camera is under open sky in the rain (the shelter map of
      // the static scene at the optical centre); after that they run off over
      // kDropletLifetimeSec (the count falls linearly to 0).
      if (IsRaining(effects)) {
        if (!shelter_) {
          const RenderSettings::Backend backend = settings_.backend;
          shelter_ = std::make_unique<ShelterMap>(
              [backend](const SceneDescription& s) { return MakeRayQuery(s, backend); });
        }
        shelter_->Update(scene_, start, pool_.get());
        if (!shelter_->Sheltered(X_WO_start.translation().cast<float>()))
          last_wet_time_ = start.time_sec;
      }
      const int count = LensDropletCount(c.lens_droplet_count, last_wet_time_, start.time_sec);
      if (count > 0)
        ApplyLensDroplets(count, start.time_sec, HashKeys(settings_.seed, camera_index_, 3),
                          &out->rgb);
    }
    if (c.jpeg_quality > 0) RoundTripJpeg(c.jpeg_quality, &out->rgb);
  } else {
    out->rgb = ImageU8();
    out->radiance = ImageF();
  }

  if (depth_model_) {
    DepthNoiseInputs in;
    in.normal_O = &out->truth.normal_O;
    in.fx = spec_.intrinsics.fx;
    in.fy = spec_.intrinsics.fy;
    in.cx = spec_.intrinsics.cx;
    in.cy = spec_.intrinsics.cy;
    const Camera depth_camera(X_WO_start, spec_.intrinsics);  // rays in the optical frame only
    in.camera = &depth_camera;
    // IR reflectance from the hit geom's material: base colour luminance, -1 for mirror-like
    ImageF reflectance(W, H, 1, 1.0f);
    std::map<int, float> by_id;
    for (const Geom& g : scene_.geoms) {
      float r = 1.0f;
      if (g.material >= 0 && g.material < static_cast<int>(scene_.materials.size())) {
        const Material& m = scene_.materials[g.material];
        r = 0.2126f * m.base_color.x() + 0.7152f * m.base_color.y() + 0.0722f * m.base_color.z();
        if (m.metallic > 0.5f && m.roughness < 0.2f) r = -1.0f;
      }
      by_id[g.id] = r;
    }
    for (size_t i = 0; i < reflectance.data.size(); ++i) {
      auto it = by_id.find(out->truth.geom_id.data[i]);
      if (it != by_id.end()) reflectance.data[i] = it->second;
    }
    in.reflectance = &reflectance;
    ImageF transmittance;
    if (effects && (!effects->homogeneous_media.empty() || !effects->grid_media.empty())) {
      CameraMotion m;
      if (moving) {
        m.X_WO_end = X_WO_end;
        m.end_sec = span;
        m.time_sec = (truth_k + 0.5) * T / n;
        m.line_time_sec = row_time;
      }
      transmittance =
          DepthTransmittance(out->truth.depth_m, Camera(X_WO_start, spec_.intrinsics, m), *effects,
                             HashKeys(settings_.seed, camera_index_, frame_index, 4), pool_.get());
      in.transmittance = &transmittance;
    }
    ImageF ambient;  // the scene's luminance (cd/m^2), the matcher's texture and ambient light
    if (depth_reads_light && !out->truth.radiance.empty()) {
      ambient = ImageF(W, H, 1);
      const ImageF& rad = out->truth.radiance;
      for (size_t i = 0; i < ambient.data.size(); ++i)
        ambient.data[i] = 0.2126f * rad.data[3 * i] + 0.7152f * rad.data[3 * i + 1] +
                          0.0722f * rad.data[3 * i + 2];
      in.ambient_cd_m2 = &ambient;
    }
    ApplyDepthNoise(out->truth.depth_m, in, *depth_model_,
                    HashKeys(settings_.seed, camera_index_, frame_index, 2), &out->depth_m,
                    pool_.get());
  } else {
    out->depth_m = out->truth.depth_m;
  }
}

double CameraImager::BrightestRadiance(Renderer* renderer, const WorldSnapshot& start,
                                       const EffectsFrame* effects, const CameraImages& last) {
  auto brightest = [](const ImageF& img) {
    float b = 0;
    for (float v : img.data)
      if (std::isfinite(v)) b = std::max(b, v);
    return static_cast<double>(b);
  };
  if (!last.radiance.empty()) return brightest(last.radiance);
  if (!last.truth.radiance.empty()) return brightest(last.truth.radiance);
  if (!truth_view_) return 0;
  // the ground-truth sub-frame again, its rgb with the radiance
  CameraView view = *truth_view_;
  view.outputs = CameraOutputs::None();
  view.outputs[ImageKind::kRgb] = true;
  view.want_radiance = true;
  RenderedFrame frame;
  const auto t0 = std::chrono::steady_clock::now();
  renderer->Render(truth_moving_ ? interp_ : start, effects, view, &frame);
  renderer_sec_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return brightest(frame.radiance);
}

}  // namespace penumbra

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
#include "penumbra/render/white_balance.h"
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

}  // namespace

double FrameSpanSec(const CameraSensorConfig& c, int height) {
  return c.exposure_time_sec + std::max(0, height - 1) * c.rolling_shutter_line_time_sec;
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
  if (config.noise.enabled || depth_model_ || config.motion_blur_samples > 1)
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
  const double T = c.exposure_time_sec;
  const bool moving = end != nullptr && end->time_sec > start.time_sec;
  const double span = moving ? end->time_sec - start.time_sec : 0.0;
  const int n = moving ? c.motion_blur_samples : 1;
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
  const bool need_radiance = keep_radiance_ || n > 1 || c.noise.enabled || gray_world || adapts;
  truth_view_.reset();
  truth_moving_ = moving;
  RenderedFrame sub;
  for (int k = 0; k < n; ++k) {
    const double s = (k + 0.5) * T / n;
    CameraView view;
    view.X_WO = X_WO_start;
    view.intrinsics = spec_.intrinsics;
    view.near_m = spec_.near_m;
    view.frame_index = frame_index * n + k;
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
      view.motion.line_time_sec = c.rolling_shutter_line_time_sec;
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
    // exposure with adaptation over sim time; one frame's metering is the renderer's (Film::Ev100
    // of this very radiance)
    const bool developed = n == 1 && !out->truth.rgb.empty();
    if (!developed && radiance.empty())
      throw Error(fmt::format(
          "camera '{}': frame {}: the renderer gave neither rgb nor radiance; expected the rgb "
          "it was asked for (CameraOutputs rgb)",
          spec_.name, frame_index));
    double ev = developed ? out->truth.ev100 : film_.Ev100(radiance, pool_.get());
    if (adapts && last_ev_) {
      const double dt = std::max(0.0, start.time_sec - *last_time_);
      ev = ev + (*last_ev_ - ev) * std::exp(-dt / c.auto_exposure_time_constant_sec);
    }
    last_ev_ = ev;
    last_time_ = start.time_sec;
    out->ev100 = ev;
    // gray world needs this frame's radiance; the other modes' gains were known before it
    const Eigen::Vector3f wb_gains =
        gray_world ? GainsForFrame(c.white_balance, daylight_white_, radiance) : wb_before;
    if (c.noise.enabled) {
      const float h = static_cast<float>(ExposureFromEv100(ev));
      if (exposed_.width != W || exposed_.height != H || exposed_.channels != 3)
        exposed_ = ImageF(W, H, 3);
      for (size_t i = 0; i < radiance.data.size(); ++i) exposed_.data[i] = radiance.data[i] * h;
      ApplyImageNoise(exposed_, c.noise, HashKeys(settings_.seed, camera_index_, frame_index, 1),
                      &dn_, pool_.get());
      const float inv_max = static_cast<float>(1.0 / (std::ldexp(1.0, c.noise.adc_bits) - 1.0));
      for (float& v : dn_.data) v *= inv_max;
      film_.Develop(dn_, -std::log2(1.2), pool_.get(), &out->rgb, wb_gains);  // exposure H = 1
    } else if (developed && ev == out->truth.ev100 && wb_gains == wb_before) {
      out->rgb = out->truth.rgb;  // the renderer developed this very radiance at this EV and gains
    } else {
      film_.Develop(radiance, ev, pool_.get(), &out->rgb, wb_gains);
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
        m.line_time_sec = c.rolling_shutter_line_time_sec;
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

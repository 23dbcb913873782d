#pragma once
// image formation of one camera over a run: motion blur and rolling shutter from two world
// snapshots, auto-exposure adaptation, sensor noise, lens droplets, JPEG and depth noise.
//
// timeline of a frame captured at snapshot time t0 with exposure T, n = motion_blur_samples and
// rolling-shutter line time l (sensors/camera_sensor_config.h):
//   - the frame spans D = T + (H - 1) l. `end` is a snapshot at t1 >= t0 + D (the first physics
//     step after it); everything that moves is interpolated between `start` and `end` at
//     a = s / (t1 - t0): the camera pose (position linear, rotation slerp; render/camera/camera.h)
//     per pixel row, and every body pose X_WB per sub-frame (so moving bodies blur too, but are not
//     skewed by the rolling shutter: their poses do not change within one sub-frame).
//   - sub-frame k (k < n) is rendered at s_k = (k + 0.5) T / n with row v seen at s_k + v l; the
//     sub-frames' radiance images are averaged (box shutter). without `end` nothing moves.
//   - ground-truth images (depth, range, normals, segmentations) come from the pixel-centre rays
//     of sub-frame n / 2 (s = T / 2 for odd n): exact, never blended.
// particle streaks (rain, snow, sparks) are drawn by the renderer over the exposure of each
// sub-frame from the effects given to Capture (those of the capture instant).
//
// optics (OpticsConfig): the averaged radiance is vignetted (cos^n of each pixel's field
// angle), its red and blue images magnified against green (lateral chromatic aberration) and
// blurred by a Gaussian PSF, in that order, before anything is metered or exposed.
//
// exposure: the renderer's auto or manual EV100 (render/film/film.h) of the averaged radiance is
// the target; with auto_exposure_time_constant_sec = tau > 0 the EV used adapts as EV_k = EV_target
// + (EV_{k-1} - EV_target) exp(-(t_k - t_{k-1}) / tau) (state per camera; the first frame uses its
// target). the exposed values x = radiance * H(EV) go through the sensor model
// (sensors/image_noise.h) when noise is enabled, then the film's tone curve and sRGB. with
// auto_exposure enabled (a camera profile, sensors/camera_profile.h) the target is met by a shutter
// time and an analog gain within the camera's limits (AutoExposureConfig), metered on a
// quarter-size render of the capture instant (one more render per frame, 1/16 of the pixels: a
// camera's statistics grid), so a frame's exposure depends on that frame alone (a replay from any
// frame reproduces it): the sub-frames span that shutter time, the gain raises the ISO of the
// sensor model, and the raw values (DN / full scale) are developed with raw full scale at the
// filmic curve's white (kFilmicWhite), the highlight roll-off.

#include <cstdint>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "penumbra/core/image.h"
#include "penumbra/core/thread_pool.h"
#include "penumbra/render/film/film.h"
#include "penumbra/render/particles/shelter_map.h"
#include "penumbra/render/renderer.h"
#include "penumbra/sensors/camera_sensor_config.h"
#include "penumbra/sensors/depth_noise.h"

namespace penumbra {

/// images of one captured frame.
struct CameraImages {
  RenderedFrame truth;  ///< renderer images: ground truth (depth_m exact z-depth) and radiance
  ImageF radiance;      ///< (H x W x 3) linear radiance averaged over the sub-frames, cd/m^2
  ImageU8 rgb;          ///< (H x W x 3) uint8 sRGB after exposure, noise, droplets and JPEG
  ImageF depth_m;       ///< (H x W x 1) z-depth in m after depth noise (= truth.depth_m without)
  double ev100 = 0;     ///< exposure value used
  /// with auto_exposure: the shutter time (s) and analog gain (>= 1) of this frame; else
  /// exposure_time_sec and 1.
  double exposure_time_sec = 0, analog_gain = 1;
  double time_sec = 0;               ///< capture time t0 (exposure starts)
  double mid_exposure_time_sec = 0;  ///< time of the ground-truth images, t0 + s_{n/2}
  Pose X_WO = Pose::Identity();      ///< optical frame at mid_exposure_time_sec (row 0)
  /// the renderer's stop request ended a render of this frame (RenderedFrame::stopped): the
  /// images are unfinished and must not be used.
  bool stopped = false;
};

/// checks the ranges of `c` (see CameraSensorConfig).
/// @throws ConfigError with key `key_prefix`.<field> naming the bad value and the valid range.
void ValidateCameraSensorOrThrow(const CameraSensorConfig& c, const std::string& key_prefix);

/// the span D = T + (H - 1) l of a frame: the end snapshot must be at least this late (T the
/// longest shutter time the camera may use, l = RowTimeSec).
double FrameSpanSec(const CameraSensorConfig& c, int height);

/// the rolling shutter's time between rows, s: rolling_shutter_line_time_sec, or when it is 0
/// the readout time / height.
double RowTimeSec(const CameraSensorConfig& c, int height);

/// the exposed value at which the filmic tone curve (render/film/film_math.h AcesFilmic) reaches
/// display white: with auto_exposure the raw full scale is developed at this value.
double FilmicWhite();

/// stateful image formation of one camera (auto-exposure state). not thread-safe.
class CameraImager {
 public:
  /// @param camera_index  index in SceneDescription::cameras (keys the random numbers)
  /// @throws ConfigError for bad settings (ValidateCameraSensorOrThrow; unknown depth preset).
  /// @param scene  the rendered scene (materials give the depth sensor's IR reflectance);
  ///                referenced, must outlive this object
  CameraImager(const CameraSpec& spec, const CameraSensorConfig& config,
               const RenderSettings& render_settings, int camera_index,
               const SceneDescription& scene);

  /// renders and forms frame `frame_index` captured at `start`. `effects` are what this camera
  /// sees at `start` (scene/effects_frame.h; null = clear conditions), used for every
  /// sub-frame. `X_WO_start` / `X_WO_end` are the optical frame at `start` and at `end`;
  /// `end` = null (or not later than start) means nothing moves during the exposure. when a
  /// render is stopped (RenderedFrame::stopped) Capture returns at once with out->stopped set.
  /// @throws Error from the renderer.
  void Capture(Renderer* renderer, const WorldSnapshot& start, const EffectsFrame* effects,
               const Pose& X_WO_start, const WorldSnapshot* end, const Pose& X_WO_end,
               int64_t frame_index, CameraImages* out);

  /// whether Capture always fills out->radiance (default true). off, it asks the renderer for
  /// the radiance (CameraView::want_radiance) and fills out->radiance only when the camera
  /// model reads it: motion-blur sub-frames, sensor noise, gray-world white balance or
  /// exposure adaptation; otherwise out->radiance is left empty and out->rgb is the
  /// renderer's developed rgb (the same bytes as with it on). CameraSink turns it off.
  void set_keep_radiance(bool on) { keep_radiance_ = on; }
  bool keep_radiance() const { return keep_radiance_; }

  /// the largest finite radiance value (any channel, cd/m^2) of the frame the last Capture
  /// formed, for the black-frame warning: the maximum of out->radiance when Capture filled it,
  /// else its ground-truth sub-frame rendered again with the radiance (the same view, snapshot
  /// and effects; renderers keep no state between frames, so this changes no later frame).
  /// `start` and `effects` must be the last Capture's. 0 before any Capture.
  /// @throws Error from the renderer.
  double BrightestRadiance(Renderer* renderer, const WorldSnapshot& start,
                           const EffectsFrame* effects, const CameraImages& last);

  const CameraSpec& spec() const { return spec_; }
  const CameraSensorConfig& config() const { return config_; }
  /// wall time spent inside Renderer::Render by this imager's captures so far, s (the rest of
  /// a capture is the camera model: exposure, noise, develop, copies). a run timing only: it
  /// never reaches an image.
  double renderer_sec() const { return renderer_sec_; }

 private:
  CameraSpec spec_;
  CameraSensorConfig config_;
  RenderSettings settings_;
  Film film_;
  int camera_index_;
  const SceneDescription& scene_;
  std::optional<DepthNoiseModel> depth_model_;
  Eigen::Vector3f daylight_white_{1, 1, 1};  // DaylightWhite(scene_), for white_balance daylight
  // lens droplets: where rain can reach the camera (built at the first frame with rain) and
  // the sim time the lens was last under open sky in the rain
  std::unique_ptr<ShelterMap> shelter_;
  std::optional<double> last_wet_time_;
  std::optional<double> last_ev_, last_time_;
  ImageF optic_, optic_tmp_;          // the radiance after the optics
  ImageF meter_optic_, meter_tmp_;    // auto exposure's metering view after the optics
  std::unique_ptr<ThreadPool> pool_;  // for the per-pixel passes (null when there are none)
  ImageF accum_, exposed_, dn_;
  double renderer_sec_ = 0;
  bool keep_radiance_ = true;
  // the last Capture's ground-truth sub-frame (BrightestRadiance renders it again): its view
  // and, for a moving camera, its interpolated snapshot
  std::optional<CameraView> truth_view_;
  bool truth_moving_ = false;
  WorldSnapshot interp_;
};

/// frames per second of CameraImager::Capture for a small scene (a box room, 320 x 240, realtime
/// tier) with each noise option in turn: "none", "shot_read", "motion_blur_4", "rolling_shutter",
/// "jpeg_q80", "lens_droplets", "depth_realsense_d435", "all", then each camera profile as
/// "profile_<name>" (sensors/camera_profile.h). for `penumbra bench sensors`.
/// returns (option name, frames per second) in that order; `frames` frames each.
std::vector<std::pair<std::string, double>> CameraNoiseBench(int frames = 20);

}  // namespace penumbra

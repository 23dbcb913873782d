#include "penumbra/sinks/camera_sink.h"

#include <fmt/format.h>
#include <spdlog/spdlog.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <utility>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/output/camera_info.h"
#include "penumbra/output/camera_writer.h"
#include "penumbra/scene/camera_pose.h"
#include "penumbra/world/camera_specs.h"

namespace penumbra {
namespace {

// a frame counts as black when no byte of its rgb image is above this (of 255)
constexpr uint8_t kBlackLevel = 2;

bool IsBlack(const ImageU8& rgb) {
  return !rgb.data.empty() &&
         std::all_of(rgb.data.begin(), rgb.data.end(), [](uint8_t v) { return v <= kBlackLevel; });
}

// true when nothing in the scene gives light: no light with intensity and colour, a black sky,
// no emissive material (effects may still add lights: the rendered radiance decides).
bool SceneHasNoLight(const SceneDescription& scene) {
  for (const Light& l : scene.lights)
    if (l.active && l.intensity > 0 && l.color.maxCoeff() > 0) return false;
  for (const Material& m : scene.materials)
    if (m.emission.maxCoeff() > 0) return false;
  const Sky& s = scene.sky;
  return s.type == Sky::Type::kUniform ? !(s.radiance.maxCoeff() > 0) : !(s.zenith_luminance > 0);
}

// the likely cause of a black frame, for the warning.
// `brightest` is the frame's largest radiance value (CameraImager::BrightestRadiance).
std::string BlackFrameCause(const SceneDescription& scene, const RenderSettings& render,
                            const CameraImages& img, double brightest) {
  if (brightest > 0) {
    return fmt::format(
        "at exposure EV100 {:.3g} ({} exposure{}, compensation_ev {:.3g}) although its brightest "
        "pixel is {:.3g} cd/m^2: the exposure is too dark; expected render.exposure with {}",
        img.ev100, render.auto_exposure ? "auto" : "manual",
        render.auto_exposure ? "" : fmt::format(" ev100 {:.3g}", render.ev100),
        render.exposure_compensation_ev, brightest,
        render.auto_exposure
            ? std::string("a larger compensation_ev")
            : fmt::format("ev100 at most about {:.3g} (log2 of the brightest luminance x 100 / "
                          "12.5), a larger compensation_ev or mode: auto",
                          std::log2(brightest * 8.0)));
  }
  if (SceneHasNoLight(scene)) {
    return "because the world has no light: no light with an intensity and colour above 0, a "
           "black sky (sky.luminance_cd_m2 or sky.color 0, or zenith_luminance_cd_m2 0) and no "
           "emissive material; expected lights:, a sky or an emissive material";
  }
  return fmt::format(
      "because no light reaches it: the camera may be inside a model's geometry (its position "
      "at this frame is [{:.3g}, {:.3g}, {:.3g}] m) or see only unlit surfaces; expected the "
      "camera outside every model, facing something lit",
      img.X_WO.translation().x(), img.X_WO.translation().y(), img.X_WO.translation().z());
}

// moves the images of a frame that the writer never gets (the renderer's radiance, rgb and
// depth, the imager's radiance) from `from` to `to`, leaving them empty in `from`.
void MoveUnwrittenImages(CameraImages* from, CameraImages* to) {
  to->truth.radiance = std::exchange(from->truth.radiance, {});
  to->truth.rgb = std::exchange(from->truth.rgb, {});
  to->truth.depth_m = std::exchange(from->truth.depth_m, {});
  to->radiance = std::exchange(from->radiance, {});
}

}  // namespace

double CaptureSpanSec(const CameraSpec& spec, const CameraSensorConfig& c) {
  if (c.motion_blur_samples <= 1 && c.rolling_shutter_line_time_sec <= 0) return 0.0;
  return FrameSpanSec(c, spec.intrinsics.height);
}

ShutterSchedule::ShutterSchedule(const SceneDescription& scene, const WorldConfig& world) {
  const std::vector<CameraSensorConfig> cfg = SensorConfigsFor(scene, world);
  for (size_t i = 0; i < scene.cameras.size(); ++i)
    span_.push_back(CaptureSpanSec(scene.cameras[i], cfg[i]));
}

bool ShutterSchedule::Due(double time_sec) {
  bool due = false;
  while (!ends_.empty() && *ends_.begin() <= time_sec + 1e-12) {
    ends_.erase(ends_.begin());
    due = true;
  }
  return due;
}

void ShutterSchedule::Add(double time_sec, const std::vector<int>& cameras) {
  for (int c : cameras)
    if (span_[c] > 0) ends_.insert(time_sec + span_[c]);
}

CameraSink::CameraSink(const SceneDescription& scene, const WorldConfig& world, double timestep_sec,
                       Renderer* renderer, const std::string& output_dir, ViewerEffects effects,
                       CameraSinkOptions options)
    : scene_(scene),
      renderer_(renderer),
      render_(world.render),
      effects_(std::move(effects)),
      options_(std::move(options)),
      writer_(output_dir,
              [&] {
                AsyncFrameWriterOptions w = options_.writer;
                // a write error ends the run as soon as it happens (pipeline/sim_loop.h)
                w.on_error = [this](std::exception_ptr e) {
                  if (report_error_) report_error_(e);
                };
                w.on_written = [this](CameraFrame&& f) { buffers_.Return(std::move(f)); };
                return w;
              }()),
      schedule_(timestep_sec),
      timestep_sec_(timestep_sec),
      shutters_(scene, world),
      worker_(static_cast<size_t>(std::max(1, options_.render_queue))) {
  selected_.assign(scene.cameras.size(), options_.cameras.empty() ? 1 : 0);
  warned_black_.assign(scene.cameras.size(), 0);
  rendered_once_.assign(scene.cameras.size(), 0);
  scratch_.resize(scene.cameras.size());
  for (const std::string& name : options_.cameras) {
    const int c = scene.FindCamera(name);
    if (c < 0) {
      std::string names;
      for (const CameraSpec& cam : scene.cameras) names += (names.empty() ? "" : ", ") + cam.name;
      throw ConfigError("", 0, "--cameras",
                        "no camera named '" + name + "'; expected some of: " + names);
    }
    selected_[c] = 1;
  }
  std::vector<CameraSpec> selected;
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    if (!selected_[i]) continue;
    writer_.AddCamera(scene.cameras[i].name, scene.cameras[i].intrinsics, scene.cameras[i].outputs);
    selected.push_back(scene.cameras[i]);
  }
  const std::vector<CameraSensorConfig> cfg = SensorConfigsFor(scene, world);
  imager_configs_ = cfg;
  next_frame_.assign(scene.cameras.size(), 0);
  frame_base_.assign(scene.cameras.size(), 0);
  imagers_.reserve(scene.cameras.size());
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    imagers_.emplace_back(scene.cameras[i], cfg[i], world.render, static_cast<int>(i), scene);
    // the writer never reads the radiance: the black-frame warning asks for it
    imagers_.back().set_keep_radiance(false);
    span_.push_back(CaptureSpanSec(scene.cameras[i], cfg[i]));
  }
  WriteCameraInfo(output_dir, CameraInfosFor(selected));
  if (!world.semantic_classes.empty()) {
    // the labels of the semantic_segmentation ids, in file order
    nlohmann::ordered_json classes = nlohmann::ordered_json::object();
    for (const SemanticClassConfig& c : world.semantic_classes) classes[c.name] = c.id;
    WriteFileAtomic(std::filesystem::path(output_dir) / "semantic_classes.json",
                    classes.dump(2) + "\n");
  }
  for (const CameraSpec& c : scene.cameras) {
    const int id = schedule_.Add(c.name, c.rate_hz);
    if (schedule_.exceeds_physics_rate(id))
      spdlog::warn(
          "camera '{}': rate_hz {:.6g} is faster than the physics rate ({:.6g} Hz); "
          "it renders one frame per physics step",
          c.name, c.rate_hz, schedule_.physics_rate_hz());
  }
}

CameraSink::~CameraSink() { worker_.Finish(); }

void CameraSink::OnStart(const LoopStart& start) {
  report_error_ = start.report_error;
  schedule_.StartAt(start.step);  // a loop from a later step (a replay) keeps the frame indices
  worker_.Start(start.report_error);
}

void CameraSink::StartEpisode(int64_t start, int64_t step) {
  episode_start_ = start;
  later_episode_ = true;
  schedule_ = SensorSchedule(timestep_sec_);
  for (size_t i = 0; i < scene_.cameras.size(); ++i) {
    schedule_.Add(scene_.cameras[i].name, scene_.cameras[i].rate_hz);
    frame_base_[i] = -1;
  }
  schedule_.StartAt(step - start);
  // on the render thread, in order: the open exposures end at the episode's last snapshot,
  // then every imager starts over
  worker_.Post([this] {
    CompletePending(true);
    for (const CameraImager& imager : imagers_) renderer_sec_before_ += imager.renderer_sec();
    imagers_.clear();
    for (size_t i = 0; i < scene_.cameras.size(); ++i) {
      imagers_.emplace_back(scene_.cameras[i], imager_configs_[i], render_, static_cast<int>(i),
                            scene_);
      imagers_.back().set_keep_radiance(false);
    }
  });
}

SnapshotContent CameraSink::Wants(int64_t step, double time_sec) {
  Capture c;
  c.step = step;
  due_.clear();
  if (options_.episode_start) {
    const int64_t start = options_.episode_start();
    if (start != episode_start_) StartEpisode(start, step);
  }
  schedule_.Due(step - episode_start_, &due_);
  for (const SensorFiring& f : due_) {
    // frame k of the episode: noise keyed by k, the written index goes on
    int64_t frame = f.index;
    if (later_episode_) {
      if (frame_base_[f.sensor] < 0) frame_base_[f.sensor] = next_frame_[f.sensor] - f.index;
      frame += frame_base_[f.sensor];
    }
    next_frame_[f.sensor] = frame + 1;
    if (!selected_[f.sensor]) continue;
    c.cameras.push_back(f.sensor);
    c.frames.push_back(frame);
    c.noise_frames.push_back(f.index);
  }
  const bool shutter_due = shutters_.Due(time_sec);
  if (!shutter_due && c.cameras.empty()) {
    capture_.reset();
    return SnapshotContent::kNone;
  }
  shutters_.Add(time_sec, c.cameras);
  capture_ = std::move(c);
  return SnapshotContent::kPoses;
}

void CameraSink::OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) {
  if (!capture_ || capture_->step != snapshot->step) return;
  std::vector<std::shared_ptr<const EffectsFrame>> effects;
  if (effects_) {
    for (int c : capture_->cameras)
      effects.push_back(
          effects_(*snapshot, CameraPoseInWorld(scene_.cameras[c], *snapshot).translation()));
  }
  worker_.Post([this, snapshot, capture = std::move(*capture_), effects = std::move(effects)] {
    Render(snapshot, capture, effects);
  });
  capture_.reset();
}

void CameraSink::OnFinish(const LoopFinish& finish) {
  // exposures still open end with the last snapshot, unless the run failed
  if (finish.reason != LoopEndReason::kError) worker_.Post([this] { CompletePending(true); });
  worker_.Finish();
  writer_.Flush();
}

double CameraSink::renderer_sec() const {
  double sec = renderer_sec_before_;
  for (const CameraImager& imager : imagers_) sec += imager.renderer_sec();
  return sec;
}

void CameraSink::Render(const std::shared_ptr<const WorldSnapshot>& snapshot,
                        const Capture& capture,
                        const std::vector<std::shared_ptr<const EffectsFrame>>& effects) {
  while (!pending_.empty() && pending_.front().end_time <= snapshot->time_sec + 1e-12) {
    Complete(pending_.front(), snapshot.get());
    pending_.pop_front();
  }
  for (size_t i = 0; i < capture.cameras.size(); ++i) {
    const int c = capture.cameras[i];
    Pending p{c,
              capture.frames[i],
              capture.noise_frames[i],
              snapshot,
              i < effects.size() ? effects[i] : nullptr,
              snapshot->time_sec + span_[c]};
    if (span_[c] > 0) {
      pending_.push_back(std::move(p));
    } else {
      Complete(p, nullptr);
    }
  }
  last_ = snapshot;
  if (options_.on_rendered) options_.on_rendered(snapshot->time_sec, frames_);
}

void CameraSink::CompletePending(bool with_last) {
  for (const Pending& p : pending_)
    Complete(p, with_last && last_ && last_->time_sec > p.start->time_sec ? last_.get() : nullptr);
  pending_.clear();
}

void CameraSink::Complete(const Pending& p, const WorldSnapshot* end) {
  const CameraSpec& spec = scene_.cameras[p.camera];
  const Pose X0 = CameraPoseInWorld(spec, *p.start);
  const Pose X1 = end ? CameraPoseInWorld(spec, *end) : X0;
  // the images of this camera's earlier frames, overwritten in place (FrameBufferPool)
  CameraImages img;
  MoveUnwrittenImages(&scratch_[p.camera], &img);
  buffers_.Take(spec.name, &img);
  const auto t0 = std::chrono::steady_clock::now();
  imagers_[p.camera].Capture(renderer_, *p.start, p.effects.get(), X0, end, X1, p.noise_frame,
                             &img);
  const double sec = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  render_sec_ += sec;
  if (!rendered_once_[p.camera]) {
    rendered_once_[p.camera] = 1;
    render_first_frames_sec_ += sec;
  }
  if (img.stopped) {
    MoveUnwrittenImages(&img, &scratch_[p.camera]);
    // the stop request (SIGINT / SIGTERM) ended the render: the frame is not written
    spdlog::info(
        "camera '{}': frame {} at {:.6g} s was being rendered when the run was stopped; "
        "not written",
        spec.name, p.frame, p.start->time_sec);
    return;
  }
  // the first black frame of each camera gets a warning with the likely cause
  if (!warned_black_[p.camera] && IsBlack(img.rgb)) {
    warned_black_[p.camera] = 1;
    spdlog::warn("camera '{}': frame {} (t = {:.6g} s) is black (every pixel <= {} of 255) {}",
                 spec.name, p.frame, img.mid_exposure_time_sec, kBlackLevel,
                 BlackFrameCause(scene_, render_, img,
                                 imagers_[p.camera].BrightestRadiance(renderer_, *p.start,
                                                                      p.effects.get(), img)));
  }
  CameraFrame cf;
  cf.camera = spec.name;
  cf.index = p.frame;
  cf.step = p.start->step;
  cf.time_sec = img.mid_exposure_time_sec;
  cf.X_WO = img.X_WO;
  cf.rgb = std::move(img.rgb);
  cf.depth_m = std::move(img.depth_m);
  cf.geom_id = std::move(img.truth.geom_id);
  cf.range_m = std::move(img.truth.range_m);
  cf.normal_O = std::move(img.truth.normal_O);
  cf.body_id = std::move(img.truth.body_id);
  cf.semantic_class = std::move(img.truth.semantic_class);
  MoveUnwrittenImages(&img, &scratch_[p.camera]);  // for the camera's next frame
  ++frames_;
  if (options_.on_frame) {
    auto shared = std::make_shared<const CameraFrame>(cf);
    options_.on_frame(shared);
  }
  writer_.Submit(std::move(cf));
}

}  // namespace penumbra

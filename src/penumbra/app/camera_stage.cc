#include "penumbra/app/camera_stage.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>

#include "penumbra/core/error.h"
#include "penumbra/core/output_file.h"
#include "penumbra/output/camera_info.h"
#include "penumbra/output/camera_writer.h"
#include "penumbra/output/png_io.h"
#include "penumbra/session/camera_specs.h"
#include "penumbra/session/scene_assembly.h"

namespace penumbra {
namespace {

ImageU16 IdsToU16(const ImageI32& ids, int offset, const std::string& what) {
  ImageU16 out(ids.width, ids.height, 1);
  for (size_t i = 0; i < ids.data.size(); ++i) {
    const int64_t v = static_cast<int64_t>(ids.data[i]) + offset;
    if (v < 0 || v > 65535)
      throw Error(what + " id " + std::to_string(ids.data[i]) + " does not fit a 16-bit PNG");
    out.data[i] = static_cast<uint16_t>(v);
  }
  return out;
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

CameraStage::CameraStage(const SceneDescription& scene, const WorldConfig& world,
                         Renderer* renderer, const std::string& output_dir)
    : scene_(scene), renderer_(renderer), output_dir_(output_dir) {
  const std::vector<CameraSensorConfig> cfg = SensorConfigsFor(scene, world);
  imagers_.reserve(scene.cameras.size());
  for (size_t i = 0; i < scene.cameras.size(); ++i) {
    imagers_.emplace_back(scene.cameras[i], cfg[i], world.render, static_cast<int>(i), scene);
    span_.push_back(CaptureSpanSec(scene.cameras[i], cfg[i]));
    const CameraOutputs& o = scene.cameras[i].outputs;
    const std::filesystem::path folder = CameraFolder(scene.cameras[i].name);
    for (auto [want, name] : {std::pair{o.range, "range"}, std::pair{o.normals, "normals"},
                              std::pair{o.instance_segmentation, "instance_segmentation"},
                              std::pair{o.semantic_segmentation, "semantic_segmentation"}}) {
      if (want) CreateOutputFolder(output_dir, folder / name);
    }
  }
  WriteCameraInfo(output_dir, CameraInfosFor(scene.cameras));
  if (!world.semantic_classes.empty()) {
    // the labels of the semantic_segmentation ids, in file order
    nlohmann::ordered_json classes = nlohmann::ordered_json::object();
    for (const SemanticClassConfig& c : world.semantic_classes) classes[c.name] = c.id;
    WriteFileAtomic(std::filesystem::path(output_dir) / "semantic_classes.json",
                    classes.dump(2) + "\n");
  }
}

void CameraStage::OnSnapshot(const WorldSnapshot& snapshot, const std::vector<int>& cameras,
                             const std::vector<int64_t>& frame_indices,
                             const std::vector<std::shared_ptr<const EffectsFrame>>& effects,
                             const Submit& submit) {
  while (!pending_.empty() && pending_.front().end_time <= snapshot.time_sec + 1e-12) {
    Complete(pending_.front(), &snapshot, submit);
    pending_.pop_front();
  }
  for (size_t i = 0; i < cameras.size(); ++i) {
    Pending p{cameras[i], frame_indices[i], snapshot, snapshot.time_sec + span_[cameras[i]]};
    if (i < effects.size()) p.start.effects = effects[i];
    if (span_[cameras[i]] > 0) {
      pending_.push_back(std::move(p));
    } else {
      Complete(p, nullptr, submit);
    }
  }
  if (!last_) last_ = std::make_unique<WorldSnapshot>();
  *last_ = snapshot;
}

void CameraStage::Finish(const Submit& submit) {
  for (const Pending& p : pending_)
    Complete(p, last_ && last_->time_sec > p.start.time_sec ? last_.get() : nullptr, submit);
  pending_.clear();
}

void CameraStage::Complete(const Pending& p, const WorldSnapshot* end, const Submit& submit) {
  const CameraSpec& spec = scene_.cameras[p.camera];
  const Pose X0 = CameraPoseInWorld(spec, p.start);
  const Pose X1 = end ? CameraPoseInWorld(spec, *end) : X0;
  CameraImages img;
  const auto t0 = std::chrono::steady_clock::now();
  imagers_[p.camera].Capture(renderer_, p.start, X0, end, X1, p.frame, &img);
  render_sec_ += std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  WriteExtras(spec, p.frame, img);
  CameraFrame cf;
  cf.camera = spec.name;
  cf.index = p.frame;
  cf.time_sec = img.mid_exposure_time_sec;
  cf.X_WO = img.X_WO;
  cf.rgb = std::move(img.rgb);
  cf.depth_m = std::move(img.depth_m);
  cf.geom_id = std::move(img.truth.geom_id);
  submit(std::move(cf));
}

void CameraStage::WriteExtras(const CameraSpec& spec, int64_t frame,
                              const CameraImages& img) const {
  const CameraOutputs& o = spec.outputs;
  if (!o.range && !o.normals && !o.instance_segmentation && !o.semantic_segmentation) return;
  const std::filesystem::path folder = std::filesystem::path(output_dir_) / CameraFolder(spec.name);
  const std::string file = FrameFileName(frame);
  if (o.range)
    WritePngGray16((folder / "range" / file).string(), DepthToMillimetres(img.truth.range_m));
  if (o.normals) {
    const ImageF& n = img.truth.normal_O;
    ImageU8 rgb(n.width, n.height, 3);
    for (size_t i = 0; i < n.data.size(); ++i) {
      const float v = std::clamp((n.data[i] + 1.0f) * 0.5f * 255.0f, 0.0f, 255.0f);
      rgb.data[i] = static_cast<uint8_t>(std::lround(v));
    }
    WritePngRgb8((folder / "normals" / file).string(), rgb);
  }
  if (o.instance_segmentation)
    WritePngGray16((folder / "instance_segmentation" / file).string(),
                   IdsToU16(img.truth.body_id, 1, "body"));
  if (o.semantic_segmentation)
    WritePngGray16((folder / "semantic_segmentation" / file).string(),
                   IdsToU16(img.truth.semantic_class, 0, "semantic class"));
}

}  // namespace penumbra

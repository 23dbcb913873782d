#pragma once
// the camera part of `penumbra run`: exposures that need a later snapshot (motion blur, rolling
// shutter; sensors/camera_imager.h), image formation per camera, and the camera outputs beyond
// rgb/depth/segmentation:
//
// - DIR/camera_info.yaml, DIR/camera_info.json: ROS CameraInfo per camera (output/camera_info.h)
// - DIR/semantic_classes.json: {class name: id} of the world file's `semantic_classes:`
// - DIR/<camera>/range/NNNNNN.png: 16-bit range along the pixel ray, mm, 0 = no hit
// - DIR/<camera>/normals/NNNNNN.png: 8-bit rgb (n_O + 1) / 2 * 255 of the unit normal facing the
//   camera in the optical frame
// - DIR/<camera>/instance_segmentation/NNNNNN.png: 16-bit body index + 1, 0 = background
// - DIR/<camera>/semantic_segmentation/NNNNNN.png: 16-bit semantic class id, 0 = none
//
// depth/ holds the depth sensor's measurement (with depth_noise) or the exact z-depth; all other
// images are exact. frames.csv time/pose: the capture instant, or mid-exposure (sub-frame n/2)
// when the frame uses motion blur or a rolling shutter.

#include <deque>
#include <functional>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "penumbra/output/camera_frame.h"
#include "penumbra/render/renderer.h"
#include "penumbra/sensors/camera_imager.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// the span of sim time camera `c`'s frames need after their capture (0: rendered at once).
double CaptureSpanSec(const CameraSpec& spec, const CameraSensorConfig& config);

/// physics-thread side: which steps must be handed over as end-of-exposure snapshots.
class ShutterSchedule {
 public:
  ShutterSchedule(const SceneDescription& scene, const WorldConfig& world);
  /// true if an exposure started earlier ends at or before `time_sec` (consumes those ends).
  bool Due(double time_sec);
  /// records the exposures of `cameras` starting at `time_sec`.
  void Add(double time_sec, const std::vector<int>& cameras);

 private:
  std::vector<double> span_;
  std::multiset<double> ends_;
};

/// render-thread side. not thread-safe.
class CameraStage {
 public:
  using Submit = std::function<void(CameraFrame&&)>;
  /// writes camera_info.yaml/json (and semantic_classes.json) and makes the extra output folders.
  /// @throws ConfigError for bad camera sensor settings; Error if files cannot be written.
  CameraStage(const SceneDescription& scene, const WorldConfig& world, Renderer* renderer,
              const std::string& output_dir);

  /// hands over one snapshot from the physics thread (in order): completes pending exposures
  /// that end by its time, then captures `cameras` (frame_indices, per-camera effects or empty).
  /// finished frames go to `submit` (in frame order per camera).
  void OnSnapshot(const WorldSnapshot& snapshot, const std::vector<int>& cameras,
                  const std::vector<int64_t>& frame_indices,
                  const std::vector<std::shared_ptr<const EffectsFrame>>& effects,
                  const Submit& submit);

  /// completes every pending exposure with the last snapshot seen (the run ended).
  void Finish(const Submit& submit);

  double render_sec() const { return render_sec_; }

 private:
  struct Pending {
    int camera;
    int64_t frame;
    WorldSnapshot start;
    double end_time;
  };
  void Complete(const Pending& p, const WorldSnapshot* end, const Submit& submit);
  void WriteExtras(const CameraSpec& spec, int64_t frame, const CameraImages& img) const;

  const SceneDescription& scene_;
  Renderer* renderer_;
  std::string output_dir_;
  std::vector<CameraImager> imagers_;
  std::vector<double> span_;
  std::deque<Pending> pending_;
  std::unique_ptr<WorldSnapshot> last_;
  double render_sec_ = 0;
};

}  // namespace penumbra

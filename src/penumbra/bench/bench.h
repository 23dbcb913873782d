#pragma once
// `penumbra bench render|physics`: throughput measurements on real worlds. these
// are benchmarks, never pass/fail tests; they print numbers and targets.

#include <optional>
#include <string>
#include <vector>

#include "penumbra/render/render_ablation.h"
#include "penumbra/render/render_settings.h"

namespace penumbra {

/// options of `penumbra bench render`.
struct RenderBenchOptions {
  std::string world_file;  ///< world to render (default: the bundled default world)
  int frames = 60;         ///< timed frames per resolution
  int warmup_frames = 5;   ///< untimed frames first
  int threads = 0;         ///< render threads, 0 = all cores
  std::string tier = "realtime";
  /// --backend; nullopt = the world's render.backend.
  std::optional<RenderSettings::Backend> backend;
  /// --batch N: batch rendering (render/cuda/cuda_batch_renderer.h) of N cameras per launch
  /// instead (backend cuda); 0 = the single-camera benchmark.
  int batch = 0;
  int batch_width = 128;  ///< --size WxH of the batch benchmark
  int batch_height = 128;
  int sessions = 1;       ///< --sessions S: the batch's cameras spread over S sessions of the world
  bool adversity = true;  ///< also time the presets none/minor/major (bench/effects_bench.h)
  /// --preset NAME: time only these presets' lines (of none, minor, major; a profile of one
  /// condition) and skip the plain 640x480 / 800x800 lines; empty = the plain lines, then all
  /// three presets (unless adversity is false).
  std::vector<std::string> presets;
  /// parts of the renderer to switch off (RenderAblation's fields by their --ablate names:
  /// mirror, mirror-sparse, sky-volume, texture-filter, shadows, sun-occluder, film); the
  /// frames/s then say what the part costs (docs/performance.md, "What costs what").
  std::vector<std::string> ablate;
  /// time only the 640x480 resolution (skip 800x800).
  bool only_640x480 = false;
};

/// the names `penumbra bench render --ablate` takes, in RenderAblation's order.
const std::vector<std::string>& AblationNames();

/// switches off the parts `names` names in *ablation. @throws ConfigError naming an unknown
/// part and listing the known ones.
void ApplyAblation(const std::vector<std::string>& names, RenderAblation* ablation);

/// renders the world's first camera at 640x480 and 800x800 (RGB + depth) while the
/// world moves, and prints frames/s and Mrays/s for each. returns 0.
int BenchRender(const RenderBenchOptions& options);

/// options of `penumbra bench physics`.
struct PhysicsBenchOptions {
  std::string world_file;  ///< world whose composed model is stepped (default world)
  /// a bare MJCF file, stepped as well (the default world is then not measured unless
  /// world_file is given); its peak memory is compared with MuJoCo alone
  std::string model_file;
  double sim_seconds = 20;
  bool controllers = true;         ///< also report controller cost on the bundled robot worlds
  double controller_seconds = 10;  ///< simulated seconds per controller-cost episode
  /// internal: this process is a child of the memory comparison: "idle" (nothing), "bare"
  /// (RunBareMujocoLoop) or "penumbra" (a session of the model, stepped); it prints
  /// "vm_hwm_kib <n>" and exits
  std::string memory_child;
};

/// the ratio target of `bench physics`: Penumbra's steps/s over a bare mj_step loop's.
inline constexpr double kPhysicsThroughputTarget = 0.98;
/// the memory target: a bare model's session peak memory above that of the libraries, over the
/// same for a bare mj_step loop (both fresh processes of this executable).
inline constexpr double kPhysicsMemoryTarget = 2.0;

/// prints the machine, then Penumbra's physics steps/s against a bare mj_step loop on the same
/// model for the world (composed, no controllers) and the model, and, for a model, the peak
/// resident memory of three fresh processes of this executable (libraries only, a bare mj_step
/// loop, a session of the model stepped as a run steps it with no cameras). returns 0.
int BenchPhysics(const PhysicsBenchOptions& options);

/// the frame rate `penumbra bench render` aims for: 640x480 rgb+depth, realtime tier, on the
/// 2-core CI machine (docs/benchmarks.md), frames/s.
inline constexpr double kRenderTargetFps = 30.0;
/// the adversity preset `major`'s target of the same measurement, frames/s.
inline constexpr double kMajorPresetTargetFps = 10.0;

/// "met" when `measured` >= `target`, else "NOT met": the verdict of a ratio target (two
/// measurements on the same machine, e.g. steps/s with and without a sink), which holds on any
/// machine. absolute targets (frames/s, ms) use BenchTargetVerdict (core/bench_machine.h).
const char* TargetVerdict(double measured, double target);

/// prints the realtime frame-rate target line of a render bench: "target on <machine>:
/// <subject>>= T frames/s at 640x480 realtime: <verdict> (F frames/s here)" with the machine the
/// target was set on and BenchTargetVerdict's verdict (met / NOT met there, "not judged" naming
/// both machines elsewhere), or "not applicable (tier X)" when `tier` is not "realtime".
/// `subject` is "" or e.g. "major ".
void PrintRealtimeFpsTarget(const std::string& subject, double target_fps, double measured_fps,
                            const std::string& tier);

}  // namespace penumbra

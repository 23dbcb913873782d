#include "penumbra/sinks/run/run_outputs.h"

#include <fmt/format.h>

#include <initializer_list>
#include <utility>

#include "penumbra/core/build_info.h"
#include "penumbra/physics/mujoco_version.h"
#include "penumbra/render/backends/renderer_factory.h"

namespace penumbra {

RunOutputs::RunOutputs(Session& session, const WorldConfig& world,
                       const std::filesystem::path& out_dir, RunOutputsOptions options)
    : session_(session), world_(world) {
  Simulation& sim = session.sim();
  EffectsStage& effects = session.effects();
  const ViewerEffects viewer_effects = [&effects](const WorldSnapshot& s,
                                                  const Eigen::Vector3d& p_W) {
    return effects.Evaluate(s, p_W);  // per viewer, beside the snapshot
  };
  CameraSinkOptions camera_options;
  camera_options.on_rendered = [this](double t, int64_t frames) { progress_->Update(t, frames); };
  camera_options.cameras = std::move(options.cameras);
  camera_options.render_queue = options.render_queue;
  camera_options.writer.on_image = std::move(options.on_image);
  // a `reset` (Simulation::ResetControllers) restarts the cameras with the episode, as the
  // sensors (SensorSink follows the same simulation)
  camera_options.episode_start = [&sim] { return sim.controller_episode_start(); };
  cameras_ =
      std::make_unique<CameraSink>(session.scene(), world, sim.timestep(), session.renderer(),
                                   out_dir.string(), viewer_effects, camera_options);
  sensors_ =
      std::make_unique<SensorSink>(world, sim, session.scene(), out_dir.string(), viewer_effects);
  trajectory_ = std::make_unique<TrajectorySink>(out_dir / "trajectory.csv", sim.qpos().size());
  metrics_ = MakeMetricsSink(world, sim, out_dir.string(), options.metrics_mode);
  falls_ = MakeFallSink(world, sim);
  ProgressOptions progress_options;
  progress_options.mode =
      options.progress ? ProgressOptions::Mode::kAuto : ProgressOptions::Mode::kOff;
  progress_options.pass_interval_sec = options.progress_pass_interval_sec;
  progress_.emplace(options.end_time_sec, progress_options);
  // the pathtraced tier's sample passes, on the render thread (as on_rendered above)
  if (Renderer* renderer = session.renderer(); renderer && options.progress) {
    std::vector<std::string> names;
    for (const CameraSpec& c : session.scene().cameras) names.push_back(c.name);
    renderer->set_progress_callback([this, names](const RenderProgress& p) {
      const std::string name =
          p.camera_index >= 0 && p.camera_index < static_cast<int>(names.size())
              ? names[p.camera_index]
              : std::to_string(p.camera_index);
      progress_->RenderPass(fmt::format("camera '{}' frame {}", name, p.frame_index), p.passes_done,
                            p.passes);
    });
  }
}

RunOutputs::~RunOutputs() {
  if (Renderer* renderer = session_.renderer()) renderer->set_progress_callback({});
}

void RunOutputs::AddTo(SimLoop* loop) {
  for (Sink* sink : std::initializer_list<Sink*>{sensors_.get(), cameras_.get(), trajectory_.get(),
                                                 metrics_.get(), falls_.get()})
    if (sink) loop->AddSink(sink);
}

void RunOutputs::Finish(std::map<std::string, double>* timings) {
  progress_->Finish();
  for (const auto& [kind, sec] : sensors_->busy_sec()) (*timings)["sensors_" + kind + "_sec"] = sec;
  (*timings)["render_sec"] = cameras_->render_sec();
  (*timings)["render_first_frames_sec"] = cameras_->render_first_frames_sec();
  (*timings)["render_renderer_sec"] = cameras_->renderer_sec();
  const PngWriteTimes png = cameras_->png_times();
  (*timings)["png_encode_sec"] = png.encode_sec;
  (*timings)["png_write_sec"] = png.write_sec;
}

RunManifest RunOutputs::Describe(const std::string& world_file,
                                 const std::vector<std::string>& command_line, double sim_time_sec,
                                 bool interrupted, const std::map<std::string, double>& timings,
                                 double peak_rss_mib) const {
  const EffectsStage& effects = session_.effects();
  RunManifest m;
  m.world_file = world_file;
  m.seed = world_.seed;
  m.penumbra_version = PENUMBRA_VERSION;
  m.mujoco_version = MujocoVersion();
  m.embree_version = RendererVersion(world_.render.backend);
  m.timings_sec = timings;
  m.peak_resident_memory_mib = peak_rss_mib;
  m.frames_per_camera = cameras_->FramesWritten();
  m.sim_duration_sec = sim_time_sec;
  m.interrupted = interrupted;
  m.command_line = command_line;
  m.adversity = effects.PresetLabel();
  m.effects = effects.EffectLabels();
  m.agents = effects.AgentLabels();
  if (metrics_) m.metrics_json = metrics_->SummaryJson();  // its OnFinish ran before
  if (falls_) m.falls_json = falls_->SummaryJson();
  return m;
}

}  // namespace penumbra

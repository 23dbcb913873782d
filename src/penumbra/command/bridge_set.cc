#include "penumbra/command/bridge_set.h"

#include "penumbra/command/run_description.h"

namespace penumbra {

BridgeSet::BridgeSet(Session& session, const WorldConfig& world, RunOutputs& outputs,
                     BridgeSetOptions options, const std::vector<RunBridgeFactory>& factories) {
  model_info_ = DescribeRun(session, world);
  RunControlOptions control_options;
  control_options.start_paused = options.lockstep;
  control_options.realtime_factor = options.realtime_factor;
  control_options.external_stop = options.external_stop;
  control_ = std::make_unique<RunControl>(&session.sim(), control_options);
  dispatcher_ = std::make_unique<CommandDispatcher>(session, world, control_.get(), model_info_,
                                                    options.lockstep, options.live);
  RunBridgeContext context{session, world, *dispatcher_, *control_, model_info_};
  for (const RunBridgeFactory& f : factories)
    if (f) bridges_.push_back(f(context));
  std::erase(bridges_, nullptr);

  CameraSink& cameras = outputs.cameras();
  cameras_ = &cameras;
  SensorSink& sensors = outputs.sensors();
  cameras.set_on_frame([this](const std::shared_ptr<const CameraFrame>& frame) {
    for (auto& b : bridges_) b->OnCameraFrame(frame);
  });
  sensors.set_on_sample([this](const SensorSample& sample) {
    for (auto& b : bridges_) b->OnSensorSample(sample);
  });
  control_->AddDrain([&cameras, &sensors] {
    cameras.Drain();
    sensors.Drain();
  });
}

BridgeSet::~BridgeSet() = default;

void BridgeSet::Configure(PhysicsSourceOptions* physics, SimLoopOptions* loop) {
  physics->realtime = false;
  RunControl* control = control_.get();
  CameraSink* cameras = cameras_;
  physics->before_step = [control, cameras](Simulation& sim) {
    // at real-time pacing no captured frame waits for the renderer when commands apply: the
    // next rendered frame shows them (a live view drops no frame, it never queues stale ones)
    if (control->realtime_factor() > 0) cameras->Drain();
    return control->BeforeStep(sim);
  };
  loop->stop_request = control_->stop_flag();
}

void BridgeSet::AddTo(SimLoop* loop) {
  loop->AddSink(control_.get());
  for (auto& b : bridges_) loop->AddSink(b.get());
}

}  // namespace penumbra

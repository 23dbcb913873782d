#pragma once
// the hook by which middleware bridges (ZeroMQ, ROS, the browser viewer) attach to a live
// `penumbra run`: RunOptions::bridges (run/runner.h) holds factories; the runner calls each
// factory once the run is set up, with a RunBridgeContext, and wires the bridge it returns:
//
//   - as a pipeline Sink (pipeline/sink.h), added to the run's SimLoop after the outputs and
//     the RunControl: OnStart, Wants/OnSnapshot for every step (ask for the snapshot content
//     the bridge publishes, e.g. kFull at a state rate), OnFinish; loop thread;
//   - OnCameraFrame: every camera frame as it is completed, with its raw images
//     (output/camera_frame.h: rgb8, depth in m, segmentation ...), on the render thread;
//   - OnSensorSample: every IMU, MuJoCo-sensor and LiDAR sample (sinks/sensor_sink.h), on the
//     sensor thread;
//   - commands: the context's CommandDispatcher (command/command_dispatcher.h) is the one
//     command layer of the run; a bridge turns its middleware's requests into dispatcher
//     requests (JSON objects, docs/zmq-protocol.md) and sends the replies back.
//
// ordering guarantee for lockstep: a `step` reply's Done callback runs only after every
// OnCameraFrame / OnSensorSample / OnSnapshot call for outputs of the steps it took has
// returned (RunControl drains the camera and sensor threads first). a bridge that queues its
// outgoing messages in one queue in call order (as the ZeroMQ bridge does) therefore sends the
// step's data before the step's reply.
//
// callbacks may run concurrently on the three threads; a bridge synchronises its own state.
// they must be quick (copy or queue, never block on a network peer): a slow bridge slows the
// run. errors: a factory may throw (ConfigError for bad settings, Error for e.g. a port in
// use): the run then fails before any step. errors during the run go to
// LoopStart::report_error (ends the run) or to the bridge's own log.

#include <functional>
#include <memory>
#include <nlohmann/json.hpp>

#include "penumbra/output/camera_frame.h"
#include "penumbra/pipeline/sink.h"
#include "penumbra/session/session.h"
#include "penumbra/sinks/sensor_sink.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

class CommandDispatcher;
class RunControl;

/// what a bridge gets from the run; everything outlives the bridge.
struct RunBridgeContext {
  Session& session;          ///< the world as loaded: sim(), scene() (cameras), effects()
  const WorldConfig& world;  ///< the world with the run's overrides
  CommandDispatcher& dispatcher;
  RunControl& control;
  /// the `model_info` reply fields (command/run_description.h): names, cameras with
  /// intrinsics, sensors, controllers.
  const nlohmann::json& model_info;
};

/// one middleware bridge of a live run (see the file comment).
class RunBridge : public Sink {
 public:
  /// SinkStage::kBridges: after the run control.
  SinkStage stage() const override { return SinkStage::kBridges; }
  ~RunBridge() override = default;
  /// a completed camera frame (render thread).
  virtual void OnCameraFrame(const std::shared_ptr<const CameraFrame>& frame) {}
  /// a sensor sample (sensor thread).
  virtual void OnSensorSample(const SensorSample& sample) {}
  /// the default Sink methods: nothing wanted.
  SnapshotContent Wants(int64_t, double) override { return SnapshotContent::kNone; }
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>&) override {}
};

/// makes a bridge for a run. @throws ConfigError / Error (the run fails before its first step).
using RunBridgeFactory = std::function<std::unique_ptr<RunBridge>(const RunBridgeContext& context)>;

}  // namespace penumbra

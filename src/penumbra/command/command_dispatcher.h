#pragma once
// the one command layer of a live run, shared by every bridge (ZeroMQ, ROS, the browser
// viewer): a decoded request (a JSON object: {"cmd": NAME, "id": ANY?, ...fields}, the schema
// of docs/zmq-protocol.md) in, a reply object out. every field is checked here, before
// anything is queued: a missing or mistyped field, a name the model does not have or an
// unknown command gives an error reply naming the field (command/command_error.h), never an
// exception. commands that change the simulation run through RunControl at a step boundary
// (command/run_control.h), so lockstep runs stay deterministic.
//
// commands: one table (Commands(): name, when it is carried out, whether it is logged, its
// handler) that Dispatch looks a request's `cmd` up in; it equals the table of
// docs/zmq-protocol.md "Commands" (tests/command/command_table_test.cc). the live commands
// (set_adversity, set_effect, start_recording, stop_recording) go through the run's
// LiveControl (live/live_control.h; not_available when the dispatcher has none).
// transport-level commands (the ZeroMQ bridge's `sync`) are the bridges' own.

#include <functional>
#include <nlohmann/json.hpp>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include "penumbra/command/command_error.h"
#include "penumbra/command/request_reader.h"
#include "penumbra/command/run_control.h"
#include "penumbra/live/live_control.h"
#include "penumbra/session/session.h"
#include "penumbra/world/world_config.h"

namespace penumbra {

/// the protocol version of docs/zmq-protocol.md that this build speaks.
inline constexpr int kCommandProtocolVersion = 1;

/// checks requests and carries them out on the run (see the file comment). thread-safe.
class CommandDispatcher {
 public:
  /// receives the whole reply: {"ok", "cmd", "id" (when the request had one), ...}.
  using Done = std::function<void(nlohmann::json reply)>;

  /// `session`, `world` and `control` must outlive the dispatcher; `model_info` is the
  /// `model_info` reply (command/run_description.h: DescribeRun). `lockstep`: the run was
  /// started paused (hello's `mode`). `live`: the run's live effects and recorder (may be
  /// null: the four live commands then reply not_available); it must outlive the dispatcher.
  CommandDispatcher(Session& session, const WorldConfig& world, RunControl* control,
                    nlohmann::json model_info, bool lockstep, LiveControl* live = nullptr);

  /// checks `request` and carries it out; `done` receives the reply exactly once: at once (on
  /// this thread) for errors and read-only commands, else on the loop thread once the command
  /// was applied (for `step`: once the steps are taken and their outputs drained). never throws.
  void Dispatch(const nlohmann::json& request, Done done);
  /// Dispatch and wait for the reply. not from the loop thread (it would wait for itself).
  nlohmann::json Call(const nlohmann::json& request);

  /// when a command is carried out (docs/zmq-protocol.md "Commands", column "carried out").
  enum class CommandTiming {
    kNow,           ///< checked and answered at once, on the caller's thread
    kStepBoundary,  ///< queued and carried out by the loop thread at the next step boundary
    kLive,          ///< a live change (LiveControl), applied from the next step
  };
  /// one row of the command table.
  struct CommandInfo {
    std::string_view name;  ///< the request's `cmd`
    CommandTiming timing;
    /// it changes the simulation: recorded as a "command" event of the run's logs
    /// (LiveControl::RecordCommand) once it ran.
    bool logged = false;
    /// checks the request's fields and replies or queues (throws CommandError).
    void (CommandDispatcher::*handle)(const CommandInfo& info, RequestReader& rd,
                                      const Done& done) = nullptr;
  };
  /// the command table, sorted by name.
  static std::span<const CommandInfo> Commands();
  /// the row of command `name`, or nullptr.
  static const CommandInfo* FindCommand(std::string_view name);
  /// the commands Dispatch knows, sorted (the names of Commands()).
  static std::vector<std::string> CommandNames();
  /// the `model_info` reply fields.
  const nlohmann::json& model_info() const { return model_info_; }
  /// the run's live controls (the `live` of the constructor; null when it has none).
  LiveControl* live() const { return live_; }

 private:
  struct Target {
    int index = -1;
    std::string robot;
    std::vector<std::string> commands;  // ControllerCommands (controller_capabilities.h)
    int joints = 0;                     // JointTarget: joints in its command vectors
    bool lateral = true;                // TwistTarget: can move sideways
    std::string type;                   // Controller::type(), for messages
  };
  // the handlers of the command table (each checks its fields; throws CommandError)
  void Hello(const CommandInfo& info, RequestReader& rd, const Done& done);
  void ModelInfo(const CommandInfo& info, RequestReader& rd, const Done& done);
  void GetState(const CommandInfo& info, RequestReader& rd, const Done& done);
  void Step(const CommandInfo& info, RequestReader& rd, const Done& done);
  void SetCtrl(const CommandInfo& info, RequestReader& rd, const Done& done);
  void Twist(const CommandInfo& info, RequestReader& rd, const Done& done);
  void JointTargets(const CommandInfo& info, RequestReader& rd, const Done& done);
  void Waypoints(const CommandInfo& info, RequestReader& rd, const Done& done);
  void SetMocap(const CommandInfo& info, RequestReader& rd, const Done& done);
  void Reset(const CommandInfo& info, RequestReader& rd, const Done& done);
  void PauseResume(const CommandInfo& info, RequestReader& rd, const Done& done);
  void SetRealtimeFactor(const CommandInfo& info, RequestReader& rd, const Done& done);
  void Stop(const CommandInfo& info, RequestReader& rd, const Done& done);
  void SetAdversity(const CommandInfo& info, RequestReader& rd, const Done& done);
  void SetEffect(const CommandInfo& info, RequestReader& rd, const Done& done);
  void StartRecording(const CommandInfo& info, RequestReader& rd, const Done& done);
  void StopRecording(const CommandInfo& info, RequestReader& rd, const Done& done);
  // checks that no unknown field is left and submits `action` to the run control
  void Queue(const CommandInfo& info, RequestReader& rd, const Done& done,
             RunControl::Action action);
  // the run's live controls (throws not_available without them)
  LiveControl& Live(const CommandInfo& info) const;
  // `action` that also records `request` as a "command" event of the run's logs (LiveControl::
  // RecordCommand) once it ran, for the commands that change the simulation (info.logged)
  RunControl::Action LoggedAction(const CommandInfo& info, const nlohmann::json& request,
                                  RunControl::Action action) const;
  // the controller a controller command addresses (`robot` field, or the only one)
  const Target& FindTarget(RequestReader& rd, const std::string& command);

  Session& session_;
  const WorldConfig& world_;
  RunControl* control_;
  nlohmann::json model_info_;
  bool lockstep_ = false;
  LiveControl* live_ = nullptr;
  std::vector<Target> targets_;
  std::vector<std::string> actuator_names_;
  std::vector<std::string> mocap_names_;
  std::vector<bool> mocap_driven_;
  std::vector<std::string> key_names_;
};

}  // namespace penumbra

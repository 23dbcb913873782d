#pragma once
// a run log (docs/run-log.md) started and stopped while the run goes on (the bridges' start/stop
// recording; the viewer's record button): the log's header is that of a log the run would
// have written with --record, its first step record is the step at which the recording
// started, with the live changes applied before it (live/live_effects.h) as "live" events
// at that step, and it ends complete (end chunk) at the step at which it was stopped, so that
// `penumbra replay` replays it from its first step with the same visuals.
//
// threading: StartRecording / StopRecording / RecordSensor from any thread; the sink methods
// and OnChange on the loop thread. a start takes effect at the next step the loop hands to its
// sinks; a stop at once, between two steps (the loop thread appends under the same lock), so
// in lockstep a log started and stopped between the same requests holds the same steps.

#include <atomic>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <string>
#include <vector>

#include "penumbra/pipeline/sink.h"
#include "penumbra/runlog/run_log_writer.h"
#include "penumbra/session/session.h"

namespace penumbra {

/// a finished live recording.
struct LiveRecording {
  std::string path;                         ///< the .plog written, relative to the output folder
  std::string file;                         ///< the same on disk (output folder / path)
  uint64_t bytes = 0;                       ///< its size
  int64_t steps = 0;                        ///< step records in it
  int64_t first_step = -1, last_step = -1;  ///< its first and last step (-1: none)
};

/// starts and stops run logs of a running Session; a pipeline sink (register it after the
/// cameras and sensors, so that their sensor records reach it before it closes at the end).
class LiveRecorder : public Sink {
 public:
  /// SinkStage::kRecording: after the cameras and sensors: their records of a step reach the log
  /// first.
  SinkStage stage() const override { return SinkStage::kRecording; }
  /// `session` must outlive this object. `command_line` goes into the logs' headers.
  /// `output_folder`: the run's output folder; every recording is a new file inside it
  /// (core/output_path_policy.h).
  LiveRecorder(Session& session, std::string command_line, std::filesystem::path output_folder);
  /// closes an open log (errors are logged).
  ~LiveRecorder() override;
  LiveRecorder(const LiveRecorder&) = delete;
  LiveRecorder& operator=(const LiveRecorder&) = delete;

  /// creates the new file `path` (relative to the output folder) now, header written, and
  /// records from the next step the loop reaches. the path follows the one policy for files
  /// clients name (core/output_path_policy.h: relative, no "..", no links, ends in .plog,
  /// never overwrites). `sensors`: the log also holds the cameras' images and the sensors'
  /// outputs from then on (sensor records, as --record-sensors), as far as they are written
  /// before the stop.
  /// @throws ConfigError("", 0, "path", ...) for a path the policy refuses (the problem names
  ///         the path and the rule); ConfigError("", 0, "recording", ...) when a recording is
  ///         active or the loop has finished (no step would follow; nothing is created then);
  ///         RunLogError when the header cannot be written.
  void StartRecording(const std::string& path, bool sensors);

  /// closes the active log now (every record appended so far, then the end chunk) and says
  /// what it holds.
  /// @throws ConfigError("", 0, "recording", ...) when no recording is active; RunLogError
  ///         when the log could not be written (the recording has ended then too).
  LiveRecording StopRecording();

  /// whether a recording is active.
  bool recording() const;
  /// whether the loop has finished (OnFinish ran): StartRecording is refused from then on.
  bool finished() const;

  /// whether a recording with sensor records is active (thread-safe, lock-free): callers
  /// skip building records otherwise.
  bool wants_sensor_records() const { return wants_sensors_.load(std::memory_order_relaxed); }

  /// a sensor output of the run (thread-safe): kept when a recording with sensors is active
  /// and its step is at or after the recording's first step.
  void RecordSensor(const SensorRecord& record);

  /// a live change applied at `step` (loop thread; LiveControl wires it to LiveEffects): kept
  /// for logs started later and recorded in the active one.
  void OnChange(int64_t step, double time_sec, const nlohmann::json& change);

  /// a command carried out at `step` (loop thread; LiveControl::RecordCommand): recorded as a
  /// "command" event in the active log once it has its first step.
  void RecordCommand(int64_t step, double time_sec, const std::string& payload_json);

  /// the finished recording of a log still open when the loop ended (closed in OnFinish),
  /// or one with path "" when none was.
  LiveRecording closed_at_finish() const;

  SnapshotContent Wants(int64_t step, double time_sec) override;
  void OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) override;
  /// closes an open log; one that got no step (started as the run stopped) is removed instead
  /// of being left empty (a warning says so). @throws RunLogError from closing it.
  void OnFinish(const LoopFinish& finish) override;

 private:
  LiveRecording CloseLocked();
  void FailLocked(const std::exception& e);

  Session& session_;
  std::string command_line_;
  std::filesystem::path output_folder_;
  std::string file_;      // the active log on disk
  UniqueFd file_folder_;  // the folder holding it, and its name there (for unlinkat)
  std::string file_name_;
  mutable std::mutex mu_;
  std::unique_ptr<RunLogWriter> writer_;
  bool sensors_ = false;
  std::atomic<bool> wants_sensors_{false};
  bool started_ = false;  // the first step was appended (with the earlier changes)
  int64_t first_step_ = -1;
  int64_t last_step_ = -1;
  std::string error_;                    // a write error that ended the recording
  std::vector<nlohmann::json> history_;  // every change applied so far, with its step
  LiveRecording at_finish_;
  bool finished_ = false;
};

}  // namespace penumbra

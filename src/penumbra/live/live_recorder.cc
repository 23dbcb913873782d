#include "penumbra/live/live_recorder.h"

#include <fcntl.h>
#include <spdlog/spdlog.h>
#include <unistd.h>

#include "penumbra/core/build_info.h"
#include "penumbra/core/error.h"
#include "penumbra/core/output_path_policy.h"
#include "penumbra/output/recorder_sink.h"
#include "penumbra/live/run_log_header.h"

namespace penumbra {

LiveRecorder::LiveRecorder(Session& session, std::string command_line,
                           std::filesystem::path output_folder)
    : session_(session),
      command_line_(std::move(command_line)),
      output_folder_(std::move(output_folder)) {}

LiveRecorder::~LiveRecorder() {
  std::lock_guard<std::mutex> lock(mu_);
  if (!writer_) return;
  try {
    CloseLocked();
  } catch (const std::exception& e) {
    spdlog::error("live recording: {}", e.what());
  }
}

void LiveRecorder::StartRecording(const std::string& path, bool sensors) {
  std::lock_guard<std::mutex> lock(mu_);
  if (writer_)
    throw ConfigError("", 0, "recording",
                      "already recording to " + writer_->path() + "; expected a stop first");
  if (finished_)
    throw ConfigError("", 0, "recording",
                      "the run has ended; no step would be recorded; expected a running run");
  // the one policy for files a client names: a new file inside the output folder
  NewOutputFile file;
  try {
    file = OpenNewFileInside(output_folder_, path, ".plog");
  } catch (const OutputPathError& e) {
    throw ConfigError("", 0, "path", e.what());
  }
  RunLogHeader header = MakeRunLogHeader(session_, PENUMBRA_VERSION, command_line_);
  header.has_sensor_records = sensors;
  try {
    // named by its relative path: errors and replies never show the server's folders
    writer_ = std::make_unique<RunLogWriter>(std::move(file.fd), file.relative, header);
  } catch (...) {
    // created above by this call: not left empty (removed where it was made, not by path)
    ::unlinkat(file.folder.get(), file.name.c_str(), 0);
    throw;
  }
  file_ = file.path.string();
  // kept to remove the file where it was made should no step reach it (OnFinish)
  file_folder_ = std::move(file.folder);
  file_name_ = file.name;
  sensors_ = sensors;
  wants_sensors_ = sensors;
  started_ = false;
  first_step_ = last_step_ = -1;
  error_.clear();
  spdlog::info("live recording to {} from the next step", file_);
}

LiveRecording LiveRecorder::CloseLocked() {
  LiveRecording r;
  r.path = writer_->path();
  r.file = file_;
  std::unique_ptr<RunLogWriter> writer = std::move(writer_);
  wants_sensors_ = false;
  writer->Close();
  const RunLogWriterStats st = writer->stats();
  r.bytes = st.file_bytes;
  r.steps = st.steps;
  r.first_step = st.first_step;
  r.last_step = st.last_step;
  return r;
}

LiveRecording LiveRecorder::StopRecording() {
  std::lock_guard<std::mutex> lock(mu_);
  if (!writer_) {
    if (!error_.empty()) {
      const std::string e = error_;
      error_.clear();
      throw RunLogError(e);
    }
    throw ConfigError("", 0, "recording", "no recording is active; expected a start first");
  }
  LiveRecording r = CloseLocked();
  spdlog::info("live recording stopped: {} ({} steps, {} bytes)", r.path, r.steps, r.bytes);
  return r;
}

bool LiveRecorder::finished() const {
  std::lock_guard<std::mutex> lock(mu_);
  return finished_;
}

bool LiveRecorder::recording() const {
  std::lock_guard<std::mutex> lock(mu_);
  return writer_ != nullptr;
}

void LiveRecorder::RecordSensor(const SensorRecord& record) {
  std::lock_guard<std::mutex> lock(mu_);
  if (!writer_ || !sensors_ || !started_ || record.step < first_step_) return;
  writer_->RecordSensor(record);
}

void LiveRecorder::OnChange(int64_t step, double time_sec, const nlohmann::json& change) {
  nlohmann::json entry = change;
  entry["step"] = step;
  entry["time_sec"] = time_sec;
  std::lock_guard<std::mutex> lock(mu_);
  history_.push_back(entry);
  if (!writer_ || !started_) return;
  try {
    writer_->RecordEvent(step, time_sec, "live", change.dump());
  } catch (const std::exception& e) {
    FailLocked(e);
  }
}

void LiveRecorder::RecordCommand(int64_t step, double time_sec, const std::string& payload_json) {
  std::lock_guard<std::mutex> lock(mu_);
  if (!writer_ || !started_) return;
  try {
    writer_->RecordEvent(step, time_sec, "command", payload_json);
  } catch (const std::exception& e) {
    FailLocked(e);
  }
}

void LiveRecorder::FailLocked(const std::exception& e) {
  // a recording that fails (disk full) ends; the run goes on and the stop reports it
  error_ = std::string("live recording to ") + writer_->path() + " failed: " + e.what();
  spdlog::error("{}", error_);
  try {
    writer_->Close();
  } catch (const std::exception&) {
  }
  writer_.reset();
  wants_sensors_ = false;
}

SnapshotContent LiveRecorder::Wants(int64_t step, double) {
  std::lock_guard<std::mutex> lock(mu_);
  return writer_ && step > last_step_ ? SnapshotContent::kState : SnapshotContent::kNone;
}

void LiveRecorder::OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) {
  std::lock_guard<std::mutex> lock(mu_);
  if (!writer_ || snapshot->step <= last_step_) return;
  try {
    if (!started_) {
      // the conditions so far: every change applied before (and at) this step, in order,
      // as events of the first step
      for (const nlohmann::json& h : history_) {
        nlohmann::json change = h;
        change.erase("step");
        change.erase("time_sec");
        change["applied_at_step"] = h["step"];
        writer_->RecordEvent(snapshot->step, snapshot->time_sec, "live", change.dump());
      }
      started_ = true;
      first_step_ = snapshot->step;
    }
    writer_->Append(*snapshot);  // its SimState part is the step record
    last_step_ = snapshot->step;
  } catch (const std::exception& e) {
    FailLocked(e);
  }
}

void LiveRecorder::OnFinish(const LoopFinish&) {
  std::lock_guard<std::mutex> lock(mu_);
  finished_ = true;
  if (!writer_) return;
  if (!started_) {
    // started as the run stopped: no step reached it; an empty log is removed (where it was
    // made, not by path), not left
    const LiveRecording r = CloseLocked();
    if (file_folder_.get() >= 0) ::unlinkat(file_folder_.get(), file_name_.c_str(), 0);
    spdlog::warn("live recording {} removed: the run stopped before its first step", r.path);
    return;
  }
  at_finish_ = CloseLocked();
  spdlog::info("live recording closed at the end of the run: {} ({} steps, {} bytes)",
               at_finish_.path, at_finish_.steps, at_finish_.bytes);
}

LiveRecording LiveRecorder::closed_at_finish() const {
  std::lock_guard<std::mutex> lock(mu_);
  return at_finish_;
}

}  // namespace penumbra

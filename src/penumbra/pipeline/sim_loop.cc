#include "penumbra/pipeline/sim_loop.h"

#include <algorithm>

#include "penumbra/core/error.h"

namespace penumbra {

const char* SinkStageName(SinkStage stage) {
  switch (stage) {
    case SinkStage::kLiveChanges:
      return "live_changes";
    case SinkStage::kOutputs:
      return "outputs";
    case SinkStage::kRecording:
      return "recording";
    case SinkStage::kRunControl:
      return "run_control";
    case SinkStage::kBridges:
      return "bridges";
    case SinkStage::kManifest:
      return "manifest";
  }
  return "unknown";
}

std::string ErrorMessage(std::exception_ptr e) {
  try {
    std::rethrow_exception(e);
  } catch (const std::exception& x) {
    return x.what();
  } catch (...) {
    return "unknown error";
  }
}

SimLoop::SimLoop(Source* source, SimLoopOptions options) : source_(source), options_(options) {}

SimLoop::~SimLoop() {
  if (thread_.joinable()) thread_.join();
}

void SimLoop::AddSink(Sink* sink) {
  if (started_) throw Error("SimLoop: AddSink after Start");
  sinks_.push_back(sink);
}

std::vector<Sink*> SimLoop::OrderedSinks() const {
  std::vector<Sink*> ordered = sinks_;
  // stable: registration order within a stage
  std::stable_sort(ordered.begin(), ordered.end(), [](const Sink* a, const Sink* b) {
    return static_cast<int>(a->stage()) < static_cast<int>(b->stage());
  });
  return ordered;
}

void SimLoop::Start() {
  if (started_) throw Error("SimLoop: started twice");
  started_ = true;
  sinks_ = OrderedSinks();
  thread_ = std::thread([this] { Loop(); });
}

LoopFinish SimLoop::Wait() {
  if (!started_) throw Error("SimLoop: Wait before Start");
  if (thread_.joinable()) thread_.join();
  return finish_;
}

bool SimLoop::ReportError(std::exception_ptr e) {
  if (!e) return false;
  failed_.store(true);
  return errors_.Record(e);
}

void SimLoop::Loop() {
  LoopStart start;
  start.step = source_->step();
  start.time_sec = source_->time_sec();
  start.end_time_sec = options_.end_time_sec;
  start.report_error = [this](std::exception_ptr e) { ReportError(e); };
  LoopEndReason reason = LoopEndReason::kEndTime;
  try {
    for (Sink* s : sinks_) s->OnStart(start);
    for (;;) {
      const int64_t step = source_->step();
      const double time = source_->time_sec();
      SnapshotContent content = SnapshotContent::kNone;
      for (Sink* s : sinks_) content = Richer(content, s->Wants(step, time));
      if (content != SnapshotContent::kNone) {
        const std::shared_ptr<const WorldSnapshot> snapshot = source_->Snapshot(content);
        for (Sink* s : sinks_) s->OnSnapshot(snapshot);
      }
      if (failed_.load()) {
        reason = LoopEndReason::kError;
        break;
      }
      if (time >= options_.end_time_sec - 1e-9) break;
      // a stop request (SIGINT/SIGTERM) ends the run at this step boundary
      if (options_.stop_request && options_.stop_request->load() != 0) {
        reason = LoopEndReason::kStopRequested;
        break;
      }
      if (!source_->Advance()) {
        // a source that stops because a stop was requested meanwhile (e.g. a live run waiting
        // for commands) ends as stopped
        reason = options_.stop_request && options_.stop_request->load() != 0
                     ? LoopEndReason::kStopRequested
                     : LoopEndReason::kSourceEnded;
        break;
      }
    }
  } catch (...) {
    ReportError(std::current_exception());
    reason = LoopEndReason::kError;
  }
  // an error recorded by a sink's thread while the last step was handed over also ends the run
  // as failed
  if (failed_.load()) reason = LoopEndReason::kError;
  finish_.reason = reason;
  finish_.step = source_->step();
  finish_.time_sec = source_->time_sec();
  finish_.error = errors_.get();
  for (Sink* s : sinks_) {
    try {
      s->OnFinish(finish_);
    } catch (...) {
      ReportError(std::current_exception());
    }
    // later sinks (e.g. the manifest) see the errors of the earlier ones' OnFinish
    finish_.error = errors_.get();
  }
  finish_.error = errors_.get();
}

}  // namespace penumbra

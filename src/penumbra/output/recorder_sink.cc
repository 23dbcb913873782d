#include "penumbra/output/recorder_sink.h"

#include <utility>

namespace penumbra {
RecorderSink::RecorderSink(const std::string& path, const RunLogHeader& header,
                           const RunLogWriterOptions& options)
    : writer_(std::make_unique<RunLogWriter>(path, header, options)) {}

RecorderSink::RecorderSink(UniqueFd fd, const std::string& name, const RunLogHeader& header,
                           const RunLogWriterOptions& options)
    : writer_(std::make_unique<RunLogWriter>(std::move(fd), name, header, options)) {}

RecorderSink::~RecorderSink() = default;

SnapshotContent RecorderSink::Wants(int64_t step, double) {
  return step > last_step_ ? SnapshotContent::kState : SnapshotContent::kNone;
}

void RecorderSink::OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) {
  if (snapshot->step <= last_step_) return;
  last_step_ = snapshot->step;
  writer_->Append(*snapshot);
}

void RecorderSink::OnFinish(const LoopFinish&) { writer_->Close(); }

}  // namespace penumbra

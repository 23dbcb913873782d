#include "penumbra/output/recorder_sink.h"

namespace penumbra {
namespace {

void CopyState(const WorldSnapshot& s, StepRecord* r) {
  r->step = s.step;
  r->time_sec = s.time_sec;
  r->qpos.assign(s.qpos.begin(), s.qpos.end());
  r->qvel.assign(s.qvel.begin(), s.qvel.end());
  r->act.assign(s.act.begin(), s.act.end());
  r->ctrl.assign(s.ctrl.begin(), s.ctrl.end());
  r->qacc_warmstart.assign(s.qacc_warmstart.begin(), s.qacc_warmstart.end());
  r->qfrc_applied.assign(s.qfrc_applied.begin(), s.qfrc_applied.end());
  r->xfrc_applied.assign(s.xfrc_applied.begin(), s.xfrc_applied.end());
  r->mocap_pos.assign(s.mocap_pos.begin(), s.mocap_pos.end());
  r->mocap_quat.assign(s.mocap_quat.begin(), s.mocap_quat.end());
  r->userdata.assign(s.userdata.begin(), s.userdata.end());
  r->controller_next_update.assign(s.controller_next_update.begin(),
                                   s.controller_next_update.end());
}

}  // namespace

StepRecord StepRecordOf(const WorldSnapshot& snapshot) {
  StepRecord r;
  CopyState(snapshot, &r);
  return r;
}

RecorderSink::RecorderSink(const std::string& path, const RunLogHeader& header,
                           const RunLogWriterOptions& options)
    : writer_(std::make_unique<RunLogWriter>(path, header, options)) {}

RecorderSink::~RecorderSink() = default;

SnapshotContent RecorderSink::Wants(int64_t step, double) {
  return step > last_step_ ? SnapshotContent::kState : SnapshotContent::kNone;
}

void RecorderSink::OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) {
  if (snapshot->step <= last_step_) return;
  last_step_ = snapshot->step;
  CopyState(*snapshot, &scratch_);
  writer_->Append(scratch_);
}

void RecorderSink::OnFinish(const LoopFinish&) { writer_->Close(); }

}  // namespace penumbra

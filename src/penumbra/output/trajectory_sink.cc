#include "penumbra/output/trajectory_sink.h"

#include <fmt/format.h>

#include <iterator>

namespace penumbra {

std::string TrajectoryHeader(size_t nq) {
  std::string h = "step,time_sec";
  for (size_t i = 0; i < nq; ++i) fmt::format_to(std::back_inserter(h), ",qpos{}", i);
  return h + "\n";
}

std::string TrajectoryRow(const WorldSnapshot& s) {
  std::string row = fmt::format("{},{:.17g}", s.step, s.time_sec);
  for (double v : s.qpos) fmt::format_to(std::back_inserter(row), ",{:.17g}", v);
  row += '\n';
  return row;
}

TrajectorySink::TrajectorySink(const std::filesystem::path& path, size_t nq)
    : file_(path), worker_(256) {
  file_.Append(TrajectoryHeader(nq));
}

void TrajectorySink::OnStart(const LoopStart& start) {
  last_step_ = start.step;
  worker_.Start(start.report_error);
}

SnapshotContent TrajectorySink::Wants(int64_t step, double) {
  return step > last_step_ ? SnapshotContent::kState : SnapshotContent::kNone;
}

void TrajectorySink::OnSnapshot(const std::shared_ptr<const WorldSnapshot>& snapshot) {
  if (snapshot->step <= last_step_) return;
  last_step_ = snapshot->step;
  worker_.Post([this, snapshot] { file_.Append(TrajectoryRow(*snapshot)); });
}

void TrajectorySink::OnFinish(const LoopFinish&) {
  worker_.Finish();
  file_.Close();
}

}  // namespace penumbra

// libFuzzer target: the TUM trajectory reader (eval/trajectory.h) and, for what it accepts, the
// evaluation `penumbra eval ate|rpe` runs. an input holding a line "===" is two files: ground
// truth above, estimate below; otherwise the trajectory is evaluated against itself. the
// documented failure is ConfigError; any other exception, a crash, a sanitizer report, or a
// non-finite ATE / RPE statistic of accepted input is a finding. docs/fuzzing.md.

#include <cmath>
#include <cstddef>
#include <cstdint>
#include <string_view>

#include "penumbra/core/error.h"
#include "penumbra/eval/trajectory.h"
#include "penumbra/eval/trajectory_evaluation.h"

namespace {

void CheckFinite(const penumbra::ErrorStats& s) {
  if (s.count > 0 && !(std::isfinite(s.rmse) && std::isfinite(s.mean) && std::isfinite(s.max)))
    __builtin_trap();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  using namespace penumbra;
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  const size_t split = text.find("\n===\n");
  try {
    const Trajectory gt = ParseTumTrajectory(text.substr(0, split), "gt.txt");
    const Trajectory est = split == std::string_view::npos
                               ? gt
                               : ParseTumTrajectory(text.substr(split + 5), "est.txt");
    for (AlignmentModel model : {AlignmentModel::kSe3, AlignmentModel::kSim3}) {
      EvaluationOptions options;
      options.alignment = model;
      try {
        const TrajectoryEvaluation r = EvaluateTrajectory(gt, est, options, "gt.txt", "est.txt");
        CheckFinite(r.ate_m);
        CheckFinite(r.rpe_translation_m);
        CheckFinite(r.rpe_rotation_deg);
      } catch (const ConfigError&) {
      }
    }
  } catch (const ConfigError&) {
  }
  return 0;
}

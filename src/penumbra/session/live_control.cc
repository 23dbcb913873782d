#include "penumbra/session/live_control.h"

namespace penumbra {

LiveControl::LiveControl(Session& session, const std::string& command_line,
                         const std::filesystem::path& output_folder)
    : effects_(session), recorder_(session, command_line, output_folder) {
  effects_.set_on_applied([this](int64_t step, double time_sec, const nlohmann::json& change) {
    recorder_.OnChange(step, time_sec, change);
    if (run_log_) run_log_->RecordEvent(step, time_sec, "live", change.dump());
  });
}

}  // namespace penumbra

#include "penumbra/live/live_control.h"

#include <spdlog/spdlog.h>

namespace penumbra {

LiveControl::LiveControl(Session& session, const std::string& command_line,
                         const std::filesystem::path& output_folder)
    : effects_(session), recorder_(session, command_line, output_folder) {
  effects_.set_on_applied([this](int64_t step, double time_sec, const nlohmann::json& change) {
    recorder_.OnChange(step, time_sec, change);
    if (run_log_) run_log_->RecordEvent(step, time_sec, "live", change.dump());
  });
}

void LiveControl::RecordCommand(int64_t step, double time_sec, const nlohmann::json& command) {
  const std::string payload = command.dump();
  recorder_.RecordCommand(step, time_sec, payload);
  if (!run_log_) return;
  try {
    run_log_->RecordEvent(step, time_sec, "command", payload);
  } catch (const std::exception& e) {
    spdlog::error("run log: the command at step {} could not be recorded: {}", step, e.what());
  }
}

}  // namespace penumbra

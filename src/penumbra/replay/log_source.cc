#include "penumbra/replay/log_source.h"

#include <fmt/format.h>

#include <nlohmann/json.hpp>

#include "penumbra/core/error.h"
#include "penumbra/live/run_log_header.h"
#include "penumbra/physics/physics_source.h"

namespace penumbra {

void CheckLoggedTimestep(const RunLogHeader& header, const Simulation& sim,
                         const std::string& log_path) {
  if (header.timestep_sec != sim.timestep())
    throw ConfigError(log_path, 0, "",
                      fmt::format("the replay model's timestep is {:.17g} s; the log was recorded "
                                  "at {:.17g} s; expected the recorded physics unchanged",
                                  sim.timestep(), header.timestep_sec));
}

LogSource::LogSource(RunLogReader* reader, Simulation* sim, LogSourceOptions options)
    : reader_(reader),
      sim_(sim),
      map_(reader->header().layout, RunLogLayoutOf(*sim), reader->path()),
      state_(sim->GetState()) {
  CheckLoggedTimestep(reader_->header(), *sim_, reader_->path());
  if (!reader_->SeekStep(options.first_step) || !reader_->NextStep(&current_))
    throw RunLogError(fmt::format("{}: no step at or after step {} (the log's steps are {} to {})",
                                  reader_->path(), options.first_step, reader_->first_step(),
                                  reader_->last_step()));
  for (const EventRecord& e : reader_->Events(options.first_step)) {
    if (e.kind != "command") continue;
    const nlohmann::json payload = nlohmann::json::parse(e.payload, nullptr, false);
    if (payload.is_object() && payload.value("cmd", nlohmann::json()) == "reset")
      reset_steps_.insert(e.step);
  }
}

void LogSource::ApplyCurrent() {
  if (applied_step_ == current_.step) return;
  map_.Apply(current_, &state_);
  sim_->SetState(state_);
  sim_->ApplyMocapDrivers(map_.unlogged_mocap());
  applied_step_ = current_.step;
}

std::shared_ptr<const WorldSnapshot> LogSource::Snapshot(SnapshotContent content) {
  ApplyCurrent();
  const std::shared_ptr<WorldSnapshot> s = TakeSnapshot(*sim_, content);
  // the controllers' schedule as logged (the replay runs none)
  s->controller_next_update = current_.controller_next_update;
  return s;
}

bool LogSource::Advance() {
  // a reset at the boundary after this step: the episode starts here, as in the run
  if (reset_steps_.count(current_.step)) {
    ApplyCurrent();
    sim_->ResetControllers();
  }
  if (!reader_->NextStep(&next_)) return false;
  std::swap(current_, next_);
  return true;
}

}  // namespace penumbra

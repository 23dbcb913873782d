#include "penumbra/physics/physics_source.h"

#include <spdlog/spdlog.h>

#include <thread>

namespace penumbra {

PhysicsSource::PhysicsSource(Simulation* sim, PhysicsSourceOptions options)
    : sim_(sim), options_(options), step_(sim->step_count()), time_sec_(sim->time()) {}

std::shared_ptr<WorldSnapshot> TakeSnapshot(const Simulation& sim, SnapshotContent content) {
  auto s = std::make_shared<WorldSnapshot>();
  if (content == SnapshotContent::kState || content == SnapshotContent::kNone) {
    sim.SnapshotState(s.get());
  } else {
    sim.Snapshot(s.get(), content == SnapshotContent::kFull ? Simulation::SnapshotContent::kFull
                                                            : Simulation::SnapshotContent::kPoses);
  }
  return s;
}

std::shared_ptr<const WorldSnapshot> PhysicsSource::Snapshot(SnapshotContent content) {
  // the first snapshot (the run's start, before any step of this source): the controllers due
  // now run first, so that it holds the ctrl the first step applies and its sensors see it (a
  // standing robot with no ctrl yet would fall freely: an IMU read 0 instead of gravity)
  if (!advanced_) sim_->RunDueControllers();
  return TakeSnapshot(*sim_, content);
}

bool PhysicsSource::Advance() {
  advanced_ = true;
  if (!wall0_) wall0_ = Clock::now();
  if (options_.realtime) {
    std::this_thread::sleep_until(*wall0_ + std::chrono::duration_cast<Clock::duration>(
                                                std::chrono::duration<double>(sim_->time())));
  }
  if (options_.before_step && !options_.before_step(*sim_)) return false;
  const auto t0 = Clock::now();
  sim_->Step();
  busy_sec_ += std::chrono::duration<double>(Clock::now() - t0).count();
  step_ = sim_->step_count();
  time_sec_ = sim_->time();
  for (const std::string& w : sim_->TakeWarnings()) spdlog::warn("physics: {}", w);
  return true;
}

}  // namespace penumbra

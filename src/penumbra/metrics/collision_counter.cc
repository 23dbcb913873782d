#include "penumbra/metrics/collision_counter.h"

#include <algorithm>

namespace penumbra {

CollisionCounter::CollisionCounter(double min_force_N, double debounce_sec)
    : min_force_N_(min_force_N), debounce_sec_(debounce_sec) {}

void CollisionCounter::Update(double t, const std::map<ContactPairKey, double>& pair_force_N) {
  // active pairs start or extend their episode
  for (const auto& [pair, force] : pair_force_N) {
    peak_ = std::max(peak_, force);
    if (!(force >= min_force_N_)) continue;
    auto it = open_.find(pair);
    // back after a gap of at least the debounce time (between two detection instants)
    if (it != open_.end() && !it->second.active &&
        t - it->second.episode.end_sec >= debounce_sec_) {
      closed_.push_back(it->second.episode);
      open_.erase(it);
      it = open_.end();
    }
    if (it == open_.end()) {
      open_.emplace(pair, Open{CollisionEpisode{pair, t, t, force}, true});
      ++count_;
      ++by_pair_[pair];
    } else {
      it->second.episode.end_sec = t;
      it->second.episode.peak_force_N = std::max(it->second.episode.peak_force_N, force);
    }
  }
  // inactive pairs close once the debounce time has passed since their last active instant
  for (auto it = open_.begin(); it != open_.end();) {
    const auto f = pair_force_N.find(it->first);
    it->second.active = f != pair_force_N.end() && f->second >= min_force_N_;
    if (!it->second.active && t - it->second.episode.end_sec >= debounce_sec_) {
      closed_.push_back(it->second.episode);
      it = open_.erase(it);
    } else {
      ++it;
    }
  }
}

void CollisionCounter::Finish() {
  for (const auto& [pair, open] : open_) closed_.push_back(open.episode);
  open_.clear();
}

std::vector<CollisionEpisode> CollisionCounter::TakeClosed() {
  std::vector<CollisionEpisode> out = std::move(closed_);
  closed_.clear();
  return out;
}

}  // namespace penumbra

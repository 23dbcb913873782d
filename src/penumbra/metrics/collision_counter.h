#pragma once
// collision episodes from a sequence of per-pair contact forces (the `contacts` metric of
// world/metrics_config.h). a pair is *active* at an instant when the sum of the normal forces
// of its contacts is >= min_force_N. an episode starts when an inactive pair becomes active; it
// stays open while the pair is active and closes once the pair has been inactive for
// debounce_sec: a pair that becomes active again less than debounce_sec after its last active
// instant continues the same episode (contact chatter, a bounce), so episodes closer than the
// debounce time merge; a gap of debounce_sec or more starts a new one. debounce_sec = 0: every
// run of consecutive active instants is an episode.

#include <cstdint>
#include <map>
#include <utility>
#include <vector>

namespace penumbra {

/// a pair of contact sides (ids and their order chosen by the caller, e.g. body indices).
using ContactPairKey = std::pair<int, int>;

/// one collision episode of a pair.
struct CollisionEpisode {
  ContactPairKey pair;
  double start_sec = 0;     ///< first active instant, s
  double end_sec = 0;       ///< last active instant, s
  double peak_force_N = 0;  ///< largest pair normal force during the episode, N
};

/// counts collision episodes per pair (see the file comment). not thread-safe.
class CollisionCounter {
 public:
  /// `min_force_N` >= 0, `debounce_sec` >= 0 (not checked: world/metrics_config.h validates).
  CollisionCounter(double min_force_N, double debounce_sec);

  /// one detection instant at `time_sec` (not earlier than the previous call's): the normal
  /// force (N) of every pair in contact; pairs not listed have none. starts, extends and closes
  /// episodes as described above; closed episodes are kept for TakeClosed.
  void Update(double time_sec, const std::map<ContactPairKey, double>& pair_force_N);
  /// closes every open episode (the end of a run).
  void Finish();

  /// episodes started so far (open ones included).
  int64_t count() const { return count_; }
  /// episodes started so far per pair.
  const std::map<ContactPairKey, int64_t>& count_by_pair() const { return by_pair_; }
  /// pairs with an open episode.
  int open_episodes() const { return static_cast<int>(open_.size()); }
  /// largest pair force seen at any instant, N (0 if none).
  double peak_force_N() const { return peak_; }
  /// the episodes closed since the last call, in closing order (pairs by key at one instant).
  std::vector<CollisionEpisode> TakeClosed();

 private:
  double min_force_N_, debounce_sec_;
  int64_t count_ = 0;
  double peak_ = 0;
  std::map<ContactPairKey, int64_t> by_pair_;
  struct Open {
    CollisionEpisode episode;
    bool active = false;  ///< active at the last instant
  };
  std::map<ContactPairKey, Open> open_;
  std::vector<CollisionEpisode> closed_;
};

}  // namespace penumbra

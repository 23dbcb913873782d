#include "penumbra/metrics/collision_counter.h"

#include <gtest/gtest.h>

#include <map>
#include <vector>

namespace penumbra {
namespace {

const ContactPairKey kWall{1, -3};
const ContactPairKey kBox{1, 5};

// feeds one force per instant for one pair (0 = no contact), dt apart
void Feed(CollisionCounter* c, const ContactPairKey& pair, const std::vector<double>& forces,
          double dt, double t0 = 0) {
  for (size_t i = 0; i < forces.size(); ++i) {
    std::map<ContactPairKey, double> f;
    if (forces[i] > 0) f[pair] = forces[i];
    c->Update(t0 + dt * static_cast<double>(i), f);
  }
}

TEST(CollisionCounterTest, ChatterWithinTheDebounceTimeIsOneEpisode) {
  // contact at 0.1 s, bounces off for 0.03 s twice, then stays; debounce 0.05 s
  CollisionCounter c(/*min_force_N=*/1.0, /*debounce_sec=*/0.05);
  Feed(&c, kWall, {0, 5, 8, 0, 0, 0, 6, 7, 0, 0, 0, 9, 9, 9}, 0.01, 0.09);
  EXPECT_EQ(c.count(), 1);
  EXPECT_EQ(c.open_episodes(), 1);
  c.Finish();
  const std::vector<CollisionEpisode> e = c.TakeClosed();
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NEAR(e[0].start_sec, 0.10, 1e-12);
  EXPECT_NEAR(e[0].end_sec, 0.22, 1e-12);
  EXPECT_DOUBLE_EQ(e[0].peak_force_N, 9);
  EXPECT_EQ(c.count_by_pair().at(kWall), 1);
}

TEST(CollisionCounterTest, WithoutDebounceEveryRunOfContactCounts) {
  CollisionCounter c(1.0, 0.0);
  Feed(&c, kWall, {0, 5, 8, 0, 0, 0, 6, 7, 0, 0, 0, 9, 9, 9}, 0.01);
  EXPECT_EQ(c.count(), 3);
  const std::vector<CollisionEpisode> closed = c.TakeClosed();
  ASSERT_EQ(closed.size(), 2u) << "the third is still open";
  EXPECT_NEAR(closed[0].start_sec, 0.01, 1e-12);
  EXPECT_NEAR(closed[0].end_sec, 0.02, 1e-12);
  EXPECT_NEAR(closed[1].start_sec, 0.06, 1e-12);
}

TEST(CollisionCounterTest, GapsAsLongAsTheDebounceTimeSplitEpisodes) {
  // back 0.06 s after the last active instant (0.02 -> 0.08), debounce 0.05: a new episode
  CollisionCounter c(1.0, 0.05);
  Feed(&c, kWall, {0, 5, 5, 0, 0, 0, 0, 0, 5, 5}, 0.01);
  EXPECT_EQ(c.count(), 2);
  // also when the gap was seen only early (a coarse detection rate)
  CollisionCounter sparse(1.0, 0.05);
  sparse.Update(0.0, {{kWall, 5}});
  sparse.Update(0.02, {});
  sparse.Update(0.08, {{kWall, 5}});
  EXPECT_EQ(sparse.count(), 2);
  // 0.04 s (0.02 -> 0.06): the same one
  CollisionCounter d(1.0, 0.05);
  Feed(&d, kWall, {0, 5, 5, 0, 0, 0, 5, 5}, 0.01);
  EXPECT_EQ(d.count(), 1);
}

TEST(CollisionCounterTest, ForcesBelowTheMinimumAreNoCollision) {
  CollisionCounter c(10.0, 0.0);
  Feed(&c, kWall, {0, 2, 9.9, 3, 0, 12, 0}, 0.01);
  EXPECT_EQ(c.count(), 1);
  EXPECT_DOUBLE_EQ(c.peak_force_N(), 12);
  // a resting contact below the minimum that rises above it starts one episode
  CollisionCounter d(10.0, 0.0);
  Feed(&d, kWall, {3, 3, 3, 11, 11, 3, 3}, 0.01);
  EXPECT_EQ(d.count(), 1);
}

TEST(CollisionCounterTest, PairsAreCountedSeparately) {
  CollisionCounter c(1.0, 0.1);
  c.Update(0.0, {{kWall, 5}});
  c.Update(0.1, {{kWall, 5}, {kBox, 2}});
  c.Update(0.2, {{kBox, 2}});
  c.Update(0.4, {});
  c.Update(0.5, {{kWall, 3}});
  EXPECT_EQ(c.count(), 3);
  EXPECT_EQ(c.count_by_pair().at(kWall), 2);
  EXPECT_EQ(c.count_by_pair().at(kBox), 1);
}

}  // namespace
}  // namespace penumbra

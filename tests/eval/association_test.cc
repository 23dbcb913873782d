// timestamp association (TUM associate.py): greedy by smallest |dt| below max_dt, each pose
// used once; with jitter, gaps and an offset.
#include "penumbra/eval/association.h"

#include <gtest/gtest.h>

#include "penumbra/core/error.h"

namespace penumbra {
namespace {

using Pairs = std::vector<std::pair<size_t, size_t>>;

Association Associate(const std::vector<double>& gt, const std::vector<double>& est,
                      double max_dt = 0.02, double offset = 0) {
  AssociationOptions o;
  o.max_dt_sec = max_dt;
  o.offset_sec = offset;
  return AssociateTimestamps(gt, est, o);
}

TEST(Association, JitterWithinMaxDtPairsEveryPose) {
  // ground truth at 10 Hz; the estimate 0..15 ms late or early, alternating
  std::vector<double> gt, est;
  for (int k = 0; k < 10; ++k) {
    gt.push_back(0.1 * k);
    est.push_back(0.1 * k + (k % 2 == 0 ? 0.015 : -0.012));
  }
  const Association a = Associate(gt, est);
  Pairs expected;
  for (size_t k = 0; k < 10; ++k) expected.emplace_back(k, k);
  EXPECT_EQ(a.pairs, expected);
  EXPECT_EQ(a.unmatched_ground_truth, 0u);
  EXPECT_EQ(a.unmatched_estimate, 0u);
}

TEST(Association, GapsLeaveUnmatchedPoses) {
  // ground truth 0.0 .. 1.9 s at 10 Hz; the estimate lost tracking at 0.5 .. 0.9 s and stopped
  // after 1.5 s, and has two poses of its own far from any ground truth (2.5, 3.0 s)
  std::vector<double> gt, est;
  for (int k = 0; k < 20; ++k) gt.push_back(0.1 * k);
  for (int k : {0, 1, 2, 3, 4, 10, 11, 12, 13, 14, 15}) est.push_back(0.1 * k + 0.004);
  est.push_back(2.5);
  est.push_back(3.0);
  const Association a = Associate(gt, est);
  const Pairs expected = {{0, 0},  {1, 1},  {2, 2},  {3, 3},  {4, 4},  {10, 5},
                          {11, 6}, {12, 7}, {13, 8}, {14, 9}, {15, 10}};
  EXPECT_EQ(a.pairs, expected);
  EXPECT_EQ(a.unmatched_ground_truth, 9u);  // 5..9 and 16..19
  EXPECT_EQ(a.unmatched_estimate, 2u);      // 2.5 and 3.0 s
}

TEST(Association, GreedyBySmallestDifferenceEachPoseUsedOnce) {
  // gt a1 = 1.00, a2 = 1.04; estimate b1 = 1.03, b2 = 1.07; max_dt 0.05.
  // candidates: (a2, b1) 0.01, (a1, b1) 0.03, (a2, b2) 0.03; (a1, b2) 0.07 is out.
  // associate.py takes (a2, b1) first; then b1 and a2 are used, so a1 and b2 stay unmatched
  // (nearest-neighbour per ground-truth pose in time order would give (a1, b1), (a2, b2))
  const Association a = Associate({1.00, 1.04}, {1.03, 1.07}, 0.05);
  EXPECT_EQ(a.pairs, (Pairs{{1, 0}}));
  EXPECT_EQ(a.unmatched_ground_truth, 1u);
  EXPECT_EQ(a.unmatched_estimate, 1u);
  // two ground-truth poses compete for one estimate: the nearer one wins
  EXPECT_EQ(Associate({1.00, 1.03}, {1.02}, 0.05).pairs, (Pairs{{1, 0}}));
  // a tie (|dt| 0.25 both, exactly representable) goes to the earlier estimate
  EXPECT_EQ(Associate({1.0}, {0.75, 1.25}, 0.5).pairs, (Pairs{{0, 0}}));
}

TEST(Association, MaxDtIsExclusiveAndOffsetShiftsTheEstimate) {
  EXPECT_TRUE(Associate({1.0}, {1.5}, 0.5).pairs.empty());  // |dt| = 0.5 is not < 0.5
  EXPECT_EQ(Associate({1.0}, {1.5}, 0.5000001).pairs, (Pairs{{0, 0}}));
  // an estimate stamped 100 s later (another clock): nothing without the offset
  const std::vector<double> gt = {0.0, 0.5, 1.0}, est = {100.0, 100.5, 101.0};
  EXPECT_TRUE(Associate(gt, est).pairs.empty());
  EXPECT_EQ(Associate(gt, est, 0.02, -100.0).pairs, (Pairs{{0, 0}, {1, 1}, {2, 2}}));
}

TEST(Association, EstimateFasterThanGroundTruthUsesTheNearestEstimates) {
  // ground truth at 10 Hz (0, 0.1, ...), the estimate at 30 Hz offset by 5 ms: each
  // ground-truth pose gets the estimate 5 ms from it; the others stay unmatched
  std::vector<double> gt, est;
  for (int k = 0; k < 10; ++k) gt.push_back(0.1 * k);
  for (int k = 0; k < 30; ++k) est.push_back(k / 30.0 + 0.005);
  const Association a = Associate(gt, est);
  ASSERT_EQ(a.pairs.size(), 10u);
  for (size_t k = 0; k < 10; ++k) EXPECT_EQ(a.pairs[k], std::make_pair(k, 3 * k));
  EXPECT_EQ(a.unmatched_estimate, 20u);
}

TEST(Association, RejectsABadWindow) {
  for (double bad : {0.0, -1.0, std::numeric_limits<double>::quiet_NaN(),
                     std::numeric_limits<double>::infinity()}) {
    AssociationOptions o;
    o.max_dt_sec = bad;
    try {
      AssociateTimestamps({0}, {0}, o);
      FAIL() << bad;
    } catch (const ConfigError& e) {
      EXPECT_EQ(e.key(), "max_dt_sec");
    }
  }
  AssociationOptions o;
  o.offset_sec = std::numeric_limits<double>::infinity();
  EXPECT_THROW(o.ValidateOrThrow(), ConfigError);
}

}  // namespace
}  // namespace penumbra

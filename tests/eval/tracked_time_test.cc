// time tracked against the ground truth's sampling: constructed estimates over a 10 Hz ground
// truth of 41 frames (0 .. 4 s) that keep all, some or few of the frames.
#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/eval/trajectory_evaluation.h"
#include "penumbra/eval/trajectory_metrics.h"

namespace penumbra {
namespace {

Pose At(double x) {
  Pose X = Pose::Identity();
  X.translation() = Eigen::Vector3d(x, 0.1 * std::sin(x), 0);
  return X;
}

// frames 0 .. 40 at 10 Hz along x (0.25 m per frame); the estimate keeps the frames in `kept`
// with their exact poses
struct Case {
  Trajectory gt, est;
};
Case Frames(const std::vector<int>& kept, int frames = 41, double period = 0.1) {
  Case c;
  for (int k = 0; k < frames; ++k) {
    c.gt.time_sec.push_back(k * period);
    c.gt.X_WB.push_back(At(0.25 * k));
  }
  for (int k : kept) {
    c.est.time_sec.push_back(k * period);
    c.est.X_WB.push_back(At(0.25 * k));
  }
  return c;
}

TrajectoryEvaluation Eval(const Case& c, EvaluationOptions o = {}) {
  o.alignment = AlignmentModel::kNone;
  return EvaluateTrajectory(c.gt, c.est, o, "gt", "est");
}

std::vector<int> Range(int first, int last, int step = 1) {
  std::vector<int> v;
  for (int k = first; k <= last; k += step) v.push_back(k);
  return v;
}

TEST(TrackedTime, ADenseEstimateTracksEverything) {
  const TrajectoryEvaluation r = Eval(Frames(Range(0, 40)));
  EXPECT_NEAR(r.frame_period_sec, 0.1, 1e-12);
  EXPECT_NEAR(r.tracked.max_gap_sec, 0.3, 1e-12);
  EXPECT_NEAR(r.tracked.fraction, 1.0, 1e-12);
  EXPECT_EQ(r.expected_poses, 41u);
  EXPECT_DOUBLE_EQ(r.pose_fraction, 1.0);
}

TEST(TrackedTime, ThreePosesOf41FramesTrackAlmostNothing) {
  // frames 0, 20 and 40: the estimate's own median spacing is 2 s, and a limit of 3 x that
  // (the old default) counted all 4 s as tracked. against the ground truth's 0.1 s period the
  // 2 s intervals are losses: 0 s tracked; the ATE rests on 3 of 41 poses
  const TrajectoryEvaluation r = Eval(Frames({0, 20, 40}));
  EXPECT_NEAR(r.tracked.max_gap_sec, 0.3, 1e-12);
  EXPECT_DOUBLE_EQ(r.tracked.tracked_sec, 0.0);
  EXPECT_DOUBLE_EQ(r.tracked.fraction, 0.0);
  EXPECT_EQ(r.association.pairs.size(), 3u);
  EXPECT_NEAR(r.pose_fraction, 3.0 / 41.0, 1e-12);
  EXPECT_DOUBLE_EQ(r.tracked_path_coverage, 0.0);
  // three consecutive frames: 0.2 s of 4 s
  const TrajectoryEvaluation first = Eval(Frames({0, 1, 2}));
  EXPECT_NEAR(first.tracked.fraction, 0.05, 1e-12);
  EXPECT_NEAR(first.pose_fraction, 3.0 / 41.0, 1e-12);
}

TEST(TrackedTime, TwoPosesAndOnePose) {
  // two poses at the ends: one 4 s interval, a loss (the old default limit was 12 s)
  const TrajectoryEvaluation two = Eval(Frames({0, 40}));
  EXPECT_DOUBLE_EQ(two.tracked.fraction, 0.0);
  EXPECT_NEAR(two.pose_fraction, 2.0 / 41.0, 1e-12);
  // one pose: no interval to track, and too few poses to evaluate
  EXPECT_DOUBLE_EQ(ComputeTrackedTime({2.0}, 0, 4, 0.3).tracked_sec, 0.0);
  EXPECT_THROW(Eval(Frames({20})), ConfigError);
}

TEST(TrackedTime, GapsInTheMiddleAreLossesWhateverTheEstimateSpacing) {
  // dense 0 .. 5, then every 5th frame: intervals 5 x 0.1 s and 7 x 0.5 s; the estimate's
  // median spacing is 0.5 s (the old limit 1.5 s counted everything). now 0.5 s of 4 s
  std::vector<int> kept = Range(0, 5);
  for (int k : Range(10, 40, 5)) kept.push_back(k);
  const TrajectoryEvaluation r = Eval(Frames(kept));
  EXPECT_NEAR(r.tracked.tracked_sec, 0.5, 1e-12);
  EXPECT_NEAR(r.tracked.fraction, 0.125, 1e-12);
  EXPECT_NEAR(r.pose_fraction, 13.0 / 41.0, 1e-12);
  // every 4th frame (3 lost between poses): nothing tracked, 11 of 41 poses
  const TrajectoryEvaluation quarter = Eval(Frames(Range(0, 40, 4)));
  EXPECT_DOUBLE_EQ(quarter.tracked.fraction, 0.0);
  EXPECT_NEAR(quarter.pose_fraction, 11.0 / 41.0, 1e-12);
  // every 3rd frame (two lost): the limit's 3 periods still count it
  EXPECT_NEAR(Eval(Frames(Range(0, 39, 3))).tracked.fraction, 3.9 / 4.0, 1e-9);
  // one jump: dense, but frames 11 .. 29 lost: 1.0 + 1.0 s tracked
  std::vector<int> jump = Range(0, 10);
  for (int k : Range(30, 40)) jump.push_back(k);
  EXPECT_NEAR(Eval(Frames(jump)).tracked.fraction, 0.5, 1e-12);
}

TEST(TrackedTime, AFasterGroundTruthNeedsTheCamerasFramePeriod) {
  // ground truth at 100 Hz (0 .. 4 s), the estimate at 25 Hz from a camera that ran 4 s: by
  // default the limit is 3 x 0.01 s and the 0.04 s camera period reads as lost frames; with
  // the camera's frame period given the limit is 0.12 s and everything is tracked
  Case c = Frames(Range(0, 400, 4), 401, 0.01);
  EXPECT_DOUBLE_EQ(Eval(c).tracked.fraction, 0.0);
  EvaluationOptions o;
  o.frame_period_sec = 0.04;
  const TrajectoryEvaluation r = Eval(c, o);
  EXPECT_NEAR(r.tracked.max_gap_sec, 0.12, 1e-12);
  EXPECT_NEAR(r.tracked.fraction, 1.0, 1e-12);
  EXPECT_EQ(r.expected_poses, 101u);
  EXPECT_DOUBLE_EQ(r.pose_fraction, 1.0);
  // --max-gap still overrides the limit
  o.max_gap_sec = 0.01;
  EXPECT_DOUBLE_EQ(Eval(c, o).tracked.fraction, 0.0);
  for (double bad : {0.0, -0.1, std::nan(""), HUGE_VAL}) {
    EvaluationOptions b;
    b.frame_period_sec = bad;
    try {
      Eval(c, b);
      ADD_FAILURE() << "frame_period_sec " << bad << " accepted";
    } catch (const ConfigError& e) {
      EXPECT_NE(std::string(e.what()).find("frame_period_sec"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace penumbra

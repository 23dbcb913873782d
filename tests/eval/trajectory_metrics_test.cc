// ATE, RPE, coverage, scaled ATE and time tracked on small trajectories whose expected
// values are worked out by hand in the comments.
#include "penumbra/eval/trajectory_metrics.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "penumbra/core/error.h"
#include "penumbra/eval/trajectory_evaluation.h"

namespace penumbra {
namespace {

Pose At(double x, double y, double z, double yaw_deg = 0) {
  Pose X = Pose::Identity();
  X.linear() = Eigen::AngleAxisd(yaw_deg * std::numbers::pi / 180, Eigen::Vector3d::UnitZ())
                   .toRotationMatrix();
  X.translation() = Eigen::Vector3d(x, y, z);
  return X;
}

Trajectory Make(const std::vector<double>& t, const std::vector<Pose>& X) {
  Trajectory tr;
  tr.time_sec = t;
  tr.X_WB = X;
  return tr;
}

TEST(ErrorStats, HandComputed) {
  // e = {0, 0.5, 0, 1}: mean 1.5 / 4 = 0.375; rmse sqrt((0.25 + 1) / 4) = sqrt(0.3125)
  // = 0.5590169943749475; sorted {0, 0, 0.5, 1}: median (0 + 0.5) / 2 = 0.25;
  // std sqrt(0.3125 - 0.375^2) = sqrt(0.171875) = 0.414578098794425
  const ErrorStats s = SummarizeErrors({0, 0.5, 0, 1});
  EXPECT_EQ(s.count, 4u);
  EXPECT_DOUBLE_EQ(s.mean, 0.375);
  EXPECT_DOUBLE_EQ(s.rmse, 0.5590169943749475);
  EXPECT_DOUBLE_EQ(s.median, 0.25);
  EXPECT_DOUBLE_EQ(s.std, 0.414578098794425);
  EXPECT_EQ(s.min, 0.0);
  EXPECT_EQ(s.max, 1.0);
  EXPECT_EQ(SummarizeErrors({3, 1, 2}).median, 2.0);  // odd count: the middle value
  const ErrorStats none = SummarizeErrors({});
  EXPECT_EQ(none.count, 0u);
  EXPECT_TRUE(std::isnan(none.rmse) && std::isnan(none.median) && std::isnan(none.max));
}

TEST(Ate, CoverageAndScaledAteHandComputedWithoutAlignment) {
  // ground truth along x: (0,0,0) (1,0,0) (2,0,0) (3,0,0); path 3 m.
  // estimate (same times): (0,0,0) (1.3,0.4,0) (2,0,0) (3,0.6,0.8)
  // errors: 0, |(0.3,0.4,0)| = 0.5, 0, |(0,0.6,0.8)| = 1  -> the ErrorStats of HandComputed.
  // estimate path: |(1.3,0.4,0)| = sqrt(1.85) = 1.3601470508735443
  //              + |(0.7,-0.4,0)| = sqrt(0.65) = 0.806225774829855
  //              + |(1,0.6,0.8)| = sqrt(2) = 1.4142135623730951   = 3.5805863880764948 m
  // coverage = 3 / 3.5805863880764948 = 0.837851590451812
  // scaled ATE = 0.5590169943749475 / 0.837851590451812 = 0.6672028802541238 m
  const std::vector<double> t = {0, 1, 2, 3};
  const Trajectory gt = Make(t, {At(0, 0, 0), At(1, 0, 0), At(2, 0, 0), At(3, 0, 0)});
  const Trajectory est = Make(t, {At(0, 0, 0), At(1.3, 0.4, 0), At(2, 0, 0), At(3, 0.6, 0.8)});
  EvaluationOptions o;
  o.alignment = AlignmentModel::kNone;
  const TrajectoryEvaluation r = EvaluateTrajectory(gt, est, o, "gt", "est");
  EXPECT_EQ(r.association.pairs.size(), 4u);
  ASSERT_EQ(r.ate_errors_m.size(), 4u);
  EXPECT_DOUBLE_EQ(r.ate_errors_m[1], 0.5);
  EXPECT_DOUBLE_EQ(r.ate_errors_m[3], 1.0);
  EXPECT_DOUBLE_EQ(r.ate_m.rmse, 0.5590169943749475);
  EXPECT_DOUBLE_EQ(r.ate_m.mean, 0.375);
  EXPECT_DOUBLE_EQ(r.ate_m.median, 0.25);
  EXPECT_DOUBLE_EQ(r.ate_m.std, 0.414578098794425);
  EXPECT_DOUBLE_EQ(r.ate_m.max, 1.0);
  EXPECT_DOUBLE_EQ(r.ground_truth_path_m, 3.0);
  EXPECT_DOUBLE_EQ(r.estimate_path_m, 3.5805863880764948);
  EXPECT_DOUBLE_EQ(r.coverage, 0.837851590451812);
  EXPECT_DOUBLE_EQ(r.scaled_ate_m, 0.6672028802541238);
  EXPECT_EQ(r.alignment.scale, 1.0);
  EXPECT_TRUE(r.alignment.R_AB.isIdentity(0));
}

TEST(Ate, Sim3RecoversAMonocularEstimateAndCoverageFollowsTheAlignment) {
  // the estimate is the ground truth seen from another frame at half scale:
  // p_est = 0.5 R^T (p_gt - t). sim3 alignment undoes it: ATE 0, paths equal, coverage 1.
  // se3 alignment cannot: the aligned estimate path is half the ground truth's, coverage 2
  const Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.7, Eigen::Vector3d(1, -2, 0.5).normalized()).toRotationMatrix();
  const Eigen::Vector3d tr(3, -1, 2);
  std::vector<double> t;
  std::vector<Pose> gt_poses, est_poses;
  for (int k = 0; k < 50; ++k) {
    const double a = 0.2 * k;
    const Pose X = At(2 * std::cos(a), std::sin(2 * a), 0.1 * std::sin(a), 10 * k);
    t.push_back(0.1 * k);
    gt_poses.push_back(X);
    Pose Y = Pose::Identity();
    Y.linear() = R.transpose() * X.linear();
    Y.translation() = 0.5 * R.transpose() * (X.translation() - tr);
    est_poses.push_back(Y);
  }
  const Trajectory gt = Make(t, gt_poses), est = Make(t, est_poses);
  EvaluationOptions o;
  o.alignment = AlignmentModel::kSim3;
  const TrajectoryEvaluation sim3 = EvaluateTrajectory(gt, est, o, "gt", "est");
  EXPECT_NEAR(sim3.alignment.scale, 2.0, 1e-9);
  EXPECT_LT((sim3.alignment.R_AB - R).cwiseAbs().maxCoeff(), 1e-9);
  EXPECT_LT(sim3.ate_m.max, 1e-9);
  EXPECT_NEAR(sim3.coverage, 1.0, 1e-9);
  EXPECT_LT(sim3.scaled_ate_m, 1e-9);
  // RPE of the sim3-aligned estimate: scale applied to relative translations, so 0
  EXPECT_LT(sim3.rpe_translation_m.max, 1e-9);
  EXPECT_LT(sim3.rpe_rotation_deg.max, 1e-5);

  o.alignment = AlignmentModel::kSe3;
  const TrajectoryEvaluation se3 = EvaluateTrajectory(gt, est, o, "gt", "est");
  EXPECT_EQ(se3.alignment.scale, 1.0);
  EXPECT_NEAR(se3.coverage, 2.0, 1e-12);
  EXPECT_GT(se3.ate_m.rmse, 0.3);
  EXPECT_NEAR(se3.scaled_ate_m, se3.ate_m.rmse / 2.0, 1e-12);
}

// ground truth Q moves 1 m along x per step without turning; the estimate P turns 90 deg
// about z in the first step and moves 2 m along its own x (world y) in the second:
//   Q0 = (I, 0)  Q1 = (I, (1,0,0))  Q2 = (I, (2,0,0))
//   P0 = (I, 0)  P1 = (Rz90, (1,0,0))  P2 = (Rz90, (1,2,0))
// E_ij = (Q_i^-1 Q_j)^-1 (P_i^-1 P_j):
//   E_01 = (I, (-1,0,0)) (Rz90, (1,0,0)) = (Rz90, 0)          -> 0 m, 90 deg
//   E_12 = (I, (-1,0,0)) (I, Rz90^T (0,2,0) = (2,0,0)) = (I, (1,0,0))  -> 1 m, 0 deg
//   E_02 = (I, (-2,0,0)) (Rz90, (1,2,0)) = (Rz90, (-1,2,0))    -> sqrt(5) m, 90 deg
struct RpeCase {
  std::vector<double> t = {0, 1, 2};
  std::vector<Pose> Q = {At(0, 0, 0), At(1, 0, 0), At(2, 0, 0)};
  std::vector<Pose> P = {At(0, 0, 0), At(1, 0, 0, 90), At(1, 2, 0, 90)};
};

TEST(Rpe, HandComputedPerFrame) {
  const RpeCase c;
  const std::vector<RelativePoseError> e = RelativePoseErrors(c.t, c.Q, c.P, RpeDelta{}, 0.02);
  ASSERT_EQ(e.size(), 2u);
  EXPECT_EQ(e[0].i, 0u);
  EXPECT_EQ(e[0].j, 1u);
  EXPECT_NEAR(e[0].translation_m, 0.0, 1e-15);
  EXPECT_NEAR(e[0].rotation_deg, 90.0, 1e-12);
  EXPECT_NEAR(e[1].translation_m, 1.0, 1e-15);
  EXPECT_NEAR(e[1].rotation_deg, 0.0, 1e-12);
  // statistics: translation {0, 1}: rmse sqrt(1/2) = 0.7071067811865476, mean = median = 0.5;
  // rotation {90, 0}: rmse sqrt(8100 / 2) = 63.63961030678928, mean = median = 45, max 90
  RpeCase d;
  Trajectory gt = Make(d.t, d.Q), est = Make(d.t, d.P);
  EvaluationOptions o;
  o.alignment = AlignmentModel::kNone;
  const TrajectoryEvaluation r = EvaluateTrajectory(gt, est, o, "gt", "est");
  EXPECT_NEAR(r.rpe_translation_m.rmse, 0.7071067811865476, 1e-15);
  EXPECT_NEAR(r.rpe_translation_m.mean, 0.5, 1e-15);
  EXPECT_NEAR(r.rpe_translation_m.median, 0.5, 1e-15);
  EXPECT_NEAR(r.rpe_translation_m.max, 1.0, 1e-15);
  EXPECT_NEAR(r.rpe_rotation_deg.rmse, 63.63961030678928, 1e-11);
  EXPECT_NEAR(r.rpe_rotation_deg.mean, 45.0, 1e-12);
  EXPECT_NEAR(r.rpe_rotation_deg.median, 45.0, 1e-12);
  EXPECT_NEAR(r.rpe_rotation_deg.max, 90.0, 1e-12);
  // a rigid (se3) alignment cancels in P_i^-1 P_j: the same RPE
  o.alignment = AlignmentModel::kSe3;
  const TrajectoryEvaluation se3 = EvaluateTrajectory(gt, est, o, "gt", "est");
  EXPECT_NEAR(se3.rpe_translation_m.rmse, r.rpe_translation_m.rmse, 1e-12);
  EXPECT_NEAR(se3.rpe_rotation_deg.rmse, r.rpe_rotation_deg.rmse, 1e-9);
}

TEST(Rpe, HandComputedDeltaInFramesAndSeconds) {
  const RpeCase c;
  RpeDelta two;
  two.frames = 2;
  const std::vector<RelativePoseError> e = RelativePoseErrors(c.t, c.Q, c.P, two, 0.02);
  ASSERT_EQ(e.size(), 1u);
  EXPECT_NEAR(e[0].translation_m, std::sqrt(5.0), 1e-15);
  EXPECT_NEAR(e[0].rotation_deg, 90.0, 1e-12);
  RpeDelta sec;
  sec.seconds = 2.0;
  const std::vector<RelativePoseError> s = RelativePoseErrors(c.t, c.Q, c.P, sec, 0.02);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_EQ(s[0].j, 2u);
  EXPECT_NEAR(s[0].translation_m, std::sqrt(5.0), 1e-15);
  // times 0, 1, 3 (a gap) with delta 1 s: 0 -> 1 is a pair; from 1 s the nearest pose to 2 s
  // is 1 s away (1 s and 3 s tie, the earlier is itself): no pair; from 3 s nothing follows.
  // with delta 1 frame the gap is bridged: (0,1) and (1,2)
  sec.seconds = 1.0;
  const std::vector<double> gap_t = {0, 1, 3};
  const std::vector<RelativePoseError> g = RelativePoseErrors(gap_t, c.Q, c.P, sec, 0.02);
  ASSERT_EQ(g.size(), 1u);
  EXPECT_EQ(g[0].i, 0u);
  EXPECT_EQ(g[0].j, 1u);
  EXPECT_EQ(RelativePoseErrors(gap_t, c.Q, c.P, RpeDelta{}, 0.02).size(), 2u);
  // a delta longer than the trajectory: no pairs
  two.frames = 3;
  EXPECT_TRUE(RelativePoseErrors(c.t, c.Q, c.P, two, 0.02).empty());
  RpeDelta bad;
  bad.frames = 0;
  EXPECT_THROW(RelativePoseErrors(c.t, c.Q, c.P, bad, 0.02), ConfigError);
}

TEST(TrackedTime, GapsLongerThanTheLimitAreNotTracked) {
  // ground truth 0 .. 10 s at 1 Hz; the estimate at 0,1,2,3 and 7,8,9,10 s (lost 3 .. 7 s).
  // median periods: ground truth 1 s, estimate {1,1,1,4,1,1,1} -> 1 s; default gap limit
  // 3 x 1 = 3 s; associated intervals 1,1,1,4,1,1,1: the 4 s one is a loss.
  // tracked 6 s of 10 s -> 0.6. with --max-gap 5 every interval counts: 10 s -> 1.0
  std::vector<double> gt_t, est_t;
  std::vector<Pose> gt_X, est_X;
  for (int k = 0; k <= 10; ++k) {
    gt_t.push_back(k);
    gt_X.push_back(At(k, 0, 0));
    if (k <= 3 || k >= 7) {
      est_t.push_back(k + 0.001);
      est_X.push_back(At(k, 0.01, 0));
    }
  }
  const Trajectory gt = Make(gt_t, gt_X), est = Make(est_t, est_X);
  EvaluationOptions o;
  const TrajectoryEvaluation r = EvaluateTrajectory(gt, est, o, "gt", "est");
  EXPECT_EQ(r.association.pairs.size(), 8u);
  EXPECT_EQ(r.association.unmatched_ground_truth, 3u);
  EXPECT_DOUBLE_EQ(r.tracked.max_gap_sec, 3.0);
  EXPECT_DOUBLE_EQ(r.tracked.total_sec, 10.0);
  EXPECT_DOUBLE_EQ(r.tracked.tracked_sec, 6.0);
  EXPECT_DOUBLE_EQ(r.tracked.fraction, 0.6);
  o.max_gap_sec = 5.0;
  EXPECT_DOUBLE_EQ(EvaluateTrajectory(gt, est, o, "gt", "est").tracked.fraction, 1.0);
  // the same function on its own: intervals 0.5 (counted), 2 (not), 0.5 over a 4 s span
  const TrackedTime t = ComputeTrackedTime({0, 0.5, 2.5, 3}, -1, 3, 1.0);
  EXPECT_DOUBLE_EQ(t.tracked_sec, 1.0);
  EXPECT_DOUBLE_EQ(t.fraction, 0.25);
  EXPECT_DOUBLE_EQ(MedianPeriod({0, 1, 3, 4, 10}), 1.5);  // {1, 2, 1, 6} -> (1 + 2) / 2
}

TEST(TrackedTime, TwoLostFramesCountDespiteTimestampRounding) {
  // 10 Hz ground truth at 4.3 .. 5.4 s as a TUM file writes it; the estimate lost 4.7 and 4.8
  // (two frames). the gap 4.9 - 4.6 = 0.3000000000000007 s is exactly 3 periods, the default
  // limit 3 x median period = 3 x 0.09999999999999964 = 0.29999999999999893 s: the docs count
  // it, and with the relative tolerance of 1e-9 it counts -> every interval tracked, 1.1 s.
  std::vector<double> gt_t, est_t;
  std::vector<Pose> gt_X, est_X;
  for (int k = 43; k <= 54; ++k) {
    const double t = std::stod(std::to_string(k / 10) + "." + std::to_string(k % 10));
    gt_t.push_back(t);
    gt_X.push_back(At(t, 0, 0));
    if (k == 47 || k == 48) continue;
    est_t.push_back(t);
    est_X.push_back(At(t, 0, 0));
  }
  ASSERT_EQ(gt_t[6] - gt_t[3], 0.3000000000000007);
  const TrajectoryEvaluation r =
      EvaluateTrajectory(Make(gt_t, gt_X), Make(est_t, est_X), EvaluationOptions{}, "gt", "est");
  EXPECT_EQ(r.tracked.max_gap_sec, 0.29999999999999893);
  EXPECT_NEAR(r.tracked.tracked_sec, 1.1, 1e-12);  // 0.8 s (fraction 0.727) before
  EXPECT_NEAR(r.tracked.fraction, 1.0, 1e-12);
  // the two values on their own, and a real third lost frame (0.4 s) still a loss
  EXPECT_DOUBLE_EQ(ComputeTrackedTime({4.6, 4.9}, 4.6, 4.9, 0.29999999999999893).fraction, 1.0);
  EXPECT_TRUE(GapIsTracked(0.3000000000000007, 0.29999999999999893));
  EXPECT_FALSE(GapIsTracked(5.0 - 4.6, 0.29999999999999893));
  EXPECT_FALSE(GapIsTracked(0.3 * (1 + 1e-8), 0.3));
}

TEST(TrackedPath, AnEstimateThatBarelyMovesIsNotRewarded) {
  // ground truth along x from 0 to 10 m at 1 Hz (10 m); the estimate barely moves:
  // x_k = 5 + 0.01 (k - 5), no alignment. errors |0.99 (k - 5)|: ATE RMSE = 0.99 sqrt(10)
  // = 3.1306548835 m. the paper's coverage = 10 / 0.1 = 100 -> scaled ATE 0.0313 m (better
  // than a good estimate's 0.05 below); every interval is tracked, so the tracked path
  // coverage is 1 and its scaled ATE is the ATE itself.
  std::vector<double> t;
  std::vector<Pose> gt_X, still_X, good_X;
  for (int k = 0; k <= 10; ++k) {
    t.push_back(k);
    gt_X.push_back(At(k, 0, 0));
    still_X.push_back(At(5 + 0.01 * (k - 5), 0, 0));
    good_X.push_back(At(k, k % 2 == 0 ? 0.05 : -0.05, 0));
  }
  EvaluationOptions o;
  o.alignment = AlignmentModel::kNone;
  const TrajectoryEvaluation still =
      EvaluateTrajectory(Make(t, gt_X), Make(t, still_X), o, "gt", "est");
  const TrajectoryEvaluation good =
      EvaluateTrajectory(Make(t, gt_X), Make(t, good_X), o, "gt", "est");
  EXPECT_NEAR(still.ate_m.rmse, 0.99 * std::sqrt(10.0), 1e-12);
  EXPECT_NEAR(still.coverage, 100.0, 1e-9);
  EXPECT_NEAR(still.scaled_ate_m, 0.99 * std::sqrt(10.0) / 100.0, 1e-12);
  EXPECT_DOUBLE_EQ(still.ground_truth_full_path_m, 10.0);
  EXPECT_DOUBLE_EQ(still.tracked_ground_truth_path_m, 10.0);
  EXPECT_DOUBLE_EQ(still.tracked_path_coverage, 1.0);
  EXPECT_DOUBLE_EQ(still.tracked_scaled_ate_m, still.ate_m.rmse);
  // the paper's figure ranks the still estimate first, the tracked-path one last
  EXPECT_NEAR(good.ate_m.rmse, 0.05, 1e-12);
  EXPECT_LT(still.scaled_ate_m, good.scaled_ate_m);
  EXPECT_GT(still.tracked_scaled_ate_m, 50 * good.tracked_scaled_ate_m);
}

TEST(TrackedPath, LostStretchesLeaveTheirGroundTruthPathOut) {
  // ground truth 0 .. 10 m along x at 1 Hz; the estimate (exact) lost 3 .. 7 s: tracked
  // intervals 0-1, 1-2, 2-3, 7-8, 8-9, 9-10 cover 6 m of the 10 m path -> 0.6; the estimate
  // is offset 0.3 m in y (ATE 0.3) -> tracked scaled ATE 0.3 / 0.6 = 0.5 m.
  std::vector<double> gt_t, est_t;
  std::vector<Pose> gt_X, est_X;
  for (int k = 0; k <= 10; ++k) {
    gt_t.push_back(k);
    gt_X.push_back(At(k, 0, 0));
    if (k <= 3 || k >= 7) {
      est_t.push_back(k);
      est_X.push_back(At(k, 0.3, 0));
    }
  }
  EvaluationOptions o;
  o.alignment = AlignmentModel::kNone;
  const TrajectoryEvaluation r =
      EvaluateTrajectory(Make(gt_t, gt_X), Make(est_t, est_X), o, "gt", "est");
  EXPECT_DOUBLE_EQ(r.tracked_ground_truth_path_m, 6.0);
  EXPECT_DOUBLE_EQ(r.ground_truth_full_path_m, 10.0);
  EXPECT_DOUBLE_EQ(r.tracked_path_coverage, 0.6);
  EXPECT_NEAR(r.tracked_scaled_ate_m, 0.5, 1e-12);
  // a ground truth that does not move: undefined (NaN), as the paper's coverage of a still
  // estimate is
  const TrajectoryEvaluation fixed =
      EvaluateTrajectory(Make({0, 1, 2}, {At(1, 0, 0), At(1, 0, 0), At(1, 0, 0)}),
                         Make({0, 1, 2}, {At(1, 0, 0), At(2, 0, 0), At(3, 0, 0)}), o, "gt", "est");
  EXPECT_TRUE(std::isnan(fixed.tracked_path_coverage));
  EXPECT_TRUE(std::isnan(fixed.tracked_scaled_ate_m));
}

TEST(Evaluation, TooFewAssociatedPosesNameTheFilesAndTheSpans) {
  const Trajectory gt = Make({0, 1, 2}, {At(0, 0, 0), At(1, 0, 0), At(2, 0, 0)});
  const Trajectory est = Make({100, 101}, {At(0, 0, 0), At(1, 0, 0)});
  try {
    EvaluateTrajectory(gt, est, EvaluationOptions{}, "gt.txt", "est.txt");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_EQ(e.file(), "est.txt");
    EXPECT_NE(std::string(e.what()).find("0 poses associated with the ground truth gt.txt "
                                         "(|dt| < 0.02 s after adding 0 s to the estimate's "
                                         "times; ground truth spans 0 .. 2 s, estimate 100 .. "
                                         "101 s); expected at least 2: check --offset and "
                                         "--max-dt"),
              std::string::npos)
        << e.what();
  }
  EvaluationOptions o;
  o.association.offset_sec = -100;
  EXPECT_EQ(EvaluateTrajectory(gt, est, o, "gt", "est").association.pairs.size(), 2u);
  // sim3 on an estimate that never moves
  const Trajectory still = Make({0, 1, 2}, {At(1, 1, 1), At(1, 1, 1), At(1, 1, 1)});
  o = EvaluationOptions{};
  o.alignment = AlignmentModel::kSim3;
  try {
    EvaluateTrajectory(gt, still, o, "gt.txt", "still.txt");
    FAIL();
  } catch (const ConfigError& e) {
    EXPECT_NE(std::string(e.what()).find("still.txt: the 3 associated estimated positions all "
                                         "coincide"),
              std::string::npos)
        << e.what();
  }
  // se3 on it: coverage and scaled ATE undefined (NaN), not a division by zero
  o.alignment = AlignmentModel::kSe3;
  const TrajectoryEvaluation r = EvaluateTrajectory(gt, still, o, "gt", "still");
  EXPECT_TRUE(std::isnan(r.coverage));
  EXPECT_TRUE(std::isnan(r.scaled_ate_m));
  o.max_gap_sec = -1;
  EXPECT_THROW(EvaluateTrajectory(gt, still, o, "gt", "still"), ConfigError);
}

}  // namespace
}  // namespace penumbra

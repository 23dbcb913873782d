// the nav benchmark's acceptance, part (a): the harness's collision debounce and SC (Eftekhar et
// al. 2024: SC = mean over episodes of S_i / (1 + c_i)) on hand-made episodes, the episode
// judgement (time to goal, fall, timeout) on hand-made pose series, and the summary's mean
// +- std over trials.

#include "penumbra/campaign/nav_metrics.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/campaign/nav_report.h"
#include "penumbra/core/error.h"

namespace penumbra {
namespace {

TEST(NavBenchmarkMetrics, DebounceMergesIntervalsOfOnePairCloserThanTheWindow) {
  const std::vector<ContactInterval> c = {
      {"go1", "room/wall", 1.0, 1.2},
      {"room/wall", "go1", 1.5, 1.6},   // 0.3 s after: the same collision (either side order)
      {"go1", "room/wall", 2.1, 2.3},   // exactly 0.5 s after 1.6: a new one (gap >= window)
      {"go1", "room/wall", 3.5, 3.6},   // 1.2 s after: a new one
      {"go1", "room/table", 1.1, 1.1},  // another pair: its own collision
  };
  EXPECT_EQ(CountCollisions(c, 0.5, 100), 4);
  // no debounce: every interval
  EXPECT_EQ(CountCollisions(c, 0.0, 100), 5);
  // a long window merges all of a pair's intervals
  EXPECT_EQ(CountCollisions(c, 10.0, 100), 2);
  // intervals starting after the episode's end do not count
  EXPECT_EQ(CountCollisions(c, 0.5, 2.0), 2);
  EXPECT_EQ(CountCollisions({}, 0.5, 100), 0);
  // merging follows the merged run's end, not the first interval's
  EXPECT_EQ(
      CountCollisions({{"r", "w", 0, 1.0}, {"r", "w", 0.2, 0.3}, {"r", "w", 1.4, 1.5}}, 0.5, 100),
      1);
  EXPECT_THROW(CountCollisions(c, -1, 100), Error);
  EXPECT_THROW(CountCollisions({{"r", "w", 2, 1}}, 0.5, 100), Error);
}

TEST(NavBenchmarkMetrics, SuccessWeightedByCollisionsIsTheMeanOfSOverOnePlusC) {
  // (1/1 + 1/3 + 0 + 1/2) / 4 = 11/24
  EXPECT_NEAR(SuccessWeightedByCollisions({true, true, false, true}, {0, 2, 1, 1}), 11.0 / 24.0,
              1e-15);
  EXPECT_DOUBLE_EQ(SuccessWeightedByCollisions({true, true}, {0, 0}), 1.0);
  EXPECT_DOUBLE_EQ(SuccessWeightedByCollisions({false, false}, {0, 7}), 0.0);
  EXPECT_TRUE(std::isnan(SuccessWeightedByCollisions({}, {})));
  EXPECT_THROW(SuccessWeightedByCollisions({true}, {0, 1}), Error);
  EXPECT_THROW(SuccessWeightedByCollisions({true}, {-1}), Error);
}

std::vector<NavPoseSample> Line(const std::vector<double>& xs, double dt) {
  std::vector<NavPoseSample> p;
  for (size_t i = 0; i < xs.size(); ++i) p.push_back({i * dt, xs[i], 0.0, 0.285, 1, 0, 0, 0});
  return p;
}

TEST(NavBenchmarkMetrics, EpisodeSuccessTimeToGoalAndDistanceFromThePoseSeries) {
  NavEpisodeTask task;
  task.goal_x = 3;
  task.radius_m = 0.5;
  task.timeout_sec = 60;
  task.debounce_sec = 0.5;
  const std::vector<NavPoseSample> poses = Line({0, 1, 2, 2.6, 2.8}, 1.0);
  NavEpisodeMetrics m = EvaluateNavEpisode(poses, {{"go1", "room/wall", 1.0, 1.1}}, task, true);
  EXPECT_TRUE(m.success);
  EXPECT_DOUBLE_EQ(m.time_to_goal_sec, 3.0);  // first sample within 0.5 m: x = 2.6 at t = 3
  EXPECT_NEAR(m.final_goal_distance_m, 0.2, 1e-12);
  EXPECT_DOUBLE_EQ(m.episode_time_sec, 4.0);
  EXPECT_NEAR(m.path_length_m, 2.8, 1e-12);
  EXPECT_EQ(m.collisions, 1);
  EXPECT_DOUBLE_EQ(m.sc, 0.5);
  // a method that failed: no success whatever the pose
  m = EvaluateNavEpisode(poses, {}, task, false);
  EXPECT_FALSE(m.success);
  EXPECT_DOUBLE_EQ(m.sc, 0.0);
  EXPECT_DOUBLE_EQ(m.time_to_goal_sec, -1);
  // the sim timeout ends the episode: judged at t = 2 (x = 2, 1 m away)
  task.timeout_sec = 2;
  m = EvaluateNavEpisode(poses, {{"go1", "room/wall", 2.5, 2.6}}, task, true);
  EXPECT_FALSE(m.success);
  EXPECT_DOUBLE_EQ(m.final_goal_distance_m, 1.0);
  EXPECT_DOUBLE_EQ(m.episode_time_sec, 2.0);
  EXPECT_EQ(m.collisions, 0);  // after the end
}

TEST(NavBenchmarkMetrics, AFallEndsTheEpisodeAsAFailure) {
  NavEpisodeTask task;
  task.goal_x = 3;
  task.radius_m = 0.5;
  std::vector<NavPoseSample> poses = Line({0, 1, 2, 3}, 1.0);
  poses[2].z = 0.1;  // below the quadruped's 0.15 m
  NavEpisodeMetrics m = EvaluateNavEpisode(poses, {}, task, true);
  EXPECT_TRUE(m.fell);
  EXPECT_FALSE(m.success);
  EXPECT_DOUBLE_EQ(m.fall_time_sec, 2.0);
  EXPECT_DOUBLE_EQ(m.final_goal_distance_m, 1.0);
  // rolled 60 deg about x: a fall by tilt
  poses = Line({0, 1, 2, 3}, 1.0);
  poses[3].qw = std::cos(M_PI / 6);
  poses[3].qx = std::sin(M_PI / 6);
  m = EvaluateNavEpisode(poses, {}, task, true);
  EXPECT_TRUE(m.fell);
  EXPECT_FALSE(m.success);
  // 30 deg is not
  poses[3].qw = std::cos(M_PI / 12);
  poses[3].qx = std::sin(M_PI / 12);
  EXPECT_TRUE(EvaluateNavEpisode(poses, {}, task, true).success);
  EXPECT_THROW(EvaluateNavEpisode({}, {}, task, true), Error);
}

NavRow Row(int trial, const std::string& episode, bool success, int collisions, double ttg,
           double dist, const std::string& status = "ok") {
  NavRow r;
  r.world = "w";
  r.episode = episode;
  r.condition = "none";
  r.method = "m";
  r.trial = trial;
  r.seed = static_cast<uint64_t>(trial);
  r.status = status;
  r.success = success;
  r.collisions = collisions;
  r.time_to_goal_sec = ttg;
  r.final_goal_distance_m = dist;
  r.sc = success ? 1.0 / (1 + collisions) : 0;
  return r;
}

TEST(NavBenchmarkMetrics, SummaryAveragesEpisodesPerTrialThenTrials) {
  BenchmarkSpec spec;
  spec.kind = "nav";
  BenchmarkWorld w;
  w.name = "w";
  w.episodes.resize(2);
  spec.worlds = {w};
  spec.conditions = {{"none", "none"}};
  BenchmarkMethod m;
  m.name = "m";
  spec.methods = {m};
  spec.seeds = {1, 2};
  const std::vector<NavRow> rows = {
      Row(1, "a", true, 0, 6.0, 0.4), Row(1, "b", true, 1, 10.0, 0.2),  // SC 0.75
      Row(2, "a", true, 0, 8.0, 0.3), Row(2, "b", false, 2, NAN, 1.3),  // SC 0.5
  };
  const std::vector<NavSummaryLine> lines = SummarizeNav(spec, rows);
  ASSERT_EQ(lines.size(), 1u);
  const NavSummaryLine& l = lines[0];
  EXPECT_EQ(l.rows, 4);
  EXPECT_EQ(l.ok, 4);
  EXPECT_DOUBLE_EQ(l.success.mean, 0.75);               // trials 1.0 and 0.5
  EXPECT_NEAR(l.success.std, std::sqrt(0.125), 1e-12);  // sample std of {1, 0.5}
  EXPECT_DOUBLE_EQ(l.collisions.mean, 0.75);            // trials 0.5 and 1.0
  EXPECT_DOUBLE_EQ(l.time_to_goal_sec.mean, 8.0);       // trials (6 + 10) / 2 and 8 (successes)
  EXPECT_DOUBLE_EQ(l.time_to_goal_sec.std, 0.0);
  EXPECT_DOUBLE_EQ(l.sc.mean, 0.625);  // trials 0.75 and 0.5
  EXPECT_NEAR(l.sc.std, std::sqrt(0.03125), 1e-12);
  EXPECT_DOUBLE_EQ(l.goal_distance_m.mean, (0.3 + 0.8) / 2);  // trials 0.3 and 0.8
  // a run_failed row is a failure that adds no collisions or distance
  std::vector<NavRow> more = rows;
  more[3] = Row(2, "b", false, 0, NAN, NAN, "run_failed");
  const NavSummaryLine l2 = SummarizeNav(spec, more)[0];
  EXPECT_EQ(l2.ok, 3);
  EXPECT_DOUBLE_EQ(l2.success.mean, 0.75);
  EXPECT_DOUBLE_EQ(l2.collisions.mean, 0.25);  // trials 0.5 and 0
}

}  // namespace
}  // namespace penumbra

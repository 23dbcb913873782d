// SensorSchedule: exact firing steps and counts over 10 s on the step count, no drift; rates
// above the physics rate fire every step without looping over skipped samples.
#include "penumbra/sensors/sensor_schedule.h"

#include <gtest/gtest.h>

#include <cmath>

#include "penumbra/core/error.h"
#include "penumbra/scene/sim_time.h"

namespace penumbra {
namespace {

TEST(SensorScheduleTest, FiresAtFirstStepAtOrAfterEachSampleTimeWithoutDrift) {
  for (double dt : {0.002, 0.0015, 0.003}) {
    SensorSchedule s(dt);
    const double rates[] = {30, 10, 200};
    for (double r : rates) s.Add("s" + std::to_string(static_cast<int>(r)), r, 0.05);
    std::vector<std::vector<SensorFiring>> fired(3);
    // steps up to the first one at or after 10 s, as the runner does
    for (int64_t n = 0;; ++n) {
      std::vector<SensorFiring> due;
      s.Due(n, &due);
      for (const SensorFiring& f : due) fired[f.sensor].push_back(f);
      if (SimTimeOfStep(n, dt) >= 10.0 - 1e-9) break;
    }
    for (int i = 0; i < 3; ++i) {
      const double rate = rates[i];
      // samples k = 0 .. 10 rate, all within [0, 10 s]
      const int64_t expected = static_cast<int64_t>(std::llround(10.0 * rate)) + 1;
      ASSERT_EQ(static_cast<int64_t>(fired[i].size()), expected) << "rate " << rate << " dt " << dt;
      EXPECT_EQ(s.skipped(i), 0);
      for (int64_t k = 0; k < expected; ++k) {
        const SensorFiring& f = fired[i][k];
        ASSERT_EQ(f.index, k);
        // the first step whose time is >= k / rate, exactly (no tolerance)
        int64_t n = 0;
        while (SimTimeOfStep(n, dt) * rate < static_cast<double>(k) &&
               std::fma(SimTimeOfStep(n, dt), rate, -static_cast<double>(k)) < 0)
          ++n;
        ASSERT_EQ(f.capture_time_sec, SimTimeOfStep(n, dt)) << "k " << k << " dt " << dt;
        ASSERT_GE(f.capture_time_sec, static_cast<double>(k) / rate);
        ASSERT_LT(f.capture_time_sec - static_cast<double>(k) / rate, dt);
        ASSERT_EQ(f.delivery_time_sec, f.capture_time_sec + 0.05);
      }
    }
  }
}

TEST(SensorScheduleTest, SampleTimesAreAtLeastKOverRateAndFloorGivesK) {
  // rates dividing the physics rate: floor(t * rate) == k for every sample (summed MuJoCo
  // time gave 3.999999999999781 for frame 40 of a 10 Hz camera at 500 Hz)
  for (double dt : {0.002, 0.001, 0.005, 0.01}) {
    for (double rate : {1.0, 10.0, 25.0, 30.0, 50.0, 100.0}) {
      SensorSchedule s(dt);
      s.Add("s", rate);
      if (std::fmod(PhysicsRateHz(dt), rate) != 0) continue;
      int64_t k = 0;
      for (int64_t n = 0; n <= static_cast<int64_t>(std::llround(60.0 / dt)); ++n) {
        std::vector<SensorFiring> due;
        s.Due(n, &due);
        for (const SensorFiring& f : due) {
          ASSERT_EQ(f.index, k);
          ASSERT_GE(f.capture_time_sec, static_cast<double>(k) / rate);
          ASSERT_EQ(static_cast<int64_t>(std::floor(f.capture_time_sec * rate)), k)
              << "dt " << dt << " rate " << rate << " t " << f.capture_time_sec;
          ++k;
        }
      }
      EXPECT_EQ(k, static_cast<int64_t>(60 * rate) + 1);
    }
  }
}

TEST(SensorScheduleTest, SameStepSameTimeAndRatesAbovePhysicsFireEveryStep) {
  SensorSchedule s(0.002);
  s.Add("a", 100, 0);
  s.Add("b", 50, 0);
  s.Add("fast", 1000, 0);
  s.Add("absurd", 1e300, 0);  // used to loop once per skipped sample
  s.Add("imu", 1e12, 0);
  EXPECT_FALSE(s.exceeds_physics_rate(0));
  EXPECT_TRUE(s.exceeds_physics_rate(2));
  EXPECT_TRUE(s.exceeds_physics_rate(3));
  EXPECT_EQ(s.effective_rate_hz(3), 500.0);
  int both = 0;
  std::vector<int64_t> fast_indices;
  for (int step = 0; step <= 100; ++step) {
    std::vector<SensorFiring> due;
    s.Due(step, &due);
    bool a = false, b = false;
    int every_step = 0;
    for (const SensorFiring& f : due) {
      if (f.sensor == 0) a = true;
      if (f.sensor == 1) b = true;
      if (f.sensor >= 2) ++every_step;
      if (f.sensor == 3) fast_indices.push_back(f.index);
      EXPECT_EQ(f.capture_time_sec, SimTimeOfStep(step, 0.002));
    }
    EXPECT_EQ(every_step, 3) << step;
    both += a && b;
  }
  EXPECT_EQ(both, 11);  // 50 Hz frames coincide with 100 Hz frames over 0.2 s
  ASSERT_EQ(fast_indices.size(), 101u);
  EXPECT_EQ(fast_indices.back(), 100);  // consecutive, no gaps
  EXPECT_EQ(s.skipped(3), 0);
  EXPECT_THROW(s.Add("zero", 0, 0), Error);
  EXPECT_THROW(s.Add("neg", 10, -1), Error);
  EXPECT_THROW(SensorSchedule(0.0), Error);
}

TEST(SensorScheduleTest, AJumpOverManyStepsSkipsArithmetically) {
  SensorSchedule s(0.001);
  s.Add("s", 250);
  std::vector<SensorFiring> due;
  s.Due(0, &due);
  // a billion steps later: one firing (the first overdue sample), the others up to
  // t = 1e6 s counted as skipped, and the next one is the first after that time
  s.Due(1000000000, &due);
  ASSERT_EQ(due.size(), 2u);
  EXPECT_EQ(due[1].index, 1);
  EXPECT_EQ(s.skipped(0), 250000000 - 1);
  due.clear();
  s.Due(1000000004, &due);
  ASSERT_EQ(due.size(), 1u);
  EXPECT_EQ(due[0].index, 250000001);
}

// a loop that starts at a later step (a replay from --from) fires what a run from step 0 fires
// from that step on, with the same indices and capture times
TEST(SensorScheduleTest, StartAtFiresAsARunFromStepZeroFromThatStepOn) {
  for (double dt : {0.002, 0.0015, 0.003}) {
    const double rates[] = {10, 30, 7.3, 1000};  // 1000 Hz: above the physics rate (every step)
    for (int64_t start : {int64_t{1}, int64_t{9000}, int64_t{4567}, int64_t{6001}}) {
      SensorSchedule full(dt), late(dt);
      for (double r : rates) {
        full.Add("s", r);
        late.Add("s", r);
      }
      late.StartAt(start);
      std::vector<SensorFiring> a, b;
      for (int64_t n = 0; n < start + 800; ++n) {
        std::vector<SensorFiring> due;
        full.Due(n, &due);
        if (n >= start) a.insert(a.end(), due.begin(), due.end());
        if (n >= start) late.Due(n, &b);
      }
      ASSERT_EQ(a.size(), b.size()) << "dt " << dt << " start " << start;
      ASSERT_FALSE(a.empty());
      for (size_t i = 0; i < a.size(); ++i) {
        EXPECT_EQ(a[i].sensor, b[i].sensor);
        EXPECT_EQ(a[i].index, b[i].index);
        EXPECT_EQ(a[i].capture_time_sec, b[i].capture_time_sec);
        EXPECT_EQ(a[i].nominal_time_sec, b[i].nominal_time_sec);
      }
    }
  }
  // StartAt(0) leaves a fresh schedule as it is; a negative step is refused
  SensorSchedule s(0.002);
  s.Add("s", 10);
  s.StartAt(0);
  std::vector<SensorFiring> due;
  s.Due(0, &due);
  ASSERT_EQ(due.size(), 1u);
  EXPECT_EQ(due[0].index, 0);
  EXPECT_THROW(s.StartAt(-1), Error);
}

}  // namespace
}  // namespace penumbra
